#!/usr/bin/env python3
"""Why D2's dry u_mf is 9 % below seed 000's at 2000 kg/m3 and not at 1000: the packed bed's porosity.

    python3 research/scripts/d2-packing-porosity.py > research/d2-packing-porosity/POROSITY.md

Reads the job table of results/validation/d2-dry-umf/REPORT.md (one job per velocity and particle kind; mean
pressure drop, its standard deviation, the bed weight per area and the mean bead height over 1.5-3.5 s). Below
u_mf the bed is packed, and the porosity that the drag law needs to give the measured pressure drop is solved
for. The model is Di Felice's drag as the engine has it (PHYSICS §3, `src/engine/models/drag.rs`):
- F = ½ C_d ρ_g π R² w² ε^(2−χ), with w = U/ε the interstitial slip;
- the gas momentum carries −ε∇p, so ΔP/H = n F/ε and each bead feels F/ε in all;
- hence ΔP/(W/A) = F(U, ε)/(ε m g), and u_mf is where F(u_mf, ε)/(ε m g) = 1.

The script prints, for each particle kind:
- the packed-bed porosity from the pressure drop (ε_ΔP, every packed velocity);
- the porosity from the bed's height (ε_h): one layer of spheres in a slab one diameter deep holds 2/3 of the
  slab's area fraction φ₂, and the bed is 2 × the mean centre height tall;
- the porosity at which the same law puts u_mf at our measured value, and at the seed's Table 4 value.

No other dependency than the Python standard library.
"""

import math
import sys

from reportlib import job_rows, slab_porosity

REPORT = "results/validation/d2-dry-umf/REPORT.md"
GAS_DENSITY_KG_PER_M3 = 1.23
GAS_VISCOSITY_PA_S = 1.8e-5
G_M_PER_S2 = 9.81
WIDTH_M = 0.03
# Seed 000 Table 4, dry column, by (radius mm, density kg/m3).
SEED_UMF_M_PER_S = {(1.35, 2000.0): 1.64, (1.5, 2000.0): 1.75, (1.5, 1000.0): 1.21}
# A packed bed's σ(ΔP) is at most 0.1 % of W/A; a moving one's at least 1.5 % (D3's criterion uses 1 %).
PACKED_SIGMA_FRACTION = 0.01


def drag_n(u_m_per_s, porosity, radius_m):
    """Di Felice drag on one bead in a bed of superficial velocity U at rest (seed 000 eqs 2.71-2.73)."""
    w = u_m_per_s / porosity
    re = GAS_DENSITY_KG_PER_M3 * 2.0 * radius_m * porosity * w / GAS_VISCOSITY_PA_S
    cd = (0.63 + 4.8 / math.sqrt(re)) ** 2
    chi = 3.7 - 0.65 * math.exp(-((1.5 - math.log10(re)) ** 2) / 2.0)
    return 0.5 * cd * GAS_DENSITY_KG_PER_M3 * math.pi * radius_m**2 * w * w * porosity ** (2.0 - chi)


def solve_porosity(ratio, u_m_per_s, radius_m, mass_kg):
    """ε with F(U, ε)/(ε m g) = ratio, by bisection (the left side falls monotonically with ε)."""
    lo, hi = 0.25, 0.9
    f = lambda e: drag_n(u_m_per_s, e, radius_m) / (e * mass_kg * G_M_PER_S2) - ratio
    if f(lo) < 0.0 or f(hi) > 0.0:
        raise SystemExit(f"no porosity in [{lo}, {hi}] gives ΔP/(W/A) = {ratio:.4f} at {u_m_per_s} m/s")
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if f(mid) > 0.0 else (lo, mid)
    return 0.5 * (lo + hi)


def measured_umf(path):
    """Our u_mf per particle kind, from the report's checks (e.g. '| u_mf, R = 1.35 mm, rho = 2000 kg/m3 | 1.5000 |')."""
    out = {}
    for line in open(path, encoding="utf-8"):
        if line.startswith("| u_mf, R = "):
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            name = cells[0].split(",")
            radius_mm = float(name[1].split("=")[1].split()[0])
            density = float(name[2].split("=")[1].split()[0])
            out[(radius_mm, density)] = float(cells[1])
    return out


def main():
    rows = job_rows(REPORT)
    ours = measured_umf(REPORT)
    groups = {}
    for r in rows:
        key = (round(float(r["param.radius_m"]) * 1e3, 3), float(r["param.density_kg_per_m3"]))
        groups.setdefault(key, []).append(r)
    print("# D2: the packed bed's porosity behind the dry u_mf\n")
    print(f"Command: `python3 research/scripts/d2-packing-porosity.py`, from the job table of `{REPORT}`. "
          + __doc__.split("for. ")[1].split("No other dependency")[0].strip() + "\n")
    print("| R (mm) | ρ (kg/m3) | packed velocities (m/s) | ε_ΔP (range) | ε_h | ε at our u_mf | ε at the seed's u_mf |")
    print("|---|---|---|---|---|---|---|")
    for (radius_mm, density), jobs in sorted(groups.items()):
        radius_m = radius_mm * 1e-3
        mass_kg = density * 4.0 / 3.0 * math.pi * radius_m**3
        depth_m = float(jobs[0]["param.domain.hi_m[2]"])
        eps_dp, eps_h, packed_u = [], [], []
        for j in sorted(jobs, key=lambda j: float(j["param.u_m_per_s"])):
            u = float(j["param.u_m_per_s"])
            weight = float(j["metric.bed_weight_per_area_pa [Pa]"])
            mean_dp = float(j["metric.pressure_drop_mean_pa [Pa]"])
            sigma = float(j["metric.pressure_drop_std_pa [Pa]"])
            if sigma > PACKED_SIGMA_FRACTION * weight:
                continue
            packed_u.append(u)
            eps_dp.append(solve_porosity(mean_dp / weight, u, radius_m, mass_kg))
            beads = weight * WIDTH_M * depth_m / (mass_kg * G_M_PER_S2)
            eps_h.append(slab_porosity(beads, radius_m, WIDTH_M, depth_m,
                                       float(j["metric.mean_height_time_avg_m [m]"])))
        ours_eps = solve_porosity(1.0, ours[(radius_mm, density)], radius_m, mass_kg)
        seed_eps = solve_porosity(1.0, SEED_UMF_M_PER_S[(radius_mm, density)], radius_m, mass_kg)
        mean = lambda v: sum(v) / len(v)
        print(f"| {radius_mm:g} | {density:g} | {packed_u[0]:g}-{packed_u[-1]:g} | {mean(eps_dp):.3f} "
              f"({min(eps_dp):.3f}-{max(eps_dp):.3f}) | {mean(eps_h):.3f} | {ours_eps:.3f} "
              f"({ours[(radius_mm, density)]:g} m/s) | {seed_eps:.3f} ({SEED_UMF_M_PER_S[(radius_mm, density)]:g} m/s) |")
    print("\nFor scale, one layer of touching spheres in a slab one diameter deep: hexagonal order ε = "
          f"{1 - math.pi / (3 * math.sqrt(3)):.3f}, square order ε = {1 - math.pi / 6:.3f}.")
    return 0


if __name__ == "__main__":
    sys.exit(main())
