#!/usr/bin/env bash
# fenestra example: phases I and II of the three-phase method for the bundled office (two window groups: south with
# a venetian blind, west with clear glazing), with fenestra's tools only (the commands of docs/three-phase.md):
#
#   V  (45 sensors x 145 Klems patches, per group)  oconv … window_vmx.rad window_west_vmx.rad;
#        rtcontrib -I+ … -o V_%s.vmx -b kbinS -m SouthGroup -b kbinW -m WestGroup < sensors.pts
#   D  (145 Klems patches x 146 sky, per group)     oconv … sky_dmx.rad;
#        genklemsamp … window_out.rad | rtcontrib -c N … -b rbin -m skyglow   (and window_west_out.rad)
#
# Usage: examples/three-phase/matrices.sh [OUTDIR]      (default: examples/three-phase/out/matrices)
# Settings (environment): V_OPTS (default "-ab 6 -ad 6250 -lw 2e-5", traced REPLICAS times per sensor: 50 000
# first-bounce samples in all, where -ad 50000 -lw 2e-5 discards about half of its 50 000 by the weight limit), D_OPTS ("-ab 2 -ad 1000 -lw 1e-4"), D_C (rays per Klems patch, 1000) — the parameters of
# the matrices in matrices/; REPLICAS (8; 0: none) independent replicas per record written beside each matrix
# (X.err: standard errors, X.rep: replicas, for dctimestep -Rv/-Rd); FENESTRA_BIN=dir to use already-built binaries
# instead of building them.
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
V_OPTS=${V_OPTS:--ab 6 -ad 6250 -lw 2e-5}
REPLICAS=${REPLICAS:-8}
err=()
if [ "$REPLICAS" -gt 0 ]; then err=(-E -Er "$REPLICAS"); fi
D_OPTS=${D_OPTS:--ab 2 -ad 1000 -lw 1e-4}
D_C=${D_C:-1000}
out=${1:-$here/out/matrices}
mkdir -p "$out"
out=$(cd "$out" && pwd)
cd "$here/scene"

echo "== V: rtcontrib -I+ $V_OPTS … -b kbinS -m SouthGroup -b kbinW -m WestGroup < sensors.pts" >&2
oconv materials.rad room.rad window_vmx.rad window_west_vmx.rad > "$out/vmx.oct"
# shellcheck disable=SC2086  # the option strings are meant to be split
rtcontrib -n "$nproc" -fo -I+ $V_OPTS "${err[@]}" -faa -f klems_full.cal -bn Nkbins -o "$out/V_%s.vmx" \
  -b kbinS -m SouthGroup -b kbinW -m WestGroup "$out/vmx.oct" < sensors.pts

oconv materials.rad room.rad exterior.rad sky_dmx.rad > "$out/dmx.oct"
for group in "SouthGroup window_out.rad 0 -1 0" "WestGroup window_west_out.rad -1 0 0"; do
  # shellcheck disable=SC2086
  set -- $group
  echo "== D $1: genklemsamp -c $D_C -vd $3 $4 $5 $2 | rtcontrib -c $D_C $D_OPTS … -b rbin -m skyglow" >&2
  # shellcheck disable=SC2086
  genklemsamp -ff -c "$D_C" -vd "$3" "$4" "$5" -vu 0 0 1 "$2" |
    rtcontrib -n "$nproc" -fo -c "$D_C" -ffa $D_OPTS "${err[@]}" -e MF:1 -f reinhart.cal -b rbin -bn Nrbins \
      -o "$out/D_$1.dmx" -m skyglow "$out/dmx.oct"
done
echo "V_SouthGroup.vmx, V_WestGroup.vmx, D_SouthGroup.dmx, D_WestGroup.dmx written to $out" >&2
if [ "$REPLICAS" -gt 0 ]; then echo "  with their standard errors (.err) and $REPLICAS replicas per record (.rep)" >&2; fi
