#!/usr/bin/python3
"""weilgen against OpenTURNS at equal accuracy, in one run, on the gantry grinder.

  Sobol'   dx at X=0, Y=1500, Z=600 (order 1): first-order and total indices of the 21 errors to
           max |S - S_exact| <= 1e-4 over all 42, S_exact from `weilgen sensitivity --method exact`.
  FORM     the radial limit state dp = |(dx, dy, dz)| <= t at the same pose (t chosen so that
           P_f is about 1e-3): reliability index beta against the exact beta of the ellipsoid.
  IS       the same P_f to a coefficient of variation <= 2 % (each tool's own estimate), with
           the estimate within 3 of its standard errors of the exact P_f (a three-term weighted
           chi-square, integrated over the sphere).

For each tool and method, N doubles until the accuracy is met; then the run at that N is
timed `--repeats` times, alternating tools, and the median is reported. What is timed:
  weilgen    the whole process (fork/exec, model loading, the computation, writing the JSON),
             wall clock and CPU time (user + sys of the child);
  OpenTURNS  the computation inside one Python process (design or FORM/sampling, model
             evaluation, estimators), wall clock and process CPU time; not the interpreter
             start or `import openturns`. The model handed to OpenTURNS is the same order-1
             model: the linear form whose coefficients `weilgen sensitivity --method local`
             prints, evaluated with NumPy on the whole sample (the fastest evaluation Python
             offers; the 21 coefficients reproduce the generated model exactly at order 1).

Usage: bench/openturns/bench_vs_openturns.py [path/to/weilgen] [--repeats R] [--threads T]
Needs Debian's python3-openturns (bench/openturns/run.sh installs it).
"""
import argparse
import json
import math
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np
import openturns as ot

POSE = "X=0,Y=1500,Z=600"
MACHINE = "gantry_grinder"
SOBOL_TOL = 1e-4
IS_COV = 0.02
TARGET_PF = 1e-3


def load():
    return "%.2f %.2f %.2f" % os.getloadavg()


class Weilgen:
    def __init__(self, binary, threads):
        self.binary = binary
        self.threads = threads
        self.tmp = tempfile.mkdtemp(prefix="weilgen_vs_ot_")

    def command(self, args):
        return [self.binary] + args + ["--quiet", "--threads", str(self.threads)]

    def run(self, args):
        """Runs weilgen; returns (json document, wall s, cpu s)."""
        path = os.path.join(self.tmp, "out.json")
        cmd = self.command(args) + ["--json", path]
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        done = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        wall = time.perf_counter() - t0
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        if done.returncode != 0:
            sys.exit("weilgen failed (%s):\n%s" % (" ".join(cmd), done.stderr))
        cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
        with open(path) as f:
            return json.load(f), wall, cpu


def timed(fn):
    """(result, wall s, process cpu s) of fn()."""
    c0 = time.process_time()
    t0 = time.perf_counter()
    result = fn()
    return result, time.perf_counter() - t0, time.process_time() - c0


# ---------------------------------------------------------------------------------------------
# The model: coefficients and distributions from weilgen's own documents.

def read_model(wg):
    doc, _, _ = wg.run(["sensitivity", MACHINE, "--at", POSE, "--outputs", "dx,dy,dz",
                        "--method", "exact"])
    errors = [i["error"] for i in doc["inputs"]]
    sigma = []
    for i in doc["inputs"]:
        if not i["distribution"].startswith("normal(") or i["unit"] not in ("mm", "rad"):
            sys.exit("expected normal errors in mm or rad, got %s" % i)
        sigma.append(i["stddev"])
    local, _, _ = wg.run(["sensitivity", MACHINE, "--at", POSE, "--outputs", "dx,dy,dz",
                          "--method", "local"])
    index = {e: j for j, e in enumerate(errors)}
    coeff = np.zeros((3, len(errors)))
    s_exact = np.zeros(len(errors))
    for r in local["results"]:
        coeff["xyz".index(r["output"][1]), index[r["error"]]] = r["coefficient"]
    for r in doc["results"]:
        if r["output"] == "dx":
            s_exact[index[r["error"]]] = r["S_exact"]
    return errors, np.array(sigma), coeff, s_exact


# ---------------------------------------------------------------------------------------------
# Sobol' indices.

