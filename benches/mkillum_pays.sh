#!/usr/bin/env bash
# Does the proxy pay? Rendering noise against time, with and without mkillum's proxy, on
# the reference room (../shared/reference/mkillum): glass window and BSDF window (the
# reference blind's Klems file). For each -ad, six seeds of fenestra's rtrace
# (-ab 5 -aa 0 -lw 1e-5, the 45 sensors); prints the time per run and the mean over the
# sensors of each sensor's relative standard deviation across the seeds. The proxy is made
# once per window (mkillum -ab 2 -ad 1024, time printed).
# Usage: benches/mkillum_pays.sh [seeds]
set -euo pipefail
cd "$(dirname "$0")/.."
seeds=${1:-6}
. benches/mkillum_room.sh
cd "$tmp"
export RAYPATH=".:$lib"
noise() { # label octree ad
  local t0 t1
  t0=$(date +%s.%N)
  for s in $(seq 1 "$seeds"); do
    "$bin/rtrace" -n 2 -h -I+ -ab 5 -ad "$3" -aa 0 -lw 1e-5 -seed "$s" "$2" < sensors.pts > "out_$s.txt"
  done
  t1=$(date +%s.%N)
  python3 - "$1" "$3" "$seeds" "$t0" "$t1" <<'PY'
import statistics as st, sys
label, ad, n = sys.argv[1], sys.argv[2], int(sys.argv[3])
t = (float(sys.argv[5]) - float(sys.argv[4])) / n
runs = [[0.265 * float(a) + 0.670 * float(b) + 0.065 * float(c)
         for a, b, c in (l.split()[:3] for l in open(f"out_{k}.txt"))] for k in range(1, n + 1)]
cols = list(zip(*runs))
rsd = [st.stdev(c) / st.mean(c) for c in cols if st.mean(c) > 0]
print(f"{label:<18} -ad {ad:>5}: {t:5.2f} s per run, mean {st.mean(st.mean(c) for c in cols):7.3f}, "
      f"per-sensor relative sd {100 * st.mean(rsd):5.2f}%")
PY
}
for w in glass bsdf; do
  "$bin/oconv" materials.rad room.rad exterior.rad "window_$w.rad" sky.rad skyfunc_glow.rad > "$w.oct"
  t0=$(date +%s.%N)
  "$bin/mkillum" -n 2 -ab 2 -ad 1024 -aa 0 -lw 1e-4 "$w.oct" < "window_illum_$w.rad" > "ill_$w.rad"
  t1=$(date +%s.%N)
  echo "mkillum ($w window): $(python3 -c "print(f'{$t1 - $t0:.2f}')") s"
  "$bin/oconv" -f materials.rad room.rad exterior.rad "window_$w.rad" sky.rad skyfunc_glow.rad "ill_$w.rad" > "p_$w.oct"
  for ad in 1024 4096 8192; do
    noise "$w no proxy" "$w.oct" "$ad"
    noise "$w proxy" "p_$w.oct" "$ad"
  done
done
