"""E5 (the kiln's h_w): how the estimate depends on what is fitted. For every finished job of an E5-like campaign it
reads `series.csv` and prints, beside the product's metric (the core's log slope from the wall's start, eq. 5.21),
- the delay before the core warms (the first time it is 1 % of the way the whole bed has gone),
- h_w from the core fitted only from that delay on,
- h_w from the inner core (half the radius),
- h_w from the whole bed's mean temperature (the core grown to the bed: eq. 5.21 with <T_bed>).

    python3 research/scripts/e5-kiln-estimators.py results/e5-kiln-heat-transfer > research/e5-kiln-estimators/ESTIMATORS.md
"""

import csv
import json
import math
import os
import sys

TABLE7 = {  # density kg/m3, heat capacity J/(kg K)
    "glass": (2700.0, 800.0),
    "steel": (7900.0, 477.0),
    "aluminium": (2700.0, 900.0),
}


def fit_slope(t, y):
    n = len(t)
    if n < 3:
        return float("nan")
    mt, my = sum(t) / n, sum(y) / n
    stt = sum((a - mt) ** 2 for a in t)
    sty = sum((a - mt) * (b - my) for a, b in zip(t, y))
    return sty / stt if stt > 0 else float("nan")


def h_w(slope, cp_w, arc, radius, length, omega):
    t_c = arc / omega
    area = arc * radius * length
    return cp_w * -math.expm1(slope * t_c) / (area * t_c)


def main(campaign_dir):
    rows = []
    jobs = os.path.join(campaign_dir, "jobs")
    for job in sorted(os.listdir(jobs)):
        d = os.path.join(jobs, job)
        if not os.path.exists(os.path.join(d, "result.json")):
            continue
        spec = json.load(open(os.path.join(d, "job.json")))
        params = spec["params"]
        p = {k.split(".")[-1]: v for k, v in params} if isinstance(params, list) else params
        scenario = spec["scenario"]
        material = scenario["species"][0]["material"]
        radius_p = scenario["species"][0]["radius_m"]
        drum = scenario["walls"][0]["drum"]
        heat = scenario["heat"]
        wall = heat["walls"]["drum"]
        t_w, from_s = wall["temperature_k"], wall.get("from_s", 0.0)
        omega = drum["rotation_rpm"] * 2 * math.pi / 60
        length = scenario["domain"]["hi_m"][2] - scenario["domain"]["lo_m"][2]
        summary = json.load(open(os.path.join(d, "summary.json")))
        density, cp = TABLE7[material]
        cp_w = cp * summary["particles"] * density * 4 / 3 * math.pi * radius_p**3
        series = list(csv.DictReader(open(os.path.join(d, "series.csv"))))
        t = [float(r["time_s"]) for r in series]
        col = lambda name: [float(r[name]) for r in series]
        core, inner, bed, arc = col("core_temperature_k"), col("inner_core_temperature_k"), col(
            "mean_temperature_k"
        ), col("drum_contact_arc_rad")
        k0 = next(k for k in range(len(t)) if t[k] >= from_s)
        window = range(k0, len(t))
        arc_mean = sum(arc[k] for k in window) / len(window)

        def estimate(values, start):
            ks = [k for k in window if t[k] >= start and values[k] < t_w]
            ys = [math.log((t_w - values[k]) / (t_w - values[k0])) for k in ks]
            s = fit_slope([t[k] for k in ks], ys)
            return h_w(s, cp_w, arc_mean, drum["radius_m"], length, omega)

        # The core's delay: the first time it has gone 1 % of the way the whole bed has gone by the end.
        target = core[k0] + 0.01 * (bed[-1] - bed[k0])
        delay = next((t[k] - from_s for k in window if core[k] >= target), float("nan"))
        metrics = {m["name"]: m["value"] for m in json.load(open(os.path.join(d, "result.json")))["metrics"]}
        rows.append(
            (
                material,
                drum["rotation_rpm"],
                "vacuum" if scenario.get("gas", {}).get("vacuum") else "air",
                metrics["wall_heat_transfer_coefficient_w_per_m2_k"],
                delay,
                estimate(core, from_s + delay) if delay == delay else float("nan"),
                estimate(inner, from_s),
                estimate(bed, from_s),
                bed[-1] - bed[k0],
            )
        )
    print("| material | rpm | gas | h_w core (product) | core delay s | h_w core after delay | h_w inner core | h_w bed mean | bed rise K |")
    print("|---|---|---|---|---|---|---|---|---|")
    for r in sorted(rows):
        print("| {} | {:g} | {} | {:.3g} | {:.2f} | {:.3g} | {:.3g} | {:.3g} | {:.3f} |".format(*r))


if __name__ == "__main__":
    main(sys.argv[1])
