#!/usr/bin/env python3
"""The net force on a D8-type bed by mechanism, level by level, through the rising branch of seed 001's cycle: for
each job of a campaign run with `output.net_forces: true` and `gas.inflow_levels`, one line per level from the
cycle's slowest level on, each value a mean over the second half of the level's hold (as the cycle metrics read
them), forces over the bed weight W:

  U       the level's superficial velocity (m/s)
  dP*     seed 001's ΔP/(W'/A) (node_pressure_drop_pa over node_weight_per_area_pa)
  fluid   the gas's force against gravity
  side_f  the sidewalls' friction (their contact and cohesion forces against gravity)
  side_n  the sidewalls' normal load (their contact forces across gravity, `*_contact_across_n`)
  mob     side_f over μ side_n: the share of the friction the sidewalls could give that they do give (negative:
          holding the bed down)
  dist_c  the distributor's contact force; dist_h its cohesion
  h_mm    the beads' mean centre height

A diagnostic for D8's sidewall-friction checks, not a reducer.

    pip install pyyaml
    research/scripts/cycle-net-forces.py results/d8-step-friction
    research/scripts/cycle-net-forces.py results/d8-step-friction --levels 8 --friction 0.3

The sidewalls are the walls named box_x_lo and box_x_hi, the distributor box_y_lo (D8's box); --sidewalls and
--distributor name others."""
import argparse
import glob
import json
import os

from reportlib import cycle_levels, read_job

ap = argparse.ArgumentParser()
ap.add_argument("dir", help="a campaign directory (with jobs/)")
ap.add_argument("--levels", type=int, default=20, help="levels to print from the slowest one on")
ap.add_argument("--friction", type=float, default=0.3, help="the bead-wall friction coefficient μ")
ap.add_argument("--sidewalls", nargs="+", default=["box_x_lo", "box_x_hi"])
ap.add_argument("--distributor", default="box_y_lo")
args = ap.parse_args()


def label(params):
    parts = []
    for key, value in params.items():
        if isinstance(value, dict):
            value = json.dumps(value, separators=(",", ":"))
        parts.append(f"{key}={value}")
    return " ".join(parts)


for job_dir in sorted(glob.glob(os.path.join(args.dir, "jobs", "*"))):
    params, metrics, rows = read_job(job_dir)
    if metrics is None:
        continue
    levels = cycle_levels(job_dir)
    slowest = min(range(len(levels)), key=lambda k: levels[k][0])
    print(f"{os.path.basename(job_dir)}  {label(params)}")
    print("  lvl      U     dP*   fluid   side_f  side_n     mob  dist_c  dist_h    h_mm")
    t = [float(r["time_s"]) for r in rows]
    for k in range(slowest, min(slowest + args.levels, len(levels))):
        u, lo, hi = levels[k]
        sel = [r for r, tk in zip(rows, t) if lo <= tk < hi]
        if not sel:
            break

        def mean(column_sum):
            return sum(column_sum(r) for r in sel) / len(sel)

        def col(r, name):
            return float(r[name])

        weight = mean(lambda r: col(r, "weight_n"))
        dp = mean(lambda r: col(r, "node_pressure_drop_pa") / col(r, "node_weight_per_area_pa"))
        fluid = mean(lambda r: col(r, "fluid_force_up_n")) / weight
        side_f = mean(lambda r: sum(col(r, f"wall_{w}_contact_up_n") + col(r, f"wall_{w}_cohesion_up_n")
                                    for w in args.sidewalls)) / weight
        side_n = mean(lambda r: sum(col(r, f"wall_{w}_contact_across_n") for w in args.sidewalls)) / weight
        mob = side_f / (args.friction * side_n) if side_n > 0 else float("nan")
        dist_c = mean(lambda r: col(r, f"wall_{args.distributor}_contact_up_n")) / weight
        dist_h = mean(lambda r: col(r, f"wall_{args.distributor}_cohesion_up_n")) / weight
        height = mean(lambda r: col(r, "mean_height_m")) * 1000
        print(f"  {k:3d} {u:6.3f} {dp:7.4f} {fluid:7.4f} {side_f:+8.4f} {side_n:7.4f} {mob:+7.3f}"
              f" {dist_c:+7.4f} {dist_h:+7.4f} {height:7.3f}")
    print()