def weilgen_sobol(wg, n, seed=1):
    return wg.run(["sensitivity", MACHINE, "--at", POSE, "--outputs", "dx", "--method", "sobol",
                   "--samples", str(n), "--seed", str(seed)])


def weilgen_sobol_error(doc, errors, s_exact):
    worst = 0.0
    for r in doc["results"]:
        e = s_exact[errors.index(r["error"])]
        worst = max(worst, abs(r["S"] - e), abs(r["ST"] - e))
    return worst


ESTIMATORS = {
    "Saltelli": ot.SaltelliSensitivityAlgorithm,
    "Jansen": ot.JansenSensitivityAlgorithm,
    "Martinez": ot.MartinezSensitivityAlgorithm,
    "MauntzKucherenko": ot.MauntzKucherenkoSensitivityAlgorithm,
}


def openturns_design(n, sigma, seed):
    """OpenTURNS's Sobol' design [A; B; A_B^1; ...] of N base rows. seed None: its default QMC
    design (SobolIndicesExperiment on the 2d-dimensional plain Sobol' sequence,
    deterministic). Otherwise the same design from the same sequence with OpenTURNS's only QMC
    randomisation, a random shift modulo 1 (LowDiscrepancyExperiment.setRandomize), seeded
    through RandomGenerator: SobolIndicesExperiment itself offers no randomised QMC, so the
    design is assembled here in its row order (checked to reproduce it exactly without the
    shift)."""
    d = len(sigma)
    if seed is None:
        ot.ResourceMap.SetAsString("SobolIndicesExperiment-SamplingMethod", "QMC")
        dist = ot.ComposedDistribution([ot.Normal(0.0, float(s)) for s in sigma])
        return ot.SobolIndicesExperiment(dist, n).generate()
    ot.RandomGenerator.SetSeed(seed)
    twice = ot.ComposedDistribution([ot.Normal(0.0, float(s)) for s in sigma] * 2)
    exp = ot.LowDiscrepancyExperiment(ot.SobolSequence(2 * d), twice, n, True)
    exp.setRandomize(True)
    u = np.asarray(exp.generate())
    a, b = u[:, :d], u[:, d:]
    rows = [a, b]
    for i in range(d):
        e = a.copy()
        e[:, i] = b[:, i]
        rows.append(e)
    return ot.Sample(np.vstack(rows))


def openturns_sobol(estimator, n, sigma, cdx, seed=None):
    """Design, evaluation, first and total indices (no intervals)."""
    x = openturns_design(n, sigma, seed)
    y = ot.Sample((np.asarray(x) @ cdx).reshape(-1, 1))
    algo = ESTIMATORS[estimator](x, y, n)
    return np.array(algo.getFirstOrderIndices()), np.array(algo.getTotalOrderIndices())


def doubling(first, last, error_of, tol):
    """Smallest N = first * 2^j <= last with error_of(N) <= tol, and the errors seen."""
    n, seen = first, []
    while n <= last:
        err = error_of(n)
        seen.append((n, err))
        if err <= tol:
            return n, seen
        n *= 2
    return None, seen


def median_timing(runs):
    walls = [w for w, _ in runs]
    cpus = [c for _, c in runs]
    return statistics.median(walls), statistics.median(cpus)


def log2s(n):
    return "2^%d" % int(math.log2(n)) if n else "> max"


