#!/usr/bin/env python3
"""How loose D3's lattice settles without gas, against the beads' stiffness, restitution and friction.

    python3 research/scripts/settle-porosity-probe.py --out results/settle-porosity-probe > REPORT.md

Builds scenarios from campaigns/validation/d3-wet-umf.yaml with the gas and the liquid removed: the lattice of 400
beads (3.0 mm apart) falls and settles for 0.8 s. For each Young's modulus (default 1e7, 1e9 and 6.9e10 Pa, the
last the seed's glass), each restitution coefficient (default D3's 0.9; `--restitutions`) and each friction
coefficient (default D3's and the seed's 0.3, particles and walls alike; `--friction-coefficients`) and each
rolling-resistance coefficient (default none, as in D3; `--rolling-friction-coefficients`, a constant directional
torque) it runs the unjittered lattice (seed 1) and the jittered one (D3's 0.14 mm, seeds 1-3, or 1-N with `--seeds N`), with
`granflow simulate`, two at a time; a finished run is not rerun. It prints the final mean bead height and bed top
and the porosity of the settled bed, ε = 1 - (2/3) φ₂, where φ₂ = N π R² / (W H) is the area fraction of the bed
(H = 2 x the mean centre height) and 2/3 the volume share of a sphere in the slab one diameter deep.

Needs PyYAML.
"""

import argparse
import copy
import json
import os
import sys

from reportlib import load_campaign, simulate_all, slab_porosity

CAMPAIGN = "campaigns/validation/d3-wet-umf.yaml"
END_TIME_S = 0.8
D3_RESTITUTION = 0.9
D3_FRICTION = 0.3


def wall_time(summary):
    """The run's wall time, or 'reused' for a run finished earlier (simulate then resumes at its last step and steps
    nothing)."""
    if summary.get("resumed_from_step") == summary["step"]:
        return "reused"
    return f"{summary['wall_time_s']:.0f}"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default="results/settle-porosity-probe")
    ap.add_argument("--granflow", default="target/release/granflow")
    ap.add_argument("--youngs-moduli-pa", type=float, nargs="+", default=[1e7, 1e9, 6.9e10])
    ap.add_argument("--restitutions", type=float, nargs="+", default=[D3_RESTITUTION])
    ap.add_argument("--rolling-friction-coefficients", type=float, nargs="+", default=[0.0])
    ap.add_argument("--seeds", type=int, default=3, help="jittered lattices per setting (seeds 1..N)")
    ap.add_argument("--friction-coefficients", type=float, nargs="+", default=[D3_FRICTION])
    args = ap.parse_args()
    base = load_campaign(CAMPAIGN)["base"]
    base.pop("gas")
    base.pop("cohesion")
    base["time"]["end_time_s"] = END_TIME_S
    base["output"] = {"checkpoint_every_steps": 10**9, "keep_checkpoints": 1, "series_every_steps": 1000}
    jitter_m = base["fill"][0]["lattice"]["jitter_m"]
    os.makedirs(args.out, exist_ok=True)
    jobs = []
    kinds = [
        (m, e, mu, mu_r)
        for m in args.youngs_moduli_pa
        for e in args.restitutions
        for mu in args.friction_coefficients
        for mu_r in args.rolling_friction_coefficients
    ]
    for modulus, restitution, friction, rolling in kinds:
        for jitter, seeds in ((0.0, (1,)), (jitter_m, range(1, args.seeds + 1))):
            for seed in seeds:
                s = copy.deepcopy(base)
                for sp in s["species"]:
                    sp["youngs_modulus_pa"] = modulus
                    sp["friction_coefficient"] = friction
                    sp["rolling_friction_coefficient"] = rolling
                    sp["liquid_content"] = 0.0
                for fill in s["fill"]:
                    fill["lattice"]["jitter_m"] = jitter
                s["contact"]["normal"]["hertz"]["restitution"] = restitution
                if rolling > 0.0:
                    s["contact"]["rolling"] = "constant_directional_torque"
                s["seed"] = seed
                # (D3's own values keep the names of the runs made before the options existed.)
                tag = "" if restitution == D3_RESTITUTION else f"-e{restitution:g}"
                tag += "" if friction == D3_FRICTION else f"-mu{friction:g}"
                tag += "" if rolling == 0.0 else f"-mur{rolling:g}"
                s["name"] = f"E{modulus:g}{tag}-jitter{jitter:g}-s{seed}"
                path = os.path.join(args.out, s["name"] + ".json")
                with open(path, "w") as fh:
                    json.dump(s, fh)
                jobs.append(((modulus, restitution, friction, rolling), jitter, seed, path, os.path.join(args.out, s["name"])))

    summaries = simulate_all(args.granflow, [(path, run_dir) for *_, path, run_dir in jobs])

    species = base["species"][0]
    radius_m = species["radius_m"]
    width_m = base["domain"]["hi_m"][0] - base["domain"]["lo_m"][0]
    depth_m = base["domain"]["hi_m"][2] - base["domain"]["lo_m"][2]
    print("# Settled porosity of D3's lattice against the beads' stiffness, restitution, friction and rolling resistance (no gas)\n")
    print(f"Command: `python3 research/scripts/settle-porosity-probe.py --out {args.out} --youngs-moduli-pa "
          f"{' '.join(f'{m:g}' for m in args.youngs_moduli_pa)} --restitutions {' '.join(f'{e:g}' for e in args.restitutions)} --friction-coefficients {' '.join(f'{mu:g}' for mu in args.friction_coefficients)} --rolling-friction-coefficients {' '.join(f'{mu:g}' for mu in args.rolling_friction_coefficients)} --seeds {args.seeds}`. Each run is `granflow simulate` of D3's lattice without gas or liquid for {END_TIME_S} s; {__doc__.split('two at a time; ')[1].split('Needs')[0].strip()}\n")
    print("| E (Pa) | restitution | friction | rolling friction | lattice | seed | mean height (mm) | bed top (mm) | ε | wall time (s) |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    by_kind = {}
    for ((modulus, restitution, friction, rolling), jitter, seed, _, _), summary in zip(jobs, summaries):
        eps = slab_porosity(summary["particles"], radius_m, width_m, depth_m, summary["mean_height_m"])
        by_kind.setdefault((modulus, restitution, friction, rolling, jitter), []).append(eps)
        kind = "jittered" if jitter > 0 else "exact"
        print(f"| {modulus:g} | {restitution:g} | {friction:g} | {rolling:g} | {kind} | {seed} | {summary['mean_height_m'] * 1e3:.2f} | {summary['bed_top_m'] * 1e3:.2f} "
              f"| {eps:.3f} | {wall_time(summary)} |")
    print(f"\n| E (Pa) | restitution | friction | rolling friction | exact lattice ε | jittered ε, mean of {args.seeds} | its standard error |")
    print("|---|---|---|---|---|---|---|")
    for modulus, restitution, friction, rolling in kinds:
        exact = by_kind[(modulus, restitution, friction, rolling, 0.0)][0]
        values = by_kind[(modulus, restitution, friction, rolling, jitter_m)]
        jittered = sum(values) / len(values)
        spread = (sum((v - jittered) ** 2 for v in values) / max(len(values) - 1, 1)) ** 0.5 / len(values) ** 0.5
        print(f"| {modulus:g} | {restitution:g} | {friction:g} | {rolling:g} | {exact:.3f} | {jittered:.3f} | {spread:.3f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
