#!/usr/bin/env python3
"""Summary of seed 000's Ca_g campaign (campaigns/seed-000-cag-fluidized-bed.yaml) against the thesis's Table 4.

    python3 research/scripts/seed000-summary.py results/seed-000-cag-fluidized-bed > SUMMARY.md

Reads only the campaign's database (standard library only): the per-kind, per-liquid u_mf of the derived table,
each job's Ca_g, and the mixing rate constants, and prints Markdown.
"""

import json
import math
import sqlite3
import sys
from collections import defaultdict

# Seed 000 Table 4 (line 3085 of the extraction): (R mm, rho) -> dry, Ca_g 1.0, 1.5, 2.0 (m/s).
TABLE4 = {
    (1.35, 2000.0): (1.64, 1.66, 1.70, 1.75),
    (1.50, 2000.0): (1.75, 1.78, 1.81, 1.87),
    (1.50, 1000.0): (1.21, 1.23, 1.25, 1.29),
}
TENSIONS = [0.01, 0.02, 0.04, 0.08]


def kind_of(params):
    return (round(params["radius_m"] * 1e3, 2), params["density_kg_per_m3"])


def liquid_of(params):
    """None for dry, else the surface tension."""
    return None if params["liquid_content"] == 0.0 else params["surface_tension_n_per_m"]


def spearman(xs, ys):
    def ranks(v):
        order = sorted(range(len(v)), key=lambda i: v[i])
        r = [0.0] * len(v)
        i = 0
        while i < len(order):
            j = i
            while j + 1 < len(order) and v[order[j + 1]] == v[order[i]]:
                j += 1
            for k in range(i, j + 1):
                r[order[k]] = (i + j) / 2.0
            i = j + 1
        return r

    rx, ry = ranks(xs), ranks(ys)
    mx, my = sum(rx) / len(rx), sum(ry) / len(ry)
    sxy = sum((a - mx) * (b - my) for a, b in zip(rx, ry))
    sxx = sum((a - mx) ** 2 for a in rx)
    syy = sum((b - my) ** 2 for b in ry)
    return sxy / math.sqrt(sxx * syy) if sxx > 0 and syy > 0 else float("nan")


def fmt(v, digits=2):
    return "–" if v is None or (isinstance(v, float) and math.isnan(v)) else f"{v:.{digits}f}"


