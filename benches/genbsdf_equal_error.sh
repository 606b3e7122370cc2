#!/usr/bin/env bash
# genBSDF at equal Monte Carlo error (issue 18's speed criterion): Radiance's genBSDF at -c 1000 (Klems, +f +b, colour)
# against fenestra's at a -c whose element noise is no larger, same blind, same machine, same run.
#   - Radiance: pyradiance's genbsdf.generate_bsdf (its port of genBSDF.pl driving the real rfluxmtx/rcontrib/rmtxop,
#     genBSDF's -ab 5 -ad 700 -lw 3e-6, three colour channels) at -c 1000 on 2 processes, timed. Its noise: Radiance's
#     rfluxmtx draws the same start points and directions in every run (two runs at -c 1000 differ only by their
#     ambient sampling: 0.1% of transmission), so reruns are not replicates. Runs with other sample grids are:
#     -c 960 and -c 1050 (32 x 31 and 34 x 31 samples against 33 x 31), light from the room only; the spread of the
#     three runs, scaled to the 1023 samples of -c 1000 by the square root of the sample counts, is the noise.
#   - fenestra: genBSDF -n 2 -c N +C +f +b, timed; its noise: the spread of K replicates (-r '-seed S') at the same
#     -c, light from the room only and grey (the Visible blocks do not depend on +C or +f).
#   Noise metric, per block (light from the room: transmission, reflection): relative rms over the 145 x 145
#   elements of the flux fraction (BSDF x the outgoing patch's projected solid angle), i.e.
#   sqrt(sum of element variances / sum of squared element means).
# Usage: benches/genbsdf_equal_error.sh [N] [K]   (default N = 450, K = 4; needs a testopt build and the oracle)
set -euo pipefail
cd "$(dirname "$0")/.."
N=${1:-450}
K=${2:-4}
[ "$K" -ge 2 ] || { echo "genbsdf_equal_error.sh: K (replicates) must be at least 2" >&2; exit 2; }
. benches/genbsdf_blind.sh
cd "$tmp"
t0=$(date +%s.%N)
PATH="$FENESTRA_ORACLE_BIN:$PATH" RAYPATH=".:$FENESTRA_ORACLE_LIB" "$py" - <<'PY'
from pyradiance import genbsdf
r = genbsdf.generate_bsdf("blind.rad", nsamp=1000, nproc=2, front=True)
open("oracle_1000_T.txt", "wb").write(r.back.transmittance)
open("oracle_1000_R.txt", "wb").write(r.back.reflectance)
PY
t1=$(date +%s.%N)
for c in 960 1050; do
  PATH="$FENESTRA_ORACLE_BIN:$PATH" RAYPATH=".:$FENESTRA_ORACLE_LIB" "$py" - "$c" <<'PY'
import sys
from pyradiance import genbsdf
c = int(sys.argv[1])
r = genbsdf.generate_bsdf("blind.rad", nsamp=c, nproc=2, front=False)
open(f"oracle_{c}_T.txt", "wb").write(r.back.transmittance)
open(f"oracle_{c}_R.txt", "wb").write(r.back.reflectance)
PY
done
t1b=$(date +%s.%N)
"$bin/genBSDF" -q -n 2 -c "$N" +C +f +b blind.rad > ours.xml
t2=$(date +%s.%N)
for s in $(seq 1 "$K"); do "$bin/genBSDF" -q -n 2 -c "$N" -r "-seed $s" blind.rad > "rep_$s.xml"; done
PYTHONPATH="$benches" python3 - "$t0" "$t1" "$t1b" "$t2" "$N" rep_*.xml <<'PY'
import math, re, sys
t0, t1, t1b, t2 = map(float, sys.argv[1:5])
n, reps = sys.argv[5], sys.argv[6:]
from klems_lam import LAM as lam
N = 145

def xml_fractions(path):
    """Visible blocks of a Klems XML as flux fractions f[o][i] (rows = outgoing, as written)."""
    text, out = open(path).read(), {}
    for m in re.finditer(r"<WavelengthData>(.*?)</WavelengthData>", text, re.S):
        b = m.group(1)
        if ">Visible<" not in b:
            continue
        d = re.search(r"<WavelengthDataDirection>(.*?)<", b).group(1)
        v = [float(x) for x in re.search(r"<ScatteringData>(.*?)</ScatteringData>", b, re.S)
             .group(1).replace(",", " ").split()]
        out[d] = [[v[o * N + i] * lam[o] for i in range(N)] for o in range(N)]
    return out

def oracle_fractions(path):
    """pyradiance's matrices: rows = outgoing patch, columns = incident, fractions of the incident flux."""
    return [list(map(float, l.split())) for l in open(path) if l.strip()]

def rel_rms(runs, scale=None):
    """Relative rms noise of one run, from the element-wise spread of independent runs (each first
    multiplied by its deviation's scale: sqrt(its samples / the reference count))."""
    k = len(runs)
    scale = scale or [1.0] * k
    var = sq = 0.0
    for o in range(N):
        for i in range(N):
            xs = [r[o][i] for r in runs]
            m = sum(xs) / k
            var += sum((s * (x - m)) ** 2 for s, x in zip(scale, xs)) / (k - 1)
            sq += m * m
    return math.sqrt(var / sq)

ours = [xml_fractions(p) for p in reps]
print(f"Radiance genBSDF -c 1000 +f +b (pyradiance, -n 2): {t1 - t0:.1f} s")
print(f"fenestra genBSDF -c {n} +C +f +b (-n 2): {t2 - t1b:.1f} s")
print(f"ratio {(t1 - t0) / (t2 - t1b):.2f}x")
samples = {"1000": 33 * 31, "960": 32 * 31, "1050": 34 * 31}
for name, ch, d in [("transmission", "T", "Transmission Back"), ("reflection", "R", "Reflection Back")]:
    o = rel_rms([oracle_fractions(f"oracle_{c}_{ch}.txt") for c in samples],
                [math.sqrt(v / samples["1000"]) for v in samples.values()])
    u = rel_rms([r[d] for r in ours])
    verdict = "equal or lower" if u <= o else "HIGHER"
    print(f"{name} (light from the room): noise Radiance -c 1000 {100 * o:.2f}%, "
          f"fenestra -c {n} {100 * u:.2f}% ({len(ours)} replicates): fenestra's {verdict}")
PY
