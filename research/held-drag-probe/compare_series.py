"""Compares two runs' series.csv (t > 1 s): mean and standard deviation of the bed and gas columns.

    python3 research/held-drag-probe/compare_series.py /tmp/default/series.csv /tmp/held/series.csv
"""
import csv,sys,statistics as st
def load(p):
    r=list(csv.DictReader(open(p)))
    return [x for x in r if float(x['time_s'])>1.0]
a=load(sys.argv[1]); b=load(sys.argv[2])
for col in ['bed_top_m','mean_height_m','mean_coordination','column_pressure_drop_pa','node_pressure_drop_pa','node_weight_per_area_pa','gas_outer_iterations','gas_linear_iterations']:
    va=[float(x[col]) for x in a if x[col] not in ('','NaN')]; vb=[float(x[col]) for x in b if x[col] not in ('','NaN')]
    if not va or not vb: continue
    print(f"{col:28s} default mean {st.mean(va):12.5g} sd {st.pstdev(va):10.4g} | held mean {st.mean(vb):12.5g} sd {st.pstdev(vb):10.4g} | ratio {st.mean(vb)/st.mean(va):.4f}")
