// SPDX-License-Identifier: MIT
// SphMpiTests.cs - DistributedWorld (SphMpi.cs) on every rank of MPI_COMM_WORLD, against one
// undivided world of the same particles in the same process: docs/distributed.md promises the same
// bits (the CPU backend sums in the same order on any rank count while the neighbour grid covers
// the particles' extent, which the closed tank keeps), so positions and velocities are compared
// exactly. The C# side of tests/mpi/python/test_mpi_world.py.
//
//   mcs -define:SPH_MPI -target:library -out:Sph.dll Sph.Generated.cs Sph.cs SphMpi.cs
//   mcs -r:Sph.dll -out:SphMpiTests.exe tests/SphMpiTests.cs
//   LD_LIBRARY_PATH=<dir of libsph_mpi.so> mono SphMpiTests.exe <scratch dir>        (one rank)
//   LD_LIBRARY_PATH=... mpirun -np 2 mono SphMpiTests.exe <scratch dir>
//
// Run without mpirun, MPI_Init makes a one-rank world (a singleton). Every test runs on every
// rank in the same order, and makes its collective calls before it checks anything: a failing
// check on one rank then cannot leave the others waiting in a collective call.
using System;
using System.IO;
using System.Runtime.InteropServices;
using System.Text;
using Sph;

// What the tests need of MPI itself, straight from libmpi (no MPI binding for C# is assumed).
static class Mpi
{
    [DllImport("mpi")] static extern int MPI_Initialized(out int flag);
    [DllImport("mpi")] static extern int MPI_Init(IntPtr argc, IntPtr argv);
    [DllImport("mpi")] static extern int MPI_Finalize();
    [DllImport("mpi")] static extern int MPI_Get_library_version(byte[] version, out int length);

    public static void Init()
    {
        int initialized;
        MPI_Initialized(out initialized);
        if (initialized == 0 && MPI_Init(IntPtr.Zero, IntPtr.Zero) != 0) throw new Exception("MPI_Init failed");
    }

    public static void Shutdown() { MPI_Finalize(); }

    /// MPI_COMM_WORLD's Fortran handle (MPI_Comm_c2f(MPI_COMM_WORLD)), which the standard leaves
    /// to each implementation: 0 in Open MPI, 0x44000000 in MPICH and its derivatives (Intel MPI,
    /// MVAPICH, Cray MPICH), where the Fortran and C handles are the same integer.
    public static int CommWorld
    {
        get
        {
            var text = new byte[8192];  // MPI_MAX_LIBRARY_VERSION_STRING: 256 (Open MPI) to 8192 (MPICH)
            int length;
            MPI_Get_library_version(text, out length);
            return Encoding.ASCII.GetString(text, 0, length).Contains("Open MPI") ? 0 : 0x44000000;
        }
    }
}

static class MpiTests
{
    const float Spacing = 0.02f;
    const int Frames = 6;
    static string scratch = ".";

    static void Assert(bool condition, string what)
    {
        if (!condition) throw new Exception("assertion failed: " + what);
    }

    static SphException Throws(Result expected, Action action)
    {
        try
        {
            action();
        }
        catch (SphException e)
        {
            if (e.Result != expected) throw new Exception("expected " + expected + ", got " + e.Message);
            Assert(!string.IsNullOrEmpty(e.LibraryMessage), "the exception carries the library's message");
            return e;
        }
        throw new Exception("expected SphException(" + expected + "), nothing was thrown");
    }

    static Context Cpu()
    {
        var def = ContextDef.Default();
        def.Backend = Backend.Cpu;
        def.CpuWorkerCount = 1;
        return new Context(def);
    }

    static WorldDef Def(uint capacity = 4000)
    {
        var d = WorldDef.Default();
        d.Capacity = capacity;
        d.ParticleSpacing = Spacing;
        return d;
    }

