// SPDX-License-Identifier: MIT
// SphMpi.cs - distributed worlds (include/sph_mpi.h): one world spread over the ranks of an MPI
// communicator (docs/distributed.md), the C# side of bindings/python/sph/mpi.py.
//
// libsph_mpi holds the whole of sph_c.h as well and is loaded instead of libsph, never beside it:
// each library keeps its own registry of contexts and worlds, so a context made by one is not a
// live handle to the other. Compile the bindings with -define:SPH_MPI and every [DllImport] of
// Native names libsph_mpi (Native.Library == Native.LibrarySphMpi); without it DistributedWorld
// refuses to start. The communicator crosses as its Fortran handle (an MPI_Fint: MPI_Comm_c2f,
// or MPI.NET's / your binding's equivalent); MPI must be initialised before the first world and
// finalised after the last one is disposed. README.md shows how without any MPI binding.
using System;
using System.Runtime.InteropServices;

namespace Sph
{
    /// <summary>This rank's part of a world spread over an MPI communicator's ranks
    /// (sph_mpi_world_create). Members marked COLLECTIVE must be called by every rank, in the
    /// same order, with the same scalar arguments; Dispose is one of them (it frees the
    /// world's communicator): dispose every rank's world, before MPI_Finalize. A world dropped
    /// without Dispose is never destroyed by the finaliser, whose timing differs between ranks
    /// (a collective destroy from it could wait for ranks that never come): it is leaked, with
    /// a warning on stderr, and so is its context. The rest of World's members work per rank:
    /// ParticleCount, Positions(), Ids() and CopyAttribute read this rank's own particles;
    /// colliders, sinks and force fields are replicated (make the same calls on every rank).
    /// Spawn, the fills, StepBegin and World's checkpoint calls answer ErrorUnsupported.</summary>
    public sealed class DistributedWorld : World
    {
        // Not a constant: a constant comparison would make the refusal below unreachable code
        // (a warning, an error under -warnaserror) in one of the two builds.
        static readonly bool boundToSphMpi = Native.Library == Native.LibrarySphMpi;

        /// <summary>True when these bindings were compiled with SPH_MPI, so that every call goes
        /// to libsph_mpi (the library distributed worlds need).</summary>
        public static bool Available { get { return boundToSphMpi; } }

        /// <summary>The communicator's Fortran handle the world was created over.</summary>
        public int Comm { get; private set; }

        /// <summary>COLLECTIVE. Creates this rank's part (sph_mpi_world_create). `def` as
        /// World's, the same on every rank; `context` must be a CPU context.</summary>
        public DistributedWorld(Context context, int comm, WorldDef def)
            : base(context, Create(context, comm, def, null))
        {
            Comm = comm;
        }

        /// <summary>COLLECTIVE. As above, with the distributed world's own options
        /// (MpiWorldDef.RebalanceThresholdPercent, 1-10000; 0 = 20).</summary>
        public DistributedWorld(Context context, int comm, WorldDef def, MpiWorldDef mpiDef)
            : base(context, Create(context, comm, def, mpiDef))
        {
            Comm = comm;
        }

        DistributedWorld(Context context, int comm, WorldHandle handle) : base(context, handle)
        {
            Comm = comm;
        }

        static void RequireSphMpi()
        {
            if (!boundToSphMpi)
                throw new SphException(Result.ErrorUnsupported, "DistributedWorld",
                    "distributed worlds need the bindings compiled with -define:SPH_MPI, so that every call goes " +
                    "to libsph_mpi (built where CMake finds MPI: SPH_WITH_MPI) instead of libsph");
        }

        // The handle is never finalised: its destroy is collective (the class's summary).
        static WorldHandle Adopt(WorldHandle handle)
        {
            GC.SuppressFinalize(handle);
            return handle;
        }

