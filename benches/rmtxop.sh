#!/usr/bin/env bash
# rmtxop speed against the oracle: a 146 x 8760 RGB float sky matrix (our gendaymtx -of on the
# bundled year of weather) converted to ascii (-fa) and back to float (-ff).
# Usage: benches/rmtxop.sh [path/to/fenestra/bin-folder]   (default target/release)
# Needs the oracle (.oracle/env). Uses hyperfine when installed, else a bash `time` loop
# (best of 5 wall-clock runs). Prints each step's times and the oracle/fenestra ratio.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ -z "${FENESTRA_ORACLE_BIN:-}" ]; then set -a; . .oracle/env; set +a; fi
bin=${1:-target/release}
wea=examples/three-phase/weather/sf_year.wea
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$bin/gendaymtx" -of "$wea" > "$tmp/sky.fmx"
O="$FENESTRA_ORACLE_BIN/rmtxop"
F="$bin/rmtxop"
# Same output first (the command line in the header names the same file).
"$O" -fa "$tmp/sky.fmx" > "$tmp/o.txt"
"$F" -fa "$tmp/sky.fmx" > "$tmp/f.txt"
cmp -s "$tmp/o.txt" "$tmp/f.txt" && echo "ascii outputs identical" || echo "WARNING: ascii outputs differ"
"$O" -ff "$tmp/o.txt" > "$tmp/o.f"
"$F" -ff "$tmp/o.txt" > "$tmp/f.f"
cmp -s "$tmp/o.f" "$tmp/f.f" && echo "float outputs identical" || echo "WARNING: float outputs differ"

best() { # best wall time of 5 runs of a shell command
  local b=999999 t
  for _ in 1 2 3 4 5; do
    local s=$(date +%s.%N)
    sh -c "$1"
    t=$(echo "$(date +%s.%N) - $s" | bc -l)
    b=$(echo "if ($t < $b) $t else $b" | bc -l)
  done
  printf '%.3f' "$b"
}
for step in "-fa $tmp/sky.fmx" "-ff $tmp/o.txt"; do
  if command -v hyperfine >/dev/null; then
    hyperfine --warmup 1 --runs 5 --export-json "$tmp/h.json" \
      -n oracle "$O $step > $tmp/x1" -n fenestra "$F $step > $tmp/x2"
    python3 - "$tmp/h.json" "${step%% *}" <<'PY'
import json, sys
r = {x["command"]: x["mean"] for x in json.load(open(sys.argv[1]))["results"]}
print(f"rmtxop {sys.argv[2]}: oracle {r['oracle']:.3f} s, fenestra {r['fenestra']:.3f} s, oracle/fenestra = {r['oracle']/r['fenestra']:.2f}")
PY
  else
    to=$(best "$O $step > $tmp/x1")
    tf=$(best "$F $step > $tmp/x2")
    echo "rmtxop ${step%% *} (${step##*/}): oracle $to s, fenestra $tf s, oracle/fenestra = $(echo "scale=2; $to / $tf" | bc -l)"
  fi
done
