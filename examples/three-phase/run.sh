#!/usr/bin/env bash
# fenestra example: a three-phase annual run on the bundled office (south window with a venetian blind, west window
# with clear glazing).
#
#   sky matrix s   gendaymtx -m 1 weather/sf_year.wea                     (146 Reinhart patches x 8760 hours)
#   time step      per window group dctimestep V T D s, summed by rmtxop, -c … to lux (45 sensors x 8760 hours):
#                  south window with a venetian blind (blinds_kf.xml), west window with clear glass (clear_glass_kf.xml)
#   metrics        dametrics: per sensor DA300, UDI 100-2000 and mean lux over working hours (8-18 h), sDA300/50%;
#                  with fresh matrices also how far each can move within 2 standard errors of every hour (the
#                  errors from the matrices' replicas: dctimestep -Rv -Rd -Eo)
#
#   phases I, II   matrices.sh: V (room → window, Klems) with rtcontrib -I, D (window → sky, Reinhart MF 1) with
#                  genklemsamp | rtcontrib, per window group (scene/); matrices/ holds the same at these settings
#   picture        21 March 10:00: vwrays | rtcontrib -ffc (V per pixel), dctimestep per group, pcomb; PNG and false
#                  colour by hdr2png (PICTURE_RES=px, default 200)
# Usage: examples/three-phase/run.sh   (OUT=dir to choose where results go; FENESTRA_BIN=dir to use
# already-built binaries instead of building them; MATRICES=bundled to use the bundled V and D instead of
# computing them first with fenestra's genklemsamp/rtcontrib through matrices.sh)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
top=$(cd "$here/../.." && pwd)
if [ -z "${FENESTRA_BIN:-}" ]; then
  echo "== building fenestra (cargo build --release; 2-5 minutes the first time)" >&2
  cargo build --release --manifest-path "$top/Cargo.toml" --bins
  target=$(cargo metadata --format-version 1 --no-deps --manifest-path "$top/Cargo.toml" |
    sed -n 's/.*"target_directory":"\([^"]*\)".*/\1/p')
  FENESTRA_BIN="$target/release"
fi
export PATH="$FENESTRA_BIN:$PATH"
nproc=$(nproc 2>/dev/null || echo 2)
out=${OUT:-$here/out}
mkdir -p "$out"
cd "$here"

start=$(date +%s.%N)
m=matrices
if [ "${MATRICES:-fresh}" = fresh ]; then
  echo "== phases I and II: matrices.sh (V and D of both window groups with genklemsamp | rtcontrib, rtcontrib -I)" >&2
  FENESTRA_BIN="$FENESTRA_BIN" "$here/matrices.sh" "$out/matrices"
  m="$out/matrices"
fi

echo "== sky matrix: gendaymtx -m 1 weather/sf_year.wea" >&2
gendaymtx -m 1 weather/sf_year.wea > "$out/sky.smx"
echo "== time step: dctimestep V T D sky per window group (south: blind, west: clear), summed, to lux" >&2
# with the matrices' replicas (matrices.sh writes them), each group's standard errors too
es="" ew="" errs=()
if [ -f "$m/V_SouthGroup.vmx.rep" ] && [ -f "$m/D_SouthGroup.dmx.rep" ]; then
  es="-Rv $m/V_SouthGroup.vmx.rep -Rd $m/D_SouthGroup.dmx.rep -Eo $out/ill_south.err"
  ew="-Rv $m/V_WestGroup.vmx.rep -Rd $m/D_WestGroup.dmx.rep -Eo $out/ill_west.err"
  errs=(-E "$out/ill_south.err" -E "$out/ill_west.err")
fi
rmtxop -ff "!dctimestep $es $m/V_SouthGroup.vmx matrices/blinds_kf.xml $m/D_SouthGroup.dmx $out/sky.smx" \
  + "!dctimestep $ew $m/V_WestGroup.vmx matrices/clear_glass_kf.xml $m/D_WestGroup.dmx $out/sky.smx" |
  rmtxop -fa -c 47.435 119.93 11.635 - > "$out/ill.dat"

echo "== one moment as a picture (${PICTURE_RES:=200} px): V per pixel (vwrays | rtcontrib -ffc, both groups), dctimestep per group, pcomb" >&2
pic_start=$(date +%s.%N)
gensky 3 21 10 +s -a 37.71 -o 122.21 -m 120 | genskyvec -m 1 > "$out/sky_0321_1000.skv"
mkdir -p "$out/vimg"
(
  cd scene
  oconv materials.rad room.rad window_vmx.rad window_west_vmx.rad > "$out/vimg/vmx.oct"
  # shellcheck disable=SC2046  # vwrays -d prints the -x -y options rtcontrib needs
  vwrays -ff -vf view.vf -x "$PICTURE_RES" -y "$PICTURE_RES" |
    rtcontrib -n "$nproc" -fo $(vwrays -vf view.vf -x "$PICTURE_RES" -y "$PICTURE_RES" -d) -ffc -ab 2 -ad 1024 -lw 1e-4 \
      -o "$out/vimg/%s_%03d.hdr" -f klems_full.cal -bn Nkbins -b kbinS -m SouthGroup -b kbinW -m WestGroup \
      "$out/vimg/vmx.oct"
)
pcomb "!dctimestep $out/vimg/SouthGroup_%03d.hdr matrices/blinds_kf.xml $m/D_SouthGroup.dmx $out/sky_0321_1000.skv" \
  "!dctimestep $out/vimg/WestGroup_%03d.hdr matrices/clear_glass_kf.xml $m/D_WestGroup.dmx $out/sky_0321_1000.skv" \
  > "$out/view_0321_1000.hdr"
end=$(date +%s.%N)
pic_secs=$(awk -v a="$pic_start" -v b="$end" 'BEGIN { printf "%.1f", b - a }')

echo "== annual metrics per sensor (working hours 8-18 h local standard time)"
dametrics -w weather/sf_year.wea -o 8 18 -p scene/sensors.pts -m "$out/metrics_map.svg" "${errs[@]}" "$out/ill.dat" |
  tee "$out/metrics.txt"
echo "floor-plan map of DA300 and UDI per sensor: $out/metrics_map.svg"
hdr2png -o "$out/view_0321_1000.png" "$out/view_0321_1000.hdr" 2> /dev/null
hdr2png -f auto -o "$out/view_0321_1000_falsecolor.png" "$out/view_0321_1000.hdr" 2> "$out/falsecolor_scale.txt"
echo "picture of 21 March 10:00 (radiance through both windows, as seen from the back of the room; $PICTURE_RES px, -ab 2 -ad 1024, $pic_secs s): $out/view_0321_1000.hdr"
echo "  the same as PNG: $out/view_0321_1000.png, in false colour: $out/view_0321_1000_falsecolor.png ($(cut -d: -f2- "$out/falsecolor_scale.txt"))"
awk -v a="$start" -v b="$end" -v o="$out" 'BEGIN { printf "time for the pipeline (matrices, sky matrix, time steps, picture): %.2f s (results in %s)\n", b - a, o }'
