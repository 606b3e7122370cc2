#!/usr/bin/env bash
# gendaymtx speed against the oracle: 8760 hourly steps, -m 4 (2306 patches), float output.
# Usage: benches/gendaymtx.sh [path/to/fenestra/gendaymtx]
# Needs hyperfine and the oracle (.oracle/env). Prints hyperfine's table and the ratio.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ -z "${FENESTRA_ORACLE_BIN:-}" ]; then set -a; . .oracle/env; set +a; fi
ours=${1:-target/release/gendaymtx}
wea=examples/three-phase/weather/sf_year.wea
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# same output first (float, bit-identical expected)
"$FENESTRA_ORACLE_BIN/gendaymtx" -m 4 -of "$wea" > "$tmp/oracle.smx"
"$ours" -m 4 -of "$wea" > "$tmp/ours.smx"
cmp -s <(tail -c +200 "$tmp/oracle.smx") <(tail -c +200 "$tmp/ours.smx") && echo "outputs identical (data)" || echo "WARNING: outputs differ"
hyperfine --warmup 1 --runs 5 --export-json "$tmp/h.json" \
  -n oracle "$FENESTRA_ORACLE_BIN/gendaymtx -m 4 -of $wea > $tmp/o1" \
  -n fenestra "$ours -m 4 -of $wea > $tmp/o2"
python3 - "$tmp/h.json" <<'PY'
import json, sys
r = {x["command"]: x["mean"] for x in json.load(open(sys.argv[1]))["results"]}
print(f"oracle {r['oracle']:.3f} s, fenestra {r['fenestra']:.3f} s, oracle/fenestra = {r['oracle']/r['fenestra']:.2f}")
PY