def sobol_section(wg, errors, sigma, coeff, s_exact, repeats, seeds, ot_seeds, out):
    """For every seed, the smallest N = 2^j reaching the accuracy, for weilgen (its default
    randomised replicates) and for OpenTURNS (randomised QMC, seeded; plus its deterministic
    default design). Then the run at every N some seed needed is timed `repeats` times,
    alternating tools (OpenTURNS through its own SobolIndicesExperiment, the default design:
    the same work as the shifted one), and each seed is charged the median time of its N: the
    report gives the median over seeds of those times and their ratio, and weilgen's median and
    90th-percentile seed (order statistics of the seeds' N) against OpenTURNS's deterministic
    design. `ot_seeds`: the randomised OpenTURNS designs tried (each up to 2^19)."""
    cdx = coeff[0]
    out.append("## Sobol' indices: dx at %s, max |S - S_exact| <= %g\n" % (POSE, SOBOL_TOL))
    wg_last, ot_last = 1 << 20, 1 << 19
    wg_n, ot_n = {}, {name: {} for name in ESTIMATORS}
    out.append("weilgen defaults (randomised QMC replicates, Student-t intervals), seeds 1-%d, "
               "max error by N:\n" % seeds)
    for seed in range(1, seeds + 1):
        n, seen = doubling(1 << 14, wg_last, lambda m: weilgen_sobol_error(
            weilgen_sobol(wg, m, seed)[0], errors, s_exact), SOBOL_TOL)
        wg_n[seed] = n
        out.append("- seed %d: %s -> N = %s" % (seed, ", ".join(
            "2^%d: %.2e" % (int(math.log2(m)), e) for m, e in seen), log2s(n)))
    # One OpenTURNS design per (seed, N) serves the four estimators while N doubles.
    out.append("\nOpenTURNS %s, N reaching the accuracy per design (seed None: the default "
               "deterministic QMC design; seeds 1-%d: randomised QMC, random shift):\n" % (
                   ot.__version__, ot_seeds))
    for seed in [None] + list(range(1, ot_seeds + 1)):
        # All four estimators on the default design; the seeds follow Jansen, the best one.
        names = list(ESTIMATORS) if seed is None else ["Jansen"]
        n, seen = 1 << 14, {name: [] for name in ESTIMATORS}
        while n <= ot_last and any(seed not in ot_n[name] for name in names):
            x = openturns_design(n, sigma, seed)
            y = ot.Sample((np.asarray(x) @ cdx).reshape(-1, 1))
            for name, algo in ESTIMATORS.items():
                if seed in ot_n[name] or name not in names:
                    continue
                a = algo(x, y, n)
                err = max(np.max(np.abs(np.array(a.getFirstOrderIndices()) - s_exact)),
                          np.max(np.abs(np.array(a.getTotalOrderIndices()) - s_exact)))
                seen[name].append((n, err))
                if err <= SOBOL_TOL:
                    ot_n[name][seed] = n
            if seed in ot_n["Jansen"] and n >= (1 << 17):
                break  # the others are not followed beyond 2^17 (Saltelli, Martinez: 2^19)
            n *= 2
        for name in ESTIMATORS:
            ot_n[name].setdefault(seed, None)
        out.append("- seed %s: %s" % (seed, "; ".join(
            "%s %s" % (name, log2s(ot_n[name][seed]) if ot_n[name][seed] else "> " + log2s(
                seen[name][-1][0])) for name in names)))
        out.append("  Jansen max error by N: " + ", ".join(
            "2^%d: %.2e" % (int(math.log2(m)), e) for m, e in seen["Jansen"]))
    # Timing: every N some seed needed, alternating tools.
    wg_sizes = sorted({n for n in wg_n.values() if n})
    # A shifted design that never reached the accuracy is charged the time at the largest N
    # tried: its true cost is higher, so the median over seeds is then a lower bound.
    ot_failed = any(not ot_n["Jansen"][s] for s in range(1, ot_seeds + 1))
    ot_sizes = sorted({n for n in ot_n["Jansen"].values() if n} | ({ot_last} if ot_failed else set()))
    runs = {("weilgen", n): [] for n in wg_sizes}
    runs.update({("Jansen", n): [] for n in ot_sizes})
    loads = [load()]
    for _ in range(repeats):
        for n in wg_sizes:
            _, w, c = weilgen_sobol(wg, n)
            runs[("weilgen", n)].append((w, c))
        for n in ot_sizes:
            _, w, c = timed(lambda: openturns_sobol("Jansen", n, sigma, cdx))
            runs[("Jansen", n)].append((w, c))
        loads.append(load())
    med = {key: median_timing(v) for key, v in runs.items()}
    out.append("\nTimes: median of %d runs per N; load average (1, 5, 15 min) before and after "
               "each round: %s\n" % (repeats, " | ".join(loads)))
    nv = len(errors)
    out.append("| tool | N | evaluations | seeds needing it | wall s | CPU s |")
    out.append("| --- | ---: | ---: | ---: | ---: | ---: |")
    for n in wg_sizes:
        out.append("| weilgen (whole process, %d threads) | 2^%d | %d | %d | %.3f | %.3f |" % (
            wg.threads or os.cpu_count(), int(math.log2(n)), n * (nv + 2), sum(m == n for m in wg_n.values()),
            *med[("weilgen", n)]))
    for n in ot_sizes:
        out.append("| OpenTURNS Jansen (computation, 1 thread) | 2^%d | %d | %d | %.3f | %.3f |"
                   % (int(math.log2(n)), n * (nv + 2),
                      sum(m == n for s, m in ot_n["Jansen"].items() if s is not None),
                      *med[("Jansen", n)]))
    failed_wg = [s for s, n in wg_n.items() if not n]
    failed_ot = [s for s, n in ot_n["Jansen"].items() if s is not None and not n]
    wg_t = [med[("weilgen", wg_n[s])] for s in wg_n if wg_n[s]]
    ot_t = [med[("Jansen", ot_n["Jansen"][s] or ot_last)] for s in range(1, ot_seeds + 1)]
    mw = statistics.median(t[0] for t in wg_t), statistics.median(t[1] for t in wg_t)
    mo = statistics.median(t[0] for t in ot_t), statistics.median(t[1] for t in ot_t)
    out.append("\nMedian over seeds of the time at each seed's N: weilgen %.3f s wall, %.3f s "
               "CPU (median N %s); OpenTURNS Jansen %.3f s wall, %.3f s CPU (median N %s)%s.\n"
               % (mw[0], mw[1], log2s(statistics.median_high([n or 1 << 40 for n in
                                                             wg_n.values()])),
                  mo[0], mo[1], log2s(statistics.median_high(
                      [ot_n["Jansen"][s] or 1 << 40 for s in range(1, ot_seeds + 1)])),
                  "; not reached: weilgen seeds %s, OpenTURNS seeds %s" % (failed_wg, failed_ot)
                  if failed_wg or failed_ot else ""))
    out.append("**Ratio of the median times: %s%.1fx wall, %s%.1fx CPU** (target >= 20x)%s.\n" % (
        ">= " if ot_failed else "", mo[0] / mw[0], ">= " if ot_failed else "", mo[1] / mw[1],
        "; a lower bound: OpenTURNS seeds that never reached the accuracy are charged the time "
        "at 2^%d" % int(math.log2(ot_last)) if ot_failed else ""))
    if ot_n["Jansen"].get(None):
        md = med[("Jansen", ot_n["Jansen"][None])]
        out.append("Against OpenTURNS's default deterministic design (Jansen, N = %s, %.3f s wall, "
                   "%.3f s CPU): **%.1fx wall, %.1fx CPU** over weilgen's median seed.\n" % (
                       log2s(ot_n["Jansen"][None]), md[0], md[1], md[0] / mw[0], md[1] / mw[1]))
        # weilgen's seeds by the N they need (a seed beyond the largest N tried sorts last).
        needed = sorted(n or 1 << 40 for n in wg_n.values())
        for label, q in (("median", 0.5), ("90th-percentile", 0.9)):
            n = needed[max(0, math.ceil(q * len(needed)) - 1)]
            if ("weilgen", n) not in med:
                out.append("weilgen's %s seed: beyond 2^%d.\n" % (label, int(math.log2(wg_last))))
                continue
            t = med[("weilgen", n)]
            out.append("weilgen's %s seed (N = %s, %.3f s wall, %.3f s CPU) against that design: "
                       "**%.1fx wall, %.1fx CPU** (target >= 20x).\n" % (
                           label, log2s(n), t[0], t[1], md[0] / t[0], md[1] / t[1]))
    out.append("weilgen command: `%s --seed S --json FILE`\n" % " ".join(
        wg.command(["sensitivity", MACHINE, "--at", POSE, "--outputs", "dx", "--method", "sobol",
                    "--samples", "N"])))


