#!/usr/bin/env python3
"""The regression baseline of the spindle thermal study (issue 14, docs/experiments/
gap-spindle-thermal.md): a ridge regression of each displacement channel on all temperature
sensors with first-order lags (0, 0.5, 2, 8 h), lambda chosen by 5-block time cross-validation
inside the training part, trained on the first half of the run and scored on the second half
(the same split as `weilgen gap --holdout forward:0.5`). What a competent engineer would fit by
hand; weilgen's held-out RMS is compared with its score.

Usage: ridge_thermal.py DATA.csv [--rpm] [--lags 0,0.5,2,8] [--json OUT.json]
Prints the held-out RMS per channel and over all channels (um), and the chosen lambdas; --json
writes them ({"heldout_rms_um": all channels, "per_channel_um": {...}}) for bench/gap.
Needs Debian's python3-numpy (run with /usr/bin/python3).
"""
import argparse
import csv
import json
import math

import numpy as np


def lagged(t, x, tau_s):
    if tau_s <= 0:
        return x.copy()
    f = x.copy()
    for k in range(1, len(x)):
        a = 1 - math.exp(-(t[k] - t[k - 1]) / tau_s)
        f[k] = f[k - 1] + a * (x[k] - f[k - 1])
    return f


def ridge_fit(X, y, lam):
    # Intercept unpenalised: centre on the training mean.
    xm, ym = X.mean(axis=0), y.mean()
    Xc, yc = X - xm, y - ym
    p = X.shape[1]
    beta = np.linalg.solve(Xc.T @ Xc + lam * np.eye(p), Xc.T @ yc)
    return beta, ym - xm @ beta


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("data")
    ap.add_argument("--rpm", action="store_true", help="add the spindle speed as a heat input")
    ap.add_argument("--lags", default="0,0.5,2,8", help="first-order lags in hours")
    ap.add_argument("--train-fraction", type=float, default=0.5)
    ap.add_argument("--json", help="write the held-out RMS values to this file")
    a = ap.parse_args()
    with open(a.data) as fh:
        rows = list(csv.DictReader(fh))
    t = np.array([float(r["t_s"]) for r in rows])
    sensors = [k for k in rows[0] if k.startswith("T_")]
    inputs = [np.array([float(r[s]) for r in rows]) for s in sensors]
    if a.rpm:
        inputs.append(np.array([float(r["rpm"]) for r in rows]) / 1000.0)
    lags = [float(v) * 3600 for v in a.lags.split(",")]
    X = np.column_stack([lagged(t, x, tau) for x in inputs for tau in lags])
    cut = t[0] + a.train_fraction * (t[-1] - t[0])
    train, test = t < cut, t >= cut
    # Standardise on the training part.
    mu, sd = X[train].mean(axis=0), X[train].std(axis=0)
    sd[sd == 0] = 1
    Xs = (X - mu) / sd
    lams = 10.0 ** np.arange(-3, 6.01, 0.25)
    idx = np.flatnonzero(train)
    blocks = np.array_split(idx, 5)
    total_ss, total_n = 0.0, 0
    per_channel = {}
    for ch in ("dx_um", "dy_um", "dz_um"):
        y = np.array([float(r[ch]) for r in rows])
        cv = []
        for lam in lams:
            ss = 0.0
            for b in blocks:
                tr = np.setdiff1d(idx, b)
                beta, c = ridge_fit(Xs[tr], y[tr], lam)
                ss += float(np.sum((y[b] - Xs[b] @ beta - c) ** 2))
            cv.append(ss)
        lam = lams[int(np.argmin(cv))]
        beta, c = ridge_fit(Xs[train], y[train], lam)
        res = y[test] - Xs[test] @ beta - c
        per_channel[ch] = math.sqrt(np.mean(res ** 2))
        print(f"{ch}: held-out RMS {per_channel[ch]:.3f} um (lambda {lam:.3g})")
        total_ss += float(np.sum(res ** 2))
        total_n += int(res.size)
    print(f"all channels: held-out RMS {math.sqrt(total_ss / total_n):.3f} um "
          f"({len(inputs)} inputs x {len(lags)} lags, train {int(train.sum())} rows)")
    if a.json:
        with open(a.json, "w") as fh:
            json.dump({"heldout_rms_um": math.sqrt(total_ss / total_n),
                       "per_channel_um": per_channel, "inputs": len(inputs),
                       "lags_h": a.lags, "rpm": a.rpm}, fh, indent=2)


if __name__ == "__main__":
    main()
