# SPDX-License-Identifier: MIT
"""sph.mpi (bindings/python/sph/mpi.py) on every rank of MPI.COMM_WORLD, against one undivided
world of the same particles in the same process: docs/distributed.md promises the same bits
(the CPU backend sums in the same order on any rank count while the neighbour grid covers the
particles' extent, which the closed tank keeps), so positions and velocities are compared
exactly. Every test runs on every rank in the same order: the collective calls then match.
"""
import gc
import warnings

import numpy as np
import pytest

import sph
import sph.mpi
from sph import _generated as g

from conftest import CALLS

SPACING = 0.02
FRAMES = 6


def tank_scene(ctx, world):
    """A closed tank, the same on every rank (the scene is replicated)."""
    tank = ctx.shape("box", half_extents=(0.2, 0.15, 0.07), voxel_size=0.01)
    world.add_collider(tank, transform=(0.0, 0.15, 0.0), inverted=True)
    world.set_params(gravity=(0.0, -9.81, 0.0), stiffness=100.0, viscosity=1.0, dt_max=0.002)


def test_the_library_is_libsph_mpi():
    assert sph.mpi.library_has_mpi(), "run with SPH_LIBRARY=.../libsph_mpi.so"


def test_a_dam_break_equals_the_undivided_world(ctx, comm):
    with ctx.world(capacity=4000, particle_spacing=SPACING) as ref:
        tank_scene(ctx, ref)
        ref.fill_box((-0.2, 0.0, -0.06), (0.0, 0.14, 0.06), velocity=(0.1, 0.0, 0.0))
        order = np.argsort(ref.ids())
        x0, v0 = ref.positions()[order], ref.velocities()[order]
        world = sph.mpi.DistributedWorld(ctx, comm.py2f(), capacity=4000, particle_spacing=SPACING)
        try:
            tank_scene(ctx, world)
            # Every collective call first, then the checks: a failing assertion on one rank then
            # cannot leave the others waiting in a collective. Rank 0 adds every particle, so the
            # ids are the undivided world's.
            first = world.add_particles(x0 if comm.rank == 0 else None, v0 if comm.rank == 0 else None)
            steps = []
            for _ in range(FRAMES):
                steps.append((ref.step(1 / 50), world.step(1 / 50)))
            c = world.counts()
            local_sum = comm.allreduce(world.particle_count)
            ranks_holding = comm.allreduce(int(world.particle_count > 0))
            merged = world.gather(root=0)
            last = comm.size - 1
            only = world.gather(root=last, velocities=False, ids=False)  # the others pass nothing
            own = comm.gather((world.ids(), world.positions()), root=0)
            problems = []
            if first != (0 if comm.rank == 0 else len(x0)):  # ids in rank order: rank 0 added all
                problems.append(f"rank {comm.rank}: first id {first}")
            if any(s != (sph.Result.OK, sph.Result.OK) for s in steps):
                problems.append(f"rank {comm.rank}: steps returned {steps}")
            if (c.rank, c.rank_count, c.local_count) != (comm.rank, comm.size, world.particle_count):
                problems.append(f"rank {comm.rank}: counts {c.rank}, {c.rank_count}, {c.local_count}")
            if not c.global_count == len(x0) == local_sum:
                problems.append(f"global count {c.global_count}, ranks' sum {local_sum}, added {len(x0)}")
            if c.rebalances < 1:  # the first frame always cuts
                problems.append(f"rebalances {c.rebalances}")
            if ranks_holding != comm.size:
                problems.append(f"{ranks_holding} of {comm.size} ranks hold particles")
            if comm.rank == 0:
                order = np.argsort(ref.ids())
                x, v = ref.positions()[order], ref.velocities()[order]
                moved = float(np.abs(x - x0).max())
                if moved < 0.5 * SPACING:
                    problems.append(f"the column moved {moved} m in {FRAMES} frames")
                if not np.array_equal(merged["ids"], np.arange(len(x0), dtype=np.uint32)):
                    problems.append("the gather's ids are not 0..n-1")
                else:
                    differ = int(np.count_nonzero(np.any(merged["positions"] != x, axis=1) |
                                                  np.any(merged["velocities"] != v, axis=1)))
                    if differ:
                        problems.append(f"{differ} of {len(x)} particles differ from the undivided world on "
                                        f"{comm.size} ranks")
                # Each rank's own particles, together, are the world's.
                ids = np.concatenate([i for i, _ in own])
                xs = np.concatenate([p for _, p in own])
                k = np.argsort(ids)
                if not (np.array_equal(ids[k], merged["ids"]) and np.array_equal(xs[k], merged["positions"])):
                    problems.append("the ranks' own particles are not the gathered ones")
            elif merged is not None:
                problems.append(f"rank {comm.rank} got a gather for root 0")
            if comm.rank == last and not (set(only) == {"positions"} and only["positions"].shape == (len(x0), 3)):
                problems.append(f"the gather onto rank {last}: {only}")
            problems = sum(comm.allgather(problems), [])
            assert not problems, problems
        finally:
            world.close()


