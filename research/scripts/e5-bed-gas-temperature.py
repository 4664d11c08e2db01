"""E5 (the kiln's h_w): how warm is the gas inside the bed, against the particles and the freeboard? For every air job
of an E5-like campaign it reads the last checkpoint's gas temperature and porosity (h5py) and prints the mean gas
temperature of the cells inside the drum by porosity class (bed: ε < 0.7; edge: 0.7-0.99; freeboard: ε ≥ 0.99) beside
the particles' mean temperature.

    python3 research/scripts/e5-bed-gas-temperature.py results/e5-kiln-heat-transfer
"""
import glob
import json
import os
import sys

import h5py
import numpy as np


def main(campaign):
    print("| material | rpm | particles K | gas in bed K | gas at bed edge K | gas in freeboard K |")
    print("|---|---|---|---|---|---|")
    for job in sorted(glob.glob(os.path.join(campaign, "jobs", "*"))):
        spec = json.load(open(os.path.join(job, "scenario.json")))
        gas = spec.get("gas")
        if not gas or gas.get("vacuum"):
            continue
        checkpoints = sorted(glob.glob(os.path.join(job, "ckpt-*.h5")))
        if not checkpoints:
            continue
        with h5py.File(checkpoints[-1], "r") as f:
            t_gas = f["/gas/temperature_k"][:]
            eps = f["/gas/porosity"][:]
            t_particles = f["/particles/temperature_k"][:]
        lo, hi = spec["domain"]["lo_m"], spec["domain"]["hi_m"]
        n = gas["cells"]
        drum = spec["walls"][0]["drum"]
        cell = np.arange(len(t_gas))
        i, j = cell % n[0], (cell // n[0]) % n[1]
        x = lo[0] + (i + 0.5) * (hi[0] - lo[0]) / n[0] - drum["axis_point_m"][0]
        y = lo[1] + (j + 0.5) * (hi[1] - lo[1]) / n[1] - drum["axis_point_m"][1]
        inside = np.hypot(x, y) < drum["radius_m"]

        def mean(mask):
            m = mask & inside
            return f"{t_gas[m].mean():.1f}" if m.any() else "-"

        print(
            f"| {spec['species'][0].get('material')} | {drum['rotation_rpm']:g} | {t_particles.mean():.2f} | "
            f"{mean(eps < 0.7)} | {mean((eps >= 0.7) & (eps < 0.99))} | {mean(eps >= 0.99)} |"
        )


if __name__ == "__main__":
    main(sys.argv[1])
