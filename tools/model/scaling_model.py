#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The weak-scaling model of docs/scaling.md (issue 19 item 6): time per substep of one rank of
a distributed world against particles per rank and rank count, from the measured single-GPU
substep and assumed link constants. Prints the table docs/scaling.md shows; every constant is an
option, so the table can be recalibrated when the two-rank run on one GPU (scripts/gpu-test) and
the two-GPU run are measured.

  tools/model/scaling_model.py [--fixed-ms 0.148] [--ns-small 0.823] [--ns-large 0.72]
                               [--halo-bytes 52] [--support 1.8] [--messages 12]
"""
import argparse
import math


def halo_particles(n, support):
    """Particles within one support radius (in lattice spacings) outside a cube of n particles of
    an FCC lattice (sqrt(2) particles per spacing^3): what a rank receives per exchange when a
    space-filling curve gives it a compact, cube-like domain."""
    rho = math.sqrt(2.0)
    a = (n / rho) ** (1.0 / 3.0)
    return rho * ((a + 2.0 * support) ** 3 - a ** 3)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--fixed-ms", type=float, default=0.148, help="substep cost independent of N, ms")
    p.add_argument("--ns-small", type=float, default=0.823, help="ns per particle-substep up to 4M")
    p.add_argument("--ns-large", type=float, default=0.72, help="ns per particle-substep above 4M")
    p.add_argument("--halo-bytes", type=float, default=52.0, help="bytes per halo particle per substep")
    p.add_argument("--support", type=float, default=1.8, help="kernel radius in particle spacings")
    p.add_argument("--messages", type=int, default=12, help="messages per substep (2 exchanges x 6 faces)")
    args = p.parse_args()
    links = [  # name, bandwidth per GPU per direction (B/s), latency per message (s), rank counts
        ("NVLink 4, one node", 450e9, 10e-6, (2, 8)),
        ("InfiniBand NDR 400G", 50e9, 10e-6, (16, 1024)),
        ("host-staged MPI, one GPU", 12e9, 30e-6, (2,)),
    ]
    print("| particles per rank | halo share | halo bytes/substep | compute ms | link | exchange ms "
          "| ranks | step reduction ms | efficiency |")
    print("|---|---|---|---|---|---|---|---|---|")
    for n in (1e6, 1e7, 1e8, 1e9):
        h = halo_particles(n, args.support)
        compute = args.fixed_ms * 1e-3 + (args.ns_small if n <= 4e6 else args.ns_large) * 1e-9 * n
        for name, beta, alpha, rank_counts in links:
            exchange = args.messages * alpha + args.halo_bytes * h / beta
            for ranks in rank_counts:
                reduction = 20e-6 * math.log2(ranks)  # an allreduce of one float per substep
                total = compute + exchange + reduction
                print(f"| {n:.0e} | {100 * h / n:.1f} % | {args.halo_bytes * h / 1e6:.1f} MB | {1e3 * compute:.2f} "
                      f"| {name} | {1e3 * exchange:.3f} | {ranks} | {1e3 * reduction:.3f} | {100 * compute / total:.1f} % |")


if __name__ == "__main__":
    main()
