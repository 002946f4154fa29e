#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""What share of the device's bandwidth and FP32 rate the substep achieves (issue 10, item 3).

    bench/ncu_share.py NCU_CSV PARTICLES OUT_JSON

NCU_CSV is the --csv --print-units base log of
    ncu --metrics gpu__time_duration.sum,dram__bytes.sum,
                  smsp__sass_thread_inst_executed_op_ffma_pred_on.sum,
                  smsp__sass_thread_inst_executed_op_fadd_pred_on.sum,
                  smsp__sass_thread_inst_executed_op_fmul_pred_on.sum
over a window of whole substeps of bench/rest_sphere (scripts/bench-gpu runs it). FP32
operations count an FMA as two. The number of substeps in the window is the number of
density_kernel launches (one per substep with the symplectic Euler integrator).
"""
import csv
import json
import sys
from collections import defaultdict

METRICS = {
    "gpu__time_duration.sum": "ns",
    "dram__bytes.sum": "bytes",
    "smsp__sass_thread_inst_executed_op_ffma_pred_on.sum": "ffma",
    "smsp__sass_thread_inst_executed_op_fadd_pred_on.sum": "fadd",
    "smsp__sass_thread_inst_executed_op_fmul_pred_on.sum": "fmul",
}


def kernel_name(signature):
    """'void sph::<unnamed>::density_kernel<0>(...)' -> 'density_kernel'."""
    name = signature.replace("(anonymous namespace)::", "").replace("<unnamed>::", "")
    if name.startswith("void "):
        name = name[5:]
    name = name.split("(")[0].split("<")[0].strip()
    return name.split("::")[-1]


def number(text):
    return float(text.replace(",", "")) if text not in ("", "n/a") else 0.0


def main():
    if len(sys.argv) != 4:
        print(__doc__, file=sys.stderr)
        return 2
    path, particles, out = sys.argv[1], int(sys.argv[2]), sys.argv[3]
    with open(path) as f:
        lines = [l for l in f if l.startswith('"')]  # ncu's own ==PROF== lines are not CSV
    launches = defaultdict(dict)  # launch id -> {kernel, metric: value}
    for row in csv.DictReader(lines):
        key = METRICS.get(row.get("Metric Name", ""))
        if key is None:
            continue
        launch = launches[row["ID"]]
        launch["kernel"] = kernel_name(row["Kernel Name"])
        unit = row.get("Metric Unit", "")
        value = number(row["Metric Value"])
        if key == "ns" and unit in ("usecond", "us"):
            value *= 1e3
        elif key == "ns" and unit in ("msecond", "ms"):
            value *= 1e6
        launch[key] = value
    if not launches:
        print(f"ncu_share: no metric rows in {path}", file=sys.stderr)
        return 1
    by_kernel = defaultdict(lambda: defaultdict(float))
    for launch in launches.values():
        k = by_kernel[launch["kernel"]]
        k["launches"] += 1
        for key in METRICS.values():
            k[key] += launch.get(key, 0.0)
    substeps = by_kernel["density_kernel"]["launches"] if "density_kernel" in by_kernel else 0
    if substeps == 0:
        print("ncu_share: no density_kernel launch in the window", file=sys.stderr)
        return 1

    def flops(k):
        return 2.0 * k["ffma"] + k["fadd"] + k["fmul"]

    total = defaultdict(float)
    for k in by_kernel.values():
        for key in ("ns", "bytes", "ffma", "fadd", "fmul"):
            total[key] += k[key]
    result = {
        "particles": particles,
        "kernels": len(launches),
        "substeps": substeps,
        "kernel_ms_per_substep": total["ns"] * 1e-6 / substeps,
        "dram_bytes_per_substep": total["bytes"] / substeps,
        "dram_gb_s": total["bytes"] / total["ns"],  # bytes per ns = GB/s
        "fp32_flop_per_substep": flops(total) / substeps,
        "fp32_tflop_s": flops(total) / total["ns"] * 1e-3,
        "by_kernel": sorted(
            [{"name": name, "launches": int(k["launches"]), "ms_per_substep": k["ns"] * 1e-6 / substeps,
              "dram_gb_s": k["bytes"] / k["ns"] if k["ns"] else 0.0,
              "fp32_tflop_s": flops(k) / k["ns"] * 1e-3 if k["ns"] else 0.0} for name, k in by_kernel.items()],
            key=lambda k: -k["ms_per_substep"]),
    }
    with open(out, "w") as f:
        json.dump(result, f, indent=1)
    print(f"ncu: {substeps} substeps, {result['kernel_ms_per_substep']:.3f} ms kernel time per substep, "
          f"DRAM {result['dram_gb_s']:.0f} GB/s, FP32 {result['fp32_tflop_s']:.2f} TFLOP/s")
    for k in result["by_kernel"]:
        print(f"  {k['name']:<32} {k['ms_per_substep']:.4f} ms/substep  {k['dram_gb_s']:7.0f} GB/s  "
              f"{k['fp32_tflop_s']:6.2f} TFLOP/s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
