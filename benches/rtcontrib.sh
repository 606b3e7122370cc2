#!/usr/bin/env bash
# rtcontrib speed against the oracle's rcontrib, same run, same machine (issue 7 benchmark):
#   V: rcontrib -n 2 -I+ -ab 6 -ad 50000 -lw 2e-5 -faa -f klems_full.cal -b kbinS -bn Nkbins -m SouthGroup
#      over the 45 sensors of the reference office (reference threephase commands.sh, "V rcontrib -I").
#   D: the same rays (145 Klems bins x 1000 samples over the south window, from fenestra's genklemsamp when it
#      works, else from a fixed-seed stand-in sampler below) through
#      rcontrib -n 2 -c 1000 -ffa -ab 2 -ad 1000 -lw 1e-4 -e MF:1 -f reinhart.cal -b rbin -bn Nrbins -m skyglow.
# Runs alternate oracle / fenestra; wall and user seconds of each run are printed, then the best of each.
# Usage: benches/rtcontrib.sh [runs] [V|D|VD]   (needs .oracle/env and testopt builds of rcontrib, oconv)
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-3}
which=${2:-VD}
[ -f .oracle/env ] || scripts/oracle.sh > /dev/null
set -a; . .oracle/env; set +a
export FENESTRA_NO_PROGRESS=1
bin=$(realpath "${CARGO_TARGET_DIR:-target}/testopt")
lib=$(realpath lib)
ref=${FENESTRA_SHARED:-$(cd .. && pwd)/shared}/reference/threephase
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
cp "$ref"/{materials.rad,room.rad,exterior.rad,window_vmx.rad,window_out.rad,sky_dmx.rad,sensors.pts} "$tmp/"
cd "$tmp"
O="$FENESTRA_ORACLE_BIN"
"$O/oconv" materials.rad room.rad window_vmx.rad > vmx.oct
"$O/oconv" materials.rad room.rad exterior.rad sky_dmx.rad > dmx.oct

timeit() { # label command...
  local t0 t1
  /usr/bin/time -o t.txt -f "%e %U" "${@:2}" > out.txt 2>/dev/null
  read -r t0 t1 < t.txt
  echo "$1 wall $t0 user $t1"
}

best() { # label file
  awk -v l="$1" '$1==l {w=$3; u=$5; if (bw=="" || w<bw) {bw=w; bu=u}} END {printf "%s best wall %.2f s (user %.2f s)\n", l, bw, bu}' "$2"
}

if [[ $which == *V* ]]; then
  vopts="-n 2 -I+ -ab 6 -ad 50000 -lw 2e-5 -faa -f klems_full.cal -b kbinS -bn Nkbins -m SouthGroup"
  : > v.log
  for _ in $(seq "$runs"); do
    RAYPATH=.:$FENESTRA_ORACLE_LIB timeit oracle-V sh -c "$O/rcontrib $vopts vmx.oct < sensors.pts" | tee -a v.log
    RAYPATH=.:$lib timeit fenestra-V sh -c "$bin/rcontrib $vopts materials.rad room.rad window_vmx.rad < sensors.pts" | tee -a v.log
  done
  best oracle-V v.log; best fenestra-V v.log
fi

if [[ $which == *D* ]]; then
  if "$bin/genklemsamp" -ff -c 1000 -vd 0 -1 0 -vu 0 0 1 window_out.rad > rays.bin 2>/dev/null \
     && [ "$(stat -c %s rays.bin)" -eq $((145 * 1000 * 24)) ]; then
    echo "D rays: fenestra genklemsamp"
  else
    echo "D rays: stand-in sampler (fenestra genklemsamp not available)"
    python3 - > rays.bin <<'EOF'
import math, random, struct, sys
# uniform points on the south window (x 1..3, z 0.9..2.4, y = -0.01 outside), one direction per
# sample inside each Klems bin's theta/phi range, pointing out of the room (-y)
rng = random.Random(7)
bounds = [0, 5, 15, 25, 35, 45, 55, 65, 75, 90]
naz = [1, 8, 16, 20, 24, 24, 24, 16, 12]
out = sys.stdout.buffer
for r in range(9):
    for p in range(naz[r]):
        for _ in range(1000):
            th = math.radians(rng.uniform(bounds[r], bounds[r + 1]))
            ph = 2 * math.pi * (p + rng.random() - 0.5) / naz[r]
            dx, dz, dy = math.sin(th) * math.cos(ph), math.sin(th) * math.sin(ph), -math.cos(th)
            out.write(struct.pack('6f', rng.uniform(1, 3), -0.01, rng.uniform(0.9, 2.4), dx, dy, dz))
EOF
  fi
  dopts="-n 2 -c 1000 -ffa -ab 2 -ad 1000 -lw 1e-4 -e MF:1 -f reinhart.cal -b rbin -bn Nrbins -m skyglow"
  : > d.log
  for _ in $(seq "$runs"); do
    RAYPATH=.:$FENESTRA_ORACLE_LIB timeit oracle-D sh -c "$O/rcontrib $dopts dmx.oct < rays.bin" | tee -a d.log
    RAYPATH=.:$lib timeit fenestra-D sh -c "$bin/rcontrib $dopts materials.rad room.rad exterior.rad sky_dmx.rad < rays.bin" | tee -a d.log
  done
  best oracle-D d.log; best fenestra-D d.log
fi
