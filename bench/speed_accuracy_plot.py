#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Plots bench/speed_accuracy's CSV: the surge front's mean error against the cost (wall seconds
per simulated second), one marker per integrator, one colour per resolution, lambda written
next to each point. The lower-left envelope is the Pareto front a user picks from.

    python3 bench/speed_accuracy_plot.py speed_accuracy.csv speed_accuracy.png
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    rows = [r for r in csv.DictReader(open(sys.argv[1])) if r["status"] == "ok"]
    if not rows:
        sys.exit("speed_accuracy_plot: no successful runs in " + sys.argv[1])
    layers = sorted({int(r["layers"]) for r in rows})
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    markers = {"symplectic_euler": "o", "rk4": "s"}
    fig, ax = plt.subplots(figsize=(8, 5.5))
    for i, n in enumerate(layers):
        for integrator, marker in markers.items():
            sel = [r for r in rows if int(r["layers"]) == n and r["integrator"] == integrator]
            if not sel:
                continue
            x = [float(r["wall_s_per_simulated_s"]) for r in sel]
            y = [100.0 * float(r["mean_error"]) for r in sel]
            ax.plot(x, y, marker=marker, linestyle="-" if integrator == "rk4" else "--", color=colours[i % len(colours)],
                    label=f"{integrator.replace('_', ' ')}, {n} layers ({sel[0]['particles']} particles)")
            for r, xi, yi in zip(sel, x, y):
                ax.annotate(f"λ={float(r['step_factor']):g}", (xi, yi), textcoords="offset points", xytext=(4, 3),
                            fontsize=7)
    points = sorted((float(r["wall_s_per_simulated_s"]), 100.0 * float(r["mean_error"])) for r in rows)
    front, best = [], float("inf")
    for x, y in points:
        if y < best:
            front.append((x, y))
            best = y
    ax.plot([p[0] for p in front], [p[1] for p in front], color="black", linewidth=3, alpha=0.2, label="Pareto front")
    ax.axhline(8.0, color="grey", linestyle=":", linewidth=1, label="validation bound, mean 8 %")
    ax.set_xscale("log")
    ax.set_xlabel("cost: wall seconds per simulated second (" + rows[0]["backend"] + ")")
    ax.set_ylabel("surge front mean error vs Martin & Moyce (1952), %")
    ax.set_title("Dam break: accuracy against cost")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(sys.argv[2], dpi=120)
    print("wrote " + sys.argv[2])


if __name__ == "__main__":
    main()