def main(directory):
    db = sqlite3.connect(f"{directory}/campaign.sqlite")
    jobs = {}
    for job_id, status, wall in db.execute("SELECT job_id, status, wall_time_s FROM jobs"):
        jobs[job_id] = {"params": {}, "status": status, "wall_s": wall, "metrics": {}}
    # The `params` table holds each sweep axis under its short name (radius_m, u_m_per_s, ...).
    for job_id, name, real, text in db.execute("SELECT job_id, name, value_real, value_text FROM params"):
        jobs[job_id]["params"][name] = real if real is not None else text
    for job_id, name, value in db.execute("SELECT job_id, name, value FROM metrics"):
        jobs[job_id]["metrics"][name] = value
    done = [j for j in jobs.values() if j["status"] == "done"]

    umf = defaultdict(dict)  # (kind, liquid) -> name -> value
    for group_json, name, value in db.execute("SELECT group_json, name, value FROM derived"):
        g = json.loads(group_json)
        umf[(kind_of(g), liquid_of(g))][name] = value

    def job_at(kind, liquid, u):
        for j in done:
            p = j["params"]
            if kind_of(p) == kind and liquid_of(p) == liquid and abs(p["u_m_per_s"] - u) < 1e-9:
                return j
        return None

    velocities = sorted({j["params"]["u_m_per_s"] for j in done})
    print("# Seed 000's Ca_g campaign: u_mf against Table 4, and mixing against Ca_g\n")
    print(
        f"{len(done)} of {len(jobs)} jobs done; {sum(j['wall_s'] or 0 for j in done) / 3600:.1f} h of job wall time "
        f"(two jobs at a time on 2 cores). Velocities: {', '.join(f'{u:g}' for u in velocities)} m/s.\n"
    )

    print("## u_mf\n")
    print(
        "u_mf is the lowest velocity of the sweep from which σ(ΔP) stays above 1 % of W/A at every higher velocity "
        "(the sustained-fluctuation reading of seed 000's criterion, §4.1.2; resolution 0.1 m/s); Ca_g is the job's own "
        "Ca_g at that velocity (seed 000 eq. 4.1 with the drag on one bead at u_mf). The thesis gives u_mf at Ca_g = "
        "1.0, 1.5 and 2.0; its wet columns are reproduced beside ours, which are per surface tension.\n"
    )
    print("| kind (R, ρ) | liquid | u_mf (m/s) | Ca_g at u_mf | shift from dry | largest-jump reading | Table 4 |")
    print("|---|---|---|---|---|---|---|")
    for kind, seed in TABLE4.items():
        dry = umf.get((kind, None), {}).get("u_mf_sustained_fluctuation_m_per_s")
        for liquid in [None] + TENSIONS:
            d = umf.get((kind, liquid), {})
            u = d.get("u_mf_sustained_fluctuation_m_per_s")
            jump = d.get("u_mf_pressure_fluctuation_m_per_s")
            j = job_at(kind, liquid, u) if u is not None else None
            cag = j["metrics"].get("granular_capillary_number") if (j and liquid is not None) else None
            shift = (u / dry - 1.0) * 100.0 if (u is not None and dry and liquid is not None) else None
            label = "dry" if liquid is None else f"γ = {liquid:g} N/m"
            table = (
                f"dry {seed[0]:.2f}"
                if liquid is None
                else ("Ca_g 1.0/1.5/2.0: " + " / ".join(f"{v:.2f}" for v in seed[1:]) if liquid == TENSIONS[0] else "")
            )
            u_text = fmt(u, 1) if u is not None else f"below {velocities[0]:g} or not bracketed"
            shift_text = "" if liquid is None else (f"{shift:+.0f} %" if shift is not None else "–")
            print(
                f"| R {kind[0]} mm, {kind[1]:g} kg/m³ | {label} | {u_text} | {fmt(cag)} | {shift_text} | "
                f"{fmt(jump, 1)} | {table} |"
            )
    print()
    print("Dry u_mf against Table 4 (VALIDATION D2 asks for 10 %):\n")
    for kind, seed in TABLE4.items():
        dry = umf.get((kind, None), {}).get("u_mf_sustained_fluctuation_m_per_s")
        if dry is not None:
            print(f"- R {kind[0]} mm, {kind[1]:g} kg/m³: {dry:.1f} m/s against {seed[0]:.2f} ({(dry / seed[0] - 1) * 100:+.0f} %)")
        else:
            print(f"- R {kind[0]} mm, {kind[1]:g} kg/m³: not bracketed by the sweep (Table 4: {seed[0]:.2f} m/s)")
    print()

    print("## Mixing rate against Ca_g\n")
    print(
        "k is the rate constant of the intensity of segregation towards the random mixture (10 nearest neighbours, "
        "fitted from 1 s to 5 s), 1/s; '–' where the bed did not mix enough to fit (packed or nearly so). Ca_g in "
        "brackets.\n"
    )
    pooled = []
    for kind in TABLE4:
        print(f"### R {kind[0]} mm, {kind[1]:g} kg/m³\n")
        print("| u (m/s) | dry | " + " | ".join(f"γ = {g:g}" for g in TENSIONS) + " |")
        print("|---|---|" + "---|" * len(TENSIONS))
        xs, ys = [], []
        for u in velocities:
            cells = []
            for liquid in [None] + TENSIONS:
                j = job_at(kind, liquid, u)
                if j is None:
                    cells.append("")
                    continue
                k = j["metrics"].get("mixing_rate_to_random_per_s")
                cag = j["metrics"].get("granular_capillary_number")
                if liquid is None:
                    cells.append(fmt(k))
                else:
                    cells.append(f"{fmt(k)} ({fmt(cag)})")
                    if k is not None and cag is not None:
                        xs.append(cag)
                        ys.append(k)
            print(f"| {u:g} | " + " | ".join(cells) + " |")
        rho = spearman(xs, ys) if len(xs) > 2 else float("nan")
        pooled += list(zip(xs, ys))
        print(f"\nWet jobs with a fitted k: {len(xs)}; Spearman rank correlation of k with Ca_g: {rho:+.2f}.\n")
    print("### k of the wet bed over k of the dry bed at the same velocity\n")
    print(
        "Median over the velocities where both beds mixed enough to fit k (the number of velocities in brackets); "
        "below 1: the liquid slows mixing.\n"
    )
    print("| kind (R, ρ) | " + " | ".join(f"γ = {g:g}" for g in TENSIONS) + " |")
    print("|---|" + "---|" * len(TENSIONS))
    for kind in TABLE4:
        cells = []
        for liquid in TENSIONS:
            ratios = []
            for u in velocities:
                wet, dry = job_at(kind, liquid, u), job_at(kind, None, u)
                if wet is None or dry is None:
                    continue
                kw = wet["metrics"].get("mixing_rate_to_random_per_s")
                kd = dry["metrics"].get("mixing_rate_to_random_per_s")
                if kw is not None and kd is not None and kd > 0.0:
                    ratios.append(kw / kd)
            ratios.sort()
            n = len(ratios)
            median = (ratios[n // 2] if n % 2 else 0.5 * (ratios[n // 2 - 1] + ratios[n // 2])) if n else None
            cells.append(f"{fmt(median)} ({n})")
        print(f"| R {kind[0]} mm, {kind[1]:g} kg/m³ | " + " | ".join(cells) + " |")
    print()
    if pooled:
        rho = spearman([p[0] for p in pooled], [p[1] for p in pooled])
        print(f"All kinds pooled: {len(pooled)} wet jobs, Spearman rank correlation of k with Ca_g {rho:+.2f}.\n")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "results/seed-000-cag-fluidized-bed")
