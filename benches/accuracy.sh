#!/usr/bin/env bash
# What accuracy costs in time: the daylight matrix D and the view matrix V of the bundled office
# (examples/three-phase/scene) at increasing sample counts, with fenestra's own Monte Carlo standard
# errors (rtcontrib -E). For each run: wall time, and the standard error relative to the value,
# median over the matrix elements that are not zero, and for the whole matrix (sum of all elements).
#   D: genklemsamp -c N | rtcontrib -c N -ab 2 -ad 1000 -lw 1e-4 -E   for N = 25 … 400 rays per Klems patch
#   V: rtcontrib -I+ -ab 3 -ad A -lw 1e-4 -E (-Eb 4 replicas)        for A = 256 … 4096
# Usage: benches/accuracy.sh   (FENESTRA_BIN=dir of built binaries; default target/testopt). Prints a
# markdown table (the one in docs/accuracy.md).
set -euo pipefail
cd "$(dirname "$0")/.."
bin=$(realpath "${FENESTRA_BIN:-${CARGO_TARGET_DIR:-target}/testopt}")
export PATH="$bin:$PATH" FENESTRA_LIB="$PWD/lib" FENESTRA_NO_PROGRESS=1
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
cd examples/three-phase/scene
oconv materials.rad room.rad exterior.rad sky_dmx.rad > "$tmp/dmx.oct"
oconv materials.rad room.rad window_vmx.rad > "$tmp/vmx.oct"

# stats VALUES ERRORS: median relative se of non-zero elements, relative se of the total
stats() {
  paste <(sed '1,/^$/d' "$1" | tr '\t ' '\n\n' | awk 'NF') \
        <(sed '1,/^$/d' "$2" | tr '\t ' '\n\n' | awk 'NF') > "$tmp/pairs"
  med=$(awk '$1 > 1e-9 { print $2 / $1 }' "$tmp/pairs" | sort -g |
    awk '{ r[NR] = $1 } END { printf "%.3f", 100 * r[int((NR + 1) / 2)] }')
  tot=$(awk '{ v += $1; e2 += $2 * $2 } END { printf "%.4f", 100 * sqrt(e2) / v }' "$tmp/pairs")
  printf "%s%% | %s%%" "$med" "$tot"
}

echo "| matrix | samples | wall s | median rel. se (non-zero elements) | rel. se of the matrix total |"
echo "|---|---|---|---|---|"
for n in 25 50 100 200 400; do
  start=$(date +%s.%N)
  genklemsamp -ff -c "$n" -vd 0 -1 0 -vu 0 0 1 window_out.rad |
    rtcontrib -n 2 -fo -c "$n" -ffa -ab 2 -ad 1000 -lw 1e-4 -e MF:1 -f reinhart.cal -b rbin -bn Nrbins \
      -o "$tmp/D.dmx" -E -m skyglow "$tmp/dmx.oct"
  end=$(date +%s.%N)
  printf "| D (145×146) | -c %s | %.1f | %s |\n" "$n" "$(echo "$end - $start" | bc)" "$(stats "$tmp/D.dmx" "$tmp/D.dmx.err")"
done
for a in 256 512 1024 2048 4096; do
  start=$(date +%s.%N)
  rtcontrib -n 2 -fo -I+ -ab 3 -ad "$a" -lw 1e-4 -faa -f klems_full.cal -b kbinS -bn Nkbins \
    -o "$tmp/V.vmx" -E -m SouthGroup "$tmp/vmx.oct" < sensors.pts
  end=$(date +%s.%N)
  printf "| V (45×145) | -ad %s (×4 replicas) | %.1f | %s |\n" "$a" "$(echo "$end - $start" | bc)" "$(stats "$tmp/V.vmx" "$tmp/V.vmx.err")"
done
