#!/usr/bin/env python3
"""Overshoot peaks of a finished seed 001 cycle campaign (D8) read from each job's series.csv with another level
window: a sensitivity check of `pressure_overshoot_ratio` (src/analysis/fluidization.rs), not part of the reducers.

    research/scripts/cycle-peaks.py results/d8-cohesion-beds [--from-fraction 0.0] [--column]

Each level's ΔP* is the mean ΔP over [start + f·hold, end of the level) over the mean W'/A there (the first-node
reading), or over W/A of the whole bed with --column; the peak is the top of the rising branch's climb, as in the
reducer. Prints one line per job and the mean peak per cohesion setting."""
import argparse, json, os, sqlite3

from reportlib import cycle_levels, read_job

ap = argparse.ArgumentParser()
ap.add_argument("dir")
ap.add_argument("--from-fraction", type=float, default=0.5)
ap.add_argument("--column", action="store_true")
args = ap.parse_args()

db = sqlite3.connect(os.path.join(args.dir, "campaign.sqlite"))
groups = {}
for (job_id,) in db.execute("SELECT job_id FROM jobs WHERE status = 'done' ORDER BY ordinal"):
    job_dir = os.path.join(args.dir, "jobs", job_id)
    p, metrics, rows = read_job(job_dir)
    t = [float(r["time_s"]) for r in rows]
    dp = [float(r["column_pressure_drop_pa" if args.column else "node_pressure_drop_pa"]) for r in rows]
    w = None if args.column else [float(r["node_weight_per_area_pa"]) for r in rows]
    whole = metrics["bed_weight_per_area_pa"]
    star = []
    for u, a, b in cycle_levels(job_dir, args.from_fraction):
        idx = [i for i in range(len(t)) if a <= t[i] < b]
        mean = sum(dp[i] for i in idx) / len(idx)
        weight = whole if w is None else sum(w[i] for i in idx) / len(idx)
        star.append((u, mean / weight))
    slowest = min(range(len(star)), key=lambda k: star[k][0])
    rising = star[slowest:]
    k = 1
    while k < len(rising) and rising[k][1] >= rising[k - 1][1]:
        k += 1
    peak = rising[k - 1]
    key = json.dumps(p.get("cohesion"))
    groups.setdefault(key, []).append(peak[1])
    print(f"{job_id} {key} seed {p.get('seed')}: peak ΔP* {peak[1]:.4f} at {peak[0]:.4f} m/s")
print()
for key, peaks in groups.items():
    print(f"{key}: mean peak {sum(peaks) / len(peaks):.4f} ({len(peaks)} jobs)")
