#!/usr/bin/env bash
# mkillum speed against the oracle's mkillum, same run, same machine (issue 19 benchmark), on the reference
# room (../shared/reference/mkillum, commands.sh): both windows (glass, BSDF blinds), then rtrace on the
# sensors without and with each tool's own proxy.
#   mkillum -n 2 -ab 2 -ad 1024 -aa 0 -lw 1e-4 scene.oct < window_illum_*.rad
#   rtrace -n 2 -h -I+ -ab 5 -ad 8192 -aa 0 -lw 1e-5 scene[_ill].oct < sensors.pts
# Runs alternate oracle / fenestra; wall and user seconds are printed, then the best of each.
# Usage: benches/mkillum.sh [runs]   (needs .oracle/env and a testopt build)
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-3}
[ -f .oracle/env ] || scripts/oracle.sh > /dev/null
set -a; . .oracle/env; set +a
. benches/mkillum_room.sh
O="$FENESTRA_ORACLE_BIN"

timeit() { # label command...
  local t0 t1
  /usr/bin/time -o t.txt -f "%e %U" "${@:2}" > /dev/null 2>&1 || echo "$1 failed"
  read -r t0 t1 < t.txt
  echo "$1 wall $t0 user $t1"
}
best() { # label file
  awk -v l="$1" '$1==l && $2=="wall" {w=$3; u=$5; if (bw=="" || w<bw) {bw=w; bu=u}} END {printf "%-22s best wall %.2f s (user %.2f s)\n", l, bw, bu}' "$2"
}

for w in glass bsdf; do
  mkdir -p "$tmp/o_$w" "$tmp/f_$w"
  scene="materials.rad room.rad exterior.rad window_$w.rad sky.rad skyfunc_glow.rad"
  (cd "$tmp/o_$w" && for f in ../*.rad ../*.pts ../*.xml; do ln -sf "$f" .; done \
    && RAYPATH=".:$FENESTRA_ORACLE_LIB" "$O/oconv" $scene > scene.oct)
  (cd "$tmp/f_$w" && for f in ../*.rad ../*.pts ../*.xml; do ln -sf "$f" .; done \
    && RAYPATH=".:$lib" "$bin/oconv" $scene > scene.oct)
  : > "$tmp/$w.log"
  for _ in $(seq "$runs"); do
    (cd "$tmp/o_$w" && RAYPATH=".:$FENESTRA_ORACLE_LIB" timeit "oracle-mkillum-$w" sh -c "$O/mkillum -n 2 -ab 2 -ad 1024 -aa 0 -lw 1e-4 scene.oct < window_illum_$w.rad > illum.rad") | tee -a "$tmp/$w.log"
    (cd "$tmp/f_$w" && RAYPATH=".:$lib" timeit "fenestra-mkillum-$w" sh -c "$bin/mkillum -n 2 -ab 2 -ad 1024 -aa 0 -lw 1e-4 scene.oct < window_illum_$w.rad > illum.rad") | tee -a "$tmp/$w.log"
  done
  (cd "$tmp/o_$w" && RAYPATH=".:$FENESTRA_ORACLE_LIB" "$O/oconv" -f $scene illum.rad > ill.oct)
  (cd "$tmp/f_$w" && RAYPATH=".:$lib" "$bin/oconv" -f $scene illum.rad > ill.oct)
  for _ in $(seq "$runs"); do
    for oct in scene ill; do
      (cd "$tmp/o_$w" && RAYPATH=".:$FENESTRA_ORACLE_LIB" timeit "oracle-rtrace-$w-$oct" sh -c "$O/rtrace -n 2 -h -I+ -ab 5 -ad 8192 -aa 0 -lw 1e-5 $oct.oct < sensors.pts") | tee -a "$tmp/$w.log"
      (cd "$tmp/f_$w" && RAYPATH=".:$lib" timeit "fenestra-rtrace-$w-$oct" sh -c "$bin/rtrace -n 2 -h -I+ -ab 5 -ad 8192 -aa 0 -lw 1e-5 $oct.oct < sensors.pts") | tee -a "$tmp/$w.log"
    done
  done
  for l in oracle-mkillum fenestra-mkillum oracle-rtrace-$w-scene oracle-rtrace-$w-ill fenestra-rtrace-$w-scene fenestra-rtrace-$w-ill; do
    case $l in *mkillum) best "$l-$w" "$tmp/$w.log";; *) best "$l" "$tmp/$w.log";; esac
  done
done
