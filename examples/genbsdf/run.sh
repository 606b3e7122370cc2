#!/usr/bin/env bash
# fenestra example: geometry → BSDF → three-phase annual run.
#
#   1. genBSDF     the curved venetian blind (blinds_curved20.mgf: 15 slats, 25 mm chord, 20 mm pitch, tilted
#                  20°) into a Klems BSDF with colour, both sides: genBSDF +C +f +b +mgf (prints a summary)
#   2. checkBSDF   what the file holds (hemispherical totals, reciprocity, energy check)
#   3. three-phase the bundled office's south window (examples/three-phase) for a year: dctimestep V T D s with our
#                  blind, and again with Radiance's genBSDF file of the same blind (matrices/blinds_kf.xml):
#                  per-sensor mean illuminance over working hours with both, and their difference
# Usage: examples/genbsdf/run.sh   (C=samples per direction, default 200; OUT=dir for results;
# FENESTRA_BIN=dir to use already-built binaries)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
. "$here/../lib.sh"
out=${OUT:-$here/out}
mkdir -p "$out"
tp="$top/examples/three-phase"

start=$(date +%s.%N)
echo "== genBSDF -n $nproc -c ${C:-200} +C +f +b +mgf blinds_curved20.mgf" >&2
genBSDF -n "$nproc" -c "${C:-200}" +C +f +b +mgf "$here/blinds_curved20.mgf" > "$out/blind.xml"
t_bsdf=$(date +%s.%N)
echo "== checkBSDF" >&2
checkBSDF "$out/blind.xml" | sed -n '/fenestra: hemispherical/,$p'
echo "== sky matrix and time steps (south window only, bundled V and D)" >&2
gendaymtx -m 1 "$tp/weather/sf_year.wea" > "$out/sky.smx"
for t in ours radiance; do
  xml="$out/blind.xml"
  [ "$t" = radiance ] && xml="$tp/matrices/blinds_kf.xml"
  dctimestep "$tp/matrices/V_SouthGroup.vmx" "$xml" "$tp/matrices/D_SouthGroup.dmx" "$out/sky.smx" |
    rmtxop -fa -c 47.435 119.93 11.635 - > "$out/ill_$t.dat"
done
end=$(date +%s.%N)

echo "== mean illuminance over working hours (8-18 h), south window with the blind only"
awk -v WEA="$tp/weather/sf_year.wea" '
  BEGIN {
    n = 0
    while ((getline line < WEA) > 0) {
      split(line, f, /[ \t]+/)
      if (f[1] ~ /^[0-9]+$/ && f[2] ~ /^[0-9]+$/ && f[3] != "") { n++; work[n] = (f[3] >= 8 && f[3] < 18) }
    }
  }
  FNR == 1 { file++; body = 0; row = 0 }
  body == 0 { if ($0 == "") body = 1; next }
  NF > 0 {
    row++; nw = 0; sum = 0
    for (k = 1; k <= NF; k++) if (work[k]) { nw++; sum += $k }
    mean[file, row] = sum / nw; rows = row
  }
  END {
    printf "%-7s %14s %14s %8s\n", "sensor", "our BSDF", "Radiance BSDF", "diff %"
    for (r = 1; r <= rows; r++) {
      d = 100 * (mean[1, r] / mean[2, r] - 1); ad += (d < 0 ? -d : d)
      a += mean[1, r]; b += mean[2, r]
      printf "%-7d %14.1f %14.1f %8.2f\n", r, mean[1, r], mean[2, r], d
    }
    printf "room: mean %.1f lux vs %.1f lux (%.2f %%), mean |difference| %.2f %%\n", a / rows, b / rows, 100 * (a / b - 1), ad / rows
  }
' "$out/ill_ours.dat" "$out/ill_radiance.dat"
awk -v a="$start" -v b="$t_bsdf" -v c="$end" 'BEGIN { printf "time: genBSDF %.1f s, sky matrix and time steps %.1f s\n", b - a, c - b }'
