#!/usr/bin/env python3
"""Who touches the sidewalls of a seed 001 cycle campaign (D8): for each job's checkpoints, the particles in contact
with the left and right walls (box_x_lo, box_x_hi), and how many of them stand in single file on the distributor:
the run of wall-touching particles that starts at the bottom (centre within 1 % of R above the distributor) and goes
up with centres one diameter apart (within 1 %). A diagnostic for D8's sidewall-friction check, not a reducer.

    pip install h5py numpy
    research/scripts/sidewall-contacts.py results/d8-cohesion-beds
    research/scripts/sidewall-contacts.py results/d8-hamaker-wall-rolling --walls 2 3   # walls given as planes

Prints one line per job and checkpoint: contacts on each sidewall, the single-file run on each, the bed's highest
wall contact."""
import argparse, glob, json, os, sqlite3

import h5py
import numpy as np

ap = argparse.ArgumentParser()
ap.add_argument("dir")
ap.add_argument("--walls", type=int, nargs=2, default=[0, 1],
                help="indices of the two sidewalls in the scenario's wall list (a box's x walls are 0 and 1)")
args = ap.parse_args()

db = sqlite3.connect(os.path.join(args.dir, "campaign.sqlite"))
rows = db.execute("SELECT job_id, params_json FROM jobs WHERE status = 'done' ORDER BY ordinal").fetchall()


def label(params):
    params = json.loads(params)
    off = params.get("cohesion_off")
    if off is not None:
        parts = (["particles"] if off.get("between_particles") else []) + off.get("walls", [])
        return "off: " + " ".join(parts)
    if "cohesion" not in params:
        return ", ".join(f"{k.rsplit('.', 1)[-1][:12]}={v}" for k, v in params.items() if k != "seed")
    c = params["cohesion"]
    if not c:
        return "dry"
    (model, p), = c.items()
    return f"{model} {p.get('depth_j', p.get('constant_j')):g} J"


def single_file(heights, radius):
    """Length of the bottom-anchored run of centres one diameter apart."""
    heights = np.sort(heights)
    if len(heights) == 0 or abs(heights[0] - radius) > 0.01 * radius:
        return 0
    run = 1
    for a, b in zip(heights, heights[1:]):
        if abs((b - a) - 2 * radius) > 0.02 * radius:
            break
        run += 1
    return run


print(f"{'case':<22} {'job':<17} {'t (s)':>5}  {'x_lo':>4} {'file':>4}  {'x_hi':>4} {'file':>4}  {'top (mm)':>8}")
for job_id, params in rows:
    for path in sorted(glob.glob(os.path.join(args.dir, "jobs", job_id, "ckpt-*.h5"))):
        with h5py.File(path, "r") as f:
            wall = f["contacts/walls/wall"][:]
            who = f["contacts/walls/i"][:]
            x = f["particles/position_m"][:]
            radius = float(np.median(f["particles/radius_m"][:]))
            time_s = float(f["gas/time_s"][0]) if "gas/time_s" in f else float("nan")
            out = []
            for w in args.walls:
                sel = who[wall == w]
                out += [len(sel), single_file(x[sel, 1], radius)]
            top = 1000 * x[who[np.isin(wall, args.walls)], 1].max() if np.isin(wall, args.walls).any() else 0.0
            print(f"{label(params):<22} {job_id:<17} {time_s:5.2f}  {out[0]:4d} {out[1]:4d}  {out[2]:4d} {out[3]:4d}  {top:8.1f}")
