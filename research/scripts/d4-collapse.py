#!/usr/bin/env python3
"""D4's collapse test: mixing rate constants of every D4 run against Ca_g, from the committed reports.

    python3 research/scripts/d4-collapse.py --out research/d4-near-umf-probe
    python3 research/scripts/d4-collapse.py --reports results/validation/d4-mixing-vs-cag-viscous/REPORT.md \
        --out research/d4-collapse-viscous

By default it reads the job tables of results/validation/d4-mixing-vs-cag/REPORT.md (2.0, 2.4, 2.8 m/s) and
research/d4-near-umf-probe/REPORT.md (1.65, 1.8 m/s): the rate constant towards a random mixture
(metric mixing_rate_to_random_per_s) and Ca_g of each job. Prints Markdown (the mean over the three packings of each
velocity and liquid, its Ca_g and its ratio to the dry bed at the same velocity) and writes collapse.png (needs
matplotlib): k against Ca_g, one marker per velocity, the dry beds at Ca_g = 0. Seed 000's Fig. 50 has every wet run
on one curve that drops as Ca_g grows. `--reports` names other D4 reports to read instead (same job table columns).
"""

import argparse
import os
import statistics
import sys

from reportlib import job_rows

REPORTS = (
    "results/validation/d4-mixing-vs-cag/REPORT.md",
    "research/d4-near-umf-probe/REPORT.md",
)
TENSIONS = (0.01, 0.02, 0.04, 0.08)
# Our dry u_mf (the mean over D3's eight packings) is read from D3's checks.
D3_REPORT = "results/validation/d3-wet-umf/REPORT.md"


def d3_dry_umf_m_per_s():
    """The value of D3's check named 'dry u_mf'."""
    for line in open(D3_REPORT, encoding="utf-8"):
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if line.startswith("|") and cells[0] == "dry u_mf":
            return float(cells[1])
    raise SystemExit(f"{D3_REPORT}: no 'dry u_mf' check")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default="research/d4-near-umf-probe")
    ap.add_argument("--reports", nargs="+", default=list(REPORTS))
    args = ap.parse_args()
    # (u, wet, γ) -> [(k, Ca_g)]; a dry job's γ only labels it.
    runs = {}
    for path in args.reports:
        for r in job_rows(path):
            u = float(r["param.u_m_per_s"])
            wet = float(r["param.liquid_content"]) > 0.0
            gamma = float(r["param.surface_tension_n_per_m"]) if wet else 0.0
            runs.setdefault((u, wet, gamma), []).append(
                (float(r["metric.mixing_rate_to_random_per_s [1/s]"]), float(r["metric.granular_capillary_number [1]"]))
            )
    velocities = sorted({u for u, _, _ in runs})
    dry_umf = d3_dry_umf_m_per_s()
    print(f"# D4 collapse test: mixing rate constant against Ca_g at {len(velocities)} gas velocities\n")
    command = "python3 research/scripts/d4-collapse.py" + (
        "" if args.reports == list(REPORTS) else " --reports " + " ".join(args.reports))
    print(f"Command: `{command} --out {args.out}`, from the job tables of "
          + " and ".join(f"`{p}`" for p in args.reports) + ". "
          "k: rate constant towards a random mixture (1/s), mean over three packings; [Ca_g]; k / k(dry) at the same "
          f"velocity. u_mf: our dry u_mf, {dry_umf} m/s (D3).\n")
    print("| u (m/s) | u / u_mf | dry k | " + " | ".join(f"γ = {g} N/m: k [Ca_g] ratio" for g in TENSIONS) + " |")
    print("|---" * (3 + len(TENSIONS)) + "|")
    mean = {key: statistics.mean(k for k, _ in v) for key, v in runs.items()}
    for u in velocities:
        dry = mean[(u, False, 0.0)]
        cells = []
        for g in TENSIONS:
            k, ca = mean[(u, True, g)], runs[(u, True, g)][0][1]
            cells.append(f"{k:.3f} [{ca:.2f}] {k / dry:.2f}")
        print(f"| {u:g} | {u / dry_umf:.2f} | {dry:.3f} | " + " | ".join(cells) + " |")
    slower = sorted((runs[(u, True, g)][0][1], u, g) for u in velocities for g in TENSIONS
                    if mean[(u, True, g)] < mean[(u, False, 0.0)])
    print("\nWet beds that mix slower than the dry bed at their velocity: "
          + ", ".join(f"{u:g} m/s with γ = {g} N/m (Ca_g {ca:.2f})" for ca, u, g in slower) + ".")
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return 0
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    for u, marker in zip(velocities, "os^Dv"):
        xs = [0.0] + [runs[(u, True, g)][0][1] for g in TENSIONS]
        ys = [mean[(u, False, 0.0)]] + [mean[(u, True, g)] for g in TENSIONS]
        ax.plot(xs, ys, marker=marker, label=f"{u:g} m/s")
    ax.set_xlabel("Ca_g (dry beds at 0)")
    ax.set_ylabel("mixing rate constant k (1/s), mean of 3 packings")
    ax.set_yscale("log")
    ax.legend(title="gas velocity")
    ax.set_title("D4: k against Ca_g (seed 000 Fig. 50: one falling curve)")
    fig.tight_layout()
    os.makedirs(args.out, exist_ok=True)
    fig.savefig(os.path.join(args.out, "collapse.png"), dpi=110)
    print(f"\ncollapse.png: k against Ca_g, one line per velocity.")
    return 0


if __name__ == "__main__":
    sys.exit(main())
