#!/usr/bin/env bash
# genBSDF (Klems, both sides) against Radiance's, same input, same machine, same run (issue 18):
#   the reference curved blind (tests/fixtures/genbsdf/blinds_curved20.mgf, converted once with
#   the oracle's mgf2rad so both read the same .rad), -c N (default 250) on 2 threads/processes.
#   Radiance's side is pyradiance.genbsdf.generate_bsdf (its port of genBSDF.pl driving the real
#   rfluxmtx/rcontrib/rmtxop binaries with genBSDF's -ab 5 -ad 700 -lw 3e-6, three colour
#   channels as genBSDF's default); ours is genBSDF -n 2 -c N +f +b. One timed run each (the
#   oracle's takes minutes at large N); prints the wall times, their ratio, and both files'
#   diffuse-incidence transmission/reflection totals for light from the room.
# Usage: benches/genbsdf.sh [N]   (needs a testopt build of genBSDF and the oracle)
set -euo pipefail
cd "$(dirname "$0")/.."
N=${1:-250}
. benches/genbsdf_blind.sh
cd "$tmp"
t0=$(date +%s.%N)
PATH="$FENESTRA_ORACLE_BIN:$PATH" RAYPATH=".:$FENESTRA_ORACLE_LIB" "$py" - "$N" <<'PY' > oracle_totals.txt
import sys
from pyradiance import genbsdf
r = genbsdf.generate_bsdf("blind.rad", nsamp=int(sys.argv[1]), nproc=2, front=True)
open("oracle_back_T.txt", "wb").write(r.back.transmittance)
open("oracle_back_R.txt", "wb").write(r.back.reflectance)
PY
t1=$(date +%s.%N)
"$bin/genBSDF" -n 2 -c "$N" +f +b blind.rad > ours.xml
t2=$(date +%s.%N)
PYTHONPATH="$benches" python3 - "$t0" "$t1" "$t2" <<'PY'
import math, sys
t0, t1, t2 = map(float, sys.argv[1:])
print(f"oracle genBSDF (pyradiance) {t1-t0:.1f} s, fenestra {t2-t1:.1f} s, ratio {(t1-t0)/(t2-t1):.2f}x")
# the oracle's matrices are rmtxop -t of rfluxmtx output: rows = outgoing patch, columns = incident
# patch, each a fraction of the incident flux (wrapBSDF divides by the outgoing patch's projected
# solid angle later); diffuse-incidence total = sum_o sum_i lam_i f[o][i] / pi
from klems_lam import LAM as lam
for name, f in [("Int->Ext Trans", "oracle_back_T.txt"), ("Interior Refl", "oracle_back_R.txt")]:
    rows = [list(map(float, l.split())) for l in open(f) if l.strip()]
    tot = sum(lam[i] * rows[o][i] for i in range(145) for o in range(145)) / math.pi
    print(f"oracle {name} diffuse {tot:.4f}")
PY
echo "fenestra (Normal, Diffuse):"; "$bin/checkBSDF" ours.xml | grep -A4 "hemispherical totals" | grep -E "^(Int->Ext Trans|Interior Refl)" || true
