"""Does a drum lift its bed, or does the bed slide? From a run's last checkpoint (or the one given).

usage: /usr/bin/python3 research/scripts/drum-slip.py RUN_DIR_OR_CHECKPOINT DRUM_RADIUS_M RPM

Prints, for the particles at the bottom of the drum (below -0.6 R) within 2.5 mm of the wall, their mean velocity
along the wall over the wall's own speed Omega R, and their mean spin over Omega; and the slope of the free
surface (least squares through the third-highest particle of ten columns across the middle 80 % of the drum).
A bed turning with the drum: about (R - a)/R and 1 (solid-body rotation). A bearing layer: about 0.5 and R/(2a).
"""
import glob
import sys

import h5py
import numpy as np

path, radius_m, rpm = sys.argv[1], float(sys.argv[2]), float(sys.argv[3])
checkpoint = path if path.endswith(".h5") else sorted(glob.glob(path + "/ckpt-*.h5"))[-1]
f = h5py.File(checkpoint, "r")
x = f["particles/position_m"][:]
v = f["particles/velocity_m_per_s"][:]
w = f["particles/angular_velocity_rad_per_s"][:]
omega = rpm * 2 * np.pi / 60
r = np.hypot(x[:, 0], x[:, 1])
bottom = (x[:, 1] < -0.6 * radius_m) & (r > radius_m - 0.0025)
print(f"{checkpoint}: t = {f.attrs.get('time_s', float('nan'))}")
print(f"  wall layer at the bottom ({bottom.sum()} particles): v_x / (Omega R) = "
      f"{np.mean(v[bottom, 0]) / (omega * radius_m):.3f}, spin / Omega = {np.mean(w[bottom, 2]) / omega:.2f}")
xs, ys = [], []
for lo in np.linspace(-0.8 * radius_m, 0.7 * radius_m, 10):
    m = (x[:, 0] >= lo) & (x[:, 0] < lo + 0.1 * radius_m)
    if m.sum() >= 3:
        xs.append(lo + 0.05 * radius_m)
        ys.append(np.sort(x[m, 1])[-3])
print(f"  free surface slope: {np.degrees(np.arctan(np.polyfit(xs, ys, 1)[0])):.1f} deg")
