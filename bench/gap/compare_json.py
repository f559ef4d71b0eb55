#!/usr/bin/python3
"""Compare two `weilgen gap --json` documents (or two directories of them) numerically.

    bench/gap/compare_json.py BEFORE AFTER [--rel 1e-6] [--abs 1e-9]

Every number must agree within max(rel * max(|a|, |b|), abs); strings must be equal once the
numbers inside them are compared the same way (a summary "bump 2.1 µm" printed from a value
that moved in its 16th digit may round differently in its last printed digit: that counts as
equal when the printed numbers agree within one unit of their last digit). Lists must have the
same length and order (the effects ranking, the where list). Exit 0 when everything agrees, 1
otherwise, listing each difference with its JSON path.
"""
import json
import math
import os
import re
import sys

NUM = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")


def close(a, b, rel, abs_):
    if isinstance(a, bool) or isinstance(b, bool):
        return a == b
    if a is None or b is None:
        return a is b
    if math.isnan(a) or math.isnan(b):
        return math.isnan(a) and math.isnan(b)
    if math.isinf(a) or math.isinf(b):
        return a == b
    return abs(a - b) <= max(rel * max(abs(a), abs(b)), abs_)


def last_digit_unit(text):
    mant = text.lower().split("e")[0]
    exp = int(text.lower().split("e")[1]) if "e" in text.lower() else 0
    decimals = len(mant.split(".")[1]) if "." in mant else 0
    return 10.0 ** (exp - decimals)


def same_text(a, b, rel):
    if a == b:
        return True
    if NUM.sub("#", a) != NUM.sub("#", b):
        return False
    for x, y in zip(NUM.findall(a), NUM.findall(b)):
        fx, fy = float(x), float(y)
        tol = max(last_digit_unit(x), last_digit_unit(y)) * 1.0000001
        if not (abs(fx - fy) <= tol or close(fx, fy, rel, 0)):
            return False
    return True


def compare(a, b, path, rel, abs_, out):
    if isinstance(a, dict) and isinstance(b, dict):
        for k in sorted(set(a) | set(b)):
            if k not in a or k not in b:
                out.append(f"{path}/{k}: only in {'after' if k in b else 'before'}")
            else:
                compare(a[k], b[k], f"{path}/{k}", rel, abs_, out)
    elif isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            out.append(f"{path}: {len(a)} entries before, {len(b)} after")
        for i, (x, y) in enumerate(zip(a, b)):
            compare(x, y, f"{path}[{i}]", rel, abs_, out)
    elif isinstance(a, (int, float)) and isinstance(b, (int, float)) and not isinstance(a, bool):
        if not close(float(a), float(b), rel, abs_):
            out.append(f"{path}: {a!r} -> {b!r}")
    elif isinstance(a, str) and isinstance(b, str):
        if not same_text(a, b, rel):
            out.append(f"{path}: {a!r} -> {b!r}")
    elif a != b:
        out.append(f"{path}: {a!r} -> {b!r}")


def load(path):
    with open(path, encoding="utf-8") as f:
        text = f.read()
    # JSON has no NaN literal; weilgen writes null, but accept NaN too.
    return json.loads(text)


def main(argv):
    args = [a for a in argv if not a.startswith("--")]
    opts = dict(zip(argv[::1], argv[1::1]))
    rel = float(opts.get("--rel", 1e-6))
    abs_ = float(opts.get("--abs", 1e-9))
    if len(args) < 2:
        print(__doc__)
        return 2
    before, after = args[0], args[1]
    pairs = []
    if os.path.isdir(before):
        for root, _, files in os.walk(before):
            for f in sorted(files):
                if f.endswith(".json"):
                    p = os.path.join(root, f)
                    pairs.append((p, os.path.join(after, os.path.relpath(p, before))))
    else:
        pairs.append((before, after))
    bad = 0
    for p, q in sorted(pairs):
        out = []
        if not os.path.exists(q):
            out.append("missing after")
        else:
            compare(load(p), load(q), "", rel, abs_, out)
        if out:
            bad += 1
            print(f"{p}: {len(out)} difference(s)")
            for line in out[:20]:
                print("   ", line)
    print(f"{len(pairs) - bad} of {len(pairs)} documents agree (rel {rel:g}, abs {abs_:g})")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
