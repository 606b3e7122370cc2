#!/usr/bin/env bash
# What accuracy costs in time, on the final result: the bundled office (examples/three-phase: south window with a
# venetian blind, west window with clear glass, 45 work-plane sensors), each knob of the three-phase pipeline turned
# on its own, the other matrices held at a converged reference. For each setting (and seed): the wall time of the
# step the knob belongs to, and the error of the final result against the reference:
#   - per-sensor illuminance under an overcast sky (21 Sep 12:00) and a clear sky with sun (21 Mar 10:00): rms over
#     the 45 sensors of the relative difference, %;
#   - DA300 and UDI100-2000 over the year (sf_year.wea, 8-18 h): mean over the sensors of |metric - reference|,
#     percentage points.
# Knobs: D rays per Klems patch (-c), V ambient divisions (-ad, -ab 6), V bounces (-ab, -ad 4096), V weight limit
# (-lw, -ab 6 -ad 4096), T from the blind's geometry (genBSDF -c, against genBSDF at a high -c). Also measured:
# the reference's own standard error (from its replicas: dctimestep -Rv -Rd -Eo) and the three-phase method's own
# limit (the converged three-phase result against a direct rtrace of the same room with both windows as BSDF
# materials, averaged over seeds).
# Writes OUT/curves.tsv (every run), OUT/{overcast,clear,udi,da300,method}.svg, OUT/method.tsv (errplot), and the generated part of
# docs/accuracy.md (between its markers) when OUT is docs/accuracy.
# Usage: benches/accuracy.sh [--quick] [--out DIR]   (FENESTRA_BIN=dir of built binaries, default target/testopt;
# --quick: two settings per knob, one seed, a cheap reference: checks that the pipeline works, not the numbers)
set -euo pipefail
cd "$(dirname "$0")/.."
top=$PWD
quick=0
out=docs/accuracy
while [ $# -gt 0 ]; do
  case $1 in
    --quick) quick=1 ;;
    --out) out=$2; shift ;;
    *) echo "usage: benches/accuracy.sh [--quick] [--out DIR]" >&2; exit 2 ;;
  esac
  shift
