#!/usr/bin/env python3
"""Cost per pose of weilgen.Model.deviation and .coefficients over numpy arrays, against the same
evaluation written in numpy at order 1 (coefficients times errors), for every shipped machine.

    PYTHONPATH=build/python /usr/bin/python3 bench/python/bench_deviation.py [N] [REPEATS]

Prints a Markdown table: wall time per pose, best of REPEATS (default 5) calls on N poses
(default 10^6). Compare with `weilgen_bench_eval` (docs/performance.md), which times the
generated header's Deviation directly in C++.
"""
import os
import sys
import time

import numpy as np

import weilgen

n = int(sys.argv[1]) if len(sys.argv) > 1 else 1_000_000
repeats = int(sys.argv[2]) if len(sys.argv) > 2 else 5


def best(f):
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        f()
        times.append(time.perf_counter() - t)
    return min(times)


print(f"N = {n} poses, best of {repeats}; {os.cpu_count()} cores; load {os.getloadavg()[0]:.1f}")
print("| machine | errors | deviation | coefficients | numpy c·e at order 1 (from coefficients) |")
print("| --- | --- | --- | --- | --- |")
for machine in ("gantry_grinder", "vmc_3axis", "two_axis", "five_axis_ac"):
    m = weilgen.Model(machine)
    rng = np.random.default_rng(1)
    q = np.column_stack([rng.uniform(-360, 360, n) if u == "deg" else rng.uniform(-500, 500, n)
                         for u in m.axis_units])
    scale = np.array([1e-5 if u == "rad" else 1e-2 for u in m.error_units])
    e = rng.standard_normal((n, len(m.errors))) * scale
    m.deviation(q[:10], e[:10])
    t_dev = best(lambda: m.deviation(q, e))
    t_coeff = best(lambda: m.coefficients(q[: n // 10])) * 10
    c = m.coefficients(q[: n // 10])
    t_numpy = best(lambda: np.einsum("nok,nk->no", c, e[: n // 10])) * 10
    print(f"| {machine} | {len(m.errors)} | {t_dev / n * 1e9:.1f} ns | {t_coeff / n * 1e9:.1f} ns"
          f" | {t_numpy / n * 1e9:.1f} ns (+ coefficients) |")
