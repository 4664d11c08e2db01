"""Writes the probe's six scenarios (JSON) into the current directory: E5's kiln (the held-drag/PISO probe's base)
at 15 rpm, 6 s (1 s settling, 5 s heating), glass and aluminium, in air with the gas lens, in air without it, and
in vacuum. Run each with `granflow simulate <name>.json --out <dir>/<name> --threads 1`."""
import json, yaml

c = yaml.safe_load(open('research/e5-held-piso-probe/e5-held-piso.yaml'))


def numbers(o):
    if isinstance(o, dict):
        return {k: numbers(v) for k, v in o.items()}
    if isinstance(o, list):
        return [numbers(v) for v in o]
    if isinstance(o, str):
        try:
            return float(o)  # PyYAML reads 1.0e7 as a string
        except ValueError:
            return o
    return o


base = numbers(c['base'])
base['seed'] = c['seed']
for material in ['glass', 'aluminium']:
    for kind in ['lens', 'air', 'vac']:
        s = json.loads(json.dumps(base))
        s['species'][0]['material'] = material
        s['walls'][0]['drum']['rotation_rpm'] = 15.0
        s['time']['end_time_s'] = 6.0
        s['gas']['vacuum'] = kind == 'vac'
        if kind == 'lens':
            s['heat'].setdefault('gas', {})['lens_conduction'] = {}
        s['name'] = f'{material}-{kind}'
        json.dump(s, open(s['name'] + '.json', 'w'), indent=1)