done
bin=$(realpath "${FENESTRA_BIN:-${CARGO_TARGET_DIR:-target}/testopt}")
export PATH="$bin:$PATH" FENESTRA_LIB="$top/lib" FENESTRA_NO_PROGRESS=1
mkdir -p "$out"
out=$(realpath "$out")
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
cp examples/three-phase/scene/*.rad examples/three-phase/scene/sensors.pts examples/three-phase/matrices/*.xml \
  examples/three-phase/weather/sf_year.wea "$work/"
cp tests/fixtures/rtrace_threephase_bsdf/skyfunc_glow.rad examples/genbsdf/blinds_curved20.mgf "$work/"
cd "$work"

if [ $quick = 1 ]; then
  D_SET="25 100"; AD_SET="256 1024"; AB_SET="1 2"; LW_SET="1e-2 1e-3"; SEEDS="1"; MF_SET="1 2"; MF_C=50
  T_SET="25"; T_REF=50
  VREF="-ab 6 -ad 1024 -lw 2e-5 -E -Er 2"; DREF=100; DIRECT_SEEDS="1 2"
else
  D_SET="25 50 100 200 400 800"; AD_SET="256 512 1024 2048 4096 8192"; AB_SET="1 2 3 4"; SEEDS="1 2 3"
  LW_SET="1e-2 3e-3 1e-3 3e-4 1e-4"; T_SET="25 50 100 200 400"; T_REF=1600
  MF_SET="1 2 4"; MF_C=1000
  VREF="-ab 6 -ad 6250 -lw 2e-5 -E -Er 32"; DREF=4000; DIRECT_SEEDS=$(seq 1 16)
fi
D_OPTS="-ab 2 -ad 1000 -lw 1e-4"

now() { date +%s.%N; }
elapsed() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.3f", b - a }'; }
oconv materials.rad room.rad window_vmx.rad window_west_vmx.rad > vmx.oct
oconv materials.rad room.rad exterior.rad sky_dmx.rad > dmx.oct
gensky 9 21 12:00 -c -a 37.71 -o 122.21 -m 120 > overcast.rad
gensky 3 21 10:00 +s -a 37.71 -o 122.21 -m 120 > clear.rad
for s in overcast clear; do genskyvec -m 1 < $s.rad > $s.skv; done
gendaymtx -m 1 sf_year.wea > year.smx

# V NAME SEED OPTS..: V of both window groups (V_NAME_SouthGroup.vmx, V_NAME_WestGroup.vmx)
V() {
  local name=$1 seed=$2; shift 2
  # shellcheck disable=SC2068
  rtcontrib -n 2 -fo -I+ $@ -seed "$seed" -faf -f klems_full.cal -bn Nkbins -o "V_${name}_%s.vmx" \
    -b kbinS -m SouthGroup -b kbinW -m WestGroup vmx.oct < sensors.pts
}
# D NAME SEED C [OPTS..]: D of both groups (D_NAME_South.dmx, D_NAME_West.dmx), C rays per Klems patch, sky
# subdivision MF (environment, default 1)
D() {
  local name=$1 seed=$2 c=$3; shift 3
  genklemsamp -ff -s "$seed" -c "$c" -vd 0 -1 0 -vu 0 0 1 window_out.rad |
    rtcontrib -n 2 -fo -c "$c" -ff $D_OPTS "$@" -seed "$seed" -e "MF:${MF:-1}" -f reinhart.cal -b rbin -bn Nrbins \
      -o "D_${name}_South.dmx" -m skyglow dmx.oct
  genklemsamp -ff -s "$seed" -c "$c" -vd -1 0 0 -vu 0 0 1 window_west_out.rad |
    rtcontrib -n 2 -fo -c "$c" -ff $D_OPTS "$@" -seed "$seed" -e "MF:${MF:-1}" -f reinhart.cal -b rbin -bn Nrbins \
      -o "D_${name}_West.dmx" -m skyglow dmx.oct
}
# LUX VNAME DNAME SKY: lux per sensor and time step (both groups summed), data only; TS (environment) is the south
# window's BSDF (default the bundled blinds_kf.xml)
LUX() {
  rmtxop -ff "!dctimestep V_$1_SouthGroup.vmx ${TS:-blinds_kf.xml} D_$2_South.dmx $3" \
    + "!dctimestep V_$1_WestGroup.vmx clear_glass_kf.xml D_$2_West.dmx $3" |
    rmtxop -fa -c 47.435 119.93 11.635 - | sed '1,/^$/d'
}
# METRICS VNAME DNAME: per sensor over the year's occupied hours (8-18 h): DA300 % and UDI100-2000 %, full
# precision (dametrics prints one decimal)
METRICS() {
  LUX "$1" "$2" year.smx |
    awk -v WEA=sf_year.wea 'BEGIN { while ((getline l < WEA) > 0) { split(l, f, /[ \t]+/)
        if (f[1] ~ /^[0-9]+$/ && f[3] != "") { n++; occ[n] = (f[3] >= 8 && f[3] < 18) } } }
      NF { h = 0; a = 0; u = 0
        for (k = 1; k <= NF; k++) if (occ[k]) { h++; a += ($k >= 300); u += ($k >= 100 && $k <= 2000) }
        printf "%.6f %.6f\n", 100 * a / h, 100 * u / h }'
}
# RMS A B: rms over lines of (a - b) / b, %
RMS() { paste "$1" "$2" | awk '{ d = ($1 - $2) / $2; s += d * d; n++ } END { printf "%.4f", 100 * sqrt(s / n) }'; }
# MAD A B COL: mean |a - b| of column COL
MAD() { paste -d' ' "$1" "$2" | awk -v C="$3" '{ d = $C - $(C + 2); s += d < 0 ? -d : d; n++ } END { printf "%.4f", s / n }'; }

echo "== reference: V $VREF, D -c $DREF (-E -Er 8)" >&2
t0=$(now); V ref 0 $VREF; t1=$(now); D ref 0 "$DREF" -E -Er 8; t2=$(now)
printf "reference: V %.1f s, D %.1f s\n" "$(elapsed $t0 $t1)" "$(elapsed $t1 $t2)" >&2
for s in overcast clear; do
  LUX ref ref $s.skv > ref_$s.dat
  # the reference's own standard error per sensor: both groups' errors in quadrature, relative
  for g in South:SouthGroup:blinds_kf West:WestGroup:clear_glass_kf; do
    IFS=: read -r d v x <<< "$g"
    dctimestep -Rv "V_ref_$v.vmx.rep" -Rd "D_ref_$d.dmx.rep" -Eo "ref_${s}_$d.err" "V_ref_$v.vmx" "$x.xml" \
      "D_ref_$d.dmx" $s.skv > /dev/null
    rmtxop -fa -c 47.435 119.93 11.635 "ref_${s}_$d.err" | sed '1,/^$/d' > "ref_${s}_$d.lux"
  done
  paste "ref_${s}_South.lux" "ref_${s}_West.lux" ref_$s.dat |
    awk '{ r = sqrt($1 * $1 + $2 * $2) / $3; s += r * r; n++ } END { printf "%.4f", 100 * sqrt(s / n) }' > ref_$s.se
done
METRICS ref ref > ref_metrics.dat

echo "== method limit: direct rtrace (both windows as BSDF materials), $(echo $DIRECT_SEEDS | wc -w) seeds" >&2
for s in overcast clear; do
  cat $s.rad skyfunc_glow.rad > ${s}_glow.rad
  oconv materials.rad room.rad exterior.rad window_bsdf.rad window_west_glass.rad ${s}_glow.rad > direct_$s.oct
  for seed in $DIRECT_SEEDS; do
    rtrace -n 2 -h -I+ -ab 6 -ad 4096 -aa 0 -lw 1e-5 -seed "$seed" direct_$s.oct < sensors.pts |
      awk '{ print 47.435 * $1 + 119.93 * $2 + 11.635 * $3 }' > direct_${s}_$seed.dat
  done
  # mean over seeds, and the standard error of that mean relative to it (rms over sensors)
  paste direct_${s}_*.dat | awk '{ m = 0; for (k = 1; k <= NF; k++) m += $k; m /= NF; v = 0
      for (k = 1; k <= NF; k++) v += ($k - m) ^ 2; se = NF > 1 ? sqrt(v / (NF - 1) / NF) : 0
      print m; s += (se / m) ^ 2; n++ } END { printf "%.4f", 100 * sqrt(s / n) > "direct_'$s'.se" }' > direct_$s.dat
done

tsv=$out/curves.tsv
printf "# benches/accuracy.sh%s, %s\n# knob\tsetting\tseed\tseconds\tovercast_rms_pct\tclear_rms_pct\tda300_mad_pts\tudi_mad_pts\n" \
  "$([ $quick = 1 ] && echo " --quick")" "$(date -u +%Y-%m-%d)" > "$tsv"
row() { # KNOB SETTING SEED SECONDS VNAME DNAME   (REF: prefix of the reference results, default ref)
  local r=${REF:-ref}
  LUX "$5" "$6" overcast.skv > o.dat
  LUX "$5" "$6" clear.skv > c.dat
  METRICS "$5" "$6" > m.dat
  printf "%s\t%s\t%s\t%.3f\t%s\t%s\t%s\t%s\n" "$1" "$2" "$3" "$4" "$(RMS o.dat ${r}_overcast.dat)" \
    "$(RMS c.dat ${r}_clear.dat)" "$(MAD m.dat ${r}_metrics.dat 1)" "$(MAD m.dat ${r}_metrics.dat 2)" >> "$tsv"
}
for c in $D_SET; do
  for seed in $SEEDS; do
    echo "== D -c $c seed $seed" >&2
    t0=$(now); D t "$seed" "$c"; t1=$(now)
    row D "$c" "$seed" "$(elapsed $t0 $t1)" ref t
  done
done
for a in $AD_SET; do
  for seed in $SEEDS; do
    echo "== V -ad $a seed $seed" >&2
    t0=$(now); V t "$seed" -ab 6 -ad "$a" -lw 2e-5; t1=$(now)
    row V-ad "$a" "$seed" "$(elapsed $t0 $t1)" t ref
  done
done
for b in $AB_SET; do
  echo "== V -ab $b" >&2
  t0=$(now); V t 1 -ab "$b" -ad 4096 -lw 2e-5; t1=$(now)
  row V-ab "$b" 1 "$(elapsed $t0 $t1)" t ref
done

for w in $LW_SET; do
  echo "== V -lw $w" >&2
  t0=$(now); V t 1 -ab 6 -ad 4096 -lw "$w"; t1=$(now)
  row V-lw "$w" 1 "$(elapsed $t0 $t1)" t ref
done

# T: the blind's BSDF from its geometry by fenestra's genBSDF at -c N samples per Klems direction, against genBSDF
# at -c T_REF (V and D the reference)
echo "== T reference: genBSDF -c $T_REF +mgf blinds_curved20.mgf" >&2
genBSDF -n 2 -c "$T_REF" +mgf blinds_curved20.mgf > T_ref.xml 2> /dev/null
TS=T_ref.xml LUX ref ref overcast.skv > refT_overcast.dat
TS=T_ref.xml LUX ref ref clear.skv > refT_clear.dat
TS=T_ref.xml METRICS ref ref > refT_metrics.dat
for c in $T_SET; do
  echo "== T: genBSDF -c $c" >&2
  t0=$(now); genBSDF -n 2 -c "$c" +mgf blinds_curved20.mgf > T_t.xml 2> /dev/null; t1=$(now)
  TS=T_t.xml REF=refT row T "$c" 1 "$(elapsed $t0 $t1)" ref ref
done

# the method: sky subdivision MF 1, 2, 4 (D at -c MF_C, V the reference) against the direct rtrace
printf "# benches/accuracy.sh%s: three-phase against direct rtrace by sky subdivision\n# MF\tD_seconds\tovercast_rms_pct\tclear_rms_pct\n" \
  "$([ $quick = 1 ] && echo " --quick")" > "$out/method.tsv"
for mf in $MF_SET; do
  echo "== sky subdivision MF $mf (D -c $MF_C) against direct rtrace" >&2
  for s in overcast clear; do genskyvec -m "$mf" < $s.rad > ${s}_mf$mf.skv; done
  t0=$(now); MF=$mf D mf$mf 1 "$MF_C"; t1=$(now)
  LUX ref mf$mf overcast_mf$mf.skv > o.dat
  LUX ref mf$mf clear_mf$mf.skv > c.dat
  printf "%s\t%s\t%s\t%s\n" "$mf" "$(elapsed $t0 $t1)" "$(RMS o.dat direct_overcast.dat)" "$(RMS c.dat direct_clear.dat)" \
    >> "$out/method.tsv"
done
# x: sky patches (Reinhart: 144 MF² + 2); D's time does not change with MF (the same rays)
awk -F'\t' '!/^#/ { printf "overcast sky\t%d\t%s\n", 144 * $1 * $1 + 2, $3 }' "$out/method.tsv" > chart_method.tsv
awk -F'\t' '!/^#/ { printf "clear sky with sun\t%d\t%s\n", 144 * $1 * $1 + 2, $4 }' "$out/method.tsv" >> chart_method.tsv
errplot -t "The method: three-phase against direct rtrace, sky MF $(echo $MF_SET | tr ' ' /)" \
  -x "sky patches (Reinhart MF $(echo $MF_SET | tr ' ' /); D -c $MF_C, the same time for each)" \
  -y "rms difference from direct rtrace (%)" \
  -H "$(cat direct_overcast.se)" "direct rtrace's own standard error, overcast" \
  -H "$(cat direct_clear.se)" "direct rtrace's own standard error, clear" -o "$out/method.svg" chart_method.tsv

# per setting: mean time, rms over seeds of each error
awk -F'\t' '!/^#/ { k = $1 "\t" $2; if (!(k in n)) order[++m] = k; n[k]++; t[k] += $4
    o[k] += $5 * $5; c[k] += $6 * $6; d[k] += $7 * $7; u[k] += $8 * $8 }
  END { for (i = 1; i <= m; i++) { k = order[i]
    printf "%s\t%.3f\t%.4f\t%.4f\t%.4f\t%.4f\n", k, t[k] / n[k], sqrt(o[k] / n[k]), sqrt(c[k] / n[k]),
      sqrt(d[k] / n[k]), sqrt(u[k] / n[k]) } }' \
  "$tsv" > summary.tsv
name() { case $1 in
  D) echo "D: rays per Klems patch, -c" ;;
  V-ad) echo "V: ambient divisions, -ad (-ab 6)" ;;
  V-ab) echo "V: bounces, -ab (-ad 4096)" ;;
  V-lw) echo "V: weight limit, -lw (-ab 6 -ad 4096)" ;;
  T) echo "T: genBSDF samples per direction, -c" ;;
esac; }
for col in 4:overcast 5:clear; do
  IFS=: read -r k what <<< "$col"
  : > chart_$what.tsv
  for knob in D V-ad V-ab V-lw T; do
    awk -F'\t' -v K="$knob" -v C="$k" -v N="$(name "$knob")" '$1 == K && $C > 0 { printf "%s\t%s\t%s\n", N, $3, $C }' \
      summary.tsv >> chart_$what.tsv
  done
done
for col in 6:da300 7:udi; do
  IFS=: read -r k what <<< "$col"
  : > chart_$what.tsv
  for knob in D V-ad V-ab V-lw T; do
    awk -F'\t' -v K="$knob" -v C="$k" -v N="$(name "$knob")" '$1 == K && $C > 0 { printf "%s\t%s\t%s\n", N, $3, $C }' \
      summary.tsv >> chart_$what.tsv
  done
done
ref_o=$(cat ref_overcast.se); ref_c=$(cat ref_clear.se)
lim_o=$(RMS ref_overcast.dat direct_overcast.dat); lim_c=$(RMS ref_clear.dat direct_clear.dat)
for sky in "overcast:Overcast sky (21 Sep 12:00)" "clear:Clear sky with sun (21 Mar 10:00)"; do
  IFS=: read -r s title <<< "$sky"
  errplot -t "$title: illuminance at 45 sensors" -x "wall time of the step (s), 2 cores" \
    -y "rms error against the reference (%)" -g "$(name D)" -g "$(name V-ad)" -g "$(name T)" \
    -H "$(cat ref_$s.se)" "the reference's own standard error" \
    -H "$(RMS ref_$s.dat direct_$s.dat)" "three-phase vs direct rtrace (the method's own limit)" \
    -o "$out/$s.svg" chart_$s.tsv
done
errplot -t "Annual UDI 100-2000 lux (8-18 h) at 45 sensors" -x "wall time of the step (s), 2 cores" \
  -y "mean |UDI - reference| (percentage points)" -g "$(name D)" -g "$(name V-ad)" \
  -o "$out/udi.svg" chart_udi.tsv
errplot -t "Annual DA300 (8-18 h) at 45 sensors" -x "wall time of the step (s), 2 cores" \
  -y "mean |DA300 - reference| (percentage points)" -g "$(name D)" -g "$(name V-ad)" \
  -o "$out/da300.svg" chart_da300.tsv

# the generated part of the page
{
  echo "<!-- generated by benches/accuracy.sh$([ $quick = 1 ] && echo " --quick") on $(date -u +%Y-%m-%d); do not edit by hand -->"
  echo
  echo "| knob | setting | wall s | overcast rms % | clear rms % | DA300 mean abs. error (points) | UDI100-2000 mean abs. error (points) |"
  echo "|---|---|---|---|---|---|---|"
  awk -F'\t' '{ printf "| %s | %s | %.2f | %.2f | %.2f | %.3f | %.2f |\n", $1, $2, $3, $4, $5, $6, $7 }' summary.tsv
  echo
  printf "Reference: V \`%s\` (%s), D \`-c %s %s -E -Er 8\`; its own standard error (rms over sensors): overcast %.2f%%, clear %.2f%%.\n" \
    "$VREF" "the value is the mean of the replicas" "$DREF" "$D_OPTS" "$ref_o" "$ref_c"
  printf "Three-phase (the reference) against direct rtrace \`-ab 6 -ad 4096 -aa 0 -lw 1e-5\`, mean of %s seeds (its own standard error %.2f%% / %.2f%%): rms %.2f%% overcast, %.2f%% clear.\n" \
    "$(echo $DIRECT_SEEDS | wc -w)" "$(cat direct_overcast.se)" "$(cat direct_clear.se)" "$lim_o" "$lim_c"
  echo
  echo "![overcast](accuracy/overcast.svg)"
  echo
  echo "![clear](accuracy/clear.svg)"
  echo
  echo "![UDI](accuracy/udi.svg)"
  echo
  echo "![DA300](accuracy/da300.svg)"
  echo
  echo "The method itself, by sky subdivision (Reinhart MF; D at \`-c $MF_C\`, V the reference), against the direct rtrace:"
  echo
  echo "| MF | D wall s | overcast rms % | clear rms % |"
  echo "|---|---|---|---|"
  awk -F'\t' '!/^#/ { printf "| %s | %.2f | %.2f | %.2f |\n", $1, $2, $3, $4 }' "$out/method.tsv"
  echo
  echo "![method](accuracy/method.svg)"
} > "$out/generated.md"
if [ "$out" = "$top/docs/accuracy" ]; then
  doc=$top/docs/accuracy.md
  awk -v gen="$out/generated.md" '
    /<!-- curves:begin -->/ { print; while ((getline l < gen) > 0) print l; skip = 1; next }
    /<!-- curves:end -->/ { skip = 0 }
    !skip { print }' "$doc" > "$doc.tmp" && mv "$doc.tmp" "$doc"
fi
cat "$out/generated.md"
