#!/usr/bin/env bash
# rtrace source thresholding (-dt/-dc) against the oracle, same run, same machine: the 60-lamp,
# 20-partition scene of tests/fixtures/direct_threshold, each tool with -dt .03 (its default) and -dt 0,
# single process/thread (-n 1), hyperfine.
#   A: -I+ -ab 0 over 30000 points (the fixture's 30 points shifted 1000 times by 1.3 mm)
#   B: -I+ -ab 1 -ad 1024 -aa 0 over 120 points (the fixture's 30 points shifted 4 times by 1.3 cm)
# Prints hyperfine's table and the mean user (CPU) time of each command: the machine is shared.
# Usage: benches/rtrace_dt.sh [runs] [threads (-n, default 1)]   (needs .oracle/env and a testopt build of rtrace)
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-3}
threads=${2:-1}
[ -f .oracle/env ] || scripts/oracle.sh > /dev/null
set -a; . .oracle/env; set +a
export FENESTRA_NO_PROGRESS=1
ours=$(realpath "${CARGO_TARGET_DIR:-target}/testopt/rtrace")
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
cp tests/fixtures/direct_threshold/{scene.rad,points.txt} "$tmp/"
cd "$tmp"
awk '{for (k = 0; k < 1000; k++) print $1 + 0.0013 * k, $2, $3, $4, $5, $6}' points.txt > many.txt
awk '{for (k = 0; k < 4; k++) print $1 + 0.013 * k, $2, $3, $4, $5, $6}' points.txt > some.txt
RAYPATH=.:$FENESTRA_ORACLE_LIB "$FENESTRA_ORACLE_BIN/oconv" scene.rad > s.oct
ref="RAYPATH=.:$FENESTRA_ORACLE_LIB $FENESTRA_ORACLE_BIN/rtrace"
for case in "A|-h -I+ -ab 0 -n $threads|many.txt" "B|-h -I+ -ab 1 -ad 1024 -aa 0 -n $threads|some.txt"; do
  IFS='|' read -r name opts input <<< "$case"
  echo "== $name: $opts < $input ($(wc -l < "$input") records); load: $(uptime | sed 's/.*load/load/')"
  hyperfine -w 1 -r "$runs" --export-markdown "times_$name.md" --export-json "times_$name.json" \
    -n "oracle -dt 0" "$ref $opts -dt 0 s.oct < $input" \
    -n "oracle -dt .03" "$ref $opts -dt .03 s.oct < $input" \
    -n "fenestra -dt 0" "$ours $opts -dt 0 scene.rad < $input" \
    -n "fenestra -dt .03" "$ours $opts -dt .03 scene.rad < $input" > /dev/null
  cat "times_$name.md"
  python3 -c 'import json,sys
for r in json.load(open(sys.argv[1]))["results"]:
    print("user %-18s %.3f s" % (r["command"], r["user"]))' "times_$name.json"
  for dt in 0 .03; do
    echo "fenestra -dt $dt: $("$ours" -v $opts -dt $dt scene.rad < "$input" 2>&1 >/dev/null | tail -1)"
  done
done
