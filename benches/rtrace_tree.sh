#!/usr/bin/env bash
# rtrace with a tensor-tree window against the oracle's, same run, same machine (issue 17):
#   the reference office (tests/fixtures/rtrace_threephase_bsdf) with the blind's rank-4 and
#   rank-3 trees (tests/fixtures/dctimestep/blinds_t4.xml, blinds_t3.xml), overcast sky,
#   rtrace -n 2 -h -I+ -aa 0 -lw 1e-4 -ad 4096 -ab 2 over the 45 sensors (the oracle at its
#   default -as), hyperfine 5 runs each; peak RSS of fenestra's run.
# Usage: benches/rtrace_tree.sh   (needs hyperfine and a testopt build of rtrace)
set -euo pipefail
cd "$(dirname "$0")/.."
[ -f .oracle/env ] || scripts/oracle.sh > /dev/null
set -a; . .oracle/env; set +a
export FENESTRA_NO_PROGRESS=1
bin=$(realpath "${CARGO_TARGET_DIR:-target}/testopt")
fx=$(realpath tests/fixtures)
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
cp "$fx"/rtrace_threephase_bsdf/*.rad "$fx"/rtrace_threephase_bsdf/sensors.pts "$fx"/dctimestep/blinds_t?.xml "$tmp/"
cd "$tmp"
O="$FENESTRA_ORACLE_BIN"
for t in t4 t3; do
  sed "s/blinds_kf.xml/blinds_$t.xml/" window_bsdf.rad > win_$t.rad
  scene="materials.rad room.rad exterior.rad win_$t.rad sky_t4_sep21_1200_overcast.rad skyfunc_glow.rad"
  "$O/oconv" $scene > $t.oct
  opts="-n 2 -h -I+ -aa 0 -lw 1e-4 -ad 4096 -ab 2"
  echo "== blinds_$t.xml"
  hyperfine -w 1 -r 5 -n oracle "RAYPATH=.:$FENESTRA_ORACLE_LIB $O/rtrace $opts $t.oct < sensors.pts > /dev/null" \
    -n fenestra "RAYPATH=. $bin/rtrace $opts $scene < sensors.pts > /dev/null" 2>/dev/null | grep -E "Time|faster"
  /usr/bin/time -f "fenestra peak RSS %M kB" env RAYPATH=. "$bin/rtrace" $opts $scene < sensors.pts > /dev/null 2> rss.txt || true
  tail -1 rss.txt
done
