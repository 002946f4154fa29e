#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""sph-run-mpi under mpirun against sph-run (ctest label mpi; issue 19).

    check_sph_run_mpi.py MPIEXEC SPH_RUN SPH_RUN_MPI SCENE WORKDIR RANKS [--refusals] [--interrupt]
                         [--backend cuda] [--vdb COMPARE_VDB_FRAMES]

Runs SCENE with sph-run (libsph, one undivided world) and with RANKS ranks of sph-run-mpi
(libsph_mpi), both as CSV frames with --stats-json, and asserts that every frame of the merged
output equals sph-run's particle for particle, every column to the printed bit (%.9g round-trips
a float), with every rank holding particles after the first step:
docs/distributed.md promises the same bits while the neighbour grid covers the particles'
extent, which a closed tank keeps. The scene's source emits across the ranks (its particles are
in the merged frames with sph-run's ids); its probes' CSV files equal sph-run's bit for bit (each
probe point is read by its slab's rank and shared); the tank's loads file equals sph-run's
within 1e-6 of the row's force (torque) magnitude: each rank sums its own particles' impulses,
in blocks that hold other particles than the undivided world's blocks, so the sums round
differently (tests/mpi/test_mpi_scene_sums.c measured ~1e-8). The --stats-json documents agree
on the frames, substeps, particle counts, time steps, top speed and (a DFSPH scene) the solves'
figures exactly (and the summaries' DFSPH lines are sph-run's), and on the mean neighbour count
within 1e-5 (the ranks' means weighted by their particles: another summation order). Also that
the --per-rank files of each frame hold every particle once, each as the merged frame has it, and (--refusals) that --backend cuda either runs (a GPU is there) or fails on every rank with exit code 4
and one message naming the option (CI: no GPU); then the scene with springs, whose merged frames
equal sph-run's bit for bit (springs across ranks; with --backend cuda on CUDA ranks against
sph-run --backend cuda, also without --refusals: scripts/gpu-test runs it).
--interrupt: SIGINT to one rank alone (not rank 0 as a rule) once frame 1 is complete: every
rank stops after the same frame (they agree once before and once after each step), exit code
130, the manifests end "interrupted" at that frame, whose files (and the probes' rows) are all
there.
--vdb COMPARE_VDB_FRAMES (builds with OpenVDB): both programs also write vdb frames and surfaces
(--format csv,vdb --surface), and every merged vdb file equals sph-run's as compare_vdb_frames reads
it: the points by id (voxel, position in it, v, density) and the level sets voxel for voxel, bit for
bit; the surface meshes (.obj) byte for byte. Then the scene with a .vdb shape (sph-run's first
surface, moved into the column's edge) as a collider, which sph-run-mpi loads through libsph_vdb_mpi:
the merged frames equal sph-run's bit for bit (by frame 3, 470 of the 560 particles are elsewhere
than without the collider: measured once, 2026-12-03). The same particles give the same level set in any
order (ParticlesToLevelSet's union of spheres is a minimum, which rounds nothing), so no tolerance.
--backend cuda: both programs on the CUDA backend (scripts/gpu-test), the whole scene (CUDA ranks
run its sink, probes, source and loads since session 15), checked as above: the distributed CUDA
world against the undivided CUDA world, bit for bit while the tables cover the tank
(docs/distributed.md, "The CUDA backend as a rank"), the source's particles on more than one rank.
"""
import json
import glob
import os
import shutil
import signal
import subprocess
import sys
import time

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


def csv_rows(path):
    with open(path, encoding="utf-8") as f:
        header, *lines = f.read().splitlines()
    return header, [line.split(",") for line in lines]


def check_object_files(single, merged):
    """The probes' files equal sph-run's bit for bit, the loads' within 1e-6 of the row's magnitude."""
    names = sorted(os.path.basename(f) for f in glob.glob(os.path.join(single, "probe_*.csv")) +
                   glob.glob(os.path.join(single, "loads_*.csv")))
    got = sorted(os.path.basename(f) for f in glob.glob(os.path.join(merged, "probe_*.csv")) +
                 glob.glob(os.path.join(merged, "loads_*.csv")))
    assert names == got, f"sph-run wrote {names}, sph-run-mpi {got}"
    worst = 0.0
    for name in names:
        h1, a = csv_rows(os.path.join(single, name))
        h2, b = csv_rows(os.path.join(merged, name))
        assert h1 == h2 and len(a) == len(b), f"{name}: {len(b)} rows of {h2}, sph-run {len(a)} of {h1}"
        if name.startswith("probe_"):
            assert a == b, f"{name} differs from sph-run's:\n" + "\n".join(
                f"  {x}\n  {y}" for x, y in zip(a, b) if x != y)
            continue
        for x, y in zip(a, b):
            # frame, time, force xyz, torque xyz, point xyz, frame_time: the point and times exact.
            assert x[:2] == y[:2] and x[8:] == y[8:], f"{name}: {y} != sph-run's {x}"
            for lo in (2, 5):
                u, v = [float(c) for c in x[lo:lo + 3]], [float(c) for c in y[lo:lo + 3]]
                size = max(sum(c * c for c in u) ** 0.5, 1e-30)
                error = max(abs(p - q) for p, q in zip(u, v)) / size
                worst = max(worst, error)
                assert error <= 1e-6, f"{name}: frame {x[0]}: {v} vs sph-run's {u} ({error:.2g} relative)"
        assert any(float(c) != 0.0 for row in a for c in row[2:5]), f"{name}: no load at all"
    print(f"{', '.join(names)}: probes equal sph-run's bit for bit, loads within {worst:.2g} of the magnitude")


def check_stats(single, merged, ranks, dfsph):
    with open(single, encoding="utf-8") as f:
        a = json.load(f)
    with open(merged, encoding="utf-8") as f:
        b = json.load(f)
    assert set(a) <= set(b), f"--stats-json: sph-run-mpi lacks {set(a) - set(b)}"
    assert b["ranks"] == ranks and b["migrated"] > 0, b
    for key in ("benchmark", "backend", "frames", "substeps", "particles_end", "particles_max", "dt_min", "dt_max",
                "max_speed"):
        assert a[key] == b[key], f"--stats-json: {key} {b[key]} != sph-run's {a[key]}"
    assert abs(a["neighbors_mean"] - b["neighbors_mean"]) <= 1e-5 * a["neighbors_mean"], (a, b)
    # DFSPH's solves (a DFSPH scene only): the ranks turn the undivided world's solves, their sums
    # exact over the ranks (docs/distributed.md), so every figure is sph-run's to the printed digit.
    assert ("dfsph" in a) == dfsph and ("dfsph" in b) == dfsph, f"--stats-json: dfsph expected {dfsph}"
    if dfsph:
        assert a["dfsph"] == b["dfsph"], f"--stats-json: dfsph {b['dfsph']} != sph-run's {a['dfsph']}"
    print(f"--stats-json: {b['frames']} frames, {b['substeps']} substeps, {b['particles_end']} particles "
          f"(at most {b['particles_max']}), {b['migrated']} migrated"
          f"{', DFSPH solves' if 'dfsph' in a else ''}: as sph-run's")


def check_vdb(compare_vdb, single, merged, frames):
    """The merged vdb frames and surfaces equal sph-run's (compare_vdb_frames), the meshes byte for byte;
    each rank's folder holds its own particles' vdb frames and no surface."""
    names = sorted(os.path.basename(f) for f in glob.glob(os.path.join(single, "fluid_*.vdb")) +
                   glob.glob(os.path.join(single, "surface_*.vdb")))
    got = sorted(os.path.basename(f) for f in glob.glob(os.path.join(merged, "fluid_*.vdb")) +
                 glob.glob(os.path.join(merged, "surface_*.vdb")))
    assert names == got and len(names) == 2 * frames, f"sph-run wrote {names}, sph-run-mpi {got}"
    for name in names:
        p = subprocess.run([compare_vdb, os.path.join(single, name), os.path.join(merged, name)],
                           capture_output=True, text=True, timeout=60)
        assert p.returncode == 0, f"{name}: {p.stdout}{p.stderr}"
        last = p.stdout.strip()
    for obj in sorted(glob.glob(os.path.join(single, "surface_*.obj"))):
        with open(obj, "rb") as f, open(os.path.join(merged, os.path.basename(obj)), "rb") as g:
            assert f.read() == g.read(), f"{os.path.basename(obj)} differs from sph-run's"
    for d in sorted(glob.glob(os.path.join(merged, "rank*"))):
        assert len(glob.glob(os.path.join(d, "fluid_*.vdb"))) == frames, f"{d}: not {frames} vdb frames"
        assert not glob.glob(os.path.join(d, "surface_*")), f"{d}: a rank's surface"
    print(f"{len(names)} vdb files (points and surfaces) and {frames} meshes equal sph-run's bit for bit "
          f"(last: {last})")


def check_vdb_shape(mpiexec, sph_run, sph_run_mpi, scene, work, ranks):
    """A .vdb shape (sph-run's first surface, the column's, moved 0.18 m along x into the column's edge) as a
    collider: sph-run-mpi loads it (libsph_vdb_mpi) and its merged frames equal sph-run's bit for bit."""
    with open(scene, encoding="utf-8") as f:
        doc = json.load(f)
    level_set = os.path.abspath(os.path.join(work, "single", "surface_0000.vdb"))
    doc["colliders"].append({"name": "vdb block", "shape": {"type": "vdb", "file": level_set},
                             "transform": {"position": [0.18, 0.0, 0.0]}})
    with_vdb = os.path.join(work, "with_vdb_shape.json")
    with open(with_vdb, "w", encoding="utf-8") as f:
        json.dump(doc, f)
    single, merged = os.path.join(work, "vdb_shape_single"), os.path.join(work, "vdb_shape_np" + ranks)
    common = ["--format", "csv", "--frames", "3", "--threads", "1", "--quiet"]
    run([sph_run, with_vdb, "--backend", "cpu", *common, "--out", single])
    run([mpiexec, "--oversubscribe", "-np", ranks, sph_run_mpi, with_vdb, "--backend", "cpu", *common, "--out", merged])
    frames = sorted(os.path.basename(f) for f in glob.glob(os.path.join(single, "fluid_*.csv")))
    assert len(frames) == 4, f"sph-run wrote {frames}"
    for name in frames:
        assert rows(os.path.join(single, name)) == rows(os.path.join(merged, name)), f"vdb shape: {name} differs"
    print(f"a .vdb shape as a collider: {len(frames)} frames on {ranks} ranks == sph-run, bit for bit")


def manifest_end(directory):
    path = os.path.join(directory, "sph-run-manifest.jsonl")
    if not os.path.exists(path):
        return None, []
    with open(path, encoding="utf-8") as f:
        lines = [json.loads(line) for line in f.read().splitlines() if line.endswith("}")]
    complete = [line["frame"] for line in lines if line.get("state") == "complete" and "frame" in line]
    ends = [line for line in lines if "end" in line]
    return (ends[-1] if ends else None), complete


def interrupt_one_rank(proc, out, ranks):
    """Waits for frame 1 of the run `proc` (mpirun), sends SIGINT to one rank; its output."""
    deadline = time.monotonic() + 60
    while 1 not in manifest_end(out)[1]:
        assert proc.poll() is None and time.monotonic() < deadline, "sph-run-mpi never completed frame 1"
        time.sleep(0.05)
    # The ranks are mpirun's children (one host); the youngest is, as a rule, the last rank.
    children = []
    for stat in glob.glob("/proc/[0-9]*/stat"):
        try:
            with open(stat, encoding="utf-8") as f:
                fields = f.read().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[1]) == proc.pid and os.path.basename(os.path.dirname(stat)).isdigit():
            children.append(int(os.path.basename(os.path.dirname(stat))))
    assert len(children) == int(ranks), f"mpirun's children: {children}"
    os.kill(max(children), signal.SIGINT)
    return proc.communicate(timeout=60)


def check_interrupt(mpiexec, sph_run_mpi, scene, work, ranks, backend):
    """SIGINT to one rank alone, once frame 1 is complete: every rank stops after the same frame."""
    out = os.path.join(work, "interrupted")
    env = dict(os.environ, **MPI_ENV)
    proc = subprocess.Popen([mpiexec, "--oversubscribe", "-np", ranks, sph_run_mpi, scene, "--backend", backend,
                             "--format", "csv", "--threads", "1", "--quiet", "--per-rank", "--frames", "5000",
                             "--out", out, "--stats-json", out + ".json"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    try:
        stdout, stderr = interrupt_one_rank(proc, out, ranks)
    finally:
        if proc.poll() is None:  # a failed check: no run of 5000 frames left behind
            proc.terminate()  # mpirun ends its ranks (SIGTERM, then SIGKILL); a killed mpirun would not
            try:
                proc.communicate(timeout=30)
            except subprocess.TimeoutExpired:
                proc.kill()
    assert proc.returncode == 130, f"interrupted run exited {proc.returncode}\n{stdout}\n{stderr}"
    end, complete = manifest_end(out)
    assert end == {"end": "interrupted", "last_frame": end["last_frame"]}, end
    last = end["last_frame"]
    assert 1 <= last < 5000 and complete == list(range(last + 1)), (end, complete)
    for r in range(int(ranks)):
        assert manifest_end(os.path.join(out, f"rank{r}"))[0] == end, f"rank{r} ended otherwise"
    for k in range(last + 1):
        assert os.path.exists(os.path.join(out, f"fluid_{k:04d}.csv")), f"frame {k} missing"
    for probe in glob.glob(os.path.join(out, "probe_*.csv")) + glob.glob(os.path.join(out, "loads_*.csv")):
        assert len(csv_rows(probe)[1]) == last, f"{probe}: not {last} rows"
    with open(out + ".json", encoding="utf-8") as f:
        assert json.load(f)["frames"] == last, "--stats-json of the interrupted run"
    assert f"interrupted; frames 0..{last} are complete" in stderr, stderr
    print(f"SIGINT to one rank: every rank stopped after frame {last}, exit code 130, manifests 'interrupted'")


def main(argv):
    mpiexec, sph_run, sph_run_mpi, scene, work, ranks = argv[1:7]
    options = argv[7:]
    backend = options[options.index("--backend") + 1] if "--backend" in options else "cpu"
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    compare_vdb = options[options.index("--vdb") + 1] if "--vdb" in options else None
    outputs = ["--format", "csv,vdb", "--surface"] if compare_vdb else ["--format", "csv"]
    single, merged = os.path.join(work, "single"), os.path.join(work, "np" + ranks)
    p_single = run([sph_run, scene, "--backend", backend, *outputs, "--threads", "1", "--quiet", "--out", single,
                    "--stats-json", single + ".json"])
    p = run([mpiexec, "--oversubscribe", "-np", ranks, sph_run_mpi, scene, "--backend", backend, *outputs,
             "--threads", "1", "--quiet", "--per-rank", "--out", merged, "--stats-json", merged + ".json"])
    print(p.stdout.strip())
    # A DFSPH scene's summary lines (its solves, figures equal over the ranks) read as sph-run's: three
    # in each summary; none for a weakly compressible scene.
    with open(scene, encoding="utf-8") as f:
        dfsph = json.load(f).get("world", {}).get("solver") == "dfsph"
    solve_lines = [[line for line in q.stdout.splitlines() if line.startswith("  DFSPH ")] for q in (p_single, p)]
    assert len(solve_lines[0]) == (3 if dfsph else 0), f"sph-run's summary: {p_single.stdout}"
    assert solve_lines[0] == solve_lines[1], f"summary's DFSPH lines: {solve_lines[1]} != sph-run's {solve_lines[0]}"

    frames = sorted(os.path.basename(f) for f in glob.glob(os.path.join(single, "fluid_*.csv")))
    assert len(frames) >= 2, f"sph-run wrote {frames}"
    differing = 0
    first = len(rows(os.path.join(single, frames[0]))[1])  # the ids a source's particles follow
    emitting = set()  # the ranks that held a source's particles
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
            if any(k >= first for k in r):
                emitting.add(os.path.basename(d))
            union.update(r)
        assert union == b, f"{name}: the ranks' files hold {len(union)} particles, the merged {len(b)}"
    assert len(glob.glob(os.path.join(merged, "rank*"))) == int(ranks), "one folder per rank"
    # The source spans the slabs: its particles were emitted (and held) on more than one rank.
    assert len(emitting) > 1, f"the source's particles were on {sorted(emitting)} only"
    if differing:
        sys.exit(f"FAIL: {differing} of {len(frames)} frames differ between sph-run and sph-run-mpi -np {ranks}")
    print(f"{len(frames)} frames of {len(a)} particles ({len(a) - first} more than frame 0: the source's, held on "
          f"{len(emitting)} ranks): sph-run-mpi on {ranks} ranks == sph-run, bit for bit ({backend} backend)")
    check_object_files(single, merged)
    check_stats(single + ".json", merged + ".json", int(ranks), dfsph)
    if compare_vdb:
        check_vdb(compare_vdb, single, merged, len(frames))
        check_vdb_shape(mpiexec, sph_run, sph_run_mpi, scene, work, ranks)
    if "--interrupt" in options:
        check_interrupt(mpiexec, sph_run_mpi, scene, work, ranks, backend)
    if backend == "cuda":
        check_springs(mpiexec, sph_run, sph_run_mpi, scene, work, ranks, backend)
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
    else:  # a GPU is here: CUDA ranks run the whole scene (its sink, probes, source and loads)
        assert p.returncode == 0, f"--backend cuda exited {p.returncode}\n{p.stderr}"
        print("--backend cuda: exit 0 (a GPU is here)")

    if backend != "cuda":  # (with --backend cuda, checked above)
        check_springs(mpiexec, sph_run, sph_run_mpi, scene, work, ranks, backend)
    return 0


def check_springs(mpiexec, sph_run, sph_run_mpi, scene, work, ranks, backend):
    """The scene with springs: every merged frame equals sph-run's bit for bit, springs crossing the slabs,
    on CPU ranks (since wt-springrank) and on CUDA ranks against sph-run --backend cuda (since
    wt-cudaspring, where they were refused before)."""
    with open(scene, encoding="utf-8") as f:
        text = f.read()
    springs = os.path.join(work, "with_springs.json")
    with open(springs, "w", encoding="utf-8") as f:
        f.write(text.replace('"capacity": 4000', '"capacity": 4000, "features": ["springs"]', 1))
    out = os.path.join(work, "springs_np" + ranks)
    single = os.path.join(work, "springs_single")
    run([sph_run, springs, "--backend", backend, "--format", "csv", "--threads", "1", "--quiet", "--out", single])
    run([mpiexec, "--oversubscribe", "-np", ranks, sph_run_mpi, springs, "--backend", backend, "--format", "csv",
         "--threads", "1", "--quiet", "--out", out])
    frames = sorted(os.path.basename(f) for f in glob.glob(os.path.join(single, "fluid_*.csv")))
    assert len(frames) >= 2, f"sph-run wrote {frames}"
    for name in frames:
        _, a = rows(os.path.join(single, name))
        _, b = rows(os.path.join(out, name))
        bad = [k for k in a if a[k] != b.get(k)]
        assert a.keys() == b.keys() and not bad, (f"springs: {name}: {len(bad)} of {len(a)} particles differ from "
                                                  f"sph-run's" + (f"; id {bad[0]}: {a[bad[0]]} vs {b.get(bad[0])}"
                                                                  if bad else ""))
    print(f"springs: {len(frames)} frames of {len(a)} particles on {ranks} ranks == sph-run, bit for bit "
          f"({backend} backend)")


if __name__ == "__main__":
    sys.exit(main(sys.argv))