    // A closed tank, the same on every rank (the scene is replicated).
    static void TankScene(Context ctx, World world)
    {
        var shape = ShapeDesc.Default();
        shape.Shape = Shape.Box;
        shape.HalfExtents = new Vec3(0.2f, 0.15f, 0.07f);
        shape.VoxelSize = 0.01f;
        using (var tank = Sdf.CreateShape(ctx, shape))
        {
            var at = Transform.Default();
            at.Position = new Vec3(0.0f, 0.15f, 0.0f);
            world.CreateCollider(tank, at, true);
        }
        var p = world.Params;
        p.Gravity = new Vec3(0.0f, -9.81f, 0.0f);
        p.Stiffness = 100.0f;
        p.Viscosity = 1.0f;
        p.DtMax = 0.002f;
        world.Params = p;
    }

    // The dam break's column in an undivided world, by id: positions, and velocities (0.1, 0, 0).
    static void Column(World reference, out Vec3[] positions, out Vec3[] velocities)
    {
        reference.FillBox(new Vec3(-0.2f, 0.0f, -0.06f), new Vec3(0.0f, 0.14f, 0.06f), new Vec3(0.1f, 0.0f, 0.0f));
        positions = ById(reference, SphAttribute.Position);
        velocities = ById(reference, SphAttribute.Velocity);
    }

    static Vec3[] ById(World world, SphAttribute attribute)
    {
        uint[] ids = world.Ids();
        var values = new Vec3[ids.Length];
        world.CopyAttribute(attribute, values);
        Array.Sort((uint[])ids.Clone(), values);
        return values;
    }

    static bool SameBits(Vec3[] a, Vec3[] b)
    {
        if (a == null || b == null || a.Length != b.Length) return false;
        for (int i = 0; i < a.Length; ++i)
            if (a[i].X != b[i].X || a[i].Y != b[i].Y || a[i].Z != b[i].Z) return false;
        return true;
    }

    // ---- the tests ----------------------------------------------------------------------------

    public static void TestTheBindingsCallLibsphMpi()
    {
        Assert(DistributedWorld.Available, "compiled with -define:SPH_MPI");
        Assert(Native.Library == "sph_mpi", "Native.Library is libsph_mpi: " + Native.Library);
    }

    public static void TestADamBreakEqualsTheUndividedWorld()
    {
        using (var ctx = Cpu())
        using (var reference = ctx.CreateWorld(Def()))
        {
            TankScene(ctx, reference);
            Vec3[] x0, v0;
            Column(reference, out x0, out v0);
            MpiCounts c;
            DistributedWorld.Gathered merged, onLast;
            uint first;
            int rank;
            using (var world = new DistributedWorld(ctx, Mpi.CommWorld, Def()))
            {
                TankScene(ctx, world);
                rank = world.Counts().Rank;
                first = world.AddParticles(rank == 0 ? x0 : null, rank == 0 ? v0 : null);  // ids as the reference's
                for (int f = 0; f < Frames; ++f)
                {
                    AssertOk(reference.Step(1f / 50f), "the reference's step");
                    AssertOk(world.Step(1f / 50f), "the distributed step");
                }
                c = world.Counts();
                merged = world.Gather();
                onLast = world.Gather(c.RankCount - 1, true, false, false);
                Assert(c.LocalCount == world.ParticleCount, "LocalCount is this rank's ParticleCount");
            }
            Assert(first == (rank == 0 ? 0u : (uint)x0.Length), "rank " + rank + ": first id " + first);
            Assert(c.GlobalCount == (ulong)x0.Length, "global count " + c.GlobalCount + " of " + x0.Length);
            Assert(c.Rebalances >= 1, "the first frame cuts the slabs");
            if (rank == c.RankCount - 1)
                Assert(onLast.Positions.Length == x0.Length && onLast.Velocities == null && onLast.Ids == null,
                       "the gather onto the last rank holds positions alone");
            if (rank != 0)
            {
                Assert(merged == null, "a gather for rank 0 gives nothing elsewhere");
                return;
            }
            Vec3[] x = ById(reference, SphAttribute.Position), v = ById(reference, SphAttribute.Velocity);
            float moved = 0;
            for (int i = 0; i < x.Length; ++i) moved = Math.Max(moved, Math.Abs(x[i].X - x0[i].X));
            Assert(moved > 0.5f * Spacing, "the column moved (" + moved + " m)");
            for (int i = 0; i < merged.Ids.Length; ++i) Assert(merged.Ids[i] == i, "the gather's ids are 0..n-1");
            Assert(SameBits(merged.Positions, x) && SameBits(merged.Velocities, v),
                   "the same bits as the undivided world on " + c.RankCount + " rank(s)");
        }
    }

