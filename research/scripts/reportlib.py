"""Helpers shared by the probe scripts: reading a `granflow report` job table and the campaign YAML, and running
scenarios with `granflow simulate`."""

import csv
import json
import math
import os
import re
import subprocess
from concurrent.futures import ThreadPoolExecutor

import yaml


def job_rows(path):
    """The finished jobs of a report's job table, each a dict from column header to cell text."""
    header, rows = None, []
    for line in open(path, encoding="utf-8"):
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if line.startswith("| status"):
            header = cells
        elif line.startswith("| done") and header:
            rows.append(dict(zip(header, cells)))
    if not rows:
        raise SystemExit(f"{path}: no finished jobs in its job table")
    return rows


def read_job(job_dir):
    """A job's directory: its parameters by full key, its metrics by name (None until the job has finished) and
    its series rows (dicts of column name to text)."""
    params = dict(json.load(open(os.path.join(job_dir, "job.json")))["params"])
    result = os.path.join(job_dir, "result.json")
    metrics = None
    if os.path.exists(result):
        metrics = {m["name"]: m["value"] for m in json.load(open(result))["metrics"]}
    with open(os.path.join(job_dir, "series.csv")) as fh:
        rows = list(csv.DictReader(fh))
    return params, metrics, rows


def cycle_levels(job_dir, from_fraction=0.5):
    """The inflow levels of a job run with `gas.inflow_levels` through one-cell jets (D8's distributor): for each
    level, its superficial velocity (the jets' velocity times their share of the inlet cells, m/s) and the window
    [start + from_fraction × hold, end of the level) in s; the cycle metrics average over from_fraction = 0.5."""
    gas = json.load(open(os.path.join(job_dir, "scenario.json")))["gas"]
    levels = gas["inflow_levels"]
    jets = gas["jets"]
    u = max(j["superficial_velocity_m_per_s"] for j in jets) * len(jets) / gas["cells"][0]
    return [
        (u * f, levels["start_s"] + (k + from_fraction) * levels["hold_s"], levels["start_s"] + (k + 1) * levels["hold_s"])
        for k, f in enumerate(levels["factors"])
    ]


def slab_porosity(beads, radius_m, width_m, depth_m, mean_height_m):
    """Porosity of a pseudo-2-D bed (one layer of spheres in a slab `depth_m` deep) from its beads' mean centre
    height: the bed is 2 x that height tall, φ₂ = N π R² / (W H) is its area fraction, and a sphere fills 2/3 of the
    cylinder of its diameter, so ε = 1 - (2/3) φ₂ (2R / D)."""
    phi_2d = beads * math.pi * radius_m**2 / (width_m * 2.0 * mean_height_m)
    return 1.0 - 2.0 / 3.0 * phi_2d * (2.0 * radius_m / depth_m)


def load_campaign(path):
    """A campaign file as plain data. PyYAML reads YAML 1.1, where 1.0e7 (no sign after the e) is a string; the
    campaigns are YAML 1.2, so floats get the 1.2 resolver."""

    class Loader(yaml.SafeLoader):
        pass

    Loader.add_implicit_resolver(
        "tag:yaml.org,2002:float",
        re.compile(r"^[-+]?(?:[0-9][0-9_]*\.[0-9_]*(?:[eE][-+]?[0-9]+)?|\.[0-9_]+(?:[eE][-+]?[0-9]+)?"
                   r"|[0-9][0-9_]*[eE][-+]?[0-9]+|[-+]?\.(?:inf|Inf|INF)|\.(?:nan|NaN|NAN))$"),
        list("-+0123456789."),
    )
    with open(path, encoding="utf-8") as fh:
        return yaml.load(fh, Loader=Loader)


def simulate_all(granflow, runs, parallel=2):
    """Runs `granflow simulate SCENARIO --out DIR` for every (scenario path, run directory) of `runs`, `parallel` at
    a time (a finished run is not rerun by simulate), and returns each run's summary, in order."""

    def run(paths):
        scenario_path, run_dir = paths
        out = subprocess.run([granflow, "simulate", scenario_path, "--out", run_dir, "--quiet"], check=True,
                             capture_output=True, text=True).stdout
        return json.loads(out[out.index("{"):])

    with ThreadPoolExecutor(parallel) as pool:
        return list(pool.map(run, runs))
