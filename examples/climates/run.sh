#!/usr/bin/env bash
# fenestra example: the three-phase office of examples/three-phase under real weather of two climates.
#
# For each typical-year weather file in weather/ (NREL TMY3, public domain: Chicago IL and Melbourne FL):
#   1. gendaymtx -m 1        the annual sky matrix, and a sun-only one (-d) for annual sunlight exposure
#   2. dctimestep V T D s    both window groups with the bundled matrices (south: venetian blind, west: clear glass),
#                            summed, to lux (and with clear glass on both windows and the sun alone, for ASE)
#   3. metrics               per sensor: DA300 and UDI 100-2000 over occupied hours (8-18 h local standard time);
#                            for the room: sDA300/50% (share of sensors lit to 300 lux half the occupied hours) and
#                            ASE1000/250 (share of sensors with more than 1000 lux of direct sun for over 250 hours)
# Usage: examples/climates/run.sh   (OUT=dir for results; FENESTRA_BIN=dir to use already-built binaries)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
. "$here/../lib.sh"
out=${OUT:-$here/out}
mkdir -p "$out"
m="$top/examples/three-phase/matrices"
pts="$top/examples/three-phase/scene/sensors.pts"
lux() { rmtxop -fa -c 47.435 119.93 11.635 - ; }

for wea in "$here"/weather/*.wea; do
  name=$(basename "$wea" .wea)
  echo "== $name: sky matrices (gendaymtx -m 1, and -d for the sun alone)" >&2
  gendaymtx -m 1 "$wea" > "$out/$name.smx" 2> "$out/$name.gendaymtx.log"
  gendaymtx -m 1 -d "$wea" > "$out/$name.sun.smx" 2>> "$out/$name.gendaymtx.log"
  echo "== $name: dctimestep (south blind + west clear; and clear glass both, sun only)" >&2
  rmtxop -ff "!dctimestep $m/V_SouthGroup.vmx $m/blinds_kf.xml $m/D_SouthGroup.dmx $out/$name.smx" \
    + "!dctimestep $m/V_WestGroup.vmx $m/clear_glass_kf.xml $m/D_WestGroup.dmx $out/$name.smx" | lux > "$out/$name.ill"
  rmtxop -ff "!dctimestep $m/V_SouthGroup.vmx $m/clear_glass_kf.xml $m/D_SouthGroup.dmx $out/$name.sun.smx" \
    + "!dctimestep $m/V_WestGroup.vmx $m/clear_glass_kf.xml $m/D_WestGroup.dmx $out/$name.sun.smx" | lux > "$out/$name.sun.ill"
  awk -v WEA="$wea" -v PTS="$pts" -v NAME="$name" -v SUN="$out/$name.sun.ill" -v PER="$out/$name.metrics.txt" '
    function body_rows(file, arr,    line, b, r, f, k, nf) {
      b = 0; r = 0
      while ((getline line < file) > 0) {
        if (!b) { if (line == "") b = 1; continue }
        nf = split(line, f, /[ \t]+/)
        if (nf == 0) continue
        r++; k = 0
        for (i = 1; i <= nf; i++) if (f[i] != "") arr[r, ++k] = f[i]
        cols[r] = k
      }
      return r
    }
    BEGIN {
      n = 0
      while ((getline line < WEA) > 0) {
        split(line, f, /[ \t]+/)
        if (f[1] ~ /^[0-9]+$/ && f[2] ~ /^[0-9]+$/ && f[3] != "") { n++; occ[n] = (f[3] >= 8 && f[3] < 18) }
      }
      s = 0
      while ((getline line < PTS) > 0) { split(line, p, /[ \t]+/); s++; px[s] = p[1]; py[s] = p[2] }
      ns = body_rows(SUN, sun)
      printf "%-7s %6s %6s %9s %9s %9s %11s\n", "sensor", "x", "y", "DA300 %", "UDI %", "mean lux", "sun>1000 h" > PER
      body = 0; row = 0
    }
    body == 0 { if ($0 == "") body = 1; next }
    NF > 0 {
      row++; no = 0; da = 0; udi = 0; sum = 0; hot = 0
      if (NF != n) { printf "run.sh: %d values for sensor %d, expected %d hours\n", NF, row, n > "/dev/stderr"; exit 1 }
      for (k = 1; k <= NF; k++) if (occ[k]) {
        no++; sum += $k
        if ($k >= 300) da++
        if ($k >= 100 && $k <= 2000) udi++
        if (sun[row, k] > 1000) hot++
      }
      printf "%-7d %6.2f %6.2f %9.1f %9.1f %9.1f %11d\n", row, px[row], py[row], 100 * da / no, 100 * udi / no, sum / no, hot > PER
      tda += da / no; tudi += udi / no
      if (da / no >= 0.5) sda++
      if (hot > 250) ase++
    }
    END {
      printf "%-28s sDA300/50%% %5.1f %%   ASE1000/250 %5.1f %%   mean DA300 %5.1f %%   mean UDI100-2000 %5.1f %%   (%d sensors, %d occupied hours)\n",
        NAME, 100 * sda / row, 100 * ase / row, 100 * tda / row, 100 * tudi / row, row, no
    }
  ' "$out/$name.ill"
done
echo "per-sensor tables: $out/*.metrics.txt"
