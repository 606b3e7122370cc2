#!/usr/bin/env bash
# Does the proxy pay? Rendering error against time, with and without mkillum's proxy, on
# the reference room (../shared/reference/mkillum): glass window and BSDF window (the
# reference blind's Klems file), the latter's proxy made both ways: from the scene
# (bsdf: the reference directive) and from the BSDF data (bmode: d=blinds_kf.xml s=64). fenestra's rtrace -n 2 -h -I+ -ab 5 -aa 0 -lw 1e-5 on the
# 45 sensors at several -ad, K seeds each:
#   - without the proxy: rtrace -seed k, k = 1..K;
#   - with it: K proxies, mkillum -seed k -ab 2 -ad 1024 -aa 0 -lw 1e-4 (the reference
#     directive, d=100 s=32), each rendered once with rtrace -seed k, so the spread holds
#     the proxy's own sampling error as well as the rendering's.
# Error: the mean over the sensors of each sensor's relative standard deviation over the K
# runs. Time: per rendering (mkillum's own time printed apart: it is made once per sky and
# serves every rendering of the room). "Equal error": the time the rendering without the
# proxy needs for the proxy's error, from its largest -ad (error^2 x time held constant, as
# for independent samples), over the proxy rendering's time.
# Usage: benches/mkillum_pays.sh [K]   (default K = 6; needs a testopt build)
set -euo pipefail
cd "$(dirname "$0")/.."
K=${1:-6}
[ "$K" -ge 2 ] || { echo "mkillum_pays.sh: K (seeds) must be at least 2" >&2; exit 2; }
. benches/mkillum_room.sh
cd "$tmp"
export RAYPATH=".:$lib"
ads="1024 4096 8192"

# render label ad octree-pattern (%s = seed): K renderings, seconds per rendering and the
# error on one line: "label ad seconds error%"
render() {
  local t0 t1
  t0=$(date +%s.%N)
  for s in $(seq 1 "$K"); do
    # shellcheck disable=SC2059
    "$bin/rtrace" -n 2 -h -I+ -ab 5 -ad "$2" -aa 0 -lw 1e-5 -seed "$s" "$(printf "$3" "$s")" < sensors.pts > "out_$s.txt"
  done
  t1=$(date +%s.%N)
  python3 - "$1" "$2" "$K" "$t0" "$t1" <<'PY'
import statistics as st, sys
label, ad, n = sys.argv[1], sys.argv[2], int(sys.argv[3])
t = (float(sys.argv[5]) - float(sys.argv[4])) / n
runs = [[0.265 * float(a) + 0.670 * float(b) + 0.065 * float(c)
         for a, b, c in (l.split()[:3] for l in open(f"out_{k}.txt"))] for k in range(1, n + 1)]
cols = list(zip(*runs))
rsd = [st.stdev(c) / st.mean(c) for c in cols if st.mean(c) > 0]
print(f"{label} {ad} {t:.3f} {100 * st.mean(rsd):.3f} {st.mean(st.mean(c) for c in cols):.4f}")
PY
}

"$bin/oconv" materials.rad room.rad exterior.rad sky.rad skyfunc_glow.rad > outside.oct
sed 's/d=100 s=32 f=ill_bsdf/d=blinds_kf.xml s=64 f=ill_bmode/' window_illum_bsdf.rad > window_illum_bmode.rad
grep -q 'd=blinds_kf.xml' window_illum_bmode.rad || { echo "mkillum_pays.sh: the reference directive changed" >&2; exit 1; }
for w in glass bsdf bmode; do
  # bmode: the BSDF window's proxy from its BSDF data (d=blinds_kf.xml s=64), sampled
  # outside the window (the room's outside, no window); rendered with the BSDF window
  win=$w; [ "$w" = bmode ] && win=bsdf
  src=outside.oct
  if [ "$w" != bmode ]; then
    "$bin/oconv" materials.rad room.rad exterior.rad "window_$win.rad" sky.rad skyfunc_glow.rad > "$w.oct"
    src="$w.oct"
  fi
  # each proxy its own data files (the directive's f= names them)
  for s in $(seq 1 "$K"); do
    sed "s/f=ill_$w/f=ill_${w}_$s/" "window_illum_$w.rad" > "win_${w}_$s.rad"
  done
  t0=$(date +%s.%N)
  for s in $(seq 1 "$K"); do
    "$bin/mkillum" -n 2 -seed "$s" -ab 2 -ad 1024 -aa 0 -lw 1e-4 "$src" < "win_${w}_$s.rad" > "ill_${w}_$s.rad"
  done
  t1=$(date +%s.%N)
  for s in $(seq 1 "$K"); do
    "$bin/oconv" -f materials.rad room.rad exterior.rad "window_$win.rad" sky.rad skyfunc_glow.rad "ill_${w}_$s.rad" > "p_${w}_$s.oct"
  done
  : > "$w.txt"
  for ad in $ads; do
    # the window without a proxy is the same for bsdf and bmode: rendered once
    if [ "$w" = bmode ]; then
      grep "^none $ad " bsdf.txt >> "$w.txt"
    else
      render none "$ad" "$w.oct" >> "$w.txt"
    fi
    render proxy "$ad" "p_${w}_%s.oct" >> "$w.txt"
  done
  python3 - "$w" "$w.txt" "$(echo "($t1 - $t0) / $K" | bc -l)" <<'PY'
import sys
w, path, mk = sys.argv[1], sys.argv[2], float(sys.argv[3])
rows = [l.split() for l in open(path)]
none = {int(r[1]): (float(r[2]), float(r[3]), float(r[4])) for r in rows if r[0] == "none"}
prox = {int(r[1]): (float(r[2]), float(r[3]), float(r[4])) for r in rows if r[0] == "proxy"}
ref = max(none)
tr, er, _ = none[ref]
print(f"{w} window (mkillum {mk:.2f} s per proxy, made once per sky)")
print("  -ad    no proxy: s, error, mean      proxy: s, error, mean      no proxy at the proxy's error    pays")
for ad in sorted(prox):
    tn, en, mn = none[ad]
    tp, ep, mp = prox[ad]
    need = tr * (er / ep) ** 2
    print(f"  {ad:5d}  {tn:6.2f} s {en:5.2f}% {mn:8.3f}   {tp:6.2f} s {ep:5.2f}% {mp:8.3f}   {need:8.2f} s"
          f"                     {need / tp:5.1f}x")
PY
done
