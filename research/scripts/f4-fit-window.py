#!/usr/bin/env python3
"""F4: how the line of CV_m against 1/sqrt(t) depends on where the fit starts.

The validation campaign fits from 1 s of coating (seed 000 §6.3.2: "all data achieved over 1 second show a linear
correlation"); the first rows after the spray starts carry the transient of the first surface layer. This refits each
job's series.csv from 1, 2, 3 and 4 s of coating with the reducer's formulas (slope, intercept, its standard error,
R²) and prints a Markdown table.

    python3 research/scripts/f4-fit-window.py <campaign dir> > research/f4-fit-window/FITS.md
"""
import csv
import glob
import json
import math
import os
import sys

SPRAY_START_S = 1.0


def fit(x, y):
    n = len(x)
    mx, my = sum(x) / n, sum(y) / n
    sxx = sum((a - mx) ** 2 for a in x)
    sxy = sum((a - mx) * (b - my) for a, b in zip(x, y))
    syy = sum((b - my) ** 2 for b in y)
    slope = sxy / sxx
    intercept = my - slope * mx
    res = sum((b - intercept - slope * a) ** 2 for a, b in zip(x, y))
    se = math.sqrt(res / (n - 2) * (1 / n + mx * mx / sxx))
    return slope, intercept, se, sxy * sxy / (sxx * syy)


def main():
    root = sys.argv[1]
    print("# F4: the CV_m line by where the fit starts\n")
    print(f"Campaign `{root}`; t is the coating time (from {SPRAY_START_S} s of simulated time).\n")
    print("| simulation | fit from (s of coating) | rows | slope (s^1/2) | intercept | s.e. | intercept/s.e. | R² |")
    print("|---|---|---|---|---|---|---|---|")
    jobs = []
    for jd in glob.glob(os.path.join(root, "jobs", "*")):
        params = dict(json.load(open(os.path.join(jd, "job.json")))["params"])
        series = os.path.join(jd, "series.csv")
        if os.path.exists(os.path.join(jd, "result.json")):
            jobs.append((params["named.simulation"], series))
    for name, series in sorted(jobs):
        rows = list(csv.DictReader(open(series)))
        for start in (1.0, 2.0, 3.0, 4.0):
            pts = [
                (1 / math.sqrt(float(r["time_s"]) - SPRAY_START_S), float(r["coating_variability"]))
                for r in rows
                if float(r["time_s"]) - SPRAY_START_S >= start
            ]
            x, y = zip(*pts)
            s, b, se, r2 = fit(x, y)
            print(f"| {name} | {start:g} | {len(x)} | {s:.3f} | {b:.3f} | {se:.4f} | {b / se:.1f} | {r2:.3f} |")


main()
