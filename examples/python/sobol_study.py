#!/usr/bin/env python3
"""Which errors of the gantry grinder drive the tool-point deviation along the Y travel?

A Sobol' study as a notebook would run it: open the machine's model, sample the first-order
and total Sobol' indices of dx and dy at five positions of Y (quasi-Monte Carlo, bootstrap
intervals), print the ranking and plot the total indices of the leading errors with matplotlib.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/sobol_study.py sobol_study.png
"""
import sys

import matplotlib

matplotlib.use("Agg")  # no display: write the figure to a file
import matplotlib.pyplot as plt
import numpy as np

import weilgen

out = sys.argv[1] if len(sys.argv) > 1 else "sobol_study.png"

model = weilgen.Model("gantry_grinder")
print(model)
print("axes", dict(zip(model.axes, model.axis_units)), "errors", len(model.errors))

# The CLI's flags as keywords: --grid X=500,Y=-1500:1500:5,Z=1000 --method sobol ...
doc = weilgen.sensitivity(model, grid={"X": 500, "Y": (-1500, 1500, 5), "Z": 1000},
                          method="sobol", outputs=["dx", "dy"], samples=4096, bootstrap=100,
                          quiet=True)
print(f"{doc['settings']['evaluations']} model evaluations, "
      f"{doc['settings']['confidence']:.0%} bootstrap intervals")

fig, axes = plt.subplots(1, 2, figsize=(11, 4.2), sharey=True)
for ax, output in zip(axes, ["dx", "dy"]):
    rows = [r for r in doc["results"] if r["output"] == output]
    y = sorted({r["pose"]["Y"] for r in rows})
    total = {}  # error -> ST at each Y (fraction of the output's variance)
    interval = {}
    for r in rows:
        i = y.index(r["pose"]["Y"])
        total.setdefault(r["error"], np.zeros(len(y)))[i] = r["ST"]
        interval.setdefault(r["error"], np.zeros((len(y), 2)))[i] = r["ST_ci"]
    leading = sorted(total, key=lambda e: -total[e].mean())[:5]
    print(f"{output}: " + ", ".join(f"{e} ST {total[e].mean():.3f}" for e in leading))
    for e in leading:
        ax.plot(y, total[e], marker="o", label=e)
        ax.fill_between(y, interval[e][:, 0], interval[e][:, 1], alpha=0.2)
    ax.set_title(f"{output}: total Sobol' indices")
    ax.set_xlabel("Y (mm)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
axes[0].set_ylabel("share of the variance of the deviation")
fig.suptitle(f"{model.name}: X = 500 mm, Z = 1000 mm")
fig.tight_layout()
fig.savefig(out, dpi=110)

with open(out, "rb") as f:
    assert f.read(8) == b"\x89PNG\r\n\x1a\n", "not a PNG"
print("wrote", out)
