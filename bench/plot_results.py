#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Plots and tables from a scripts/bench-gpu results folder (BENCHMARK.md, issue 10).

    bench/plot_results.py RESULTS_DIR

Reads RESULTS_DIR/results.json (the rest_sphere rows), ceilings.json (device_ceilings),
ncu_share.json (bench/ncu_share.py) and scenes.json (case 3) when present, and writes into
RESULTS_DIR:
  fig8_seconds_per_frame.png  s/frame against particles, GPU and CPU, with the thesis's points
  fig9_stage_shares.png       the share of each stage per size (the thesis's Figures 9 and 10)
  scaling.png                 ns per particle-substep against particles (flat = linear scaling)
  summary.md                  the tables for docs/performance.md
"""
import json
import os
import sys

try:  # the tables need nothing; the plots need matplotlib (python3-matplotlib on Debian)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    plt = None

# The thesis's Figure 8 (GeForce 8 GPU and its CPU), s/frame (BENCHMARK.md case 1).
THESIS_N = [25000, 100000, 200000, 400000, 600000]
THESIS_GPU = [0.03, 0.1, 0.18, 0.35, 0.49]
THESIS_CPU = [1.32, 3.4, 6.36, 12.31, 20.18]
STAGES = ["hash_sort", "cell_ranges", "density", "forces", "integrate", "collide", "emit", "other"]


def load(path, default):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError):
        return default


def stage_shares(row):
    """Percent of the substep per stage, in STAGES order."""
    total = sum(row["stage_ms_per_substep"].values()) or 1.0
    return [100.0 * row["stage_ms_per_substep"].get(stage, 0.0) / total for stage in STAGES]


def rows_of(rows, backend, scene, option="none"):
    out = [r for r in rows if r["backend"] == backend and r["scene"] == scene and r.get("option", "none") == option]
    return sorted(out, key=lambda r: r["particles"])


def fig8(rows, out_dir):
    fig, ax = plt.subplots(figsize=(7, 5))
    for backend, scene, style in [("cuda", "rest", "o-"), ("cuda", "moving", "s--"), ("cpu", "rest", "^-"),
                                  ("cpu", "moving", "v--")]:
        rs = rows_of(rows, backend, scene)
        if rs:
            ax.plot([r["particles"] for r in rs], [r["s_per_frame"] for r in rs], style,
                    label=f"sph {backend.upper()} ({scene})")
    ax.plot(THESIS_N, THESIS_GPU, "k:", marker="x", label="thesis GPU (GeForce 8)")
    ax.plot(THESIS_N, THESIS_CPU, "k-.", marker="+", label="thesis CPU")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("particles")
    ax.set_ylabel("seconds per frame (25 fps, dt_max 1 ms)")
    ax.set_title("Rest sphere: time per frame (thesis Figure 8)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, "fig8_seconds_per_frame.png"), dpi=120)
    plt.close(fig)


def fig9(rows, out_dir):
    groups = [(b, rows_of(rows, b, "rest")) for b in ("cuda", "cpu")]
    groups = [(b, rs) for b, rs in groups if rs]
    if not groups:
        return
    fig, axes = plt.subplots(1, len(groups), figsize=(6 * len(groups), 4.5), squeeze=False)
    for ax, (backend, rs) in zip(axes[0], groups):
        labels = [f"{r['particles'] / 1000:.0f}k" for r in rs]
        bottoms = [0.0] * len(rs)
        per_row = [stage_shares(r) for r in rs]
        for k, stage in enumerate(STAGES):
            shares = [row[k] for row in per_row]
            if max(shares) > 0.0:
                ax.bar(labels, shares, bottom=bottoms, label=stage)
                bottoms = [b + s for b, s in zip(bottoms, shares)]
        ax.set_title(f"{backend.upper()}: share of each stage (rest sphere)")
        ax.set_ylabel("% of the substep")
        ax.set_xlabel("particles")
        ax.tick_params(axis="x", rotation=45)
        ax.legend(fontsize=7, loc="lower right")
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, "fig9_stage_shares.png"), dpi=120)
    plt.close(fig)


def scaling(rows, out_dir):
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for backend, scene, style in [("cuda", "rest", "o-"), ("cuda", "moving", "s--"), ("cpu", "rest", "^-")]:
        rs = rows_of(rows, backend, scene)
        if rs:
            ax.plot([r["particles"] for r in rs], [1e9 / r["particle_substeps_per_s"] for r in rs], style,
                    label=f"{backend.upper()} {scene}")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("particles")
    ax.set_ylabel("ns per particle-substep")
    ax.set_title("Cost per particle-substep (flat = linear scaling)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, "scaling.png"), dpi=120)
    plt.close(fig)


def summary(rows, ceilings, share, scenes, out_dir):
    lines = []
    lines.append("### Case 1: rest sphere (median over the timed frames)\n")
    lines.append("| backend | case | particles | s/frame | ms/substep | particle-substeps/s | neighbours | "
                 "bytes/particle | end density error | end max speed m/s |")
    lines.append("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for backend in ("cuda", "cpu"):
        for scene in ("rest", "moving"):
            for r in rows_of(rows, backend, scene):
                lines.append(f"| {backend} | {scene} | {r['particles']} | {r['s_per_frame']:.4g} | "
                             f"{r['ms_per_substep']:.4g} | {r['particle_substeps_per_s']:.3g} | "
                             f"{r['neighbors_mean']:.1f} | {r['bytes_per_particle']:.1f} | "
                             f"{r['density_error_mean']:.2e} | {r['max_speed']:.3g} |")
    # GPU over CPU at the sizes both ran.
    gpu = {r["particles"]: r for r in rows_of(rows, "cuda", "rest")}
    cpu = {r["particles"]: r for r in rows_of(rows, "cpu", "rest")}
    common = sorted(set(gpu) & set(cpu))
    if common:
        lines.append("\nGPU over CPU (rest, same run): " + ", ".join(
            f"{n / 1000:.0f}k {cpu[n]['ms_per_substep'] / gpu[n]['ms_per_substep']:.0f}x" for n in common))
    # Flatness of the cost per particle-substep, from 100k up.
    big = [r for r in rows_of(rows, "cuda", "rest") if r["particles"] >= 90000]
    if len(big) >= 2:
        cost = [1e9 / r["particle_substeps_per_s"] for r in big]
        lines.append(f"\nCost per particle-substep on the GPU from {big[0]['particles']} to {big[-1]['particles']}: "
                     f"{min(cost):.3g} to {max(cost):.3g} ns (spread {100 * (max(cost) / min(cost) - 1):.0f} %, "
                     "target within 20 %)")
    # Stage shares.
    lines.append("\n### Stage shares (rest sphere, % of the substep)\n")
    lines.append("| backend | particles | " + " | ".join(STAGES) + " |")
    lines.append("|---|---:|" + "---:|" * len(STAGES))
    for backend in ("cuda", "cpu"):
        for r in rows_of(rows, backend, "rest"):
            lines.append(f"| {backend} | {r['particles']} | " + " | ".join(f"{x:.1f}" for x in stage_shares(r)) + " |")
    # Options.
    options = sorted({r.get("option", "none") for r in rows} - {"none"})
    if options:
        lines.append("\n### Cost of each option (rest sphere, ms/substep; the option against none in the same run)\n")
        lines.append("| backend | particles | option | ms/substep | none | cost |")
        lines.append("|---|---:|---|---:|---:|---:|")
        for backend in ("cuda", "cpu"):
            for opt in options:
                for r in rows_of(rows, backend, "rest", opt):
                    base = [b for b in rows_of(rows, backend, "rest") if b["particles"] == r["particles"]]
                    if base:
                        b = base[0]["ms_per_substep"]
                        lines.append(f"| {backend} | {r['particles']} | {opt} | {r['ms_per_substep']:.4g} | "
                                     f"{b:.4g} | {100 * (r['ms_per_substep'] / b - 1):+.1f} % |")
    if ceilings:
        lines.append(f"\n### Ceilings of the device ({ceilings.get('device', '?')})\n")
        lines.append(f"cudaMemcpy D2D {ceilings['memcpy_gb_s']:.0f} GB/s, float4 copy kernel "
                     f"{ceilings['stream_gb_s']:.0f} GB/s, FP32 FMA {ceilings['fp32_tflop_s']:.1f} TFLOP/s")
    if share:
        lines.append("\n### What the substep achieves (ncu over whole substeps, rest sphere)\n")
        lines.append(f"particles {share['particles']}, {share['kernels']} kernels over {share['substeps']:.1f} "
                     f"substeps; kernel time {share['kernel_ms_per_substep']:.3f} ms/substep; DRAM "
                     f"{share['dram_gb_s']:.0f} GB/s ({share.get('dram_share', 0) * 100:.1f} % of the copy "
                     f"kernel's); FP32 {share['fp32_tflop_s']:.2f} TFLOP/s ({share.get('fp32_share', 0) * 100:.1f} % "
                     "of the FMA ceiling)")
        lines.append("\n| kernel | ms/substep | DRAM GB/s | FP32 TFLOP/s |")
        lines.append("|---|---:|---:|---:|")
        for k in share["by_kernel"]:
            lines.append(f"| {k['name']} | {k['ms_per_substep']:.4f} | {k['dram_gb_s']:.0f} | {k['fp32_tflop_s']:.2f} |")
    dams = []
    for backend in ("cuda", "cpu"):
        dams += load(os.path.join(out_dir, f"dam_break_{backend}.json"), [])
    if dams:
        lines.append("\n### Case 2: dam break (1 simulated second, median over the frames after the first)\n")
        lines.append("| backend | particles | s/frame | substeps/frame | ms/substep | particle-substeps/s | neighbours | "
                     "bytes/particle | " + " | ".join(STAGES) + " |")
        lines.append("|---|---:|---:|---:|---:|---:|---:|---:|" + "---:|" * len(STAGES))
        for d in dams:
            lines.append(f"| {d['backend']} | {d['particles']} | {d['s_per_frame']:.4g} | {d['substeps_per_frame']:.1f} | "
                         f"{d['ms_per_substep']:.4g} | {d['particle_substeps_per_s']:.3g} | {d['neighbors_mean']:.1f} | "
                         f"{d['bytes_per_particle']:.1f} | " + " | ".join(f"{x:.1f}" for x in stage_shares(d)) + " |")
    if scenes:
        lines.append("\n### Case 3: the thesis scenes (sph-run, no output)\n")
        lines.append("| scene | backend | particles at most | frames | s/frame | thesis s/frame |")
        lines.append("|---|---|---:|---:|---:|---:|")
        for s in scenes:
            lines.append(f"| {s['scene']} | {s['backend']} | {s['particles_max']} | {s['frames']} | "
                         f"{s['s_per_frame']:.4g} | {s.get('thesis_s_per_frame', '')} |")
    with open(os.path.join(out_dir, "summary.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))


def main():
    if len(sys.argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    out_dir = sys.argv[1]
    rows = [r for r in load(os.path.join(out_dir, "results.json"), []) if r.get("benchmark") == "rest_sphere"]
    ceilings = load(os.path.join(out_dir, "ceilings.json"), None)
    share = load(os.path.join(out_dir, "ncu_share.json"), None)
    scenes = load(os.path.join(out_dir, "scenes.json"), None)
    if share and ceilings:
        share["dram_share"] = share["dram_gb_s"] / ceilings["stream_gb_s"]
        share["fp32_share"] = share["fp32_tflop_s"] / ceilings["fp32_tflop_s"]
    if rows and plt is None:
        print("plot_results: no matplotlib here: tables only; rerun where python3-matplotlib is installed "
              "for the plots", file=sys.stderr)
    elif rows:
        fig8(rows, out_dir)
        fig9(rows, out_dir)
        scaling(rows, out_dir)
    summary(rows, ceilings, share, scenes, out_dir)
    return 0


if __name__ == "__main__":
    sys.exit(main())
