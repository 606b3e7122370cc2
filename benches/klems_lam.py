"""Projected solid angles of the full Klems basis's 145 patches (rings and patch counts of the
LBNL basis), for the genBSDF benchmarks' diffuse-incidence totals; imported with benches/ on
sys.path."""
import math

EDGES = [0, 5, 15, 25, 35, 45, 55, 65, 75, 90]
COUNTS = [1, 8, 16, 20, 24, 24, 24, 16, 12]
LAM = []
for _r, _n in enumerate(COUNTS):
    _a, _b = math.radians(EDGES[_r]), math.radians(EDGES[_r + 1])
    LAM += [math.pi * (math.sin(_b) ** 2 - math.sin(_a) ** 2) / _n] * _n
