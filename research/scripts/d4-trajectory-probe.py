#!/usr/bin/env python3
"""D4 trajectory probe: how the wet beds of VALIDATION D4 mix, followed particle by particle.

    python3 research/scripts/d4-trajectory-probe.py --out results/d4-trajectory-probe > REPORT.md

Builds up to 18 scenarios from campaigns/validation/d4-mixing-vs-cag.yaml at --velocity (default 2.0 m/s): dry and
--tensions (default gamma = 0.02 and 0.08 N/m), replicate seeds 1-3, wet beads carrying --liquid-content V/R^3 of liquid (default 0.01, D4's); each as the
campaign has it (400 equal beads on a jittered lattice; --beds mono) and with five radii (0.95-1.00 x 1.35 mm, drawn
per bead, same lattice and jitter, to break the lattice's order; --beds poly), or both (default); --width-factor W
makes the bed W times as wide (domain, gas cells across and lattice columns; same height). Each runs with
`granflow simulate`, two at a time, with a checkpoint every 1600 steps (0.02 s) kept, so that every bead can be
followed. A finished run is not rerun. Prints Markdown; writes frames.png (needs matplotlib; seed 1 of the equal
beads) into --out.

Needs numpy, h5py and PyYAML. The measures do not use the campaign's kNN neighbourhoods:
- colour = which half a bead started in; f(t) = fraction of the left-starting beads in the right half, after
  shifting every bead by the bed's mean lateral drift (x is periodic, so a bed that slides sideways as a whole would
  otherwise look mixed); 0.5 = mixed;
- k_half: least-squares fit of 0.5 - f(t) = (0.5 - f(1 s)) exp(-k (t - 1 s)) over 1-5 s;
- MSD_x(1 s): mean square lateral displacement over 1 s lags (unwrapped across the periodic sides, the drift
  removed), from 1 s on;
- mean height of the bead centres and the rms vertical velocity, from 1 s on.
"""

import argparse
import copy
import json
import os
import random
import sys
from glob import glob

import h5py
import numpy as np

from reportlib import load_campaign, simulate_all

CAMPAIGN = "campaigns/validation/d4-mixing-vs-cag.yaml"
SEEDS = (1, 2, 3)
RADIUS_FACTORS = (0.95, 0.9625, 0.975, 0.9875, 1.0)
CHECKPOINT_EVERY_STEPS = 1600


def scenario(base, name, seed, liquid, gamma, poly, youngs_modulus_pa, width_factor, u_m_per_s):
    s = copy.deepcopy(base)
    # A wider bed: the domain, the gas cells across it and the lattice's columns scale; its height stays.
    s["domain"]["hi_m"][0] = base["domain"]["hi_m"][0] * width_factor
    s["gas"]["cells"][0] = base["gas"]["cells"][0] * width_factor
    for fill in s["fill"]:
        fill["lattice"]["lo_m"][0] *= width_factor
        fill["lattice"]["hi_m"][0] *= width_factor
    # A stiffer bead has a shorter contact time, so a shorter DEM step (dt is a fraction of it, t_c ~ E^(-2/5));
    # the gas step and the checkpoint interval keep their lengths in seconds.
    steps_scale = (youngs_modulus_pa / base["species"][0]["youngs_modulus_pa"]) ** 0.4
    for sp in s["species"]:
        sp["youngs_modulus_pa"] = youngs_modulus_pa
    s["gas"]["dem_steps_per_gas_step"] = round(base["gas"]["dem_steps_per_gas_step"] * steps_scale)
    s["name"] = name
    s["seed"] = seed
    s["gas"]["sides"]["y_low"]["inlet"]["superficial_velocity_m_per_s"] = u_m_per_s
    s["cohesion"]["liquid_bridge"]["surface_tension_n_per_m"] = gamma
    s.setdefault("output", {})
    s["output"]["checkpoint_every_steps"] = round(CHECKPOINT_EVERY_STEPS * steps_scale)
    s["output"]["keep_checkpoints"] = 400
    for sp in s["species"]:
        sp["liquid_content"] = liquid
    if poly:
        # Same lattice (10 x 40 points, 3 mm apart, jitter up to 0.14 mm), radii drawn per bead; colour is taken
        # from the starting half, so the species are sizes here, not colours.
        template = s["species"][0]
        s["species"] = []
        for k, f in enumerate(RADIUS_FACTORS):
            sp = dict(template)
            sp["name"] = f"r{k}"
            sp["radius_m"] = template["radius_m"] * f
            s["species"].append(sp)
        s["walls"] = [{"box": {"species": s["species"][-1]["name"]}}]
        rng = random.Random(1000 + seed)
        per = {sp["name"]: [] for sp in s["species"]}
        for iy in range(40):
            for ix in range(10 * width_factor):
                x = 0.0015 + 0.003 * ix + rng.uniform(-1.4e-4, 1.4e-4)
                y = 0.0015 + 0.003 * iy + rng.uniform(-1.4e-4, 1.4e-4)
                per[f"r{rng.randrange(len(RADIUS_FACTORS))}"].append([x, y, template["radius_m"]])
        s["fill"] = [{"explicit": {"species": k, "positions_m": v}} for k, v in per.items() if v]
    return s