# ---------------------------------------------------------------------------------------------
# Reliability: P(dp > t), dp = |(dx, dy, dz)| = |C e|, e ~ N(0, diag sigma^2).

def radial_exceedance(lams, t, grid=600):
    """P(sum_k lam_k Z_k^2 > t^2) for three lam_k: Q = R^2 w' diag(lam) w with R^2 ~ chi2_3
    independent of the direction w, uniform on the sphere; Gauss-Legendre in cos(theta) and
    the midpoint rule in phi (smooth, periodic)."""
    from scipy.special import erfc
    x, wts = np.polynomial.legendre.leggauss(grid)  # cos(theta) in [-1, 1]
    phi = (np.arange(2 * grid) + 0.5) * np.pi / grid
    st = np.sqrt(1 - x * x)
    w1 = np.outer(st, np.cos(phi))
    w2 = np.outer(st, np.sin(phi))
    w3 = np.outer(x, np.ones_like(phi))
    q = lams[0] * w1 ** 2 + lams[1] * w2 ** 2 + lams[2] * w3 ** 2
    y = t * t / q
    surv = erfc(np.sqrt(y / 2)) + np.sqrt(2 * y / np.pi) * np.exp(-y / 2)  # P(chi2_3 > y)
    return float(np.sum(wts[:, None] * surv) * (np.pi / grid) / (4 * np.pi))


