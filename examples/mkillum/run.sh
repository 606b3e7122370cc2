#!/usr/bin/env bash
# fenestra example: windows as proxy light sources (mkillum) in the reference room of tests/fixtures/mkillum
# (a south window with venetian blinds, clear sky with sun, 21 March 10:00, San Francisco).
#
#   1. mkillum, traced:    the blind window's BSDF material is in the scene; mkillum samples through it
#   2. mkillum, BSDF data: d=blinds_kf.xml: the outside sampled over the BSDF's Klems patches, T applied
#   3. rtrace:             the 45 sensors without a proxy and with each proxy; mean illuminance and timings
# Usage: examples/mkillum/run.sh   (OUT=dir for results; FENESTRA_BIN=dir to use already-built binaries)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
. "$here/../lib.sh"
fx="$top/tests/fixtures/mkillum"
out=${OUT:-$here/out}
mkdir -p "$out"
cd "$out"
export RAYPATH=".:$top/tests/fixtures/threephase"
scene="$fx/materials.rad $fx/room.rad $fx/exterior.rad $fx/sky.rad $fx/skyfunc_glow.rad"
oconv $scene "$fx/window_bsdf.rad" > room.oct
oconv $scene > outside.oct
rtopts="-n $nproc -h -I+ -ab 5 -ad 8192 -aa 0 -lw 1e-5"
lux() { awk '{s += 179*(.265*$1 + .670*$2 + .065*$3); n++} END {printf "%.0f", s/n}'; }
secs() { awk -v a="$1" -v b="$2" 'BEGIN {printf "%.2f", b - a}'; }

t0=$(date +%s.%N)
sed 's/f=win_ill/f=traced/' "$fx/window_illum.rad" |
  mkillum -n "$nproc" -ab 2 -ad 1024 -aa 0 -lw 1e-4 room.oct > illum_traced.rad
t1=$(date +%s.%N)
sed 's/d=100 s=32 f=win_ill/d=blinds_kf.xml s=64 f=bsdfdata/' "$fx/window_illum.rad" |
  mkillum -n "$nproc" -ab 2 -ad 1024 -aa 0 -lw 1e-4 outside.oct > illum_bsdf.rad
t2=$(date +%s.%N)
echo "mkillum traced through the BSDF material: $(secs "$t0" "$t1") s; from the BSDF data: $(secs "$t1" "$t2") s"
for p in none traced bsdf; do
  if [ $p = none ]; then oct=room.oct; else
    oconv -f $scene "$fx/window_bsdf.rad" illum_$p.rad > proxy_$p.oct; oct=proxy_$p.oct; fi
  a=$(date +%s.%N)
  m=$(rtrace $rtopts "$oct" < "$fx/sensors.pts" | tee irr_$p.dat | lux)
  b=$(date +%s.%N)
  echo "sensors, proxy $p: mean $m lux ($(secs "$a" "$b") s)"
done
echo "Radiance (tests/fixtures/mkillum): no proxy $(lux < "$fx/irr_bsdf_noproxy.dat") lux, its own proxy $(lux < "$fx/irr_bsdf_proxy.dat") lux"
