#!/usr/bin/env python3
"""Issue 41: each reading's D3 / D4 probe beside the committed Hertz campaign's jobs of the same packings.

Reads the job tables of the `granflow report` files (research/d41-*/*-REPORT.md, among them the Hertz campaigns
committed before issue 41 in research/d41-hertz-baseline/, and the committed results/validation/d3-wet-umf and
d4-mixing-vs-cag reports, which use the adopted readings) and prints, per report, the numbers the D3 and D4
checks use: D3 the mean stepped u_mf of the dry beds and the wet beds' shifts at Ca_g 1.0 / 1.5 / 2.0; D4 k(γ = 0.08)
/ k(dry) at 2.0 / 2.4 / 2.8 m/s and k(2.8) / k(2.0) at γ = 0.02 and 0.08 (mixing_rate_to_random_per_s). Failed jobs
are counted and left out, as are beds with no u_mf by the last level (a number they enter prints as "-"). The Hertz
column is the pre-issue-41 campaign's jobs of the same packings, run by an older engine (its dry beds on packings 1-2:
1.5000 m/s; today's engine: 1.4375, the dry jobs of d3-bond-as-printed and d3-cag-own-umf).

Run from the repository root:  python3 research/scripts/d41-compare.py
"""
import glob
import math
from collections import defaultdict

D3_BASE = "research/d41-hertz-baseline/d3-wet-umf-hertz-REPORT.md"
D4_BASE = "research/d41-hertz-baseline/d4-mixing-vs-cag-hertz-REPORT.md"
D3_ADOPTED = "results/validation/d3-wet-umf/REPORT.md"
D4_ADOPTED = "results/validation/d4-mixing-vs-cag/REPORT.md"


def job_rows(path):
    """(done rows as dicts, number of failed jobs) of a report's job table."""
    rows, failed, header = [], 0, None
    for line in open(path, encoding="utf-8"):
        if line.startswith("| status"):
            header = [c.strip().split(" [")[0] for c in line.strip().strip("|").split("|")]
        elif header and line.startswith("| done"):
            rows.append(dict(zip(header, [c.strip() for c in line.strip().strip("|").split("|")])))
        elif header and line.startswith("| failed"):
            failed += 1
    return rows, failed


def check_results(path):
    """[(check name, our number, pass/FAIL)] of a report's check table."""
    out, inside = [], False
    for line in open(path, encoding="utf-8"):
        if line.startswith("| check |"):
            inside = True
            continue
        if inside and line.startswith("|---"):
            continue
        if inside and line.startswith("|"):
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            out.append((cells[0], cells[1], cells[-1]))
        elif inside:
            break
    return out


def seeds_of(rows):
    return sorted({r["param.seed"] for r in rows}, key=int)


def d3_numbers(path, seeds):
    rows, failed = job_rows(path)
    by_case = defaultdict(list)
    for r in rows:
        if r["param.seed"] in seeds:
            case = (float(r["param.liquid_content"]) > 0, float(r["param.surface_tension_n_per_m"]))
            value = r["metric.stepped_fluidization_velocity_m_per_s"]
            # Empty: the bed did not fluidize by the last level (1.85 m/s); the mean is then undefined.
            by_case[case].append(float(value) if value else float("nan"))
    mean = {k: sum(v) / len(v) for k, v in by_case.items()}
    dry = [v for (wet, _), v in mean.items() if not wet][0]
    wet = [mean[k] for k in sorted(k for k in mean if k[0])]
    return dry, [w / dry for w in wet], failed


def d4_numbers(path, seeds):
    rows, failed = job_rows(path)
    k = defaultdict(list)
    for r in rows:
        if r["param.seed"] in seeds:
            key = (float(r["param.surface_tension_n_per_m"]), float(r["param.liquid_content"]) > 0,
                   float(r["param.u_m_per_s"]))
            k[key].append(float(r["metric.mixing_rate_to_random_per_s"]))
    k = {a: sum(b) / len(b) for a, b in k.items()}
    nan = float("nan")
    g = lambda gamma, wet, u: k.get((gamma, wet, u), nan)
    wet_over_dry = [g(0.08, True, u) / g(0.01, False, u) for u in (2.0, 2.4, 2.8)]
    fast_over_slow = [g(gamma, True, 2.8) / g(gamma, True, 2.0) for gamma in (0.02, 0.08)]
    return wet_over_dry, fast_over_slow, failed


