#!/usr/bin/python3
"""weilgen generate against SymPy doing the same truncated products (issue 17 §4).

SymPy builds the order-k error model of a serial machine the way weilgen does
(docs/generator.md): 4x4 homogeneous transforms whose entries are polynomials in the error
symbols, every product truncated at total error degree k (the nilpotent algebra
R[e]/<degree k+1>), rotation errors as sin e, 1 - cos e series truncated at k, the revolute
joints with the symbols cos_q, sin_q, the workpiece chain inverted as [R^T, -R^T p] (exact in
the algebra: a truncated rotation is orthogonal modulo the ideal), P = W^-1 T, position
outputs = translation of P minus its degree-0 part, orientation outputs = the rotation vector of
log(R_P R_P0^T) = A - A^2/2 + ... (finite, A nilpotent).

The machine comes from weilgen's own output and the machine file: bodies, joints, offsets and
the tool/workpiece points from the YAML (python3-yaml), the errors (name, body, placement,
translation or rotation, in the order they compose) from the kErrors table of the header that
`weilgen generate` writes; an ISO 230-1 name's first letter after E_ gives its direction (X/A: x,
Y/B: y, Z/C: z). Serial machines only (no links, no output transform).

The SymPy model is checked numerically against weilgen's model of the same order (the Python
module, build/python) at a few poses before any number is printed; both are the same element
of the algebra, so they agree to rounding.

  /usr/bin/python3 bench/sympy/bench_vs_sympy.py build/weilgen machines/five_axis_ac.yaml \
      --order 2 [--python-module build/python] [--repeats 3]
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile
import time

import sympy as sp
import yaml

AXIS = {"x": (1, 0, 0), "y": (0, 1, 0), "z": (0, 0, 1),
        "-x": (-1, 0, 0), "-y": (0, -1, 0), "-z": (0, 0, -1)}


def direction_of(name):
    letter = name[2]
    return {"X": (1, 0, 0), "A": (1, 0, 0), "Y": (0, 1, 0), "B": (0, 1, 0),
            "Z": (0, 0, 1), "C": (0, 0, 1)}[letter]


def read_errors(header):
    """(name, body, placement, rotation) per error, in kErrors order, from a generated header."""
    rows = []
    inside = False
    for line in open(header, encoding="utf-8"):
        if "kErrors = {{" in line:
            inside = True
            continue
        if inside and line.startswith("}};"):
            break
        if inside:
            strings = re.findall(r'"([^"]*)"', line)
            flags = re.findall(r"\b(true|false)\b", line)
            # name, iso, aliases, group, unit, body, placement; flags: PDGE, rotation
            rows.append((strings[0], strings[5], strings[6], flags[1] == "true"))
    return rows


class Truncated:
    """Polynomials in the error symbols truncated at total degree k after every product."""

    def __init__(self, errors, order):
        self.errors = errors
        self.order = order
        self.error_set = set(errors)

    def degree(self, term):
        d = 0
        for base, exp in term.as_powers_dict().items():
            if base in self.error_set:
                d += exp
        return d

    def trunc(self, expr):
        expr = sp.expand(expr)
        return sp.Add(*[t for t in sp.Add.make_args(expr) if self.degree(t) <= self.order])

    def mul(self, a, b):
        c = a * b  # sympy Matrix product, then truncation entry by entry
        return c.applyfunc(self.trunc)

    def sin_series(self, e):
        return sum((-1) ** j * e ** (2 * j + 1) / sp.factorial(2 * j + 1)
                   for j in range((self.order + 1) // 2 + 1) if 2 * j + 1 <= self.order)

    def one_minus_cos(self, e):
        return sum((-1) ** (j + 1) * e ** (2 * j) / sp.factorial(2 * j)
                   for j in range(1, self.order // 2 + 1))


def skew(u):
    x, y, z = u
    return sp.Matrix([[0, -z, y], [z, 0, -x], [-y, x, 0]])


def rot_hom(u, s, omc):
    """I + s [u]x + omc [u]x^2 as a 4x4 transform."""
    k = skew(u)
    m = sp.eye(4)
    m[:3, :3] = sp.eye(3) + s * k + omc * k * k
    return m


def trans_hom(t):
    m = sp.eye(4)
    m[0, 3], m[1, 3], m[2, 3] = t
    return m


def rigid_inverse(alg, m):
    r = m[:3, :3].T
    out = sp.eye(4)
    out[:3, :3] = r
    out[:3, 3] = (-r * m[:3, 3]).applyfunc(alg.trunc)
    return out


def build(machine_file, header, order):
    desc = yaml.safe_load(open(machine_file, encoding="utf-8"))
    params = {n: sp.Symbol(n) for n in desc.get("parameters", {})}
    errors = read_errors(header)
    esym = [sp.Symbol(n) for n, _, _, _ in errors]
    alg = Truncated(esym, order)
    bodies = desc["bodies"]
    axes = []  # (coordinate, revolute, symbol, cos, sin)
    coords = {}

    def expr(v):
        return sp.sympify(v, locals=params) if isinstance(v, str) else sp.Integer(v) \
            if isinstance(v, int) else sp.Float(v)

    def error_chain(body, placement, inverse=False):
        items = [(s, n) for s, (n, b, p, _) in zip(esym, errors) if b == body and p == placement]
        m = sp.eye(4)
        seq = list(reversed(items)) if inverse else items
        for s, n in seq:
            rotation = dict((e[0], e[3]) for e in errors)[n]
            u = direction_of(n)
            v = -s if inverse else s
            if rotation:
                step = rot_hom(u, alg.sin_series(v), alg.one_minus_cos(v))
            else:
                step = trans_hom([v * c for c in u])
            m = alg.mul(m, step)
        return m

    def body_transform(name):
        b = bodies[name] or {}
        off = b.get("offset", {}) or {}
        if off.get("rotations"):
            raise SystemExit("bench_vs_sympy: offset rotations are not supported")
        m = trans_hom([expr(v) for v in off.get("translation", [0, 0, 0])])
        j = b.get("joint")
        joint = sp.eye(4)
        if j and j["type"] != "fixed":
            q = sp.Symbol(j["coordinate"])
            u = AXIS[j["axis"]] if isinstance(j["axis"], str) else tuple(j["axis"])
            if j["type"] == "prismatic":
                joint = trans_hom([q * c for c in u])
                axes.append((j["coordinate"], False, q, None, None))
            else:
                if j.get("through"):
                    raise SystemExit("bench_vs_sympy: revolute 'through' is not supported")
                c, s = sp.Symbol("cos_" + j["coordinate"]), sp.Symbol("sin_" + j["coordinate"])
                joint = rot_hom(u, s, 1 - c)
                axes.append((j["coordinate"], True, q, c, s))
            coords[j["coordinate"]] = q
        m = alg.mul(m, error_chain(name, "before"))
        m = alg.mul(m, error_chain(name, "axis"))
        m = alg.mul(m, joint)
        m = alg.mul(m, error_chain(name, "axis", inverse=True))
        return alg.mul(m, error_chain(name, "after"))

    def chain_to(body):
        path = []
        while body is not None:
            path.append(body)
            body = (bodies[body] or {}).get("parent")
        return list(reversed(path))

    def branch(spec):
        m = sp.eye(4)
        for b in chain_to(spec["body"]):
            m = alg.mul(m, body_transform(b))
        return alg.mul(m, trans_hom([expr(v) for v in spec.get("point", [0, 0, 0])]))

    t = branch(desc["tool"])
    w = branch(desc["workpiece"])
    p = alg.mul(rigid_inverse(alg, w), t)
    zero = {s: 0 for s in esym}
    p0 = p.subs(zero)
    position = [alg.trunc(p[i, 3] - p0[i, 3]) for i in range(3)]
    a = alg.mul(p[:3, :3], p0[:3, :3].T) - sp.eye(3)
    a = a.applyfunc(alg.trunc)
    log = sp.zeros(3)
    power = sp.eye(3)
    for j in range(1, order + 1):
        power = alg.mul(power, a)
        log += power * sp.Rational((-1) ** (j + 1), j)
    orientation = [log[2, 1], log[0, 2], log[1, 0]]
    return position + orientation, axes, esym, params


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("weilgen")
    ap.add_argument("machine")
    ap.add_argument("--order", type=int, default=2)
    ap.add_argument("--python-module", default=None,
                    help="directory of weilgen's Python module (default: beside weilgen, "
                         "<build>/python)")
    ap.add_argument("--repeats", type=int, default=3, help="weilgen generate runs (min is kept)")
    ap.add_argument("--poses", type=int, default=5)
    args = ap.parse_args()

    with tempfile.TemporaryDirectory() as tmp:
        wg = []
        for _ in range(args.repeats):
            t0 = time.perf_counter()
            subprocess.run([args.weilgen, "generate", args.machine, "--order", str(args.order),
                            "--out", tmp], check=True, stdout=subprocess.DEVNULL)
            wg.append(time.perf_counter() - t0)
        name = yaml.safe_load(open(args.machine, encoding="utf-8"))["name"]
        header = os.path.join(tmp, name + (f"_o{args.order}" if args.order != 1 else "") + ".hpp")
        if not os.path.exists(header):
            header = os.path.join(tmp, name + ".hpp")
        c0, t0 = time.process_time(), time.perf_counter()
        outputs, axes, esym, params = build(args.machine, header, args.order)
        sympy_wall, sympy_cpu = time.perf_counter() - t0, time.process_time() - c0
        kept_header = open(header, encoding="utf-8").read()

    terms = sum(len(sp.Add.make_args(o)) for o in outputs)
    print(f"sympy {sp.__version__}: {args.machine} order {args.order}: {terms} terms in the 6 "
          f"outputs, {sympy_wall:.2f} s wall, {sympy_cpu:.2f} s CPU", file=sys.stderr)

    # Numerical check against weilgen's model of the same order.
    module = args.python_module or os.path.join(os.path.dirname(os.path.abspath(args.weilgen)),
                                                "python")
    sys.path.insert(0, module)
    import numpy as np
    import weilgen
    model = weilgen.Model(args.machine, order=args.order, quiet=True)
    assert [str(s) for s in esym] == list(model.errors), "error order differs"
    rng = np.random.default_rng(7)
    worst = 0.0
    scale = 0.0
    fns = [sp.lambdify([s for _, _, s, _, _ in axes] +
                       [c for _, r, _, c, _ in axes if r] + [s for _, r, _, _, s in axes if r] +
                       esym + list(params.values()), o, "math") for o in outputs]
    axis_order = list(model.axes)
    ranges = re.findall(r'\{"(\w+)", "(\w+)", (true|false), ([-\d.e+]+), ([-\d.e+]+)',
                        kept_header)
    rmap = {a: (float(lo), float(hi)) for a, _, _, lo, hi in ranges}
    defaults = dict(zip(model.params, model.param_defaults)) if hasattr(
        model, "param_defaults") else None
    if defaults is None:
        pd = re.findall(r'^\s+\{"(\w+)", "(mm|deg)", ([-\d.e+]+)\},$', kept_header, re.M)
        defaults = {n: float(v) for n, _, v in pd}
    for _ in range(args.poses):
        q = {a: rng.uniform(*rmap[a]) for a in axis_order}
        e = rng.uniform(-1, 1, len(esym)) * np.array(
            [50e-6 if str(s)[2] in "ABC" else 10e-3 for s in esym])
        ours = model.deviation([q[a] for a in axis_order], e)
        vals = [q[c] for c, _, _, _, _ in axes]
        vals += [np.cos(np.radians(q[c])) for c, r, _, _, _ in axes if r]
        vals += [np.sin(np.radians(q[c])) for c, r, _, _, _ in axes if r]
        vals += list(e) + [defaults[str(p)] for p in params.values()]
        theirs = np.array([f(*vals) for f in fns], dtype=float)
        worst = max(worst, float(np.max(np.abs(theirs - ours))))
        scale = max(scale, float(np.max(np.abs(ours))))
    ok = worst <= 1e-12 * max(scale, 1e-300) + 1e-18
    print(f"check against weilgen's order-{args.order} model at {args.poses} poses: "
          f"max |sympy - weilgen| = {worst:.2e} (max |deviation| {scale:.3g}): "
          f"{'ok' if ok else 'MISMATCH'}", file=sys.stderr)
    if not ok:
        sys.exit(1)
    print(f"| tool | {name} order {args.order} | ratio |")
    print("| --- | ---: | ---: |")
    print(f"| weilgen generate (whole process, min of {args.repeats}) | {min(wg):.3f} s | 1 |")
    print(f"| SymPy {sp.__version__} (products + truncation + log, wall) | {sympy_wall:.1f} s | "
          f"{sympy_wall / min(wg):.0f}x |")
    print(f"| SymPy CPU | {sympy_cpu:.1f} s | {sympy_cpu / min(wg):.0f}x |")


if __name__ == "__main__":
    main()
