#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""sph-run-mpi under mpirun against sph-run (ctest label mpi; issue 19).

    check_sph_run_mpi.py MPIEXEC SPH_RUN SPH_RUN_MPI SCENE WORKDIR RANKS [--refusals] [--backend cuda]

Runs SCENE with sph-run (libsph, one undivided world) and with RANKS ranks of sph-run-mpi
(libsph_mpi), both as CSV frames, and asserts that every frame of the merged output equals
sph-run's particle for particle, every column to the printed bit (%.9g round-trips a float),
with every rank holding particles after the first step:
docs/distributed.md promises the same bits while the neighbour grid covers the particles'
extent, which a closed tank keeps. Also that the --per-rank files of each frame hold every
particle once, each as the merged frame has it, and (--refusals) that sph-run-mpi refuses a
scene with a source or springs, naming it, and that --backend cuda either runs (a GPU is there)
or fails on every rank with exit code 4 and one message naming the option (CI: no GPU).
--backend cuda: both programs on the CUDA backend (scripts/gpu-test), the scene without its sinks
(a CUDA rank refuses sinks): the distributed CUDA world against the undivided CUDA world, bit for
bit while the tables cover the tank (docs/distributed.md, "The CUDA backend as a rank").
"""
import json
import glob
import os
import shutil
import subprocess
import sys

MPI_ENV = {"OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1", "OMP_NUM_THREADS": "1",
           "OMP_WAIT_POLICY": "passive"}


def run(cmd, expect=0):
    env = dict(os.environ, **MPI_ENV)
    p = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=100)
    if p.returncode != expect:
        sys.exit(f"FAIL: {' '.join(cmd)} exited {p.returncode}, expected {expect}\n{p.stdout}\n{p.stderr}")
    return p


def rows(path):
    """id -> the line's text, and the header."""
    with open(path, encoding="utf-8") as f:
        header, *lines = f.read().splitlines()
    out = {}
    for line in lines:
        key = int(line.split(",", 1)[0])
        assert key not in out, f"{path}: id {key} twice"
        out[key] = line
    return header, out


def main(argv):
    mpiexec, sph_run, sph_run_mpi, scene, work, ranks = argv[1:7]
    options = argv[7:]
    backend = options[options.index("--backend") + 1] if "--backend" in options else "cpu"
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    if backend == "cuda":
        with open(scene, encoding="utf-8") as f:
            desc = json.load(f)
        desc.pop("sinks", None)
        scene = os.path.join(work, "no_sinks.json")
        with open(scene, "w", encoding="utf-8") as f:
            json.dump(desc, f)
    single, merged = os.path.join(work, "single"), os.path.join(work, "np" + ranks)
    run([sph_run, scene, "--backend", backend, "--format", "csv", "--threads", "1", "--quiet", "--out", single])
    p = run([mpiexec, "--oversubscribe", "-np", ranks, sph_run_mpi, scene, "--backend", backend, "--format", "csv",
             "--threads", "1", "--quiet", "--per-rank", "--out", merged])
    print(p.stdout.strip())

    frames = sorted(os.path.basename(f) for f in glob.glob(os.path.join(single, "fluid_*.csv")))
    assert len(frames) >= 2, f"sph-run wrote {frames}"
    differing = 0
    for name in frames:
        h1, a = rows(os.path.join(single, name))
        h2, b = rows(os.path.join(merged, name))
        assert h1 == h2, f"{name}: columns {h2} != {h1}"
        assert a.keys() == b.keys(), f"{name}: ids differ ({len(a)} vs {len(b)} particles)"
        bad = [k for k in a if a[k] != b[k]]
        if bad:
            differing += 1
            k = bad[0]
            print(f"{name}: {len(bad)} of {len(a)} particles differ; id {k}:\n  sph-run     {a[k]}\n"
                  f"  sph-run-mpi {b[k]}")
        # Each rank's own particles, together, are the merged frame's, each once.
        union = {}
        for d in sorted(glob.glob(os.path.join(merged, "rank*"))):
            _, r = rows(os.path.join(d, name))
            assert not (union.keys() & r.keys()), f"{name}: a particle on two ranks"
            # After the first step every rank holds a slab's particles: the run was divided.
            assert r or name == frames[0], f"{name}: {os.path.basename(d)} holds no particle"
            union.update(r)
        assert union == b, f"{name}: the ranks' files hold {len(union)} particles, the merged {len(b)}"
    assert len(glob.glob(os.path.join(merged, "rank*"))) == int(ranks), "one folder per rank"
    if differing:
        sys.exit(f"FAIL: {differing} of {len(frames)} frames differ between sph-run and sph-run-mpi -np {ranks}")
    print(f"{len(frames)} frames of {len(a)} particles: sph-run-mpi on {ranks} ranks == sph-run, bit for bit"
          f" ({backend} backend)")
    if "--refusals" not in options:
        return 0

    # --backend cuda: runs where a GPU is, else every rank fails alike, one message, exit code 4.
    env = dict(os.environ, **MPI_ENV)
    p = subprocess.run([mpiexec, "--oversubscribe", "-np", ranks, sph_run_mpi, scene, "--backend", "cuda",
                        "--quiet", "--out", os.path.join(work, "cuda")], capture_output=True, text=True, env=env,
                       timeout=100)
    if p.returncode == 4:
        assert "--backend cuda" in p.stderr and p.stderr.count("sph-run-mpi:") == 1, p.stderr
        print("no GPU:", p.stderr.strip().splitlines()[0])
    else:
        assert p.returncode in (0, 3), f"--backend cuda exited {p.returncode}\n{p.stderr}"
        print(f"--backend cuda: exit {p.returncode} (a GPU is here; 3 = the CUDA rank refused the scene's sinks)")

    # A source: refused before any world is made, naming the scene object and the feature.
    with open(scene, encoding="utf-8") as f:
        text = f.read()
    bad_scene = os.path.join(work, "with_source.json")
    with open(bad_scene, "w", encoding="utf-8") as f:
        f.write(text.replace('"sinks"', '"sources": [{"shape": {"type": "sphere", "radius": 0.03}, '
                                        '"transform": {"position": [0, 0.2, 0]}}],\n  "sinks"', 1))
    p = run([mpiexec, "--oversubscribe", "-np", ranks, sph_run_mpi, bad_scene, "--quiet", "--out",
             os.path.join(work, "refused")], expect=3)
    assert "sources[0]" in p.stderr and "distributed world" in p.stderr, p.stderr
    assert p.stderr.count("sph-run-mpi:") == 1, f"one message, from rank 0:\n{p.stderr}"
    print("refused:", p.stderr.strip())

    # Springs: the library refuses the world (sph_mpi_world_create) and names the feature (RK4,
    # refused here before, works distributed since wt-mpisolve).
    bad_scene = os.path.join(work, "with_springs.json")
    with open(bad_scene, "w", encoding="utf-8") as f:
        f.write(text.replace('"capacity": 4000', '"capacity": 4000, "features": ["springs"]', 1))
    p = run([mpiexec, "--oversubscribe", "-np", ranks, sph_run_mpi, bad_scene, "--quiet", "--out",
             os.path.join(work, "refused")], expect=3)
    assert "world" in p.stderr and "SPH_FEATURE_SPRINGS" in p.stderr, p.stderr
    assert p.stderr.count("sph-run-mpi:") == 1, f"one message, from rank 0:\n{p.stderr}"
    print("refused:", p.stderr.strip().splitlines()[0])
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
