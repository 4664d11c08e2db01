"""The bed-mean, core and gas temperature rises (K above 300) at each whole second of the probe runs:
python3 rises.py <dir of runs> <run name>..."""
import csv,sys,math
for n in sys.argv[2:]:
    try: rows=list(csv.DictReader(open(sys.argv[1]+'/%s/series.csv'%n)))
    except Exception as e: print(n,'-'); continue
    out=[]
    for r in rows:
        t=float(r['time_s'])
        if abs(t-round(t))<1e-6 and t>=1:
            out.append('%.0fs mean %.3f core %.3f gas %.3f'%(t,float(r['mean_temperature_k'])-300,float(r['core_temperature_k'])-300,float(r['gas_mean_temperature_k'])-300))
    print(n,' | '.join(out))
