#!/usr/bin/env bash
# rcalc speed against the oracle, same run, same machine (issue 3): the bin expressions a
# contribution run evaluates per ray hit, over 1 000 000 random directions.
#   kbin  : rcalc -f klems_full.cal -e '$1=kbin(0,1,0,0,0,1)'-style Klems bin of each direction
#   rbin  : rcalc -e MF:1 -f reinhart.cal -e 'Dx=$1;Dy=$2;Dz=$3;$1=rbin'
# Each tool reads its own .cal files (ours from lib/, Radiance's from its library).
# Usage: benches/rcalc.sh [runs]   (needs .oracle/env, hyperfine, and a testopt build of rcalc)
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-5}
set -a; . .oracle/env; set +a
ours=$(realpath "${CARGO_TARGET_DIR:-target}/testopt/rcalc")
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
python3 - > "$tmp/dirs.txt" <<'PY'
import math, random
r = random.Random(11)
for _ in range(1000000):
    z = r.uniform(-1, 1); a = r.uniform(0, 2 * math.pi); s = math.sqrt(1 - z * z)
    print(f"{s*math.cos(a):.6f}\t{s*math.sin(a):.6f}\t{z:.6f}")
PY
k='Dx=$1;Dy=$2;Dz=$3;$1=kbin(0,1,0,0,0,1)'
b='Dx=$1;Dy=$2;Dz=$3;$1=rbin'
# fenestra evaluates blocks of records on up to 4 threads (2 here); the "1 thread" rows
# (FENESTRA_RCALC_THREADS=1) show one core's speed, and the user CPU time is printed too.
hyperfine -N -w 1 -r "$runs" --export-markdown "$tmp/times.md" --export-json "$tmp/times.json" \
  -n "oracle kbin" "env RAYPATH=$FENESTRA_ORACLE_LIB $FENESTRA_ORACLE_BIN/rcalc -f klems_full.cal -e $k $tmp/dirs.txt" \
  -n "fenestra kbin" "env FENESTRA_LIB=$PWD/lib RAYPATH=. $ours -f klems_full.cal -e $k $tmp/dirs.txt" \
  -n "fenestra kbin, 1 thread" "env FENESTRA_RCALC_THREADS=1 FENESTRA_LIB=$PWD/lib RAYPATH=. $ours -f klems_full.cal -e $k $tmp/dirs.txt" \
  -n "oracle rbin" "env RAYPATH=$FENESTRA_ORACLE_LIB $FENESTRA_ORACLE_BIN/rcalc -e MF:1 -f reinhart.cal -e $b $tmp/dirs.txt" \
  -n "fenestra rbin" "env FENESTRA_LIB=$PWD/lib RAYPATH=. $ours -e MF:1 -f reinhart.cal -e $b $tmp/dirs.txt" \
  -n "fenestra rbin, 1 thread" "env FENESTRA_RCALC_THREADS=1 FENESTRA_LIB=$PWD/lib RAYPATH=. $ours -e MF:1 -f reinhart.cal -e $b $tmp/dirs.txt"
cat "$tmp/times.md"
python3 - "$tmp/times.json" <<'PY'
import json, sys
r = {x["command"]: x for x in json.load(open(sys.argv[1]))["results"]}
print("| command | mean wall [s] | min wall [s] | mean user [s] |")
print("|---|---|---|---|")
for n, x in r.items():
    print(f"| {n} | {x['mean']:.3f} | {x['min']:.3f} | {x['user']:.3f} |")
for e in ("kbin", "rbin"):
    o, f, f1 = r[f"oracle {e}"], r[f"fenestra {e}"], r[f"fenestra {e}, 1 thread"]
    print(f"{e}: oracle/fenestra wall mean {o['mean']/f['mean']:.1f}x, min {o['min']/f['min']:.1f}x; "
          f"1 thread wall mean {o['mean']/f1['mean']:.1f}x; user CPU {o['user']/f['user']:.1f}x")
PY
uptime
# The outputs must agree (same bins) for the timing to mean anything.
env RAYPATH=$FENESTRA_ORACLE_LIB $FENESTRA_ORACLE_BIN/rcalc -f klems_full.cal -e "$k" "$tmp/dirs.txt" > "$tmp/o.txt"
env FENESTRA_LIB=$PWD/lib RAYPATH=. "$ours" -f klems_full.cal -e "$k" "$tmp/dirs.txt" > "$tmp/f.txt"
echo "kbin outputs differing: $(paste "$tmp/o.txt" "$tmp/f.txt" | awk '$1 != $2' | wc -l) of 1000000"
env RAYPATH=$FENESTRA_ORACLE_LIB $FENESTRA_ORACLE_BIN/rcalc -e MF:1 -f reinhart.cal -e "$b" "$tmp/dirs.txt" > "$tmp/o.txt"
env FENESTRA_LIB=$PWD/lib RAYPATH=. "$ours" -e MF:1 -f reinhart.cal -e "$b" "$tmp/dirs.txt" > "$tmp/f.txt"
echo "rbin outputs differing: $(paste "$tmp/o.txt" "$tmp/f.txt" | awk '$1 != $2' | wc -l) of 1000000"