    static void AssertOk(Result r, string what) { Assert(r == Result.Ok, what + ": " + r); }

    public static void TestRemovedIdsAreGatheredFromEveryRank()
    {
        var sink = SinkDef.Default();
        sink.Mode = SinkMode.OutsideBounds;
        sink.BoundsMin = new Vec3(-0.2f, 0.0f, -0.07f);  // the column's lower left corner
        sink.BoundsMax = new Vec3(-0.12f, 0.05f, 0.07f);
        using (var ctx = Cpu())
        using (var reference = ctx.CreateWorld(Def()))
        {
            TankScene(ctx, reference);
            reference.CreateSink(null, sink);
            Vec3[] x0, v0;
            Column(reference, out x0, out v0);
            uint[] gathered;
            int rank;
            using (var world = new DistributedWorld(ctx, Mpi.CommWorld, Def()))
            {
                TankScene(ctx, world);
                world.CreateSink(null, sink);
                rank = world.Counts().Rank;
                world.AddParticles(rank == 0 ? x0 : null, rank == 0 ? v0 : null);
                reference.Step(1f / 50f);
                world.Step(1f / 50f);
                gathered = world.GatherRemovedIds();
            }
            uint[] expected = reference.GetRemovedIds();
            Array.Sort(expected);
            if (rank != 0)
            {
                Assert(gathered == null, "nothing gathered away from root");
                return;
            }
            Assert(expected.Length > 0, "the sink removed particles");
            Assert(gathered.Length == expected.Length, "removed " + gathered.Length + ", expected " + expected.Length);
            for (int i = 0; i < expected.Length; ++i) Assert(gathered[i] == expected[i], "the removed ids, ascending");
        }
    }

    public static void TestBadInputIsRefused()
    {
        using (var ctx = Cpu())
        {
            // Springs run distributed on CPU ranks (they were refused, naming the feature).
            var springs = Def(100);
            springs.Features = (uint)FeatureFlags.Springs;
            using (var springy = new DistributedWorld(ctx, Mpi.CommWorld, springs))
            {
            }
            var options = MpiWorldDef.Default();
            options.RebalanceThresholdPercent = 50;
            using (var world = new DistributedWorld(ctx, Mpi.CommWorld, Def(100), options))
            {
                int ranks = world.Counts().RankCount;
                try
                {
                    world.AddParticles(new float[6], new float[9]);
                    throw new Exception("mismatched velocities were taken");
                }
                catch (ArgumentException)
                {
                }
                // The fills number ids on one rank, and one rank's checkpoint is not the world.
                Throws(Result.ErrorUnsupported, () => world.FillBox(new Vec3(0, 0, 0), new Vec3(0.04f, 0.04f, 0.04f)));
                Throws(Result.ErrorUnsupported, () => ((World)world).Save());
                Throws(Result.ErrorUnsupported, () => world.StepBegin(1f / 50f));
                Throws(Result.ErrorInvalidArgument, () => world.Gather(ranks));
                ulong count = world.GlobalCount;
                DistributedWorld.Gathered empty = world.Gather();
                Assert(count == 0, "an empty world");
                Assert(empty == null || (empty.Positions.Length == 0 && empty.Ids.Length == 0), "an empty gather");
            }
        }
    }

