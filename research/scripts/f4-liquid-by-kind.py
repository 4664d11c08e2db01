"""F4: the liquid each kind of particle holds at the end of every job of a spray-coating campaign.

Reads each job's last checkpoint: the particle's film (`particles/liquid_m3`), half of every active pair bridge and
all of an active bridge to a wall, as F4's CV_m counts them (the particles start dry). Prints a Markdown table per
kind: count, mean liquid, mean V/R³, the spread within the kind (σ/μ) and the kind's mean height, and σ/μ over all.

    /usr/bin/python3 research/scripts/f4-liquid-by-kind.py results/f4-spray-coating > research/f4-liquid-by-kind/LIQUID.md
"""
import glob
import json
import os
import sys

import h5py
import numpy as np


def held_liquid_m3(h):
    p = h["particles"]
    held = p["liquid_m3"][:].copy()
    pairs = h["contacts/pairs"]
    for a, b, v, on in zip(pairs["i"][:], pairs["j"][:], pairs["bridge_volume_m3"][:], pairs["active"][:]):
        if on and v > 0:
            held[a] += v / 2
            held[b] += v / 2
    walls = h["contacts/walls"]
    for a, v, on in zip(walls["i"][:], walls["bridge_volume_m3"][:], walls["active"][:]):
        if on and v > 0:
            held[a] += v
    return held


def main(campaign_dir):
    rows = []
    for job in sorted(glob.glob(os.path.join(campaign_dir, "jobs", "*"))):
        ckpts = sorted(glob.glob(os.path.join(job, "ckpt-*.h5")))
        if not ckpts:
            continue
        params = dict(json.load(open(os.path.join(job, "job.json")))["params"])
        with h5py.File(ckpts[-1], "r") as h:
            p = h["particles"]
            species, radius = p["species"][:], p["radius_m"][:]
            y = p["position_m"][:, 1]
            held = held_liquid_m3(h)
            step = os.path.basename(ckpts[-1])
        name = params.get("named.simulation", os.path.basename(job))
        for s in np.unique(species):
            m = species == s
            g = held[m]
            rows.append((name, step, int(s), int(m.sum()), g.mean(), np.mean(g / radius[m] ** 3), g.std() / g.mean(), 1000 * y[m].mean()))
        rows.append((name, step, "all", len(held), held.mean(), np.mean(held / radius ** 3), held.std() / held.mean(), 1000 * y.mean()))
    print(f"# F4: liquid held per kind at the end of each job (`{campaign_dir}`)\n")
    print("| simulation | checkpoint | kind | particles | mean liquid m³ | mean V/R³ | σ/μ | mean height mm |")
    print("|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r[0]} | {r[1]} | {r[2]} | {r[3]} | {r[4]:.3e} | {r[5]:.4f} | {r[6]:.3f} | {r[7]:.2f} |")


if __name__ == "__main__":
    main(sys.argv[1])