def load(run_dir):
    times, x, v = [], [], []
    for f in sorted(glob(os.path.join(run_dir, "ckpt-*.h5"))):
        with h5py.File(f, "r") as h:
            times.append(float(h.attrs["time_s"]))
            x.append(h["particles/position_m"][:, :2])
            v.append(h["particles/velocity_m_per_s"][:, :2])
    return np.array(times), np.array(x), np.array(v)


def measure(run_dir, width_m):
    t, x, v = load(run_dir)
    # Unwrap x across the periodic sides: of the images, the one nearest the position the mean velocity predicts.
    xu = x[:, :, 0].copy()
    for k in range(1, len(t)):
        predicted = xu[k - 1] + 0.5 * (v[k - 1, :, 0] + v[k, :, 0]) * (t[k] - t[k - 1])
        xu[k] = x[k, :, 0] + np.round((predicted - x[k, :, 0]) / width_m) * width_m
    drift = xu.mean(axis=1) - xu[0].mean()
    left = x[0, :, 0] < width_m / 2
    shifted = np.mod(xu - drift[:, None], width_m)
    f = np.array([np.mean(shifted[k, left] >= width_m / 2) for k in range(len(t))])
    late = t >= 1.0
    gap, tau = 0.5 - f[late], t[late] - 1.0
    rates = np.linspace(0.01, 5.0, 500)
    k_half = rates[int(np.argmin([np.sum((gap - gap[0] * np.exp(-r * tau)) ** 2) for r in rates]))]
    i0, lag = int(np.argmax(late)), int(round(1.0 / (t[1] - t[0])))
    dx = (xu[i0 + lag:] - xu[i0:len(t) - lag]) - (drift[i0 + lag:] - drift[i0:len(t) - lag])[:, None]
    at = lambda s: f[int(np.argmin(abs(t - s)))]
    return {
        "k_half": k_half,
        "f": [at(s) for s in (1.5, 2.0, 3.0, 5.0)],
        "msd_x_mm2": float(np.mean(dx ** 2) * 1e6),
        "mean_height_mm": float(x[late, :, 1].mean() * 1e3),
        "vy_rms": float(np.sqrt(np.mean(v[late, :, 1] ** 2))),
    }


