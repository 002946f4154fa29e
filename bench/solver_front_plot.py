#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Plots bench/solver_front's CSV: the front's mean error and the mean density error against wall
seconds per simulated second, one marker per solver and parameter, one point per resolution.

    solver_front_plot.py solver_front.csv [solver_front.png]
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    if len(sys.argv) < 2:
        print(__doc__)
        return 2
    rows = [r for r in csv.DictReader(open(sys.argv[1])) if r["status"] == "ok"]
    out = sys.argv[2] if len(sys.argv) > 2 else sys.argv[1].rsplit(".", 1)[0] + ".png"
    # The full neighbourhoods' mean |rho/rho0 - 1| (session 32 on): a third panel where the CSV has it.
    interior = bool(rows) and all(r.get("interior_error") for r in rows)
    fig, axes = plt.subplots(1, 3 if interior else 2, figsize=(16 if interior else 11, 4.5))
    front, density = axes[0], axes[1]
    # The mean density error over every particle (DFSPH's bound's measure) where the CSV has it
    # (session 32 on); older CSVs have only the mean over the particles above rest density.
    every_particle = bool(rows) and all(r.get("mean_density_error_all") for r in rows)
    density_column = "mean_density_error_all" if every_particle else "density_error_mean"
    density_title = (
        "mean density error over every particle, %" if every_particle else "mean compression of those above rest, %"
    )
    series = {}
    for r in rows:
        label = ("WCSPH c = %s u_ff" if r["solver"] == "wcsph" else "DFSPH bound %s") % r["parameter"]
        series.setdefault(label, []).append(r)
    for label, rs in sorted(series.items()):
        rs.sort(key=lambda r: int(r["layers"]))
        cost = [float(r["wall_s_per_simulated_s"]) for r in rs]
        marker = "o" if rs[0]["solver"] == "wcsph" else "s"
        front.plot(cost, [100 * float(r["front_error_mean"]) for r in rs], marker=marker, label=label)
        density.plot(cost, [100 * float(r[density_column]) for r in rs], marker=marker, label=label)
        if interior:
            axes[2].plot(cost, [100 * float(r["interior_error"]) for r in rs], marker=marker, label=label)
    titles = [(front, "front mean error, %"), (density, density_title)]
    if interior:
        titles.append((axes[2], "mean |rho/rho0 - 1|, full neighbourhoods, %"))
    for ax, title in titles:
        ax.set_xscale("log")
        ax.set_xlabel("wall s per simulated s (%s)" % (rows[0]["backend"] if rows else "?"))
        ax.set_ylabel(title)
        ax.grid(True, alpha=0.3)
    front.legend(fontsize=7)
    fig.suptitle("Dam break (Martin & Moyce): solver trade, points = resolutions")
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    print("wrote", out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