def test_removed_ids_are_gathered_from_every_rank(ctx, comm):
    sink = ((-0.2, 0.0, -0.07), (-0.12, 0.05, 0.07))  # the column's lower left corner
    with ctx.world(capacity=4000, particle_spacing=SPACING) as ref:
        tank_scene(ctx, ref)
        ref.add_sink(bounds=sink)
        ref.fill_box((-0.2, 0.0, -0.06), (0.0, 0.14, 0.06))
        order = np.argsort(ref.ids())
        x0 = ref.positions()[order]
        world = sph.mpi.DistributedWorld(ctx, comm.py2f(), capacity=4000, particle_spacing=SPACING)
        try:
            tank_scene(ctx, world)
            world.add_sink(bounds=sink)
            world.add_particles(x0 if comm.rank == 0 else None)
            ref.step(1 / 50)
            world.step(1 / 50)
            gathered = world.gather_removed_ids(root=0)
            own = comm.gather(world.removed_ids(), root=0)
        finally:
            world.close()
        expected = np.sort(ref.removed_ids())
        if comm.rank == 0:
            assert expected.size > 0, "the sink removed particles"
            assert np.array_equal(gathered, expected)
            assert np.array_equal(np.sort(np.concatenate(own)), expected)  # each rank's own, once
        else:
            assert gathered is None


def test_bad_input_is_refused(ctx, comm):
    with pytest.raises(TypeError, match="mpi4py communicator"):
        sph.mpi.DistributedWorld(ctx, object())
    # Springs run distributed since wt-springrank (they were refused, naming the feature).
    sph.mpi.DistributedWorld(ctx, comm, features=sph.Feature.SPRINGS).close()
    world = sph.mpi.DistributedWorld(ctx, comm, rebalance_threshold_percent=50, particle_spacing=SPACING)
    try:
        with pytest.raises(ValueError, match="velocities"):
            world.add_particles(np.zeros((2, 3)), np.zeros((3, 3)))
        # The fills number ids on one rank: refused, pointing at add_particles.
        with pytest.raises(sph.SphError) as e:
            world.fill_box((0, 0, 0), (0.1, 0.1, 0.1))
        assert e.value.result == sph.Result.ERROR_UNSUPPORTED
        with pytest.raises(sph.SphError) as e:
            world.gather(root=comm.size)
        assert e.value.result == sph.Result.ERROR_INVALID_ARGUMENT
        assert world.global_count == 0
        empty = world.gather()
        if comm.rank == 0:
            assert empty["positions"].shape == (0, 3) and empty["ids"].shape == (0,)
    finally:
        world.close()


