#!/usr/bin/env bash
# rfluxmtx speed against the oracle's rfluxmtx (which runs rcontrib and oconv as child processes),
# same run, same machine (issue 20 benchmark), with the reference office's commands (commands.sh):
#   V: rfluxmtx -n 2 -I+ -ab 6 -ad 50000 -lw 2e-5 -faf - window_rflux.rad materials.rad room.rad < sensors.pts
#   D: rfluxmtx -n 2 -c 1000 -ab 2 -ad 1000 -lw 1e-4 -faf window_rflux.rad sky_rflux.rad materials.rad room.rad exterior.rad
#   M: 5000 receivers (a ceiling of 100 x 50 tiles, each its own modifier) from a uniform sender, -ab 0 -c 2000:
#      fenestra only (one call; Radiance's rfluxmtx stops at its argument limit, checked and reported).
# Runs alternate oracle / fenestra; wall and user seconds of each run are printed, then the best of each.
# Usage: benches/rfluxmtx.sh [runs] [V|D|M|VDM]   (needs .oracle/env and a testopt build)
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-3}
which=${2:-VDM}
[ -f .oracle/env ] || scripts/oracle.sh > /dev/null
set -a; . .oracle/env; set +a
export FENESTRA_NO_PROGRESS=1
bin=$(realpath "${CARGO_TARGET_DIR:-target}/testopt")
lib=$(realpath lib)
ref=${FENESTRA_SHARED:-$(cd .. && pwd)/shared}/reference/threephase
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
cp "$ref"/{materials.rad,room.rad,exterior.rad,window_rflux.rad,sky_rflux.rad,sensors.pts} "$tmp/"
cd "$tmp"
O="$FENESTRA_ORACLE_BIN"

timeit() { # label command...
  local t0 t1
  /usr/bin/time -o t.txt -f "%e %U" "${@:2}" > out.txt 2>/dev/null || echo "$1 failed"
  read -r t0 t1 < t.txt
  echo "$1 wall $t0 user $t1"
}

best() { # label file
  awk -v l="$1" '$1==l && $2=="wall" {w=$3; u=$5; if (bw=="" || w<bw) {bw=w; bu=u}} END {printf "%s best wall %.2f s (user %.2f s)\n", l, bw, bu}' "$2"
}

oracle=(env "PATH=$O:$PATH" "RAYPATH=.:$FENESTRA_ORACLE_LIB")
ours=(env "RAYPATH=.:$lib")

if [[ $which == *V* ]]; then
  v="-n 2 -I+ -ab 6 -ad 50000 -lw 2e-5 -faf - window_rflux.rad materials.rad room.rad"
  : > v.log
  for _ in $(seq "$runs"); do
    timeit oracle-V "${oracle[@]}" sh -c "rfluxmtx $v < sensors.pts" | tee -a v.log
    timeit fenestra-V "${ours[@]}" sh -c "$bin/rfluxmtx $v < sensors.pts" | tee -a v.log
  done
  best oracle-V v.log; best fenestra-V v.log
fi

if [[ $which == *D* ]]; then
  d="-n 2 -c 1000 -ab 2 -ad 1000 -lw 1e-4 -faf window_rflux.rad sky_rflux.rad materials.rad room.rad exterior.rad"
  : > d.log
  for _ in $(seq "$runs"); do
    timeit oracle-D "${oracle[@]}" sh -c "rfluxmtx $d" | tee -a d.log
    timeit fenestra-D "${ours[@]}" sh -c "$bin/rfluxmtx $d" | tee -a d.log
  done
  best oracle-D d.log; best fenestra-D d.log
fi

if [[ $which == *M* ]]; then
  printf '#@rfluxmtx h=u u=Y\nvoid glow s 0 0 4 1 1 1 0\ns polygon snd 0 0 12 -.1 -.1 0 -.1 .1 0 .1 .1 0 .1 -.1 0\n' > snd.rad
  awk 'BEGIN { for (i = 0; i < 100; i++) for (j = 0; j < 50; j++) {
      x0 = -2 + .04 * i; y0 = -2 + .08 * j; x1 = x0 + .04; y1 = y0 + .08
      printf "#@rfluxmtx h=u\nvoid glow t%d_%d 0 0 4 1 1 1 0\nt%d_%d polygon tile%d_%d 0 0 12 %g %g 1 %g %g 1 %g %g 1 %g %g 1\n", i, j, i, j, i, j, x0, y0, x0, y1, x1, y1, x1, y0 } }' > rcv.rad
  : > m.log
  for _ in $(seq "$runs"); do
    timeit fenestra-M "${ours[@]}" sh -c "$bin/rfluxmtx -ab 0 -c 2000 -faf snd.rad rcv.rad" | tee -a m.log
  done
  best fenestra-M m.log
  if "${oracle[@]}" rfluxmtx -ab 0 -c 2000 -faf snd.rad rcv.rad > o.mtx 2> o.err; then
    echo "oracle-M: ran ($(stat -c %s o.mtx) bytes)"
  else
    echo "oracle-M: failed: $(head -c 200 o.err)"
  fi
fi