def frames(runs, out_png, times, width_m):
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return False
    fig, axes = plt.subplots(len(runs), len(times), figsize=(1.5 * len(times), 3.4 * len(runs)))
    for a, (label, run_dir) in enumerate(runs):
        t, x, _ = load(run_dir)
        left = x[0, :, 0] < width_m / 2
        for b, s in enumerate(times):
            k = int(np.argmin(abs(t - s)))
            ax = axes[a][b]
            ax.scatter(x[k, :, 0], x[k, :, 1], s=5, c=np.where(left, "tab:blue", "tab:orange"))
            ax.set_xlim(0, width_m)
            ax.set_ylim(0, 0.3)
            ax.set_aspect("equal")
            ax.set_xticks([])
            ax.set_yticks([])
            ax.set_title(f"{label} {t[k]:.2f} s", fontsize=6)
    plt.tight_layout()
    plt.savefig(out_png, dpi=100)
    return True


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default="results/d4-trajectory-probe")
    ap.add_argument("--granflow", default="target/release/granflow")
    ap.add_argument("--liquid-content", type=float, default=0.01, help="V/R^3 of liquid per wet bead (D4: 0.01)")
    ap.add_argument("--beds", choices=["mono", "poly", "both"], default="both")
    ap.add_argument("--width-factor", type=int, default=1, help="bed width as a multiple of D4's 30 mm")
    ap.add_argument("--youngs-modulus-pa", type=float, default=None, help="default: the campaign's")
    ap.add_argument("--velocity", type=float, default=2.0, help="superficial gas velocity, m/s")
    ap.add_argument("--tensions", type=float, nargs="+", default=[0.02, 0.08], help="surface tensions of the wet beds, N/m")
    args = ap.parse_args()
    campaign = load_campaign(CAMPAIGN)
    base = campaign["base"]
    width_m = (base["domain"]["hi_m"][0] - base["domain"]["lo_m"][0]) * args.width_factor
    os.makedirs(args.out, exist_ok=True)
    jobs = []
    youngs_modulus_pa = args.youngs_modulus_pa or float(base["species"][0]["youngs_modulus_pa"])
    liquids = [("dry", 0.0, 0.01)] + [(f"wet-{g}", args.liquid_content, g) for g in args.tensions]
    beds = {"mono": (False,), "poly": (True,), "both": (False, True)}[args.beds]
    for poly in beds:
        for label, liquid, gamma in liquids:
            for seed in SEEDS:
                name = f"{'poly' if poly else 'mono'}-{label}-s{seed}"
                path = os.path.join(args.out, name + ".json")
                with open(path, "w") as fh:
                    json.dump(scenario(base, name, seed, liquid, gamma, poly, youngs_modulus_pa, args.width_factor,
                                        args.velocity), fh)
                jobs.append((name, path, os.path.join(args.out, name)))

    simulate_all(args.granflow, [(path, run_dir) for _, path, run_dir in jobs])

    print(f"# D4 trajectory probe: dry and wet beds followed bead by bead ({args.velocity:g} m/s)\n")
    print(f"Command: `python3 research/scripts/d4-trajectory-probe.py --out {args.out} --liquid-content {args.liquid_content} "
          f"--beds {args.beds} --youngs-modulus-pa {youngs_modulus_pa:g} --width-factor {args.width_factor} "
          f"--velocity {args.velocity:g} --tensions {' '.join(f'{g:g}' for g in args.tensions)}`. Wet beads carry V/R³ = {args.liquid_content} of "
          f"liquid; E = {youngs_modulus_pa:g} Pa. {__doc__.split('PyYAML. ')[1].strip()}\n")
    print("| bed | liquid | seed | k_half (1/s) | f at 1.5 / 2 / 3 / 5 s | MSD_x(1 s) (mm²) | mean height (mm) | "
          "rms v_y (m/s) |")
    print("|---|---|---|---|---|---|---|---|")
    means = {}
    for name, _, run_dir in jobs:
        m = measure(run_dir, width_m)
        bed, seed = name.split("-")[0], name.rsplit("-s", 1)[1]
        label = name[len(bed) + 1:].rsplit("-s", 1)[0]
        means.setdefault((bed, label), []).append(m)
        print(f"| {bed} | {label} | {seed} | {m['k_half']:.2f} | {' / '.join(f'{v:.3f}' for v in m['f'])} | "
              f"{m['msd_x_mm2']:.1f} | {m['mean_height_mm']:.1f} | {m['vy_rms']:.3f} |")
    print("\n## Means over the three seeds\n")
    print("| bed | liquid | k_half (1/s) | k_half / dry | MSD_x(1 s) (mm²) | mean height (mm) | rms v_y (m/s) |")
    print("|---|---|---|---|---|---|---|")
    for (bed, label), ms in means.items():
        k = np.mean([m["k_half"] for m in ms])
        k_dry = np.mean([m["k_half"] for m in means[(bed, "dry")]])
        print(f"| {bed} | {label} | {k:.2f} | {k / k_dry:.2f} | {np.mean([m['msd_x_mm2'] for m in ms]):.1f} | "
              f"{np.mean([m['mean_height_mm'] for m in ms]):.1f} | {np.mean([m['vy_rms'] for m in ms]):.3f} |")
    shown = [(n.replace("mono-", "").replace("-s1", ""), d) for n, _, d in jobs if n.startswith("mono") and n.endswith("s1")]
    if shown and frames(shown, os.path.join(args.out, "frames.png"), [0.9, 1.1, 1.2, 1.3, 1.5, 2.0, 3.0, 4.0, 5.0], width_m):
        print(f"\nframes.png: seed 1 of each liquid (mono), beads coloured by the half they started in.")


if __name__ == "__main__":
    sys.exit(main())
