#!/usr/bin/env python3
"""Does D3's bed stay square-packed when loaded on a square lattice? (the two square-lattice probes)

    python3 research/scripts/square-lattice-findings.py > research/d3-square-lattice-probe/FINDINGS.md

Seed 000 §4.1 loads its fluidized beds "in a rectangular lattice", and §5.2 (Fig. 61) takes a pseudo-2-D bed's void
fraction to be 0.476, one layer of touching beads in square order. Under our Di Felice law the seed's dry u_mf of
1.64 m/s needs a packed-bed porosity of 0.469 (research/d2-packing-porosity/POROSITY.md). This script reads the
series of every job of

- results/d3-square-lattice-probe (beads dropped from a square lattice 30/11 mm apart), and
- results/d3-square-packed-probe (beads placed square-packed, columns touching; stopped after its first jobs had
  shown the same collapse, so its jobs may be unfinished),

and prints, per job: the porosity of the bed at the start and after settling (0.4-0.5 s, before the gas), from the
mean bead height (one layer of spheres in a slab one diameter deep: ε = 1 − N (4/3)πR³ / (W D · 2 h̄)), when the
columns fell (the first time the mean height is 2 % below its start), and the job's u_mf if it finished. It also
prints the u_mf that the engine's drag law gives for a packed bed at each of those porosities. Last, it runs the
square-packed bed's dry scenario without gas for 0.3 s (`granflow simulate`, in --scratch) and prints its porosity
then: whether the columns stand without the gas.

Standard library only, plus reportlib and the drag law of d2-packing-porosity.py.
"""

import argparse
import csv
import importlib.util
import json
import math
import os

from reportlib import load_campaign, read_job, simulate_all, slab_porosity

HERE = os.path.dirname(os.path.abspath(__file__))
spec = importlib.util.spec_from_file_location("packing", os.path.join(HERE, "d2-packing-porosity.py"))
packing = importlib.util.module_from_spec(spec)
spec.loader.exec_module(packing)

PROBES = ["results/d3-square-lattice-probe", "results/d3-square-packed-probe"]
RADIUS_M = 0.00135
DENSITY_KG_PER_M3 = 2000.0
BEADS = 400
WIDTH_M = 0.03
DEPTH_M = 0.0027
MASS_KG = DENSITY_KG_PER_M3 * 4.0 / 3.0 * math.pi * RADIUS_M**3


def porosity_from_mean_height(h_m):
    return slab_porosity(BEADS, RADIUS_M, WIDTH_M, DEPTH_M, h_m)


def umf_at(porosity):
    """The superficial velocity at which a packed bed of this porosity carries its weight (bisection)."""
    lo, hi = 0.1, 5.0
    f = lambda u: packing.drag_n(u, porosity, RADIUS_M) / (porosity * MASS_KG * packing.G_M_PER_S2) - 1.0
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if f(mid) > 0.0 else (mid, hi)
    return 0.5 * (lo + hi)


def job_summary(job_dir):
    params, metrics, rows = read_job(job_dir)
    t = [float(r["time_s"]) for r in rows]
    h = [float(r["mean_height_m"]) for r in rows]
    settled = [hh for tt, hh in zip(t, h) if 0.4 <= tt < 0.5]
    fell = next((tt for tt, hh in zip(t, h) if hh < 0.98 * h[0]), None)
    umf, state = None, f"stopped at {t[-1]:.2f} s"
    if metrics is not None:
        umf = metrics.get("stepped_fluidization_velocity_m_per_s")
        state = "done"
    return {
        "liquid": params["species[0].liquid_content"],
        "gamma": params["cohesion.liquid_bridge.surface_tension_n_per_m"],
        "eps0": porosity_from_mean_height(h[0]),
        "eps": porosity_from_mean_height(sum(settled) / len(settled)) if settled else None,
        "fell": fell,
        "umf": umf,
        "state": state,
    }


