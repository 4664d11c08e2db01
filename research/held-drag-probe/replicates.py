"""Means over t > 1 s of the fluidized bed's series, one row per run, and each scheme's mean and spread over its runs.

Runs are `granflow simulate` of scenarios/fluidized-bed.yaml with the lattice origin shifted by k * 1e-7 m in x
(k = 0..3: chaotic, so independent realisations), each with the every-step scheme and with drag held over the gas
step (`gas.drag_update: every_gas_step`), optionally with other solver settings:

    python3 research/held-drag-probe/replicates.py every=/tmp/rep/def0,/tmp/rep/def1 held=/tmp/rep/held0,...
"""
import csv, statistics as st, sys

COLUMNS = ['bed_top_m', 'mean_height_m', 'mean_coordination', 'column_pressure_drop_pa', 'node_pressure_drop_pa',
           'gas_outer_iterations']

def means(run):
    rows = [r for r in csv.DictReader(open(f'{run}/series.csv')) if float(r['time_s']) > 1.0]
    return [st.mean(float(r[c]) for r in rows if r[c] not in ('', 'NaN')) for c in COLUMNS]

print('| scheme | run | ' + ' | '.join(COLUMNS) + ' |')
print('|' + '---|' * (len(COLUMNS) + 2))
summary = []
for arg in sys.argv[1:]:
    name, runs = arg.split('=')
    table = [means(r) for r in runs.split(',')]
    for run, row in zip(runs.split(','), table):
        print(f'| {name} | {run} | ' + ' | '.join(f'{v:.4g}' for v in row) + ' |')
    summary.append((name, [(st.mean(col), st.stdev(col) if len(col) > 1 else 0.0) for col in zip(*table)]))
for name, cols in summary:
    print(f'| {name} | mean ± sd | ' + ' | '.join(f'{m:.4g} ± {s:.2g}' for m, s in cols) + ' |')
