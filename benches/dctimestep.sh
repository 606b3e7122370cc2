#!/usr/bin/env bash
# dctimestep speed against the oracle, same run, same machine (issue 4 benchmark):
#   dctimestep -of V T D sky > /dev/null
# V = 1000 sensors x 145 Klems patches (synthetic, deterministic values), T = blinds_kf.xml,
# D = the reference office's D.dmx (145 x 146), sky = 146 x 8760 from our gendaymtx -m 1 on
# examples/three-phase/weather/sf_year.wea.
# Usage: benches/dctimestep.sh [runs]   (needs .oracle/env, bc, testopt builds of dctimestep and gendaymtx)
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-5}
[ -f .oracle/env ] || scripts/oracle.sh > /dev/null
set -a; . .oracle/env; set +a
export FENESTRA_NO_PROGRESS=1
bin=$(realpath "${CARGO_TARGET_DIR:-target}/testopt")
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
cp tests/fixtures/threephase/{blinds_kf.xml,D.dmx} "$tmp/"
"$bin/gendaymtx" -m 1 -of examples/three-phase/weather/sf_year.wea > "$tmp/year.smx"
cd "$tmp"
python3 - <<'PY'
import struct
n, k = 1000, 145
with open("V.vmx", "wb") as f:
    f.write(b"#?RADIANCE\nsynthetic V for benches/dctimestep.sh\nNROWS=%d\nNCOLS=%d\nNCOMP=3\nFORMAT=float\n\n" % (n, k))
    vals = []
    for r in range(n):
        for c in range(k):
            v = 1e-4 * (1 + ((r * 7919 + c * 104729) % 1000) / 1000.0)
            vals += [v, v * 1.01, v * 0.99]
    f.write(struct.pack("<%df" % len(vals), *vals))
PY
best() {  # best wall time of $runs runs (after one warm-up) of "$@"
  "$@" > /dev/null
  local b=""
  for _ in $(seq "$runs"); do
    local s e t
    s=$(date +%s.%N); "$@" > /dev/null; e=$(date +%s.%N)
    t=$(echo "$e - $s" | bc -l)
    if [ -z "$b" ] || [ "$(echo "$t < $b" | bc -l)" = 1 ]; then b=$t; fi
  done
  echo "$b"
}
export RAYPATH=.:$FENESTRA_ORACLE_LIB
to=$(best "$FENESTRA_ORACLE_BIN/dctimestep" -of V.vmx blinds_kf.xml D.dmx year.smx)
tf=$(best "$bin/dctimestep" -of V.vmx blinds_kf.xml D.dmx year.smx)
printf 'best of %s: oracle %.3f s, fenestra %.3f s, ratio %.1f\n' "$runs" "$to" "$tf" "$(echo "$to / $tf" | bc -l)"
for who in oracle fenestra; do
  if [ $who = oracle ]; then cmd="$FENESTRA_ORACLE_BIN/dctimestep"; else cmd="$bin/dctimestep"; fi
  /usr/bin/time -f "$who: %e s wall, %U s user, %M kB max RSS" $cmd -of V.vmx blinds_kf.xml D.dmx year.smx > /dev/null
done
