#!/usr/bin/env bash
# rtrace speed against the oracle, same run, same machine:
#   rtrace -h -I+ -ab 6 -ad 16384 -aa 0 -lw 1e-5 -n 2 over the 45 sensors of the reference office.
# Scene: tests/fixtures/rtrace_glass_room (the reference office with clear glass, a sun and uniform
# sky/ground glows: the reference skies need skyfunc patterns, which fenestra's rtrace does not read yet).
# Usage: benches/rtrace.sh [runs]   (needs .oracle/env and a testopt build of rtrace)
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-3}
set -a; . .oracle/env 2>/dev/null || . /work/main/.oracle/env; set +a
export RAYPATH=.:$FENESTRA_ORACLE_LIB FENESTRA_NO_PROGRESS=1
ours=${CARGO_TARGET_DIR:-target}/testopt/rtrace
fx=tests/fixtures/rtrace_glass_room
scene="$fx/materials.rad $fx/room.rad $fx/exterior.rad $fx/window_glass.rad $fx/sky.rad"
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
"$FENESTRA_ORACLE_BIN/oconv" $scene > "$tmp/s.oct"
pts=/work/shared/reference/threephase/sensors.pts
opts="-h -I+ -ab 6 -ad 16384 -aa 0 -lw 1e-5 -n 2"
t() { local s e; s=$(date +%s.%N); "$@" > /dev/null 2>&1; e=$(date +%s.%N); echo "$e - $s" | bc; }
best_o=999; best_f=999
for i in $(seq "$runs"); do
  o=$(t sh -c "\"$FENESTRA_ORACLE_BIN/rtrace\" $opts $tmp/s.oct < $pts")
  f=$(t sh -c "\"$ours\" $opts -seed $i $scene < $pts")
  best_o=$(echo "if ($o < $best_o) $o else $best_o" | bc); best_f=$(echo "if ($f < $best_f) $f else $best_f" | bc)
done
echo "oracle rtrace -n 2: best of $runs: ${best_o}s"
echo "fenestra rtrace -n 2: best of $runs: ${best_f}s"
echo "ratio (oracle/fenestra): $(echo "scale=2; $best_o / $best_f" | bc)"
# rays per second: count every ray fenestra traces is not exposed; report sensors/s
echo "fenestra sensors/s: $(echo "scale=1; 45 / $best_f" | bc)"
