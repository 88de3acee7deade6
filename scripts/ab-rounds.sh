#!/usr/bin/env bash
# Rotating rounds of several cgdem builds (issue 41's technique table): each round runs every
# binary once, in an order that rotates from round to round, on the heap bench (cgdem alone,
# 5000 steps after the 0.15 s preparation, HEAP_THREADS threads, default 1) and/or the main
# job shortened to a 0.3 s collapse (one thread), and prints each binary's ratio to the first
# per round and the medians. Stop everything else while it runs (the machine is shared).
#
# Usage: bash scripts/ab-rounds.sh ROUNDS heap|main|both BASE_BIN OTHER_BIN...
rounds=$1 what=$2; shift 2
bins=("$@"); n=${#bins[@]}
cd "$(dirname "$0")/.."
heap() { rm -rf /tmp/abn-heap; "$1" bench validation/bench/heap.toml --codes cgdem --pairs 1 --threads ${HEAP_THREADS:-1} --steps 5000 --prepare 0.15 --no-outcome --out /tmp/abn-heap >/dev/null 2>&1 || { echo fail; return; }; python3 -c 'import json,sys; b=json.load(open(sys.argv[1])); print(b["medians"][0]["median_particle_steps_per_s"])' /tmp/abn-heap/bench.json; }
mainj() { rm -rf /tmp/abn-main; "$1" run validation/cases/aor_collapse.toml --lambda 8 --quiet --threads 1 --out /tmp/abn-main --set 'stage[1].max_duration=0.3' --set 'stage[1].min_duration=0.3' --set 'repose.at_times=[0.25]' >/dev/null 2>&1 || { echo fail; return; }; python3 -c 'import json,sys; print(1.0/json.load(open(sys.argv[1]))["wall_s"])' /tmp/abn-main/summary.json; }
out=$(mktemp); : > $out
for r in $(seq 1 $rounds); do
  for s in $(seq 0 $((n-1))); do
    i=$(( (s + r) % n ))
    [ $what != main ] && echo "$r,heap,$i,$(heap ${bins[$i]})" >> $out
    [ $what != heap ] && echo "$r,main,$i,$(mainj ${bins[$i]})" >> $out
  done
done
python3 - $out "${bins[@]}" <<'P'
import csv,sys,statistics as st
rows=list(csv.reader(open(sys.argv[1]))); bins=sys.argv[2:]
for what in ('heap','main'):
    v={}
    for r,w,i,x in rows:
        if w==what and x!='fail': v.setdefault(int(r),{})[int(i)]=float(x)
    if not v: continue
    for i in range(1,len(bins)):
        ratios=[d[i]/d[0] for d in v.values() if 0 in d and i in d]
        print(f"{what} {bins[i]} / {bins[0]}: median {st.median(ratios):.3f} ({' '.join(f'{x:.3f}' for x in ratios)})")
    print(what, 'values of base:', ' '.join(f"{d[0]:.4g}" for d in v.values() if 0 in d))
P