def settle_without_gas(granflow, scratch):
    """The square-packed probe's dry bed without gas for 0.3 s: (porosity at the start, at the end)."""
    base = load_campaign("research/d3-square-lattice-probe/d3-square-packed-probe.yaml")["base"]
    base.pop("gas")
    base.pop("cohesion")
    for sp in base["species"]:
        sp["liquid_content"] = 0.0
    base["name"] = "square-packed-no-gas"
    base["seed"] = 1
    base["time"]["end_time_s"] = 0.3
    os.makedirs(scratch, exist_ok=True)
    path = os.path.join(scratch, base["name"] + ".json")
    with open(path, "w") as fh:
        json.dump(base, fh)
    run_dir = os.path.join(scratch, base["name"])
    simulate_all(granflow, [(path, run_dir)], parallel=1)
    rows = list(csv.DictReader(open(os.path.join(run_dir, "series.csv"))))
    return (porosity_from_mean_height(float(rows[0]["mean_height_m"])),
            porosity_from_mean_height(float(rows[-1]["mean_height_m"])))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--granflow", default="target/release/granflow")
    ap.add_argument("--scratch", default="results/square-lattice-findings")
    args = ap.parse_args()
    print("# D3 loaded on a square lattice: the columns fall over\n")
    print("Command: `python3 research/scripts/square-lattice-findings.py` (reads the probes' job series; see the script's")
    print("docstring for the measures). The campaigns: `research/d3-square-lattice-probe/d3-square-lattice-probe.yaml` and")
    print("`research/d3-square-lattice-probe/d3-square-packed-probe.yaml`.\n")
    print("| probe | liquid V/R³ | γ (N/m) | ε at start | ε settled (0.4-0.5 s) | columns fell at (s) | u_mf (m/s) | job |")
    print("|---|---|---|---|---|---|---|---|")
    settled = []
    for probe in PROBES:
        jobs = os.path.join(probe, "jobs")
        if not os.path.isdir(jobs):
            continue
        for job in sorted(os.listdir(jobs)):
            if not os.path.exists(os.path.join(jobs, job, "series.csv")):
                continue  # never started
            s = job_summary(os.path.join(jobs, job))
            if s["eps"] is None:
                continue
            settled.append(s["eps"])
            umf = "—" if s["state"] != "done" else ("below 1.20 (moving at every level)" if s["umf"] is None else f"{s['umf']:.3f}")
            fell = "—" if s["fell"] is None else f"{s['fell']:.3f}"
            print(f"| {os.path.basename(probe)} | {s['liquid']} | {s['gamma']:.4f} | {s['eps0']:.3f} | {s['eps']:.3f} | {fell} | {umf} | {s['state']} |")
    print("\nThe engine's drag law (Di Felice, as in `research/d2-packing-porosity/POROSITY.md`) puts a packed bed's u_mf at:\n")
    print("| porosity | what | u_mf (m/s) |")
    print("|---|---|---|")
    marks = [(0.395, "one layer of touching beads in hexagonal order"),
             (min(settled), "the most compact settled bed above"),
             (0.445, "D3's jittered lattices, settled (POROSITY.md)"),
             (0.469, "the seed's 1.64 m/s (POROSITY.md)"),
             (0.476, "one layer of touching beads in square order (the seed's Fig. 61)"),
             (1.0 - (math.pi / 6.0) * 2.0 * RADIUS_M / (WIDTH_M / 11.0), "square columns 30/11 mm apart, as loaded here")]
    for eps, what in marks:
        print(f"| {eps:.3f} | {what} | {umf_at(eps):.3f} |")
    start, end = settle_without_gas(args.granflow, args.scratch)
    print(f"\nThe square-packed bed, dry, without gas (`granflow simulate`, 0.3 s): ε {start:.3f} at the start, "
          f"{end:.3f} at 0.3 s.")


if __name__ == "__main__":
    main()
