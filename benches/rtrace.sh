#!/usr/bin/env bash
# rtrace speed against the oracle, same run, same machine (issue 6 benchmark):
#   rtrace -h -I+ -ab 6 -ad 16384 -aa 0 -lw 1e-5 -n 2 over the 45 sensors of the reference office
# with the BSDF window (blinds_kf.xml) under the t1 clear sky (reference threephase, commands.sh line 52).
# Usage: benches/rtrace.sh [runs]   (needs .oracle/env and a testopt build of rtrace)
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-3}
[ -f .oracle/env ] || scripts/oracle.sh > /dev/null
set -a; . .oracle/env; set +a
export FENESTRA_NO_PROGRESS=1
ours=$(realpath "${CARGO_TARGET_DIR:-target}/testopt/rtrace")
ref=${FENESTRA_SHARED:-$(cd .. && pwd)/shared}/reference/threephase
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
cp "$ref"/{materials.rad,room.rad,exterior.rad,window_bsdf.rad,skyfunc_glow.rad,sensors.pts,sky_t1_mar21_1000_clear.rad} tests/fixtures/threephase/blinds_kf.xml "$tmp/"
cd "$tmp"
scene="materials.rad room.rad exterior.rad window_bsdf.rad sky_t1_mar21_1000_clear.rad skyfunc_glow.rad"
RAYPATH=.:$FENESTRA_ORACLE_LIB "$FENESTRA_ORACLE_BIN/oconv" $scene > s.oct
opts="-h -I+ -ab 6 -ad 16384 -aa 0 -lw 1e-5 -n 2"
hyperfine -w 1 -r "$runs" --export-markdown times.md \
  -n oracle "RAYPATH=.:$FENESTRA_ORACLE_LIB $FENESTRA_ORACLE_BIN/rtrace $opts s.oct < sensors.pts" \
  -n fenestra "RAYPATH=. $ours $opts $scene < sensors.pts"
cat times.md
RAYPATH=. "$ours" -v $opts $scene < sensors.pts 2>&1 >/dev/null | tail -1