def reliability_section(wg, errors, sigma, coeff, repeats, out):
    cov = coeff @ np.diag(sigma ** 2) @ coeff.T  # mm^2
    lams = np.linalg.eigvalsh(cov)
    # t (mm, rounded to 0.1 um) with P_f near TARGET_PF.
    lo, hi = 0.0, 10 * math.sqrt(lams.sum())
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if radial_exceedance(lams, mid, 200) > TARGET_PF else (lo, mid)
    t = round(hi, 4)
    p_ref = radial_exceedance(lams, t)
    p_check = radial_exceedance(lams, t, 1200)
    beta_ref = t / math.sqrt(lams[-1])
    out.append("## Reliability: P(dp > t) at %s, t = %.4f mm\n" % (POSE, t))
    out.append("Exact: P_f = %.8g (sphere quadrature 600 x 1200 nodes; 1200 x 2400: %.8g), "
               "beta_FORM = t / sqrt(lambda_max(C S C^T)) = %.10g, FORM P_f = 2 Phi(-beta) = "
               "%.6g (two design points +-u*).\n" % (p_ref, p_check, beta_ref,
                                                      2 * ot.Normal().computeCDF(-beta_ref)))
    tol = ["--tolerance", "dp=%.4fmm" % t]

    def wg_rel(method, n=None):
        args = ["reliability", MACHINE, "--at", POSE] + tol + ["--method", method]
        if n:
            args += ["--samples", str(n)]
        return wg.run(args)

    # FORM.
    doc, _, _ = wg_rel("form")
    r = doc["results"][0]
    wg_beta = r["beta"]
    wg_form = {"pf": 1 - r["reliability"], "evals": r["evaluations"], "beta": wg_beta}

    d = len(sigma)
    dist = ot.ComposedDistribution([ot.Normal(0.0, float(s)) for s in sigma])

    def limit_state():
        # dp(e) = |C e| as an OpenTURNS function: a linear function composed with the norm.
        lin = ot.LinearFunction([0.0] * d, [0.0] * 3, ot.Matrix(coeff.tolist()))
        norm = ot.SymbolicFunction(["dx", "dy", "dz"], ["sqrt(dx^2 + dy^2 + dz^2)"])
        return ot.ComposedFunction(norm, lin)

    def ot_form():
        g = limit_state()
        event = ot.ThresholdEvent(ot.CompositeRandomVector(g, ot.RandomVector(dist)),
                                  ot.Greater(), t)
        solver = ot.AbdoRackwitz()
        for setter in ("setMaximumAbsoluteError", "setMaximumRelativeError",
                       "setMaximumResidualError", "setMaximumConstraintError"):
            getattr(solver, setter)(1e-12)  # converge as far as weilgen's FORM does
        solver.setMaximumIterationNumber(1000)
        # Start at u = (1, ..., 1): dp is not differentiable at the mean (the origin).
        algo = ot.FORM(solver, event, [float(s) for s in sigma])
        algo.run()
        calls = g.getEvaluationCallsNumber() + d * g.getGradientCallsNumber()  # gradients: FD
        return algo.getResult(), event, calls

    (form_res, _, form_evals), _, _ = timed(ot_form)
    ot_beta = form_res.getHasoferReliabilityIndex()
    out.append("FORM: weilgen beta = %s (relative error %.1e, %d evaluations, P_f = 2 Phi(-beta) "
               "= %.6g); OpenTURNS AbdoRackwitz (tolerances 1e-12) beta = %.10g (relative error "
               "%.1e, about %d evaluations counting finite-difference gradients as %d each, "
               "P_f = Phi(-beta) = %.6g: one design point).\n" % (
                   ", ".join("%.10g" % x for x in wg_beta), abs(wg_beta[0] - beta_ref) / beta_ref,
                   wg_form["evals"], wg_form["pf"], ot_beta, abs(ot_beta - beta_ref) / beta_ref,
                   form_evals, d, form_res.getEventProbability()))

    # Importance sampling: N doubles until the tool's own CoV <= IS_COV and its estimate is
    # within 3 of its standard errors of the exact P_f; the actual error is reported too.
    def accurate(p, cov):
        return cov <= IS_COV and abs(p - p_ref) <= 3 * cov * p

    def wg_is(n):
        doc, _, _ = wg_rel("is", n)
        r = doc["results"][0]
        return 1 - r["reliability"], r["cov"], r["evaluations"]

    def doubling_is(first, last, fn):
        n, seen = first, []
        while n <= last:
            p, cov = fn(n)[:2]
            seen.append((n, p, cov))
            if accurate(p, cov):
                return n, seen
            n *= 2
        return None, seen

    def fmt(seen):
        return ", ".join("%d: %.4g (CoV %.2g, error %+.1f %%)" % (n, p, c, 100 * (p / p_ref - 1))
                         for n, p, c in seen)

    n_wg, seen = doubling_is(256, 1 << 18, wg_is)
    out.append("weilgen IS (lines parallel to alpha, both crossings, seed 1), by N: " + fmt(seen))

    def simulate(algo, block, n):
        """Runs an OpenTURNS simulation algorithm for n samples (whole blocks, no early stop)."""
        algo.setBlockSize(block)
        algo.setMaximumOuterSampling(max(1, n // block))
        algo.setMaximumCoefficientOfVariation(0.0)
        algo.run()
        sr = algo.getResult()
        return sr.getProbabilityEstimate(), sr.getCoefficientOfVariation()

    def ot_mixture_is(n, seed=0):
        # The competent OpenTURNS set-up for two design points +-u*: importance sampling in the
        # standard space from the mixture of N(u*, I) and N(-u*, I), after FORM.
        ot.RandomGenerator.SetSeed(seed)
        res, event, _ = ot_form()
        u = res.getStandardSpaceDesignPoint()
        unit = [1.0] * d
        mix = ot.Mixture([ot.Normal(u, unit, ot.CorrelationMatrix(d)),
                          ot.Normal(-u, unit, ot.CorrelationMatrix(d))])
        return simulate(ot.ProbabilitySimulationAlgorithm(ot.StandardEvent(event),
                                                          ot.ImportanceSamplingExperiment(mix)),
                        1024, n)

    def ot_directional(n, seed=0):
        ot.RandomGenerator.SetSeed(seed)
        event = ot.ThresholdEvent(ot.CompositeRandomVector(limit_state(), ot.RandomVector(dist)),
                                  ot.Greater(), t)
        return simulate(ot.DirectionalSampling(event), 64, n)

    def ot_post_analytical(n, seed=0):
        ot.RandomGenerator.SetSeed(seed)
        res, _, _ = ot_form()
        return simulate(ot.PostAnalyticalImportanceSampling(res), 1024, n)

    ot_methods = {"IS from the mixture N(+-u*, I)": (ot_mixture_is, 1024, 1 << 21),
                  "DirectionalSampling": (ot_directional, 1024, 1 << 15)}
    ot_n = {}
    for name, (fn, first, last) in ot_methods.items():
        n, seen = doubling_is(first, last, fn)
        ot_n[name] = n
        out.append("OpenTURNS %s, by N: %s%s" % (name, fmt(seen),
                                                 "" if n else " (not reached by %d)" % last))
    p, cov = ot_post_analytical(1 << 16)
    out.append("OpenTURNS PostAnalyticalImportanceSampling (IS around the one FORM point) at "
               "N = 65536: %.4g (CoV %.2g, error %+.0f %%): it misses the mirror design point.\n"
               % (p, cov, 100 * (p / p_ref - 1)))

    runs = {"weilgen FORM": [], "OpenTURNS FORM": [], "weilgen IS": []}
    runs.update({name: [] for name in ot_n if ot_n[name]})
    loads = [load()]
    for _ in range(repeats):
        _, w, c = wg_rel("form")
        runs["weilgen FORM"].append((w, c))
        _, w, c = timed(ot_form)
        runs["OpenTURNS FORM"].append((w, c))
        if n_wg:
            _, w, c = wg_rel("is", n_wg)
            runs["weilgen IS"].append((w, c))
        for name, (fn, _, _) in ot_methods.items():
            if ot_n[name]:
                _, w, c = timed(lambda: fn(ot_n[name]))
                runs[name].append((w, c))
        loads.append(load())
    out.append("\nMedian of %d runs; load average before and after each round: %s\n" % (
        repeats, " | ".join(loads)))
    out.append("| method | tool | N | result | evaluations | wall s | CPU s | wall ratio to "
               "weilgen |")
    out.append("| --- | --- | ---: | --- | ---: | ---: | ---: | ---: |")
    fw, fc = median_timing(runs["weilgen FORM"])
    out.append("| FORM | weilgen (whole process) | – | beta %s | %d | %.3f | %.3f | 1 |" % (
        ", ".join("%.10g" % x for x in wg_beta), wg_form["evals"], fw, fc))
    w, c = median_timing(runs["OpenTURNS FORM"])
    out.append("| FORM | OpenTURNS AbdoRackwitz (computation) | – | beta %.10g | ~%d | %.3f | %.3f "
               "| %.2f |" % (ot_beta, form_evals, w, c, w / fw))
    if n_wg:
        p, cov, evals = wg_is(n_wg)
        iw, ic = median_timing(runs["weilgen IS"])
        out.append("| IS | weilgen (whole process) | %d | P_f %.5g (CoV %.2g) | %d | %.3f | %.3f | "
                   "1 |" % (n_wg, p, cov, evals, iw, ic))
        best = None
        for name, (fn, _, _) in ot_methods.items():
            if not ot_n[name]:
                continue
            p, cov = fn(ot_n[name])
            w, c = median_timing(runs[name])
            out.append("| IS | OpenTURNS %s (computation) | %d | P_f %.5g (CoV %.2g) | %d | %.3f | "
                       "%.3f | %.1f |" % (name, ot_n[name], p, cov, ot_n[name], w, c, w / iw))
            if best is None or w < best[1]:
                best = (name, w)
        if best:
            out.append("\nIS speed-up over the fastest OpenTURNS sampler that met the accuracy "
                       "(%s): **%.1fx** wall.\n" % (best[0], best[1] / iw))
    out.append("weilgen commands: `%s --json FILE`, and `--method is --samples %s`\n" % (
        " ".join(wg.command(["reliability", MACHINE, "--at", POSE] + tol + ["--method", "form"])),
        n_wg))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("weilgen", nargs="?", default="build/weilgen")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--threads", type=int, default=0, help="weilgen --threads (0 = all cores)")
    ap.add_argument("--only", choices=["sobol", "reliability"], default=None)
    ap.add_argument("--seeds", type=int, default=10, help="weilgen's Sobol' seeds (default 10)")
    ap.add_argument("--ot-seeds", type=int, default=None,
                    help="OpenTURNS's randomised designs (default: --seeds)")
    args = ap.parse_args()
    wg = Weilgen(os.path.abspath(args.weilgen), args.threads)
    out = ["# weilgen vs OpenTURNS %s (%s)\n" % (ot.__version__, time.strftime("%Y-%m-%d %H:%M")),
           "Machine: %d CPUs, `uptime` at start: %s" % (
               os.cpu_count(), subprocess.run(["uptime"], capture_output=True,
                                             text=True).stdout.strip()),
           "Command: `%s`\n" % " ".join([sys.executable] + sys.argv)]
    errors, sigma, coeff, s_exact = read_model(wg)
    try:
        if args.only in (None, "sobol"):
            sobol_section(wg, errors, sigma, coeff, s_exact, args.repeats, args.seeds,
                          args.seeds if args.ot_seeds is None else args.ot_seeds, out)
        if args.only in (None, "reliability"):
            reliability_section(wg, errors, sigma, coeff, args.repeats, out)
    except BaseException:
        print("\n".join(out))  # what was measured before the failure
        raise
    out.append("`uptime` at end: %s" % subprocess.run(["uptime"], capture_output=True,
                                                      text=True).stdout.strip())
    print("\n".join(out))


if __name__ == "__main__":
    main()
