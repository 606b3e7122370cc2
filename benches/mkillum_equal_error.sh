#!/usr/bin/env bash
# mkillum at equal Monte Carlo error (issue 19's speed criterion), on the reference room of
# ../shared/reference/mkillum, both windows (glass, BSDF blind), same machine, same run:
#   - Radiance's mkillum -n 2 -ab 2 -ad 1024 -aa 0 -lw 1e-4 with the reference directive (d=100 s=32), K runs
#     (its sampling is seeded differently in every run: the runs are replicates);
#   - fenestra's mkillum with the same options at s=32 (equal settings) and at s=S (default 16), K runs each
#     with -seed 1..K.
# Noise metric, per run set: each direction's luminance (the data file's value x the average colour, the pole
# row and the wrap-around column left out) has a variance over the K replicates; printed are the relative rms
# over the 310 directions, sqrt(mean of var/mean^2), and the flux-weighted one, sqrt(sum var / sum mean^2).
# The ratio at equal error is Radiance's mean time over fenestra's at s=S when fenestra's noise is not larger.
# Usage: benches/mkillum_equal_error.sh [S] [K]   (default S = 16, K = 4; needs a testopt build and the oracle)
set -euo pipefail
cd "$(dirname "$0")/.."
S=${1:-16}
K=${2:-4}
[ "$K" -ge 2 ] || { echo "mkillum_equal_error.sh: K (replicates) must be at least 2" >&2; exit 2; }
[ -f .oracle/env ] || scripts/oracle.sh > /dev/null
set -a; . .oracle/env; set +a
. benches/mkillum_room.sh
[ -x "$bin/mkillum" ] || { echo "mkillum_equal_error.sh: no $bin/mkillum (cargo build --profile testopt)" >&2; exit 2; }
O="$FENESTRA_ORACLE_BIN"
opts="-n 2 -ab 2 -ad 1024 -aa 0 -lw 1e-4"

# run label dir s mkillum-command... : one run in $tmp/label (scene.oct there), wall seconds appended to
# $tmp/label.times
run() {
  local label=$1 w=$2 s=$3 t0 t1
  shift 3
  mkdir -p "$tmp/$label"
  sed "s/s=32/s=$s/" "$tmp/window_illum_$w.rad" > "$tmp/$label/win.rad"
  t0=$(date +%s.%N)
  (cd "$tmp/$label" && "$@" scene.oct < win.rad > illum.rad 2> /dev/null)
  t1=$(date +%s.%N)
  echo "$t1 - $t0" | bc >> "$tmp/$label.times"
}

noise() { # label: relative rms and flux-weighted noise over the K runs kept as $tmp/label_k/
  python3 - "$tmp" "$1" "$K" <<'PY'
import math, os, re, sys
tmp, label, k = sys.argv[1], sys.argv[2], int(sys.argv[3])
def lum(d):
    txt = open(os.path.join(d, "illum.rad")).read()
    files = re.search(r"9 red green blue (\S+) (\S+) (\S+)", txt).groups()
    avg = [float(x) for x in re.search(r"illum \S+\s*\n0\s*\n0\s*\n3 (\S+) (\S+) (\S+)", txt).groups()]
    chans = []
    for f, a in zip(files, avg):
        t = open(os.path.join(d, f)).read().split()
        na, nb = int(t[3]), int(t[6])
        v = [float(x) for x in t[7:]]
        chans.append([v[i * nb + j] * a for i in range(1, na) for j in range(nb - 1)])
    return [.265 * r + .670 * g + .065 * b for r, g, b in zip(*chans)]
runs = [lum(os.path.join(tmp, f"{label}_{i}")) for i in range(1, k + 1)]
rel, num, den = [], 0.0, 0.0
for vals in zip(*runs):
    m = sum(vals) / k
    var = sum((x - m) ** 2 for x in vals) / (k - 1)
    if m > 0:
        rel.append(var / m / m)
    num += var; den += m * m
print("%.2f%% %.2f%%" % (100 * math.sqrt(sum(rel) / len(rel)), 100 * math.sqrt(num / den)))
PY
}

mean_time() { awk '{s += $1; n++} END {printf "%.2f", s / n}' "$tmp/$1.times"; }

for w in glass bsdf; do
  scene="materials.rad room.rad exterior.rad window_$w.rad sky.rad skyfunc_glow.rad"
  for i in $(seq "$K"); do
    for t in o f32 fS; do
      d="$tmp/${w}_${t}_$i"; mkdir -p "$d"
      (cd "$d" && for f in ../*.rad ../*.xml; do ln -sf "$f" .; done)
    done
    (cd "$tmp/${w}_o_$i" && RAYPATH=".:$FENESTRA_ORACLE_LIB" "$O/oconv" $scene > scene.oct)
    (cd "$tmp/${w}_f32_$i" && RAYPATH=".:$lib" "$bin/oconv" $scene > scene.oct)
    cp "$tmp/${w}_f32_$i/scene.oct" "$tmp/${w}_fS_$i/"
    RAYPATH=".:$FENESTRA_ORACLE_LIB" run "${w}_o_$i" "$w" 32 "$O/mkillum" $opts
    RAYPATH=".:$lib" run "${w}_f32_$i" "$w" 32 "$bin/mkillum" -seed "$i" $opts
    RAYPATH=".:$lib" run "${w}_fS_$i" "$w" "$S" "$bin/mkillum" -seed "$i" $opts
  done
  for t in o f32 fS; do
    cat "$tmp"/"${w}_${t}"_*.times > "$tmp/${w}_$t.times"
  done
  read -r on ow < <(noise "${w}_o")
  read -r f32n f32w < <(noise "${w}_f32")
  read -r fsn fsw < <(noise "${w}_fS")
  to=$(mean_time "${w}_o"); t32=$(mean_time "${w}_f32"); ts=$(mean_time "${w}_fS")
  echo "$w window ($K runs each; noise: relative rms over directions / flux-weighted)"
  printf '  %-28s %6s s  noise %s / %s\n' "Radiance s=32" "$to" "$on" "$ow"
  printf '  %-28s %6s s  noise %s / %s  (%.1fx at equal settings)\n' "fenestra s=32" "$t32" "$f32n" "$f32w" "$(echo "$to / $t32" | bc -l)"
  printf '  %-28s %6s s  noise %s / %s  (%.1fx)\n' "fenestra s=$S" "$ts" "$fsn" "$fsw" "$(echo "$to / $ts" | bc -l)"
done