    public static void TestAPlainWorldIsNotADistributedOne()
    {
        using (var ctx = Cpu())
        using (var plain = ctx.CreateWorld(Def(100)))
        {
            var c = MpiCounts.Default();
            Throws(Result.ErrorUnsupported, () => SphException.Check(Native.sph_mpi_world_get_counts(plain.Handle, ref c),
                                                                     "sph_mpi_world_get_counts"));
        }
    }

    /// Saved after 3 frames, 3 more frames from the live world, from the restored one and from a
    /// loaded one: the same bits (tests/mpi/test_mpi_checkpoint.c checks the failures).
    public static void TestACheckpointContinuesBitForBit()
    {
        string path = Path.Combine(scratch, "mpi_dam.sphck");  // the same on every rank
        using (var ctx = Cpu())
        using (var reference = ctx.CreateWorld(Def()))
        {
            Vec3[] x0, v0;
            Column(reference, out x0, out v0);
            DistributedWorld.Gathered live, restored, loaded;
            SphException missing = null;
            int rank;
            using (var world = new DistributedWorld(ctx, Mpi.CommWorld, Def()))
            {
                TankScene(ctx, world);
                rank = world.Counts().Rank;
                world.AddParticles(rank == 0 ? x0 : null, rank == 0 ? v0 : null);
                for (int f = 0; f < 3; ++f) world.Step(1f / 50f);
                world.SaveFile(path);
                for (int f = 0; f < 3; ++f) world.Step(1f / 50f);
                live = world.Gather();
                world.RestoreFile(path);
                for (int f = 0; f < 3; ++f) world.Step(1f / 50f);
                restored = world.Gather();
                using (var again = DistributedWorld.LoadFile(ctx, Mpi.CommWorld, path))
                {
                    for (int f = 0; f < 3; ++f) again.Step(1f / 50f);
                    loaded = again.Gather();
                }
                try
                {
                    world.RestoreFile(Path.Combine(scratch, "missing.sphck"));  // every rank throws
                }
                catch (SphException e)
                {
                    missing = e;
                }
            }
            Assert(missing != null && missing.Result == Result.ErrorInvalidArgument,
                   "a missing manifest: " + (missing != null ? missing.Message : "nothing thrown"));
            if (rank != 0) return;
            Assert(SameBits(restored.Positions, live.Positions) && SameBits(restored.Velocities, live.Velocities),
                   "the restored world continues as the live one");
            Assert(SameBits(loaded.Positions, live.Positions) && SameBits(loaded.Velocities, live.Velocities),
                   "the loaded world continues as the live one");
        }
    }

    // ---- runner: a fixed order, the same on every rank ------------------------------------------

    static int Main(string[] args)
    {
        if (args.Length > 0) scratch = args[0];
        Mpi.Init();
        var tests = new Action[] {
            TestTheBindingsCallLibsphMpi, TestADamBreakEqualsTheUndividedWorld, TestRemovedIdsAreGatheredFromEveryRank,
            TestBadInputIsRefused, TestAPlainWorldIsNotADistributedOne, TestACheckpointContinuesBitForBit,
        };
        int passed = 0, failed = 0;
        foreach (Action test in tests)
        {
            try
            {
                test();
                ++passed;
                Console.WriteLine("PASS " + test.Method.Name);
            }
            catch (Exception e)
            {
                ++failed;
                Console.WriteLine("FAIL " + test.Method.Name + ": " + e);
            }
        }
        Console.WriteLine(passed + " passed, " + failed + " failed");
        Mpi.Shutdown();  // MPI_Finalize, after every world was disposed (their destroy is collective)
        // An empty list of tests is a failure, not an empty pass.
        if (passed + failed == 0) Console.WriteLine("FAIL no test ran");
        return failed == 0 && passed > 0 ? 0 : 1;
    }
}