def test_a_checkpoint_continues_bit_for_bit(ctx, comm, tmp_path_factory):
    """Saved after 3 frames, 3 more frames from the live world, from the restored one and from a
    loaded one: the same bits (tests/mpi/test_mpi_checkpoint.c checks the failures too)."""
    base = comm.bcast(str(tmp_path_factory.mktemp("ck")) if comm.rank == 0 else None, root=0)
    path = base + "/dam.sphck"
    with ctx.world(capacity=4000, particle_spacing=SPACING) as ref:
        ref.fill_box((-0.2, 0.0, -0.06), (0.0, 0.14, 0.06))
        order = np.argsort(ref.ids())
        x0 = ref.positions()[order]
    world = sph.mpi.DistributedWorld(ctx, comm, capacity=4000, particle_spacing=SPACING)
    loaded = None
    try:
        tank_scene(ctx, world)
        world.add_particles(x0 if comm.rank == 0 else None)
        for _ in range(3):
            world.step(1 / 50)
        world.save_file(path)
        for _ in range(3):
            world.step(1 / 50)
        live = world.gather()
        world.restore_file(path)
        for _ in range(3):
            world.step(1 / 50)
        restored = world.gather()
        loaded = sph.mpi.DistributedWorld.load_file(ctx, comm, path)
        for _ in range(3):
            loaded.step(1 / 50)
        again = loaded.gather()
        problems = []
        if comm.rank == 0:
            for name, got in (("restored", restored), ("loaded", again)):
                if not (np.array_equal(got["positions"], live["positions"]) and
                        np.array_equal(got["velocities"], live["velocities"])):
                    problems.append(f"the {name} world differs from the live one on {comm.size} ranks")
        with pytest.raises(sph.SphError) as e:  # a missing manifest: every rank raises
            world.restore_file(base + "/missing.sphck")
        if e.value.result != sph.Result.ERROR_INVALID_ARGUMENT:
            problems.append(f"rank {comm.rank}: a missing manifest gave {e.value.result}")
        problems = sum(comm.allgather(problems), [])
        assert not problems, problems
    finally:
        if loaded is not None:
            loaded.close()
        world.close()


def test_an_undivided_world_is_not_a_distributed_one(ctx):
    with ctx.world(particle_spacing=SPACING) as plain:
        with pytest.raises(sph.SphError) as e:
            sph.mpi.DistributedWorld.counts(plain)
        assert e.value.result == sph.Result.ERROR_UNSUPPORTED


def test_a_world_dropped_without_close_is_leaked_not_destroyed(comm):
    """A DistributedWorld the garbage collector takes, at another time on each rank (rank 0 before
    another world's collective step, the others after it): no sph_world_destroy runs for it (it
    is collective, sph.mpi's docstring), a ResourceWarning says so, its context is then leaked
    rather than destroyed (which would destroy the world), and every rank goes on."""
    ctx = sph.Context("cpu", cpu_worker_count=1)
    dropped = sph.mpi.DistributedWorld(ctx, comm, capacity=100, particle_spacing=SPACING)
    kept = sph.mpi.DistributedWorld(ctx, comm, capacity=100, particle_spacing=SPACING)
    kept.add_particles(np.array([[0.0, 0.1, 0.0]], np.float32) if comm.rank == 0 else None)
    world_destroys = CALLS["sph_world_destroy"]
    context_destroys = CALLS["sph_context_destroy"]
    problems = []

    def resource_warnings(action):
        # Recorded rather than asserted with pytest.warns: a rank that failed here would leave the
        # others waiting in the next collective call.
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            action()
        return [str(w.message) for w in caught if issubclass(w.category, ResourceWarning)]

    def drop():
        nonlocal dropped
        dropped = None
        gc.collect()

    dropped_warnings = resource_warnings(drop) if comm.rank == 0 else []
    kept.step(1 / 50)  # COLLECTIVE, with the dropped world gone on rank 0 only
    if comm.rank != 0:
        dropped_warnings = resource_warnings(drop)
    count = kept.global_count
    kept.close()
    context_warnings = resource_warnings(ctx.close)
    if not any("without close" in w for w in dropped_warnings):
        problems.append(f"rank {comm.rank}: no ResourceWarning for the dropped world: {dropped_warnings}")
    if not any("leaked" in w for w in context_warnings):
        problems.append(f"rank {comm.rank}: no ResourceWarning for the leaked context: {context_warnings}")
    if count != 1:
        problems.append(f"rank {comm.rank}: the kept world holds {count} particles")
    if CALLS["sph_world_destroy"] != world_destroys + 1:  # the kept world's close() alone
        problems.append(f"rank {comm.rank}: {CALLS['sph_world_destroy'] - world_destroys} world destroys")
    if CALLS["sph_context_destroy"] != context_destroys:
        problems.append(f"rank {comm.rank}: the context holding a leaked world was destroyed")
    problems = sum(comm.allgather(problems), [])
    assert not problems, problems


def test_zz_every_sph_mpi_function_was_called():
    """Runs last (file order): every function of sph_mpi.h went through the package."""
    expected = {name for name, entry in g.FUNCTIONS.items() if entry[4] == "sph_mpi"}
    assert expected, "sph_mpi.h is in the generated bindings"
    missing = sorted(expected - set(CALLS))
    assert not missing, f"sph_mpi.h functions no test reached through sph.mpi: {missing}"