        static WorldHandle Create(Context context, int comm, WorldDef def, MpiWorldDef? options)
        {
            RequireSphMpi();  // before any call: MpiWorldDef.Default() is one of libsph_mpi's
            ContextHandle contextHandle = Context.HandleOf(context, "context");
            MpiWorldDef mpiDef = options ?? MpiWorldDef.Default();
            WorldHandle handle;
            SphException.Check(Native.sph_mpi_world_create(contextHandle, ref def, comm, ref mpiDef, out handle),
                               "sph_mpi_world_create");
            return Adopt(handle);
        }

        /// <summary>COLLECTIVE. A new distributed world over `comm` from the save at `path`,
        /// saved on any rank count (sph_mpi_world_load_file). On an error on any rank, every
        /// rank throws and none has a world.</summary>
        public static DistributedWorld LoadFile(Context context, int comm, string path)
        {
            RequireSphMpi();
            ContextHandle contextHandle = Context.HandleOf(context, "context");
            if (path == null) throw new ArgumentNullException("path");
            WorldHandle handle;
            SphException.Check(Native.sph_mpi_world_load_file(contextHandle, comm, Utf8.ToNative(path), out handle),
                               "sph_mpi_world_load_file");
            return new DistributedWorld(context, comm, Adopt(handle));
        }

        ~DistributedWorld()
        {
            if (!IsDisposed && Handle != null)  // (no Handle: the constructor threw, nothing was made)
                Console.Error.WriteLine("sph: a DistributedWorld was dropped without Dispose(): leaked (its destroy is " +
                                        "collective, so the finaliser does not run it); Dispose it on every rank");
        }

        /// <summary>COLLECTIVE. Adds this rank's particles (xyz triples; null or empty adds none
        /// here) (sph_mpi_world_add_particles). Ids are numbered across the ranks in rank order;
        /// each particle moves to the rank of its slab in the next step. All-or-nothing over
        /// the ranks. Returns this rank's first id.</summary>
        public uint AddParticles(float[] positions, float[] velocities = null)
        {
            positions = positions ?? new float[0];
            if (positions.Length % 3 != 0) throw new ArgumentException("positions: a multiple of 3 floats");
            if (velocities != null && velocities.Length != positions.Length)
                throw new ArgumentException("velocities: one triple per position");
            uint first;
            SphException.Check(Native.sph_mpi_world_add_particles(Handle, positions, velocities, (uint)(positions.Length / 3),
                                                                  out first), "sph_mpi_world_add_particles");
            return first;
        }

        /// <summary>COLLECTIVE. As AddParticles(float[], float[]) from Vec3 arrays.</summary>
        public uint AddParticles(Vec3[] positions, Vec3[] velocities = null)
        {
            return AddParticles(Flatten(positions), Flatten(velocities));
        }

        static float[] Flatten(Vec3[] v)
        {
            if (v == null) return null;
            var f = new float[3 * v.Length];
            for (int i = 0; i < v.Length; ++i)
            {
                f[3 * i] = v[i].X;
                f[3 * i + 1] = v[i].Y;
                f[3 * i + 2] = v[i].Z;
            }
            return f;
        }

        /// <summary>COLLECTIVE. Advances every rank's part by frameDt (sph_mpi_world_step; World.Step
        /// is the same call). Returns Ok or Incomplete; throws SphException on every rank when a
        /// step fails on any (each rolled back).</summary>
        public new Result Step(float frameDt)
        {
            return SphException.Check(Native.sph_mpi_world_step(Handle, frameDt), "sph_mpi_world_step");
        }

        /// <summary>COLLECTIVE. This rank's and the world's counts (sph_mpi_world_get_counts):
        /// rank, rank count, local and global particles, ghosts, migrations, rebalances, and
        /// this rank's slab.</summary>
        public MpiCounts Counts()
        {
            var c = MpiCounts.Default();
            SphException.Check(Native.sph_mpi_world_get_counts(Handle, ref c), "sph_mpi_world_get_counts");
            return c;
        }

        /// <summary>COLLECTIVE. Particles of the whole world.</summary>
        public ulong GlobalCount { get { return Counts().GlobalCount; } }