def fmt(x, spec):
    return "-" if math.isnan(x) else format(x, spec)


def name_of(path):
    if path.startswith("results/"):
        return path.split("/")[-2] + " (committed, adopted readings)"
    return path.split("/")[-1].replace("-REPORT.md", "")


def reports(case, adopted):
    """The committed campaign's report (if it exists), then the research reports of this case."""
    found = sorted(glob.glob("research/d41-*/%s-*-REPORT.md" % case))
    return ([adopted] if glob.glob(adopted) else []) + found


SHORT_D3 = ["dry", "Ca 1", "Ca 1.5", "Ca 2", "Ca 1 / dry", "Ca 2 / dry"]
SHORT_D4 = ["wet/dry 2.0", "wet/dry 2.4", "wet/dry 2.8", "2.8/2.0 γ .02", "2.8/2.0 γ .08"]
for case, adopted, short in (("d3", D3_ADOPTED, SHORT_D3), ("d4", D4_ADOPTED, SHORT_D4)):
    print("## %s: each report's checks (its own packings; the committed campaign first)\n" % case.upper())
    print("| report | packings | " + " | ".join(short) + " | passed |")
    print("|---" * (len(short) + 3) + "|")
    for path in reports(case, adopted):
        checks = check_results(path)
        seeds = seeds_of(job_rows(path)[0])
        cells = ["%s %s" % ("pass" if r == "pass" else "**FAIL**", "-" if v == "NaN" else v) for _, v, r in checks]
        print("| %s | %s | %s | %d of %d |" % (name_of(path), ",".join(seeds), " | ".join(cells),
                                               sum(r == "pass" for _, _, r in checks), len(checks)))
    print()


def d3_row(path, seeds):
    dry, shifts, failed = d3_numbers(path, seeds)
    bdry, bshifts, _ = d3_numbers(D3_BASE, seeds)
    return ["%.4f" % dry] + ["-" if math.isnan(s) else "%+.1f %%" % (100 * (s - 1)) for s in shifts] + [
        "%.4f; %s" % (bdry, " / ".join("%+.1f %%" % (100 * (s - 1)) for s in bshifts)), str(failed)]


def d4_row(path, seeds):
    wd, fs, failed = d4_numbers(path, seeds)
    bwd, bfs, _ = d4_numbers(D4_BASE, seeds)
    return [fmt(x, ".2f") for x in wd + fs] + [
        " / ".join(fmt(x, ".2f") for x in bwd) + "; " + " / ".join(fmt(x, ".2f") for x in bfs), str(failed)]


SUMMARIES = (
    ("d3", D3_ADOPTED, d3_row, "## D3: mean stepped u_mf (m/s) and the wet shifts",
     ["dry", "Ca_g 1.0", "Ca_g 1.5", "Ca_g 2.0", "Hertz, same packings: dry; shifts", "failed jobs"]),
    ("d4", D4_ADOPTED, d4_row, "## D4: k(γ = 0.08)/k(dry) at 2.0 / 2.4 / 2.8 m/s; k(2.8)/k(2.0) at γ = 0.02 / 0.08",
     ["wet/dry 2.0", "2.4", "2.8", "fast/slow γ 0.02", "γ 0.08", "Hertz, same packings", "failed jobs"]),
)
for case, adopted, row, title, columns in SUMMARIES:
    print(title + "\n")
    print("| report | packings | " + " | ".join(columns) + " |")
    print("|---" * (len(columns) + 2) + "|")
    for path in reports(case, adopted):
        seeds = seeds_of(job_rows(path)[0])
        print("| %s | %s | %s |" % (name_of(path), ",".join(seeds), " | ".join(row(path, seeds))))
    print()
