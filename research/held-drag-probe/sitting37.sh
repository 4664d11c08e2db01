#!/bin/bash
# Issue 37's alternating sitting on scenarios/fluidized-bed.yaml (3 s, one thread), two rounds:
#   OLD binary on the scenario as it was at commit eaab101 (before issue 37),
#   NEW binary on the scenario without the two faster settings (the reference scheme), then as shipped.
# usage: research/held-drag-probe/sitting37.sh OLD_BINARY NEW_BINARY   (run from the repository root)
# Writes one line per run (wall time and stage times from summary.json) to /tmp/sit37/table.txt.
OLD=$1; NEW=$2; OUT=/tmp/sit37; mkdir -p $OUT
git show eaab101:scenarios/fluidized-bed.yaml > $OUT/before.yaml
grep -v "drag_update: every_gas_step\|solver: { relax_velocity: 0.9" scenarios/fluidized-bed.yaml > $OUT/reference.yaml
for k in 1 2; do
  for cfg in "old:$OLD:$OUT/before.yaml" "ref:$NEW:$OUT/reference.yaml" "new:$NEW:scenarios/fluidized-bed.yaml"; do
    IFS=: read name bin yaml <<< "$cfg"
    rm -rf $OUT/run; $bin simulate $yaml --out $OUT/run --threads 1 --quiet > $OUT/$name-$k.json 2>&1
    python3 -c "
import json
t=open('$OUT/$name-$k.json').read(); j=json.loads(t[t.index('{'):])
print('$name', $k, round(j['wall_time_s'],2), ' '.join(f'{k}={v:.2f}' for k,v in j['stage_timings_s']))" >> $OUT/table.txt
  done
done