        /// <summary>Every rank's particles on the gathering rank, ordered by id; a member is null
        /// when it was not asked for.</summary>
        public sealed class Gathered
        {
            public Vec3[] Positions;
            public Vec3[] Velocities;
            public uint[] Ids;
        }

        /// <summary>COLLECTIVE. Every rank's particles on `root`, ordered by id
        /// (sph_mpi_world_gather). On root: a Gathered with the arrays asked for. Elsewhere:
        /// null.</summary>
        public Gathered Gather(int root = 0, bool positions = true, bool velocities = true, bool ids = true)
        {
            MpiCounts c = Counts();
            bool isRoot = c.Rank == root;
            ulong n = isRoot ? c.GlobalCount : 0;
            var result = new Gathered();
            if (isRoot)
            {
                if (positions) result.Positions = new Vec3[n];
                if (velocities) result.Velocities = new Vec3[n];
                if (ids) result.Ids = new uint[n];
            }
            var pins = new GCHandle[4];
            var count = new ulong[1];
            try
            {
                pins[0] = Pin(result.Positions);
                pins[1] = Pin(result.Velocities);
                pins[2] = Pin(result.Ids);
                pins[3] = Pin(count);
                using (var world = new Borrowed(Handle))
                {
                    SphException.Check(Native.sph_mpi_world_gather(world.Pointer, root, Address(pins[0]), Address(pins[1]),
                                                                   Address(pins[2]), n, Address(pins[3])),
                                       "sph_mpi_world_gather");
                }
            }
            finally
            {
                foreach (GCHandle pin in pins)
                    if (pin.IsAllocated) pin.Free();
            }
            return isRoot ? result : null;
        }

        static GCHandle Pin(Array a)
        {
            return a != null ? GCHandle.Alloc(a, GCHandleType.Pinned) : default(GCHandle);
        }

        static IntPtr Address(GCHandle pin)
        {
            return pin.IsAllocated ? pin.AddrOfPinnedObject() : IntPtr.Zero;
        }

        /// <summary>COLLECTIVE. The ids every rank's sinks removed in the last step, on `root`,
        /// ascending (sph_mpi_world_gather_removed_ids); null elsewhere (GetRemovedIds() is this
        /// rank's own). Two collective calls on every rank: the first learns the count on root,
        /// the second fills an array of that size.</summary>
        public uint[] GatherRemovedIds(int root = 0)
        {
            bool isRoot = Counts().Rank == root;
            uint n;
            SphException.Check(Native.sph_mpi_world_gather_removed_ids(Handle, root, null, 0, out n),
                               "sph_mpi_world_gather_removed_ids");
            uint[] ids = isRoot && n > 0 ? new uint[n] : null;
            SphException.Check(Native.sph_mpi_world_gather_removed_ids(Handle, root, ids, ids != null ? n : 0, out n),
                               "sph_mpi_world_gather_removed_ids");
            return isRoot ? ids ?? new uint[0] : null;
        }

        /// <summary>COLLECTIVE. Saves the world at `path` (the same on every rank): each rank's
        /// checkpoint at path + ".rank(r).(its hash)", then rank 0's manifest at path, which
        /// replaces the set (sph_mpi_world_save_file). Succeeds or throws on every rank.</summary>
        public new void SaveFile(string path)
        {
            if (path == null) throw new ArgumentNullException("path");
            SphException.Check(Native.sph_mpi_world_save_file(Handle, Utf8.ToNative(path)), "sph_mpi_world_save_file");
        }

        /// <summary>COLLECTIVE. Replaces the world's state with the one saved at `path`, saved
        /// on any rank count (sph_mpi_world_restore_file); on an error on any rank, every rank
        /// throws and keeps its state.</summary>
        public void RestoreFile(string path)
        {
            if (path == null) throw new ArgumentNullException("path");
            SphException.Check(Native.sph_mpi_world_restore_file(Handle, Utf8.ToNative(path)), "sph_mpi_world_restore_file");
        }
    }
}
