// SPDX-License-Identifier: MIT
// Sph.cs - the idiomatic C# layer over Sph.Generated.cs: Context, World, SphException, TaskSystem.
//
// Unity-friendly: no unsafe code, blittable structs, Cdecl, SafeHandles for the heavy objects,
// bulk data through pinned arrays or raw pointers (NativeArray) with a stride, never one call
// per particle. The log callback and the task system's enqueue and finish (TaskSystem) are
// static [MonoPInvokeCallback] methods (IL2CPP needs that).
using System;
using System.Collections.Generic;
using System.Runtime.InteropServices;
using System.Text;
using System.Text.RegularExpressions;
using System.Threading;

#if !UNITY_5_3_OR_NEWER
namespace AOT
{
    /// <summary>Unity's IL2CPP marker for static methods called from native code (defined
    /// here outside Unity so the same source compiles with mono/.NET).</summary>
    [AttributeUsage(AttributeTargets.Method)]
    public sealed class MonoPInvokeCallbackAttribute : Attribute
    {
        public MonoPInvokeCallbackAttribute(Type type) { Type = type; }
        public Type Type { get; private set; }
    }
}
#endif

namespace Sph
{
    /// <summary>A failed sph_ call: <see cref="Result"/> is the sph_result code and
    /// <see cref="LibraryMessage"/> the library's sph_get_last_error() text.</summary>
    public class SphException : Exception
    {
        public Result Result { get; private set; }
        public string Function { get; private set; }
        public string LibraryMessage { get; private set; }

        public SphException(Result result, string function, string message)
            : base(Format(result, function, message))
        {
            Result = result;
            Function = function;
            LibraryMessage = message;
        }

        // "function: Result: detail". The library's message already starts with the function's
        // name ("sph_world_step: frame_dt: must be > 0"): that prefix is not repeated.
        static string Format(Result result, string function, string message)
        {
            string name = Enum.IsDefined(typeof(Result), result) ? result.ToString() : "sph_result " + (int)result;
            string detail = message;
            if (function != null && !string.IsNullOrEmpty(detail) && detail.StartsWith(function + ":", StringComparison.Ordinal))
                detail = detail.Substring(function.Length + 1).TrimStart();
            return (function != null ? function + ": " : "") + name + (string.IsNullOrEmpty(detail) ? "" : ": " + detail);
        }

        /// <summary>Throws for a negative result (reading the thread's last error at once);
        /// returns Ok or Incomplete.</summary>
        public static Result Check(Result result, string function)
        {
            if ((int)result < 0) throw new SphException(result, function, Library.LastError);
            return result;
        }
    }

    /// <summary>Library-wide queries, and the check that the loaded library matches these bindings.</summary>
    public static class Library
    {
        static bool verified;
        static readonly object verifyLock = new object();

        /// <summary>The loaded library's packed version (SPH_MAKE_VERSION).</summary>
        public static uint Version { get { return Native.sph_get_version(); } }
        public static uint AbiVersion { get { return Native.sph_get_abi_version(); } }
        public static string BuildInfo { get { return Utf8.FromNative(Native.sph_get_build_info()); } }
        /// <summary>The message of the last failed sph_ call on this thread ("" after a success).</summary>
        public static string LastError { get { return Utf8.FromNative(Native.sph_get_last_error()); } }

        public static string ResultString(Result result) { return Utf8.FromNative(Native.sph_result_string(result)); }

        public static uint MakeVersion(uint major, uint minor, uint patch) { return (major << 22) | (minor << 12) | patch; }

        public static string VersionString(uint packed)
        {
            return (packed >> 22) + "." + ((packed >> 12) & 0x3FF) + "." + (packed & 0xFFF);
        }

        /// <summary>Contexts and worlds alive in the process (a leak check for long-lived hosts).</summary>
        public static uint LiveObjectCount
        {
            get
            {
                uint n;
                SphException.Check(Native.sph_get_live_object_count(out n), "sph_get_live_object_count");
                return n;
            }
        }

        /// <summary>Describes the params struct of <paramref name="kind"/> (sph_params_get_info):
        /// its scene-file name, C type name, size and number of described fields.</summary>
        public static ParamsInfo ParamsInfo(ParamsKind kind)
        {
            var info = Sph.ParamsInfo.Default();
            SphException.Check(Native.sph_params_get_info(kind, ref info), "sph_params_get_info");
            return info;
        }

        /// <summary>Every described field of the params struct of <paramref name="kind"/>, in
        /// struct order (sph_params_get_field_info): name, offset, type, range, default, unit and
        /// what a zero in it means.</summary>
        public static ParamFieldInfo[] ParamFields(ParamsKind kind)
        {
            var fields = new ParamFieldInfo[ParamsInfo(kind).FieldCount];
            for (uint i = 0; i < fields.Length; ++i)
            {
                fields[i] = ParamFieldInfo.Default();
                SphException.Check(Native.sph_params_get_field_info(kind, i, ref fields[i]), "sph_params_get_field_info");
            }
            return fields;
        }

        /// <summary>Every physics method of the library (sph_get_physics_method_info): its name,
        /// the WorldDef field that turns it on, and where its parameters are.</summary>
        public static PhysicsMethodInfo[] PhysicsMethods()
        {
            var first = PhysicsMethodInfo.Default();
            SphException.Check(Native.sph_get_physics_method_info(0, ref first), "sph_get_physics_method_info");
            var methods = new PhysicsMethodInfo[first.MethodCount];
            methods[0] = first;
            for (uint i = 1; i < methods.Length; ++i)
            {
                methods[i] = PhysicsMethodInfo.Default();
                SphException.Check(Native.sph_get_physics_method_info(i, ref methods[i]), "sph_get_physics_method_info");
            }
            return methods;
        }

        /// <summary>Every struct whose Marshal.SizeOf or field offset differs from what the C
        /// compiler measured when the bindings were generated (empty when all match).</summary>
        public static List<string> LayoutProblems()
        {
            var problems = new List<string>();
            if (IntPtr.Size != Layout.PointerSize)
                problems.Add("bindings generated for " + (Layout.PointerSize * 8) + "-bit pointers, process is " + (IntPtr.Size * 8) + "-bit");
            for (int i = 0; i < Layout.StructTypes.Length; ++i)
            {
                int size = Marshal.SizeOf(Layout.StructTypes[i]);
                if (size != Layout.StructSizes[i])
                    problems.Add(Layout.StructNames[i] + ": Marshal.SizeOf " + size + " != C sizeof " + Layout.StructSizes[i]);
            }
            for (int i = 0; i < Layout.FieldNames.Length; ++i)
            {
                int offset = Marshal.OffsetOf(Layout.FieldStructs[i], Layout.FieldNames[i]).ToInt32();
                if (offset != Layout.FieldOffsets[i])
                    problems.Add(Layout.FieldStructs[i].Name + "." + Layout.FieldNames[i] + ": offset " + offset + " != C offsetof " + Layout.FieldOffsets[i]);
            }
            return problems;
        }

        /// <summary>Checks once per process that the library's ABI version is the one the
        /// bindings were generated for and that every struct layout matches; throws
        /// SphException(ErrorVersionMismatch) otherwise. Context's constructor calls it.</summary>
        public static void EnsureCompatible()
        {
            if (verified) return;
            lock (verifyLock)
            {
                if (verified) return;
                uint abi = AbiVersion;
                if (abi != Layout.AbiVersion)
                    throw new SphException(Result.ErrorVersionMismatch, "Library.EnsureCompatible",
                        "the sph library has ABI " + abi + " but these bindings were generated for ABI " + Layout.AbiVersion +
                        " (sph " + VersionString(Layout.Version) + ")");
                var problems = LayoutProblems();
                if (problems.Count > 0)
                    throw new SphException(Result.ErrorVersionMismatch, "Library.EnsureCompatible",
                        "struct layouts differ from the C library's: " + string.Join("; ", problems.ToArray()));
                verified = true;
            }
        }

        static readonly Regex formatPattern = new Regex(@"^\s*(?:(\d+)\s*x\s*)?(float32|uint32|int32)\b");

        /// <summary>Components and bytes per component of an attribute, read from its doc in the
        /// header ("3 x float32, metres"), so attributes added later need no code here.</summary>
        public static void AttributeFormat(SphAttribute attribute, out int components, out int componentBytes)
        {
            string type;
            if (!TryAttributeFormat(attribute, out components, out type))
                throw new ArgumentException("attribute " + attribute + ": no documented element format");
            componentBytes = 4;
        }

        // The attribute's components and their type ("float32", "uint32", "int32"); false for an
        // attribute with no documented format (one these bindings do not know).
        internal static bool TryAttributeFormat(SphAttribute attribute, out int components, out string componentType)
        {
            KeyValuePair<int, string> format;
            lock (attributeFormats)
            {
                if (!attributeFormats.TryGetValue(attribute, out format))
                {
                    int n;
                    string type;
                    ParseAttributeFormat(attribute, out n, out type);
                    format = new KeyValuePair<int, string>(n, type);
                    attributeFormats.Add(attribute, format);
                }
            }
            components = format.Key;
            componentType = format.Value;
            return componentType != null;
        }

        static readonly Dictionary<SphAttribute, KeyValuePair<int, string>> attributeFormats =
            new Dictionary<SphAttribute, KeyValuePair<int, string>>();

        static void ParseAttributeFormat(SphAttribute attribute, out int components, out string componentType)
        {
            string key = null;
            foreach (var pair in Layout.EnumMemberDocs)
                if (pair.Key.StartsWith("SPH_ATTRIBUTE_") && pair.Key.Replace("_", "").Equals("SPHATTRIBUTE" + attribute.ToString(), StringComparison.OrdinalIgnoreCase))
                    key = pair.Key;
            Match m = key == null ? Match.Empty : formatPattern.Match(Layout.EnumMemberDocs[key]);
            components = m.Success && m.Groups[1].Success ? int.Parse(m.Groups[1].Value) : 1;
            componentType = m.Success ? m.Groups[2].Value : null;
        }
    }

    /// <summary>UTF-8 strings across the boundary (Marshal.PtrToStringUTF8 is not everywhere).</summary>
    public static class Utf8
    {
        public static string FromNative(IntPtr p)
        {
            if (p == IntPtr.Zero) return null;
            int n = 0;
            while (Marshal.ReadByte(p, n) != 0) ++n;
            var bytes = new byte[n];
            Marshal.Copy(p, bytes, 0, n);
            return Encoding.UTF8.GetString(bytes);
        }

        /// <summary>A NUL-terminated UTF-8 copy, for const char* parameters.</summary>
        public static byte[] ToNative(string s)
        {
            if (s == null) throw new ArgumentNullException("s");
            var bytes = Encoding.UTF8.GetBytes(s);
            Array.Resize(ref bytes, bytes.Length + 1);
            return bytes;
        }
    }

    /// <summary>World feature bits (SPH_FEATURE_*), fixed at world creation: set them with
    /// <see cref="WorldDef.FeatureFlags"/>. A feature that is off allocates nothing and costs no
    /// work; the parameters of a feature that is off throw <c>Result.ErrorFeatureDisabled</c>.</summary>
    [Flags]
    public enum FeatureFlags : uint
    {
        None = Constants.SPH_FEATURE_NONE,
        /// <summary>Surface tension: the Morris colour field (thesis eq. 20-23) applied as a
        /// capillary stress, plus a short-range cohesion (Akinci et al. 2013) carrying 15 % of
        /// sigma, calibrated so that sigma is the physical N/m (Laplace pressures within 6 %, the
        /// mode-2 Rayleigh period within 5 % at 10 particles per radius; needs about 6 or more),
        /// parameters in <see cref="World.SurfaceTensionParams"/> (docs/physics.md).</summary>
        SurfaceTension = Constants.SPH_FEATURE_SURFACE_TENSION,
        /// <summary>Normalised density (thesis eq. 31): every particle carries a density factor
        /// (4 B of state, sorted, rolled back and checkpointed) so that particles at a free surface
        /// or a collider wall read the bulk's density instead of up to half of it; eq. 31
        /// re-normalises the carried densities on every density pass (one more gather).</summary>
        NormalizedDensity = Constants.SPH_FEATURE_NORMALIZED_DENSITY,
        /// <summary>Elasticity and plasticity: springs between neighbours made at each particle's
        /// first substep (Clavet et al. 2005), parameters in <see cref="World.SpringParams"/>.</summary>
        Springs = Constants.SPH_FEATURE_SPRINGS,
        /// <summary>Walls in the density: colliders count in the density sums and push back through
        /// the pressure force (a density map per SDF asset; docs/physics.md).</summary>
        BoundaryDensity = Constants.SPH_FEATURE_BOUNDARY_DENSITY,
        /// <summary>Loads on colliders: the fluid's force and torque on each collider over every
        /// step (<see cref="Collider.Loads"/>; docs/physics.md).</summary>
        ColliderLoads = Constants.SPH_FEATURE_COLLIDER_LOADS,
        /// <summary>A user attribute: one uint per particle the caller sets (a colour, a phase id),
        /// carried through sorts, sinks and checkpoints (<see cref="World.SetAttribute"/>,
        /// <see cref="SphAttribute.User"/>).</summary>
        UserAttribute = Constants.SPH_FEATURE_USER_ATTRIBUTE,
        /// <summary>Density diffusion (delta-SPH with the Fourtakas correction) on the carried
        /// density; needs <see cref="NormalizedDensity"/> (docs/physics.md).</summary>
        DensityDiffusion = Constants.SPH_FEATURE_DENSITY_DIFFUSION,
    }

    /// <summary>Step-size limits beyond eq. 32 (SPH_STEP_LIMIT_*): set them with
    /// <see cref="WorldParams.StepLimitFlags"/>.</summary>
    [Flags]
    public enum StepLimitFlags : uint
    {
        /// <summary>eq. 32 alone (dt = step_factor h / v_max, within [dt_min, dt_max]).</summary>
        None = 0,
        /// <summary>dt &lt;= step_factor h / c, c the equation of state's speed of sound.</summary>
        Acoustic = Constants.SPH_STEP_LIMIT_ACOUSTIC,
        /// <summary>dt &lt;= step_factor sqrt(h / |a|_max).</summary>
        Force = Constants.SPH_STEP_LIMIT_FORCE,
    }

    /// <summary>DFSPH option bits (SPH_DFSPH_* flags): set them with
    /// <see cref="Sph.DfsphParams.DfsphFlags"/>.</summary>
    [Flags]
    public enum DfsphFlags : uint
    {
        None = 0,
        /// <summary>No divergence solve (cheaper; a noisier pressure).</summary>
        SkipDivergenceSolve = Constants.SPH_DFSPH_SKIP_DIVERGENCE_SOLVE,
        /// <summary>The Jacobi solves' pressure gradient corrected to first order (Jacobi only).</summary>
        CorrectedGradient = Constants.SPH_DFSPH_CORRECTED_GRADIENT,
        /// <summary>The depth step limit (<see cref="Sph.DfsphParams.DepthStepFactor"/>) off.</summary>
        NoDepthStepLimit = Constants.SPH_DFSPH_NO_DEPTH_STEP_LIMIT,
    }

    /// <summary>How DFSPH's density solve iterates (SPH_DFSPH_JACOBI, ...): set it with
    /// <see cref="Sph.DfsphParams.DfsphLinearSolver"/>.</summary>
    public enum DfsphLinearSolver : uint
    {
        /// <summary>0: the library's default, Jacobi.</summary>
        Default = 0,
        /// <summary>The Jacobi step of Bender &amp; Koschier (the default).</summary>
        Jacobi = Constants.SPH_DFSPH_JACOBI,
        /// <summary>Jacobi-preconditioned conjugate gradients on the compressed particles.</summary>
        ConjugateGradients = Constants.SPH_DFSPH_CONJUGATE_GRADIENTS,
        /// <summary>The Jacobi steps accelerated by Chebyshev's semi-iteration (not with
        /// <see cref="DfsphFlags.CorrectedGradient"/>).</summary>
        Chebyshev = Constants.SPH_DFSPH_CHEBYSHEV,
    }

    /// <summary>DFSPH's candidate masks on the CUDA backend (docs/cuda.md): set them with
    /// <see cref="Sph.ContextDef.CudaDfsphMasksMode"/>. A CPU context checks and ignores them.</summary>
    public enum CudaDfsphMasksMode : uint
    {
        /// <summary>0, the default: the density pass records which candidates are neighbours.</summary>
        On = 0,
        /// <summary>SPH_CUDA_DFSPH_MASKS_OFF: the solves walk every candidate (no memory, slower).</summary>
        Off = Constants.SPH_CUDA_DFSPH_MASKS_OFF,
        /// <summary>SPH_CUDA_DFSPH_NEIGHBOR_LISTS: the masks and each particle's neighbour list.</summary>
        NeighborLists = Constants.SPH_CUDA_DFSPH_NEIGHBOR_LISTS,
    }

    /// <summary>Collider bits (SPH_COLLIDER_FLAG_*): set them with <see cref="Sph.ColliderDef.ColliderFlags"/>.</summary>
    [Flags]
    public enum ColliderFlags : uint
    {
        None = 0,
        /// <summary>Solid where the SDF is positive (a container).</summary>
        Inverted = Constants.SPH_COLLIDER_FLAG_INVERTED,
    }

    /// <summary>Source bits (SPH_SOURCE_FLAG_*): set them with <see cref="Sph.SourceDef.SourceFlags"/>.</summary>
    [Flags]
    public enum SourceFlags : uint
    {
        None = 0,
        /// <summary>Emitted particles take their velocity from the region's velocity channel.</summary>
        VelocityFromField = Constants.SPH_SOURCE_FLAG_VELOCITY_FROM_FIELD,
    }

    /// <summary>Analytic shape bits (SPH_SHAPE_FLAG_*): set them with <see cref="Sph.ShapeDesc.ShapeFlags"/>.</summary>
    [Flags]
    public enum ShapeFlags : uint
    {
        None = 0,
        /// <summary>A hollow box without its lid (a tank open at +y).</summary>
        OpenTop = Constants.SPH_SHAPE_FLAG_OPEN_TOP,
    }

    public partial struct DfsphParams
    {
        /// <summary>The <see cref="Flags"/> field as <see cref="Sph.DfsphFlags"/>:
        /// <c>p.DfsphFlags = DfsphFlags.SkipDivergenceSolve</c>.</summary>
        public DfsphFlags DfsphFlags
        {
            get { return (DfsphFlags)Flags; }
            set { Flags = (uint)value; }
        }

        /// <summary>The <see cref="LinearSolver"/> field as <see cref="Sph.DfsphLinearSolver"/>:
        /// <c>p.DfsphLinearSolver = DfsphLinearSolver.Chebyshev</c>.</summary>
        public DfsphLinearSolver DfsphLinearSolver
        {
            get { return (DfsphLinearSolver)LinearSolver; }
            set { LinearSolver = (uint)value; }
        }
    }

    public partial struct ContextDef
    {
        /// <summary>The <see cref="CudaDfsphMasks"/> field as <see cref="Sph.CudaDfsphMasksMode"/>:
        /// <c>def.CudaDfsphMasksMode = CudaDfsphMasksMode.NeighborLists</c>.</summary>
        public CudaDfsphMasksMode CudaDfsphMasksMode
        {
            get { return (CudaDfsphMasksMode)CudaDfsphMasks; }
            set { CudaDfsphMasks = (uint)value; }
        }
    }

    public partial struct ColliderDef
    {
        /// <summary>The <see cref="Flags"/> field as <see cref="Sph.ColliderFlags"/>.</summary>
        public ColliderFlags ColliderFlags
        {
            get { return (ColliderFlags)Flags; }
            set { Flags = (uint)value; }
        }
    }

    public partial struct SourceDef
    {
        /// <summary>The <see cref="Flags"/> field as <see cref="Sph.SourceFlags"/>.</summary>
        public SourceFlags SourceFlags
        {
            get { return (SourceFlags)Flags; }
            set { Flags = (uint)value; }
        }
    }

    public partial struct ShapeDesc
    {
        /// <summary>The <see cref="Flags"/> field as <see cref="Sph.ShapeFlags"/>.</summary>
        public ShapeFlags ShapeFlags
        {
            get { return (ShapeFlags)Flags; }
            set { Flags = (uint)value; }
        }
    }

    public partial struct WorldDef
    {
        /// <summary>The <see cref="Features"/> field as <see cref="Sph.FeatureFlags"/>:
        /// <c>def.FeatureFlags = FeatureFlags.SurfaceTension | FeatureFlags.NormalizedDensity</c>.
        /// The other options are the <see cref="ViscosityMethod"/> and
        /// <see cref="EquationOfState"/> fields.</summary>
        public FeatureFlags FeatureFlags
        {
            get { return (FeatureFlags)Features; }
            set { Features = (uint)value; }
        }
    }

    public partial struct WorldParams
    {
        /// <summary>The <see cref="StepLimits"/> field as <see cref="Sph.StepLimitFlags"/>:
        /// <c>p.StepLimitFlags = StepLimitFlags.Acoustic</c>.</summary>
        public StepLimitFlags StepLimitFlags
        {
            get { return (StepLimitFlags)StepLimits; }
            set { StepLimits = (uint)value; }
        }
    }

    /// <summary>Called on the thread inside a call on a context (or its worlds): when the call
    /// fails (LogLevel.Error with its code), and for a warning from a call that succeeds
    /// (LogLevel.Warning with Result.Ok; docs/api.md).</summary>
    public delegate void LogHandler(LogLevel level, Result code, string message);

    public sealed partial class ContextHandle
    {
        internal GCHandle LogTarget;
        internal GCHandle TaskTarget;  // the context's TaskSystem, in task_user_context

        partial void OnReleased()
        {
            if (LogTarget.IsAllocated) LogTarget.Free();
            if (TaskTarget.IsAllocated) TaskSystem.Detach(ref TaskTarget);
        }
    }

    /// <summary>A backend (the CPU or one CUDA device) that worlds are created on (sph_context).
    /// Dispose it when done; worlds and assets keep the native context alive until they are
    /// disposed too, but the Context object itself is done: after Dispose every member
    /// (<see cref="Handle"/>, <see cref="Backend"/>, CreateWorld, LoadWorld, ...) and every call
    /// that takes it (<c>new World(context, ...)</c>, the Sdf factories) throws
    /// ObjectDisposedException, whatever still lives; only <see cref="IsDisposed"/>,
    /// <see cref="TaskSystem"/> and Dispose (idempotent) still answer.</summary>
    public sealed class Context : IDisposable
    {
        // One static delegate for every context: IL2CPP can only call static methods marked
        // [MonoPInvokeCallback]; the context's handler travels in user_data as a GCHandle.
        static readonly LogFn logThunk = OnLog;
        static readonly IntPtr logThunkPointer = Marshal.GetFunctionPointerForDelegate(logThunk);

        ContextHandle handle;

        /// <summary>The native context's handle; ObjectDisposedException after Dispose (the
        /// handle may stay open while worlds or assets hold it, but it is theirs).</summary>
        public ContextHandle Handle
        {
            get
            {
                ThrowIfDisposed();
                return handle;
            }
        }

        void ThrowIfDisposed()
        {
            if (IsDisposed) throw new ObjectDisposedException("Context", "the Context was disposed (its worlds and assets may still hold the native context)");
        }

        // The handle of `context`, an argument named `parameter`: ArgumentNullException for null,
        // ObjectDisposedException once it was disposed.
        internal static ContextHandle HandleOf(Context context, string parameter)
        {
            if (context == null) throw new ArgumentNullException(parameter);
            return context.Handle;
        }

        // For SetParent after a call that checked the context: the handle even if a Dispose came
        // meanwhile (DangerousAddRef then throws only if the native context is gone).
        internal ContextHandle RawHandle { get { return handle; } }

        public Context(Backend backend = Backend.Auto) : this(DefFor(backend), null) { }

        public Context(ContextDef def, LogHandler log = null) : this(def, log, null) { }

        /// <summary>A context whose CPU worlds run their parallel loops and asynchronous steps
        /// as tasks of `taskSystem` (sph_context_def.enqueue_task / finish_task), starting no
        /// thread of their own; e.g. <c>new Context(def, null, new ThreadPoolTaskSystem())</c>.
        /// def.CpuWorkerCount still decides whether loops run in parallel (1: never). The
        /// context holds the task system until the native context is destroyed (after Dispose
        /// and its worlds'). A null taskSystem leaves def's task fields as they are; with one,
        /// they must be unset (ArgumentException). A CUDA context checks and ignores it.</summary>
        public Context(ContextDef def, LogHandler log, TaskSystem taskSystem)
        {
            Library.EnsureCompatible();
            if (taskSystem != null &&
                (def.EnqueueTask != IntPtr.Zero || def.FinishTask != IntPtr.Zero || def.TaskUserContext != IntPtr.Zero))
                throw new ArgumentException("def already names a task system (EnqueueTask, FinishTask, TaskUserContext)", "def");
            GCHandle target = default(GCHandle);
            if (log != null)
            {
                target = GCHandle.Alloc(log);
                def.LogFn = logThunkPointer;
                def.LogUserData = GCHandle.ToIntPtr(target);
            }
            GCHandle tasks = default(GCHandle);
            if (taskSystem != null) tasks = taskSystem.Attach(ref def);
            ContextHandle handle;
            Result r = Native.sph_context_create(ref def, out handle);
            if ((int)r < 0)
            {
                string message = Library.LastError;
                if (target.IsAllocated) target.Free();
                if (tasks.IsAllocated) TaskSystem.Detach(ref tasks);
                throw new SphException(r, "sph_context_create", message);
            }
            handle.LogTarget = target;
            handle.TaskTarget = tasks;
            this.handle = handle;
            TaskSystem = taskSystem;
        }

        /// <summary>The task system the context was created with, or null.</summary>
        public TaskSystem TaskSystem { get; private set; }

        static ContextDef DefFor(Backend backend)
        {
            var def = ContextDef.Default();
            def.Backend = backend;
            return def;
        }

        [AOT.MonoPInvokeCallback(typeof(LogFn))]
        static void OnLog(IntPtr userData, LogLevel level, Result code, IntPtr message)
        {
            try
            {
                var handler = (LogHandler)GCHandle.FromIntPtr(userData).Target;
                handler(level, code, Utf8.FromNative(message));
            }
            catch (Exception e)
            {
                // Nothing may unwind into C.
                Console.Error.WriteLine("sph: log handler threw: " + e);
            }
        }

        /// <summary>The backend the context resolved to (CPU or CUDA; never Auto).</summary>
        public Backend Backend
        {
            get
            {
                Backend b;
                SphException.Check(Native.sph_context_get_backend(Handle, out b), "sph_context_get_backend");
                return b;
            }
        }

        /// <summary>The engine's device allocator for this CUDA context's worlds
        /// (sph_cuda_context_set_allocator): both function pointers or neither (neither: back to
        /// cudaMalloc), set before the first world or SDF asset. A CPU context throws
        /// SphException(ErrorUnsupported).</summary>
        public void SetCudaAllocator(CudaAllocator allocator)
        {
            SphException.Check(Native.sph_cuda_context_set_allocator(Handle, ref allocator),
                               "sph_cuda_context_set_allocator");
        }

        public World CreateWorld(WorldDef def)
        {
            ThrowIfDisposed();
            return new World(this, def);
        }

        public World CreateWorld()
        {
            ThrowIfDisposed();
            return new World(this, WorldDef.Default());
        }

        /// <summary>A new world on this context from checkpoint bytes (sph_world_load; see
        /// World.Save). The context decides the backend, whichever saved it. Throws
        /// SphException (ErrorCorruptData for a damaged checkpoint; no world is created).</summary>
        public World LoadWorld(byte[] data)
        {
            ThrowIfDisposed();
            if (data == null) throw new ArgumentNullException("data");
            WorldHandle handle;
            GCHandle pin = GCHandle.Alloc(data, GCHandleType.Pinned);
            try
            {
                SphException.Check(Native.sph_world_load(Handle, pin.AddrOfPinnedObject(), (ulong)data.Length, out handle),
                    "sph_world_load");
            }
            finally
            {
                pin.Free();
            }
            return new World(this, handle);
        }

        /// <summary>A new world on this context from a checkpoint file (sph_world_load_file).</summary>
        public World LoadWorldFile(string path)
        {
            ThrowIfDisposed();
            if (path == null) throw new ArgumentNullException("path");
            WorldHandle handle;
            SphException.Check(Native.sph_world_load_file(Handle, Utf8.ToNative(path), out handle), "sph_world_load_file");
            return new World(this, handle);
        }

        /// <summary>True after Dispose (the native context may live on while worlds use it).</summary>
        public bool IsDisposed { get; private set; }

        /// <summary>Releases the caller's reference on the native context (idempotent): it is
        /// destroyed now, or when the last world or asset that holds it goes.</summary>
        public void Dispose()
        {
            if (IsDisposed) return;
            IsDisposed = true;
            handle.Dispose();
        }
    }

    // ---- the engine's task system (sph_context_def.enqueue_task / finish_task) ----------------

    /// <summary>One task the library enqueued on a <see cref="TaskSystem"/>: items [0,
    /// ItemCount) of a native sph_task_fn, split into ranges of at least MinRange items. Workers
    /// claim ranges from a shared counter (<see cref="RunNext"/>), so a range runs exactly once
    /// whoever claims it, and a thread that must wait for the task can run the unclaimed ranges
    /// itself (<see cref="RunAndWait"/>) instead of waiting for a worker that may never come
    /// free. Thread-safe; never throws from RunNext for the library's own tasks (they never
    /// throw).</summary>
    public sealed class NativeTask
    {
        // One delegate per native function: the library's loops are a few dozen functions.
        static readonly Dictionary<IntPtr, TaskFn> delegates = new Dictionary<IntPtr, TaskFn>();

        readonly TaskFn function;
        readonly IntPtr context;
        readonly long ranges;
        long next;      // ranges claimed (may run past `ranges`: claims that found nothing)
        long finished;  // ranges that have run

        internal NativeTask(TaskSystem owner, IntPtr function, uint itemCount, uint minRange, IntPtr context)
        {
            Owner = owner;
            this.function = DelegateFor(function);
            this.context = context;
            ItemCount = itemCount;
            MinRange = minRange < 1 ? 1u : minRange;
            ranges = itemCount == 0 ? 0 : Math.Max(1L, itemCount / MinRange);
        }

        static TaskFn DelegateFor(IntPtr function)
        {
            lock (delegates)
            {
                TaskFn fn;
                if (!delegates.TryGetValue(function, out fn))
                {
                    fn = (TaskFn)Marshal.GetDelegateForFunctionPointer(function, typeof(TaskFn));
                    delegates.Add(function, fn);
                }
                return fn;
            }
        }

        /// <summary>The task system the task was enqueued on.</summary>
        public TaskSystem Owner { get; private set; }
        /// <summary>The task's items (sph_enqueue_task_fn's item_count).</summary>
        public uint ItemCount { get; private set; }
        /// <summary>The fewest items a range has (the library passes 1), except a task with
        /// fewer items than that: one range of all of them.</summary>
        public uint MinRange { get; private set; }
        /// <summary>The ranges the items are split into: ItemCount / MinRange, the last range
        /// taking the remainder. At most this many workers can be busy with the task.</summary>
        public long RangeCount { get { return ranges; } }

        /// <summary>True once every range has run (each claimed and finished).</summary>
        public bool IsComplete { get { return Volatile.Read(ref finished) == ranges; } }

        /// <summary>Claims the next range and runs it on this thread, passing `worker` to the
        /// native function; returns the items it ran, or 0 when no range was left to claim.</summary>
        public uint RunNext(uint worker)
        {
            long r = Interlocked.Increment(ref next) - 1;
            if (r >= ranges) return 0;
            uint first = (uint)(r * MinRange);
            uint last = r == ranges - 1 ? ItemCount : first + MinRange;
            try
            {
                function(first, last, worker, context);
            }
            finally
            {
                // Even if the call itself failed, so that no waiter is left waiting.
                if (Interlocked.Increment(ref finished) == ranges)
                    lock (this) Monitor.PulseAll(this);
            }
            return last - first;
        }

        /// <summary>Runs ranges on this thread until none is left to claim; returns the items
        /// it ran.</summary>
        public uint RunRemaining(uint worker)
        {
            uint items = 0, ran;
            while ((ran = RunNext(worker)) != 0) items += ran;
            return items;
        }

        /// <summary>Blocks until every range has run. Only safe once none is left to claim
        /// (after <see cref="RunRemaining"/>) or where a worker that claims them is sure to come
        /// free; <see cref="RunAndWait"/> is the wait that cannot deadlock.</summary>
        public void Wait()
        {
            var spin = new SpinWait();
            while (!IsComplete && !spin.NextSpinWillYield) spin.SpinOnce();
            if (IsComplete) return;
            lock (this)
                while (!IsComplete) Monitor.Wait(this);
        }

        /// <summary>The finish that never deadlocks: runs the unclaimed ranges on this thread,
        /// then waits for those other threads are running. Returns the items it ran.</summary>
        public uint RunAndWait(uint worker)
        {
            uint items = RunRemaining(worker);
            Wait();
            return items;
        }
    }

    /// <summary>
    /// An engine's task system for a CPU context (sph_context_def.enqueue_task / finish_task;
    /// docs/embedding.md, "The engine's task system"): the library's parallel loops and each
    /// asynchronous step (World.StepBegin) run as its tasks, and the library starts no thread.
    /// Give it to <c>new Context(def, log, taskSystem)</c>; <see cref="ThreadPoolTaskSystem"/>
    /// is a ready one. A subclass implements <see cref="Enqueue"/> (hand the task's ranges to
    /// workers, each calling <c>task.RunNext(worker)</c> or <c>task.RunRemaining(worker)</c>)
    /// and may override <see cref="Finish"/>. The binding does the marshalling: static
    /// [MonoPInvokeCallback] thunks, a GCHandle to this object per context (freed when the
    /// native context is destroyed) and one per scheduled task (freed by its finish), and the
    /// contract's safety net: an exception from Enqueue or Finish never reaches native code,
    /// and whatever they did, the task's unclaimed ranges are run on the calling thread before
    /// the library is told the task is done. One task system may serve several contexts.
    /// </summary>
    public abstract class TaskSystem
    {
        // One static delegate each for every context (IL2CPP calls only static methods); the
        // task system travels in task_user_context as a GCHandle, each task as one.
        static readonly EnqueueTaskFn enqueueThunk = OnEnqueue;
        static readonly FinishTaskFn finishThunk = OnFinish;
        static readonly IntPtr enqueueThunkPointer = Marshal.GetFunctionPointerForDelegate(enqueueThunk);
        static readonly IntPtr finishThunkPointer = Marshal.GetFunctionPointerForDelegate(finishThunk);

        long tasksEnqueued, tasksRunInline, failures;
        int tasksInFlight, contexts;

        /// <summary>
        /// Schedules the task's ranges and returns true; the library later calls
        /// <see cref="Finish"/> for it. Or runs every range on this thread
        /// (<c>task.RunRemaining(worker)</c>) and returns false: the task is then done (for an
        /// asynchronous step StepBegin returns after the frame). Called from the thread inside
        /// a call on a world and, nested, from inside an asynchronous step's task on whichever
        /// worker runs it, concurrently from several threads: it must be thread-safe and must
        /// not wait for the task. If it throws, the binding runs the unclaimed ranges here.
        /// </summary>
        public abstract bool Enqueue(NativeTask task);

        /// <summary>Returns once every range of a task Enqueue scheduled has run. The default,
        /// <c>task.RunAndWait(CurrentWorker)</c>, runs the unclaimed ranges on this thread and
        /// then waits for those in flight, which never deadlocks (this may be a worker inside an
        /// asynchronous step's task). Called on the thread that enqueued a loop, or on the
        /// thread in StepWait for a step. An override that returns early or throws is made
        /// good by the binding (the same RunAndWait), never by native code.</summary>
        public virtual void Finish(NativeTask task)
        {
            if (task == null) throw new ArgumentNullException("task");
            task.RunAndWait(CurrentWorker);
        }

        /// <summary>The worker index passed to the native functions (the library does not read
        /// it): by default the managed thread id.</summary>
        public virtual uint CurrentWorker
        {
            get { return (uint)Thread.CurrentThread.ManagedThreadId; }
        }

        /// <summary>Tasks the library enqueued.</summary>
        public long TasksEnqueued { get { return Interlocked.Read(ref tasksEnqueued); } }
        /// <summary>Of those, tasks that ran whole inside the enqueue (Enqueue returned false,
        /// or failed), for which the library got NULL and calls no finish.</summary>
        public long TasksRunInline { get { return Interlocked.Read(ref tasksRunInline); } }
        /// <summary>Exceptions from Enqueue or Finish caught by the binding (the items were then
        /// run on the calling thread).</summary>
        public long Failures { get { return Interlocked.Read(ref failures); } }
        /// <summary>Tasks scheduled and not finished yet: each holds a GCHandle until its
        /// finish. 0 whenever no loop or asynchronous step is running.</summary>
        public int TasksInFlight { get { return Volatile.Read(ref tasksInFlight); } }
        /// <summary>Native contexts holding this task system (each through a GCHandle, freed when
        /// the native context is destroyed: after Dispose of the context and its worlds).</summary>
        public int ContextCount { get { return Volatile.Read(ref contexts); } }

        // Sets the def's three fields; the returned handle is freed by Detach.
        internal GCHandle Attach(ref ContextDef def)
        {
            GCHandle target = GCHandle.Alloc(this);
            Interlocked.Increment(ref contexts);
            def.EnqueueTask = enqueueThunkPointer;
            def.FinishTask = finishThunkPointer;
            def.TaskUserContext = GCHandle.ToIntPtr(target);
            return target;
        }

        internal static void Detach(ref GCHandle target)
        {
            var system = (TaskSystem)target.Target;
            target.Free();
            Interlocked.Decrement(ref system.contexts);
        }

        [AOT.MonoPInvokeCallback(typeof(EnqueueTaskFn))]
        static IntPtr OnEnqueue(IntPtr task, uint itemCount, uint minRange, IntPtr taskContext, IntPtr userContext)
        {
            // Nothing may unwind into C: whatever fails, the items run here and NULL goes back.
            NativeTask t = null;
            TaskSystem system = null;
            try
            {
                system = (TaskSystem)GCHandle.FromIntPtr(userContext).Target;
                Interlocked.Increment(ref system.tasksEnqueued);
                t = new NativeTask(system, task, itemCount, minRange, taskContext);
                bool scheduled;
                try
                {
                    scheduled = system.Enqueue(t);
                }
                catch (Exception e)
                {
                    system.Failed("Enqueue", e);
                    scheduled = false;
                }
                if (scheduled)
                {
                    GCHandle handle = GCHandle.Alloc(t);
                    Interlocked.Increment(ref system.tasksInFlight);
                    return GCHandle.ToIntPtr(handle);
                }
                t.RunAndWait(system.SafeWorker());  // what Enqueue left (nothing, if it kept its word)
                Interlocked.Increment(ref system.tasksRunInline);
                return IntPtr.Zero;
            }
            catch (Exception e)
            {
                // The binding itself failed (no memory for a handle, say): the items still run.
                Report("enqueue_task failed (the task runs on the calling thread)", e);
                try
                {
                    if (system != null) Interlocked.Increment(ref system.tasksRunInline);
                    if (t == null) t = new NativeTask(null, task, itemCount, minRange, taskContext);
                    t.RunAndWait(0);
                }
                catch (Exception inner)
                {
                    // The items could not run (no delegate for the native function, no memory):
                    // returning NULL would tell the library they had, and it would go on with a
                    // frame half computed. Stop the process with the reason instead.
                    Environment.FailFast("sph: enqueue_task could not run a task's items: " + inner);
                }
                return IntPtr.Zero;
            }
        }

        [AOT.MonoPInvokeCallback(typeof(FinishTaskFn))]
        static void OnFinish(IntPtr userTask, IntPtr userContext)
        {
            GCHandle handle;
            NativeTask t;
            try
            {
                handle = GCHandle.FromIntPtr(userTask);
                t = (NativeTask)handle.Target;
            }
            catch (Exception e)
            {
                // Not a handle OnEnqueue returned: the library broke its word; nothing to run.
                Report("finish_task got a foreign task handle", e);
                return;
            }
            TaskSystem system = t.Owner;
            try
            {
                system.Finish(t);
            }
            catch (Exception e)
            {
                system.Failed("Finish", e);
            }
            try
            {
                // Whatever Finish did, the library hears of the task's end only once it ended.
                if (!t.IsComplete) t.RunAndWait(system.SafeWorker());
            }
            catch (Exception e)
            {
                Report("a task's items failed in finish_task", e);
            }
            finally
            {
                handle.Free();
                Interlocked.Decrement(ref system.tasksInFlight);
            }
        }

        uint SafeWorker()
        {
            try
            {
                return CurrentWorker;
            }
            catch (Exception)
            {
                return 0;
            }
        }

        static void Report(string what, Exception e)
        {
            try
            {
                Console.Error.WriteLine("sph: " + what + ": " + e);
            }
            catch (Exception)
            {
            }
        }

        void Failed(string what, Exception e)
        {
            Interlocked.Increment(ref failures);
            try
            {
                OnFailure(what, e);
            }
            catch (Exception)
            {
            }
        }

        /// <summary>Called (on the failing thread) with an exception Enqueue or Finish threw,
        /// after which the binding runs the task's items itself. The default writes it to
        /// stderr; it must not throw.</summary>
        protected virtual void OnFailure(string what, Exception e)
        {
            Console.Error.WriteLine("sph: " + GetType().Name + "." + what + " threw (its items run on the calling thread): " + e);
        }
    }

    /// <summary>
    /// A <see cref="TaskSystem"/> on System.Threading.ThreadPool: each task posts up to
    /// MaxRunners pool work items that claim its ranges one at a time, and the finishing thread
    /// runs the ranges no pool thread has claimed yet, then waits only for those in flight, so a
    /// finish called inside an asynchronous step's task (nested) or while the pool is busy
    /// never deadlocks. An asynchronous step (one item) goes to the pool, so StepBegin returns
    /// at once. If the pool refuses work, the task runs on the enqueuing thread.
    /// </summary>
    public class ThreadPoolTaskSystem : TaskSystem
    {
        static readonly WaitCallback runner = RunOnPool;

        [ThreadStatic] static int poolDepth;  // > 0 inside this class's pool work items

        long itemsOnPool, itemsByCaller, nestedTasks;

        /// <summary>maxRunners: the most pool work items one task posts; 0 (default) =
        /// Environment.ProcessorCount.</summary>
        public ThreadPoolTaskSystem(int maxRunners = 0)
        {
            if (maxRunners < 0) throw new ArgumentOutOfRangeException("maxRunners");
            MaxRunners = maxRunners == 0 ? Math.Max(1, Environment.ProcessorCount) : maxRunners;
        }

        /// <summary>The most pool work items one task posts (the finishing thread helps too).</summary>
        public int MaxRunners { get; private set; }
        /// <summary>Items run by pool work items.</summary>
        public long ItemsRunOnPool { get { return Interlocked.Read(ref itemsOnPool); } }
        /// <summary>Items run off the pool: the unclaimed ranges a finishing thread ran itself,
        /// and a whole task the enqueuing thread ran when the pool refused work.</summary>
        public long ItemsRunByCaller { get { return Interlocked.Read(ref itemsByCaller); } }
        /// <summary>Tasks enqueued from inside one of this system's pool work items: the loops
        /// of asynchronous steps that ran on the pool.</summary>
        public long NestedTasks { get { return Interlocked.Read(ref nestedTasks); } }

        public override bool Enqueue(NativeTask task)
        {
            if (task == null) throw new ArgumentNullException("task");
            if (poolDepth > 0) Interlocked.Increment(ref nestedTasks);
            long runners = Math.Min(task.RangeCount, (long)MaxRunners);
            for (long i = 0; i < runners; ++i)
            {
                bool posted;
                try
                {
                    posted = ThreadPool.UnsafeQueueUserWorkItem(runner, task);
                }
                catch (Exception)
                {
                    posted = false;
                }
                if (!posted)
                {
                    if (i > 0) break;  // the posted ones and the finish run the rest
                    Interlocked.Add(ref itemsByCaller, task.RunRemaining(CurrentWorker));
                    return false;      // none posted: all ran here
                }
            }
            return true;
        }

        public override void Finish(NativeTask task)
        {
            if (task == null) throw new ArgumentNullException("task");
            Interlocked.Add(ref itemsByCaller, task.RunAndWait(CurrentWorker));
        }

        static void RunOnPool(object state)
        {
            var task = (NativeTask)state;
            var system = (ThreadPoolTaskSystem)task.Owner;
            ++poolDepth;
            try
            {
                uint items = task.RunRemaining(system.CurrentWorker);
                if (items != 0) Interlocked.Add(ref system.itemsOnPool, items);
            }
            catch (Exception e)
            {
                // An exception in a pool work item ends the process; the ranges it claimed are
                // counted finished (RunNext's finally), so no finish waits for them.
                Console.Error.WriteLine("sph: a task's items failed on the thread pool: " + e);
            }
            finally
            {
                --poolDepth;
            }
        }
    }

    public sealed partial class WorldHandle
    {
        // Between a StepBegin that succeeded and the StepWait that collected it: the library
        // refuses to destroy the world meanwhile (WORLD_LOCKED), so neither Dispose nor the
        // finaliser tries.
        internal volatile bool StepInFlight;

        // The finaliser of a world dropped with a step in flight leaks it (and keeps its
        // context): waiting there could block the finaliser thread for a whole frame, and freeing
        // it under the step is not possible.
        partial void OnReleasing(ref bool keep)
        {
            if (StepInFlight) keep = true;
        }
    }

    /// <summary>A particle fluid on a context (sph_world). Not thread-safe: use one thread at a time.
    /// Not sealed for one subclass: DistributedWorld (SphMpi.cs), a world over MPI ranks.</summary>
    public class World : IDisposable
    {
        public WorldHandle Handle { get; private set; }
        public Context Context { get; private set; }

        /// <summary>A new world on <paramref name="context"/> (sph_world_create): as
        /// <c>context.CreateWorld(def)</c>. ArgumentNullException for a null context,
        /// ObjectDisposedException for a disposed one.</summary>
        public World(Context context, WorldDef def)
        {
            ContextHandle contextHandle = Context.HandleOf(context, "context");
            WorldHandle handle;
            SphException.Check(Native.sph_world_create(contextHandle, ref def, out handle), "sph_world_create");
            handle.SetParent(contextHandle);  // the context outlives its worlds
            Handle = handle;
            Context = context;
        }

        // A world the library created from a checkpoint (on a context the caller checked).
        internal World(Context context, WorldHandle handle)
        {
            handle.SetParent(context.RawHandle);
            Handle = handle;
            Context = context;
        }

        public bool IsDisposed { get; private set; }

        /// <summary>Destroys the world (sph_world_destroy). While a step that StepBegin started
        /// is in flight it throws SphException(ErrorWorldLocked) and the world stays open:
        /// StepWait, then Dispose again. A world dropped without Dispose is destroyed by its
        /// handle's finaliser, except with a step in flight: that world (and its context) is
        /// leaked, never destroyed or waited for on the finaliser thread.</summary>
        public void Dispose()
        {
            if (Handle.StepInFlight)
                throw new SphException(Result.ErrorWorldLocked, "sph_world_destroy",
                    "a step that StepBegin started is in flight: StepWait first");
            IsDisposed = true;
            Handle.Dispose();
        }

        // ---- checkpoints ----------------------------------------------------------------------

        /// <summary>The world's whole state as checkpoint bytes (sph_world_save: a size query,
        /// then the save). A world loaded from them continues bit for bit on the same backend.</summary>
        public byte[] Save()
        {
            ulong size;
            SphException.Check(Native.sph_world_save(Handle, IntPtr.Zero, 0, out size), "sph_world_save");
            byte[] data = new byte[size];
            GCHandle pin = GCHandle.Alloc(data, GCHandleType.Pinned);
            try
            {
                SphException.Check(Native.sph_world_save(Handle, pin.AddrOfPinnedObject(), size, out size), "sph_world_save");
            }
            finally
            {
                pin.Free();
            }
            return data;
        }

        /// <summary>Saves atomically to a file (sph_world_save_file): a temporary file next to
        /// path, flushed, then renamed over it; on error a file at path is untouched.</summary>
        public void SaveFile(string path)
        {
            if (path == null) throw new ArgumentNullException("path");
            SphException.Check(Native.sph_world_save_file(Handle, Utf8.ToNative(path)), "sph_world_save_file");
        }

        /// <summary>Replaces the whole world with a checkpoint's (sph_world_restore;
        /// all-or-nothing: on error the world is unchanged).</summary>
        public void Restore(byte[] data)
        {
            if (data == null) throw new ArgumentNullException("data");
            GCHandle pin = GCHandle.Alloc(data, GCHandleType.Pinned);
            try
            {
                SphException.Check(Native.sph_world_restore(Handle, pin.AddrOfPinnedObject(), (ulong)data.Length),
                    "sph_world_restore");
            }
            finally
            {
                pin.Free();
            }
        }

        /// <summary>The def the world was created with, defaults resolved, except Capacity: the
        /// world's current capacity, larger than the def's once the world grew (never more than
        /// MaxCapacity).</summary>
        public WorldDef Def
        {
            get
            {
                var d = WorldDef.Default();
                SphException.Check(Native.sph_world_get_def(Handle, ref d), "sph_world_get_def");
                return d;
            }
        }

        public float ParticleMass
        {
            get
            {
                float m;
                SphException.Check(Native.sph_world_get_particle_mass(Handle, out m), "sph_world_get_particle_mass");
                return m;
            }
        }

        /// <summary>Runtime parameters; setting replaces them all at once (validated as a whole).</summary>
        public WorldParams Params
        {
            get
            {
                var p = WorldParams.Default();
                SphException.Check(Native.sph_world_get_params(Handle, ref p), "sph_world_get_params");
                return p;
            }
            set { SphException.Check(Native.sph_world_set_params(Handle, ref value), "sph_world_set_params"); }
        }

        // ---- optional physics (docs/physics.md): chosen in the WorldDef, tuned here -----------

        /// <summary>The feature bits the world was created with (WorldDef.Features).</summary>
        public FeatureFlags Features { get { return Def.FeatureFlags; } }

        /// <summary>The viscosity method the world was created with (WorldDef.ViscosityMethod).</summary>
        public ViscosityMethod ViscosityMethod { get { return Def.ViscosityMethod; } }

        /// <summary>The equation of state the world was created with (WorldDef.EquationOfState).</summary>
        public EquationOfState EquationOfState { get { return Def.EquationOfState; } }

        /// <summary>Surface-tension parameters (coefficient sigma in N/m, normal threshold in
        /// 1/m) of a world created with <see cref="Sph.FeatureFlags.SurfaceTension"/>; setting
        /// replaces them whole (validated, unchanged on error). Throws SphException
        /// (<c>Result.ErrorFeatureDisabled</c>) when the world does not have the feature.</summary>
        public SurfaceTensionParams SurfaceTensionParams
        {
            get
            {
                var p = SurfaceTensionParams.Default();
                SphException.Check(Native.sph_world_get_surface_tension_params(Handle, ref p), "sph_world_get_surface_tension_params");
                return p;
            }
            set
            {
                SphException.Check(Native.sph_world_set_surface_tension_params(Handle, ref value), "sph_world_set_surface_tension_params");
            }
        }

        /// <summary>Clavet viscosity parameters (linear sigma in 1/s, quadratic beta in 1/m) of a
        /// world created with <c>ViscosityMethod.Clavet</c>; setting replaces them whole. Throws
        /// SphException (<c>Result.ErrorFeatureDisabled</c>) on a world with another viscosity
        /// method.</summary>
        public ClavetViscosityParams ClavetViscosityParams
        {
            get
            {
                var p = ClavetViscosityParams.Default();
                SphException.Check(Native.sph_world_get_clavet_viscosity_params(Handle, ref p), "sph_world_get_clavet_viscosity_params");
                return p;
            }
            set
            {
                SphException.Check(Native.sph_world_set_clavet_viscosity_params(Handle, ref value), "sph_world_set_clavet_viscosity_params");
            }
        }

        /// <summary>Tait equation-of-state parameters (speed of sound c in m/s) of a world created
        /// with <c>EquationOfState.Tait</c>; setting replaces them whole. Throws SphException
        /// (<c>Result.ErrorFeatureDisabled</c>) on a world with another equation of state. Keep
        /// c &gt;= 10 x the fastest flow and c dt below about 0.4 h (lower DtMax, or
        /// <see cref="Sph.StepLimitFlags.Acoustic"/>).</summary>
        public TaitParams TaitParams
        {
            get
            {
                var p = TaitParams.Default();
                SphException.Check(Native.sph_world_get_tait_params(Handle, ref p), "sph_world_get_tait_params");
                return p;
            }
            set { SphException.Check(Native.sph_world_set_tait_params(Handle, ref value), "sph_world_set_tait_params"); }
        }

        /// <summary>Spring parameters (stiffness k in 1/s^2, link radius in m, yield ratio gamma,
        /// plasticity alpha in 1/s, damping c in 1/s) of a world created with
        /// <see cref="FeatureFlags.Springs"/>; setting replaces them whole. Throws SphException
        /// (<c>Result.ErrorFeatureDisabled</c>) on a world without the feature.</summary>
        public SpringParams SpringParams
        {
            get
            {
                var p = SpringParams.Default();
                SphException.Check(Native.sph_world_get_spring_params(Handle, ref p), "sph_world_get_spring_params");
                return p;
            }
            set { SphException.Check(Native.sph_world_set_spring_params(Handle, ref value), "sph_world_set_spring_params"); }
        }

        /// <summary>The density diffusion's parameters (delta, dimensionless) of a world created
        /// with <see cref="FeatureFlags.DensityDiffusion"/>; setting replaces them whole. Throws
        /// SphException (<c>Result.ErrorFeatureDisabled</c>) on a world without the feature.</summary>
        public DensityDiffusionParams DensityDiffusionParams
        {
            get
            {
                var p = DensityDiffusionParams.Default();
                SphException.Check(Native.sph_world_get_density_diffusion_params(Handle, ref p),
                                   "sph_world_get_density_diffusion_params");
                return p;
            }
            set
            {
                SphException.Check(Native.sph_world_set_density_diffusion_params(Handle, ref value),
                                   "sph_world_set_density_diffusion_params");
            }
        }

        /// <summary>DFSPH's parameters (the bound on the density solve's mean error, that of the
        /// divergence solve in 1/s, the two iteration caps, flags) of a world created with
        /// <c>Solver.Dfsph</c>; setting replaces them whole. Throws SphException
        /// (<c>Result.ErrorFeatureDisabled</c>) on a weakly compressible world.</summary>
        public DfsphParams DfsphParams
        {
            get
            {
                var p = DfsphParams.Default();
                SphException.Check(Native.sph_world_get_dfsph_params(Handle, ref p), "sph_world_get_dfsph_params");
                return p;
            }
            set { SphException.Check(Native.sph_world_set_dfsph_params(Handle, ref value), "sph_world_set_dfsph_params"); }
        }

        /// <summary>The solver the world was created with (WorldDef.Solver).</summary>
        public Solver Solver { get { return Def.Solver; } }

        /// <summary>The params struct of <paramref name="kind"/> (T must be its struct:
        /// WorldParams for ParamsKind.World, TaitParams for ParamsKind.Tait, ...), read from the
        /// world (sph_world_get_physics_params). Another T throws ArgumentException naming T and
        /// the kind's struct.</summary>
        public T GetPhysicsParams<T>(ParamsKind kind) where T : struct
        {
            CheckParamsType(typeof(T), kind);
            int size = Marshal.SizeOf(typeof(T));
            IntPtr buffer = Marshal.AllocHGlobal(size);
            try
            {
                for (int i = 0; i < size; ++i) Marshal.WriteByte(buffer, i, 0);
                Marshal.WriteInt32(buffer, size);
                SphException.Check(Native.sph_world_get_physics_params(Handle, kind, buffer), "sph_world_get_physics_params");
                return (T)Marshal.PtrToStructure(buffer, typeof(T));
            }
            finally { Marshal.FreeHGlobal(buffer); }
        }

        /// <summary>Replaces the params struct of <paramref name="kind"/> with
        /// <paramref name="value"/> (its struct, struct_size set), as its typed setter does
        /// (sph_world_set_physics_params). Another T throws ArgumentException, as for
        /// <see cref="GetPhysicsParams{T}"/>.</summary>
        public void SetPhysicsParams<T>(ParamsKind kind, T value) where T : struct
        {
            CheckParamsType(typeof(T), kind);
            IntPtr buffer = Marshal.AllocHGlobal(Marshal.SizeOf(typeof(T)));
            try
            {
                Marshal.StructureToPtr(value, buffer, false);
                SphException.Check(Native.sph_world_set_physics_params(Handle, kind, buffer), "sph_world_set_physics_params");
            }
            finally { Marshal.FreeHGlobal(buffer); }
        }

        // T must be the struct Library.ParamsInfo(kind) names (its C type name, through Layout):
        // a struct of another kind (or a Vec3) would be filled or sent as garbage, and two params
        // structs of the same size pass the library's struct_size check. A kind whose struct these
        // bindings do not know (a newer library's) is left to that check.
        static void CheckParamsType(Type type, ParamsKind kind)
        {
            string typeName = Utf8.FromNative(Library.ParamsInfo(kind).TypeName);
            int at = Array.IndexOf(Layout.StructNames, typeName);
            if (at < 0 || Layout.StructTypes[at] == type) return;
            throw new ArgumentException("T is " + type.Name + ", but the params struct of ParamsKind." + kind + " is " +
                                        Layout.StructTypes[at].Name + " (" + typeName + ")");
        }

        // ---- particles in ---------------------------------------------------------------------

        /// <summary>Adds particles from raw memory (e.g. NativeArray.GetUnsafeReadOnlyPtr()):
        /// count elements of 3 floats, `stride` bytes apart (0 = packed); velocities may be
        /// IntPtr.Zero. Copied before return; all-or-nothing. Returns the first new id.</summary>
        public uint Spawn(IntPtr positions, ulong positionStride, IntPtr velocities, ulong velocityStride, uint count)
        {
            var desc = SpawnDesc.Default();
            desc.Count = count;
            desc.Positions = positions;
            desc.PositionStride = positionStride;
            desc.Velocities = velocities;
            desc.VelocityStride = velocityStride;
            uint first;
            SphException.Check(Native.sph_world_spawn(Handle, ref desc, out first), "sph_world_spawn");
            return first;
        }

        /// <summary>Adds particles from xyz triples (positions.Length / 3 particles).</summary>
        public uint Spawn(float[] positions, float[] velocities = null)
        {
            if (positions == null) throw new ArgumentNullException("positions");
            if (positions.Length % 3 != 0) throw new ArgumentException("positions: a multiple of 3 floats");
            if (velocities != null && velocities.Length != positions.Length) throw new ArgumentException("velocities: one triple per position");
            return SpawnPinned(positions, velocities, 12, (uint)(positions.Length / 3));
        }

        /// <summary>Adds particles from arrays of any blittable vector struct whose first three
        /// fields are x, y, z floats (Vec3, UnityEngine.Vector3, or a larger particle struct:
        /// the stride is its size).</summary>
        public uint Spawn<T>(T[] positions, T[] velocities = null) where T : struct
        {
            if (positions == null) throw new ArgumentNullException("positions");
            if (velocities != null && velocities.Length != positions.Length) throw new ArgumentException("velocities: one per position");
            int stride = Marshal.SizeOf(typeof(T));
            if (stride < 12) throw new ArgumentException(typeof(T).Name + " is smaller than 3 floats");
            return SpawnPinned(positions, velocities, (ulong)stride, (uint)positions.Length);
        }

        uint SpawnPinned(Array positions, Array velocities, ulong stride, uint count)
        {
            GCHandle p = GCHandle.Alloc(positions, GCHandleType.Pinned);
            GCHandle v = velocities != null ? GCHandle.Alloc(velocities, GCHandleType.Pinned) : default(GCHandle);
            try
            {
                return Spawn(p.AddrOfPinnedObject(), stride, v.IsAllocated ? v.AddrOfPinnedObject() : IntPtr.Zero, stride, count);
            }
            finally
            {
                p.Free();
                if (v.IsAllocated) v.Free();
            }
        }

        /// <summary>Fills the box [min, max] on an FCC lattice at rest density; returns the count added.</summary>
        public uint FillBox(Vec3 min, Vec3 max, Vec3 velocity = default(Vec3))
        {
            var desc = FillBoxDesc.Default();
            desc.Min = min;
            desc.Max = max;
            desc.Velocity = velocity;
            uint n;
            SphException.Check(Native.sph_world_fill_box(Handle, ref desc, out n), "sph_world_fill_box");
            return n;
        }

        /// <summary>Fills a sphere on an FCC lattice; returns the count added.</summary>
        public uint FillSphere(Vec3 center, float radius, Vec3 velocity = default(Vec3))
        {
            var desc = FillSphereDesc.Default();
            desc.Center = center;
            desc.Radius = radius;
            desc.Velocity = velocity;
            uint n;
            SphException.Check(Native.sph_world_fill_sphere(Handle, ref desc, out n), "sph_world_fill_sphere");
            return n;
        }

        // ---- stepping -------------------------------------------------------------------------

        /// <summary>Advances by frameDt seconds (blocks). Returns Ok, or Incomplete when
        /// max_substeps ran out, or the step budget (<see cref="StepBudget"/>) or a cancel
        /// (<see cref="CancelStep"/>) stopped it: the world is then as after its last whole
        /// substep, ready to step again. Throws SphException (e.g. ErrorNonFinite, ErrorCapacity:
        /// the world rolled back to before the call).</summary>
        public Result Step(float frameDt)
        {
            return SphException.Check(Native.sph_world_step(Handle, frameDt), "sph_world_step");
        }

        /// <summary>Builds now what the next Step would build before its first substep (the
        /// boundary-density maps of the colliders' assets, CUDA's device copies), so that a loading
        /// screen pays for it rather than the first frame (sph_world_prepare). Optional; changes
        /// nothing a step sees.</summary>
        public void Prepare()
        {
            SphException.Check(Native.sph_world_prepare(Handle), "sph_world_prepare");
        }

        /// <summary>Wall-clock seconds one Step may take before it stops at a substep boundary
        /// and returns Incomplete; 0 is no budget (sph_world_set/get_step_budget).</summary>
        public double StepBudget
        {
            get
            {
                double seconds;
                SphException.Check(Native.sph_world_get_step_budget(Handle, out seconds), "sph_world_get_step_budget");
                return seconds;
            }
            set { SphException.Check(Native.sph_world_set_step_budget(Handle, value), "sph_world_set_step_budget"); }
        }

        /// <summary>Starts the frame Step would run on the world's own thread and returns at once
        /// (sph_world_step_begin). Until StepWait collects it every other call on the world throws
        /// ErrorWorldLocked, except CancelStep and StepDone.</summary>
        public void StepBegin(float frameDt)
        {
            SphException.Check(Native.sph_world_step_begin(Handle, frameDt), "sph_world_step_begin");
            Handle.StepInFlight = true;
        }

        /// <summary>Waits for the frame StepBegin started and returns what Step would have returned
        /// (Ok or Incomplete), or throws its error (sph_world_step_wait).</summary>
        public Result StepWait()
        {
            Result r = Native.sph_world_step_wait(Handle);
            // Collected (its result or its error), unless another call held the world.
            if (r != Result.ErrorWorldLocked) Handle.StepInFlight = false;
            return SphException.Check(r, "sph_world_step_wait");
        }

        /// <summary>True once the frame StepBegin started has ended, so StepWait will not block
        /// (sph_world_step_poll; never blocks).</summary>
        public bool StepDone()
        {
            uint done;
            SphException.Check(Native.sph_world_step_poll(Handle, out done), "sph_world_step_poll");
            return done != 0;
        }

        /// <summary>Asks the Step running on another thread (or else the next one) to stop at its
        /// next substep boundary, returning Incomplete. Safe from any thread while the world steps.</summary>
        public void CancelStep()
        {
            SphException.Check(Native.sph_world_cancel_step(Handle), "sph_world_cancel_step");
        }

        // ---- particles out --------------------------------------------------------------------

        public uint ParticleCount
        {
            get
            {
                uint n;
                SphException.Check(Native.sph_world_get_particle_count(Handle, out n), "sph_world_get_particle_count");
                return n;
            }
        }

        /// <summary>Copies particles [first, first + count) of an attribute into raw memory
        /// (e.g. NativeArray.GetUnsafePtr()): element i at dst + i * stride (0 = packed);
        /// dstSize is the buffer's size in bytes. Returns the number written.</summary>
        public uint CopyAttribute(SphAttribute attribute, IntPtr dst, ulong dstSize, ulong dstStride, uint first, uint count)
        {
            uint written;
            SphException.Check(Native.sph_world_copy_attribute(Handle, attribute, dst, dstSize, dstStride, first, count, out written),
                "sph_world_copy_attribute");
            return written;
        }

        /// <summary>Copies a float32 attribute (Position, Velocity, Density, Pressure) into a
        /// float array (3 floats per particle for vectors, 1 for scalars), as many particles as fit
        /// from `first`. Returns the number written. A uint32 attribute (Id, User) throws
        /// ArgumentException: copy it into a uint[].</summary>
        public uint CopyAttribute(SphAttribute attribute, float[] dst, uint first = 0)
        {
            if (dst == null) throw new ArgumentNullException("dst");
            int components, bytes;
            Library.AttributeFormat(attribute, out components, out bytes);
            CheckElementType(attribute, typeof(float), "dst");
            return CopyPinned(attribute, dst, (ulong)(components * bytes), (uint)(dst.Length / components), first);
        }

        /// <summary>Copies a uint32 attribute (Id, User) into an array. Returns the number
        /// written. A float32 attribute throws ArgumentException.</summary>
        public uint CopyAttribute(SphAttribute attribute, uint[] dst, uint first = 0)
        {
            if (dst == null) throw new ArgumentNullException("dst");
            CheckElementType(attribute, typeof(uint), "dst");
            return CopyPinned(attribute, dst, 4, (uint)dst.Length, first);
        }

        /// <summary>Copies into an array of blittable structs, one per particle, the attribute
        /// written at the start of each element (stride = the struct's size): Vec3 or
        /// UnityEngine.Vector3 arrays for positions, or an interleaved particle struct. The
        /// element's first field must hold the attribute's type: float for Position, Velocity,
        /// Density, Pressure; uint or int for Id and User (else ArgumentException).</summary>
        public uint CopyAttribute<T>(SphAttribute attribute, T[] dst, uint first = 0) where T : struct
        {
            if (dst == null) throw new ArgumentNullException("dst");
            CheckElementType(attribute, typeof(T), "dst");
            return CopyPinned(attribute, dst, (ulong)Marshal.SizeOf(typeof(T)), (uint)dst.Length, first);
        }

        static readonly Dictionary<Type, Type> leadingScalars = new Dictionary<Type, Type>();

        // The scalar at offset 0 of a blittable element type (float, uint, Vec3's X, a particle
        // struct's first field's), or null when it is none of float, uint, int (cached per type).
        static Type LeadingScalar(Type type)
        {
            Type scalar;
            lock (leadingScalars)
                if (leadingScalars.TryGetValue(type, out scalar)) return scalar;
            try
            {
                scalar = FindLeadingScalar(type);
            }
            catch (ArgumentException)
            {
                scalar = null;  // Marshal.OffsetOf refused a field: a layout it does not marshal
            }
            lock (leadingScalars) leadingScalars[type] = scalar;
            return scalar;
        }

        static Type FindLeadingScalar(Type type)
        {
            for (int depth = 0; depth < 8 && type != null; ++depth)
            {
                if (type == typeof(float) || type == typeof(uint) || type == typeof(int)) return type;
                if (type.IsPrimitive || type.IsEnum || !type.IsValueType) return null;
                Type inner = null;
                foreach (var field in type.GetFields(System.Reflection.BindingFlags.Instance | System.Reflection.BindingFlags.Public |
                                                     System.Reflection.BindingFlags.NonPublic))
                {
                    if (Marshal.OffsetOf(type, field.Name) == IntPtr.Zero)
                    {
                        inner = field.FieldType;
                        break;
                    }
                }
                type = inner;
            }
            return null;
        }

        // Refuses an element type whose leading scalar is not the attribute's component type (a
        // float array for ids would get uint bits as floats). Attributes without a documented
        // format, and element types whose leading scalar is unknown, are left to the library.
        static void CheckElementType(SphAttribute attribute, Type element, string parameter)
        {
            int components;
            string componentType;
            if (!Library.TryAttributeFormat(attribute, out components, out componentType)) return;
            Type scalar = LeadingScalar(element);
            if (scalar == null) return;
            bool wantFloat = componentType == "float32";
            if (wantFloat == (scalar == typeof(float))) return;
            throw new ArgumentException("SphAttribute." + attribute + " holds " + (components > 1 ? components + " x " : "") +
                                        componentType + " values, which an array of " + element.Name +
                                        (scalar == element ? "" : " (starting with " + scalar.Name + ")") + " would not hold: use " +
                                        (wantFloat ? "a float[] or an array of Vec3" : "a uint[]"), parameter);
        }

        uint CopyPinned(SphAttribute attribute, Array dst, ulong stride, uint count, uint first)
        {
            if (dst == null) throw new ArgumentNullException("dst");
            ulong size = (ulong)dst.LongLength * (ulong)Marshal.SizeOf(dst.GetType().GetElementType());
            GCHandle h = GCHandle.Alloc(dst, GCHandleType.Pinned);
            try
            {
                return CopyAttribute(attribute, h.AddrOfPinnedObject(), size, stride, first, count);
            }
            finally
            {
                h.Free();
            }
        }

        /// <summary>Positions as a new Vec3 array (current particle order).</summary>
        public Vec3[] Positions()
        {
            var a = new Vec3[ParticleCount];
            CopyAttribute(SphAttribute.Position, a);
            return a;
        }

        /// <summary>Persistent particle ids, in the same order as the other attributes.</summary>
        public uint[] Ids()
        {
            var a = new uint[ParticleCount];
            CopyAttribute(SphAttribute.Id, a);
            return a;
        }

        // ---- writing particles ----------------------------------------------------------------

        /// <summary>Overwrites particles [first, first + count) of Position, Velocity or User from
        /// raw memory: element i at src + i * stride (0 = packed); srcSize is the buffer's size in
        /// bytes. All-or-nothing: every value is checked first (sph_world_set_attribute).</summary>
        public void SetAttribute(SphAttribute attribute, IntPtr src, ulong srcSize, ulong srcStride, uint first, uint count)
        {
            SphException.Check(Native.sph_world_set_attribute(Handle, attribute, src, srcSize, srcStride, first, count),
                "sph_world_set_attribute");
        }

        /// <summary>Writes from an array of blittable elements, one per particle, the attribute
        /// read at the start of each (stride = the element's size): Vec3 or UnityEngine.Vector3
        /// for positions and velocities, uint for the user attribute, or an interleaved particle
        /// struct. Particles [first, first + src.Length). An element whose first field is not of
        /// the attribute's type (float for Position, Velocity; uint or int for User) throws
        /// ArgumentException.</summary>
        public void SetAttribute<T>(SphAttribute attribute, T[] src, uint first = 0) where T : struct
        {
            if (src == null) throw new ArgumentNullException("src");
            CheckElementType(attribute, typeof(T), "src");
            ulong stride = (ulong)Marshal.SizeOf(typeof(T));
            GCHandle h = GCHandle.Alloc(src, GCHandleType.Pinned);
            try
            {
                SetAttribute(attribute, h.AddrOfPinnedObject(), stride * (ulong)src.LongLength, stride, first, (uint)src.Length);
            }
            finally
            {
                h.Free();
            }
        }

        /// <summary>User attributes (<see cref="FeatureFlags.UserAttribute"/>), in the same order.</summary>
        public uint[] UserAttributes()
        {
            var a = new uint[ParticleCount];
            CopyAttribute(SphAttribute.User, a);
            return a;
        }

        /// <summary>Removes the particles with these ids (sph_world_remove_particles): an unknown
        /// or repeated id throws, naming the first, and removes nothing. The ids join
        /// <see cref="GetRemovedIds"/>.</summary>
        public void RemoveParticles(uint[] ids)
        {
            if (ids == null) throw new ArgumentNullException("ids");
            SphException.Check(Native.sph_world_remove_particles(Handle, ids, (uint)ids.Length), "sph_world_remove_particles");
        }

        // ---- statistics -----------------------------------------------------------------------

        /// <summary>Statistics of the last Step (zeros before the first).</summary>
        public Stats GetStats()
        {
            var s = Stats.Default();
            SphException.Check(Native.sph_world_get_stats(Handle, ref s), "sph_world_get_stats");
            return s;
        }

        // ---- colliders, sources, sinks, force fields, events ----------------------------------

        /// <summary>Places an SDF asset of this world's context as a collider (def from
        /// ColliderDef.Default(); its Sdf field is set from `sdf`).</summary>
        public Collider CreateCollider(Sdf sdf, ColliderDef def)
        {
            if (sdf == null) throw new ArgumentNullException("sdf");
            ColliderId id;
            using (var borrowed = new Borrowed(sdf.Handle))
            {
                def.Sdf = borrowed.Pointer;
                SphException.Check(Native.sph_collider_create(Handle, ref def, out id), "sph_collider_create");
            }
            return HandOut(new Collider(this, id), id.Bits);
        }

        /// <summary>A collider at `transform` with the default material.</summary>
        public Collider CreateCollider(Sdf sdf, Transform transform, bool inverted = false)
        {
            if (sdf == null) throw new ArgumentNullException("sdf");
            var def = ColliderDef.Default();
            def.Transform = transform;
            if (inverted) def.ColliderFlags |= ColliderFlags.Inverted;
            return CreateCollider(sdf, def);
        }

        /// <summary>Adds a source that fills `region` (negative inside) with particles.</summary>
        public Source CreateSource(Sdf region, SourceDef def)
        {
            if (region == null) throw new ArgumentNullException("region");
            SourceId id;
            using (var borrowed = new Borrowed(region.Handle))
            {
                def.Region = borrowed.Pointer;
                SphException.Check(Native.sph_source_create(Handle, ref def, out id), "sph_source_create");
            }
            return HandOut(new Source(this, id), id.Bits);
        }

        /// <summary>Adds a sink: with a region (SinkMode.Region) or, region null, the def's
        /// bounds (SinkMode.OutsideBounds: a def left at Region is switched to it, as Python's
        /// add_sink(bounds=...) does).</summary>
        public Sink CreateSink(Sdf region, SinkDef def)
        {
            if (region == null && def.Mode == SinkMode.Region) def.Mode = SinkMode.OutsideBounds;
            SinkId id;
            using (var borrowed = new Borrowed(region != null ? region.Handle : null))
            {
                def.Region = borrowed.Pointer;
                SphException.Check(Native.sph_sink_create(Handle, ref def, out id), "sph_sink_create");
            }
            return HandOut(new Sink(this, id), id.Bits);
        }

        /// <summary>Adds a probe or a gauge (ProbeDef.Kind), sampled inside every Step.</summary>
        public Probe CreateProbe(ProbeDef def)
        {
            ProbeId id;
            SphException.Check(Native.sph_probe_create(Handle, ref def, out id), "sph_probe_create");
            return HandOut(new Probe(this, id), id.Bits);
        }

        /// <summary>Adds a force field; `region` (optional) limits it to where that SDF is negative.</summary>
        public ForceField CreateForceField(ForceFieldDef def, Sdf region = null)
        {
            return CreateForceField(def, region, null, 0, 0, 0, GridDesc.Default().IndexToLocal);
        }

        /// <summary>Adds a ForceFieldKind.Grid force field: accelerations are ni*nj*nk xyz
        /// triples, i fastest, placed by indexToLocal (row-major 3x4).</summary>
        public ForceField CreateForceField(ForceFieldDef def, Sdf region, float[] accelerations, uint ni, uint nj, uint nk,
                                           FixedFloat12 indexToLocal)
        {
            ForceFieldId id;
            GCHandle data = default(GCHandle), grid = default(GCHandle);
            try
            {
                if (accelerations != null)
                {
                    if ((ulong)accelerations.Length != 3UL * ni * nj * nk) throw new ArgumentException("accelerations: 3 floats per voxel");
                    data = GCHandle.Alloc(accelerations, GCHandleType.Pinned);
                    var g = GridDesc.Default();
                    g.Dims = FixedUint3.From(new uint[] { ni, nj, nk });
                    g.IndexToLocal = indexToLocal;
                    g.Components = 3;
                    g.Data = data.AddrOfPinnedObject();
                    grid = GCHandle.Alloc(new GridDesc[] { g }, GCHandleType.Pinned);
                    def.Grid = grid.AddrOfPinnedObject();
                }
                using (var borrowed = new Borrowed(region != null ? region.Handle : null))
                {
                    def.Region = borrowed.Pointer;
                    SphException.Check(Native.sph_force_field_create(Handle, ref def, out id), "sph_force_field_create");
                }
            }
            finally
            {
                if (grid.IsAllocated) grid.Free();
                if (data.IsAllocated) data.Free();
            }
            return HandOut(new ForceField(this, id), id.Bits);
        }

        // ---- wrappers of ids: a loaded or restored world's objects ----------------------------

        /// <summary>The <see cref="Sph.Collider"/> of <paramref name="id"/> in this world: the
        /// wrapper this world handed out for it (CreateCollider's, or an earlier GetCollider's)
        /// while it is alive and still holds the id, else a new one, which this world then hands
        /// out (ObjectOf finds it). This is how a world made by <see cref="Sph.Context.LoadWorld"/>
        /// (it accepts the saved world's ids, by design) or brought back by
        /// <see cref="Restore"/> reaches its objects: keep the ids (their Bits) with the save,
        /// e.g. <c>loaded.GetCollider(paddleId).MoveTo(pose)</c>; a wrapper whose Dispose cleared
        /// its Id before a Restore brought the object back is replaced by a fresh one here. The id
        /// is not checked: a stale id, or one of another world, makes the wrapper's calls throw
        /// SphException(ErrorInvalidHandle), and its Dispose does nothing. The null id throws
        /// ArgumentException; a disposed world ObjectDisposedException.</summary>
        public Collider GetCollider(ColliderId id)
        {
            return Wrap(id.Bits, "id", () => new Collider(this, id));
        }

        /// <summary>The <see cref="Sph.Source"/> of <paramref name="id"/> in this world, as
        /// <see cref="GetCollider"/> does for colliders.</summary>
        public Source GetSource(SourceId id)
        {
            return Wrap(id.Bits, "id", () => new Source(this, id));
        }

        /// <summary>The <see cref="Sph.Sink"/> of <paramref name="id"/> in this world, as
        /// <see cref="GetCollider"/> does for colliders.</summary>
        public Sink GetSink(SinkId id)
        {
            return Wrap(id.Bits, "id", () => new Sink(this, id));
        }

        /// <summary>The <see cref="Sph.Probe"/> of <paramref name="id"/> in this world, as
        /// <see cref="GetCollider"/> does for colliders.</summary>
        public Probe GetProbe(ProbeId id)
        {
            return Wrap(id.Bits, "id", () => new Probe(this, id));
        }

        /// <summary>The <see cref="Sph.ForceField"/> of <paramref name="id"/> in this world, as
        /// <see cref="GetCollider"/> does for colliders.</summary>
        public ForceField GetForceField(ForceFieldId id)
        {
            return Wrap(id.Bits, "id", () => new ForceField(this, id));
        }

        T Wrap<T>(ulong bits, string parameter, Func<T> make) where T : class
        {
            if (bits == 0) throw new ArgumentException("the null id names no object", parameter);
            if (IsDisposed || Handle.IsClosed) throw new ObjectDisposedException("World");
            lock (handedOutLock)
            {
                WeakReference r;
                if (handedOut.TryGetValue(new KeyValuePair<Type, ulong>(typeof(T), bits), out r))
                {
                    var held = r.Target as T;
                    if (held != null && BitsOf(held) == bits) return held;
                }
                return HandOut(make(), bits);
            }
        }

        // For the placed objects' Dispose: removes the object with `destroy` (sph_*_destroy)
        // unless there is nothing to remove. Returns normally when the object is gone: its world
        // was disposed (destroying the world removed it), or the library calls the id stale
        // (ErrorInvalidHandle: a Restore to a save from before it was made, or an id of another
        // world, already removed). Any other error (ErrorWorldLocked while StepBegin's step runs)
        // throws, and the object stays.
        internal void RemovePlaced(Func<WorldHandle, Result> destroy, string function)
        {
            if (IsDisposed || Handle.IsClosed) return;
            Result r;
            try
            {
                r = destroy(Handle);
            }
            catch (ObjectDisposedException)
            {
                return;  // the world's handle was closed meanwhile: the world is gone
            }
            if (r == Result.ErrorInvalidHandle) return;
            SphException.Check(r, function);
        }

        // The wrappers CreateCollider/CreateSource/CreateSink/CreateProbe/CreateForceField (and
        // GetCollider & co.) handed out, by kind and id bits, held weakly (ObjectOf).
        readonly object handedOutLock = new object();
        readonly Dictionary<KeyValuePair<Type, ulong>, WeakReference> handedOut =
            new Dictionary<KeyValuePair<Type, ulong>, WeakReference>();
        int handedOutPruneAt = 64;

        T HandOut<T>(T obj, ulong bits) where T : class
        {
            lock (handedOutLock)
            {
                if (handedOut.Count >= handedOutPruneAt)
                {
                    var dead = new List<KeyValuePair<Type, ulong>>();
                    foreach (var entry in handedOut)
                        if (!entry.Value.IsAlive) dead.Add(entry.Key);
                    foreach (var key in dead) handedOut.Remove(key);
                    handedOutPruneAt = Math.Max(64, 2 * handedOut.Count);
                }
                handedOut[new KeyValuePair<Type, ulong>(typeof(T), bits)] = new WeakReference(obj);
            }
            return obj;
        }

        static Type KindOf(EventType type)
        {
            switch (type)
            {
                case EventType.SourceCapacityReached:
                case EventType.CapacityGrown: return typeof(Source);
                case EventType.SinkRemoved: return typeof(Sink);
                case EventType.ColliderLoadExceeded: return typeof(Collider);
                case EventType.ProbePressureExceeded: return typeof(Probe);
                default: return null;
            }
        }

        static ulong BitsOf(object obj)
        {
            if (obj is Collider) return ((Collider)obj).Id.Bits;
            if (obj is Source) return ((Source)obj).Id.Bits;
            if (obj is Sink) return ((Sink)obj).Id.Bits;
            if (obj is Probe) return ((Probe)obj).Id.Bits;
            if (obj is ForceField) return ((ForceField)obj).Id.Bits;
            return 0;
        }

        /// <summary>The <see cref="Collider"/>, <see cref="Probe"/>, <see cref="Source"/> or
        /// <see cref="Sink"/> an event names (its ObjectBits): the very object this world's
        /// CreateCollider / CreateProbe / CreateSource / CreateSink (or GetCollider / GetProbe /
        /// GetSource / GetSink) returned. Null when the event names no object (the DFSPH solve
        /// events), when that object was collected (the world holds weak references only) or
        /// disposed, or when it was not handed out by this World (a loaded checkpoint's objects
        /// before GetCollider &amp; co. wrapped them: call those with the saved ids). The event's type gives the kind (SourceCapacityReached
        /// and CapacityGrown a Source, SinkRemoved a Sink, ColliderLoadExceeded a Collider,
        /// ProbePressureExceeded a Probe); for a type these bindings do not know, the one object of
        /// any kind with those bits.</summary>
        public object ObjectOf(Event e)
        {
            if (e.ObjectBits == 0) return null;
            Type kind = KindOf(e.Type);
            Type[] kinds = kind != null ? new[] { kind } : new[] { typeof(Collider), typeof(Probe), typeof(Source), typeof(Sink) };
            object found = null;
            int matches = 0;
            lock (handedOutLock)
            {
                foreach (Type k in kinds)
                {
                    WeakReference r;
                    if (!handedOut.TryGetValue(new KeyValuePair<Type, ulong>(k, e.ObjectBits), out r)) continue;
                    object o = r.Target;
                    if (o == null || BitsOf(o) != e.ObjectBits) continue;
                    found = o;
                    ++matches;
                }
            }
            return matches == 1 ? found : null;
        }

        /// <summary>As <see cref="ObjectOf(Event)"/>, typed: null also when the event names an
        /// object of another kind. <c>world.ObjectOf&lt;Source&gt;(e)</c>.</summary>
        public T ObjectOf<T>(Event e) where T : class
        {
            return ObjectOf(e) as T;
        }

        /// <summary>Events of the last Step (sources at capacity, sink removals, growths, capped solves, load and pressure thresholds);
        /// <see cref="ObjectOf(Event)"/> gives the object an event names.</summary>
        public Event[] GetEvents()
        {
            uint n;
            SphException.Check(Native.sph_world_get_events(Handle, null, 0, out n), "sph_world_get_events");
            while (true)
            {
                var events = new Event[n];
                Result r = SphException.Check(Native.sph_world_get_events(Handle, events, n, out n), "sph_world_get_events");
                if (r != Result.Incomplete) return events;
            }
        }

        /// <summary>Ids of the particles sinks removed during the last Step.</summary>
        public uint[] GetRemovedIds()
        {
            uint n;
            SphException.Check(Native.sph_world_get_removed_ids(Handle, null, 0, out n), "sph_world_get_removed_ids");
            while (true)
            {
                var ids = new uint[n];
                Result r = SphException.Check(Native.sph_world_get_removed_ids(Handle, ids, n, out n), "sph_world_get_removed_ids");
                if (r != Result.Incomplete) return ids;
            }
        }

        // ---- the zero-copy CUDA tier (sph_cuda.h); ErrorUnsupported on the CPU backend ------

        /// <summary>Where an attribute lives in device memory (address, stride, count, epoch).</summary>
        public CudaAttributeView GetCudaAttribute(SphAttribute attribute)
        {
            var view = CudaAttributeView.Default();
            SphException.Check(Native.sph_cuda_world_get_attribute(Handle, attribute, ref view), "sph_cuda_world_get_attribute");
            return view;
        }

        /// <summary>The world's data epoch: grows on every call that changes particles (and past every earlier one at a restore); a view whose epoch equals it is current.</summary>
        public ulong CudaEpoch
        {
            get
            {
                ulong e;
                SphException.Check(Native.sph_cuda_world_get_epoch(Handle, out e), "sph_cuda_world_get_epoch");
                return e;
            }
        }

        public int CudaDevice
        {
            get
            {
                int d;
                SphException.Check(Native.sph_cuda_world_get_device(Handle, out d), "sph_cuda_world_get_device");
                return d;
            }
        }

        /// <summary>The world's cudaStream_t (owned by the world).</summary>
        public IntPtr CudaStream
        {
            get
            {
                IntPtr s;
                SphException.Check(Native.sph_cuda_world_get_stream(Handle, out s), "sph_cuda_world_get_stream");
                return s;
            }
        }

        /// <summary>Records a cudaEvent_t you own on the world's stream.</summary>
        public void CudaRecordEvent(IntPtr cudaEvent)
        {
            SphException.Check(Native.sph_cuda_world_record_event(Handle, cudaEvent), "sph_cuda_world_record_event");
        }

        /// <summary>Makes the world's later device work wait for a cudaEvent_t.</summary>
        public void CudaWaitEvent(IntPtr cudaEvent)
        {
            SphException.Check(Native.sph_cuda_world_wait_event(Handle, cudaEvent), "sph_cuda_world_wait_event");
        }

        /// <summary>StepBegin ordered on your cudaStream_t (IntPtr.Zero: the legacy default stream):
        /// the frame runs after your stream's earlier work and your stream's later work after the
        /// frame (sph_cuda_world_step_begin_on_stream). Collect it with StepWait.</summary>
        public void CudaStepBeginOnStream(float frameDt, IntPtr cudaStream)
        {
            SphException.Check(Native.sph_cuda_world_step_begin_on_stream(Handle, frameDt, cudaStream),
                               "sph_cuda_world_step_begin_on_stream");
        }
    }

    /// <summary>A SafeHandle's pointer, kept alive (AddRef) while a call uses it; null gives IntPtr.Zero.</summary>
    struct Borrowed : IDisposable
    {
        readonly SafeHandle handle;
        readonly bool added;
        public readonly IntPtr Pointer;

        public Borrowed(SafeHandle h)
        {
            handle = h;
            added = false;
            Pointer = IntPtr.Zero;
            if (h == null) return;
            h.DangerousAddRef(ref added);
            Pointer = h.DangerousGetHandle();
        }

        public void Dispose()
        {
            if (added) handle.DangerousRelease();
        }
    }

    /// <summary>A signed-distance asset (sph_sdf; negative inside) owned by a context and
    /// shared by colliders, sources, sinks and force fields of its worlds. Dispose releases
    /// the caller's reference; objects using it keep it alive.</summary>
    public sealed class Sdf : IDisposable
    {
        public SdfHandle Handle { get; private set; }
        public Context Context { get; private set; }

        Sdf(Context context, SdfHandle handle)
        {
            handle.SetParent(context.RawHandle);  // the context outlives its assets
            Handle = handle;
            Context = context;
        }

        /// <summary>An analytic shape sampled into a grid (ShapeDesc.Default() for the defaults).</summary>
        public static Sdf CreateShape(Context context, ShapeDesc desc)
        {
            ContextHandle contextHandle = Context.HandleOf(context, "context");
            SdfHandle h;
            SphException.Check(Native.sph_sdf_create_shape(contextHandle, ref desc, out h), "sph_sdf_create_shape");
            return new Sdf(context, h);
        }

        /// <summary>An asset from a triangle mesh (copied): vertices holds x, y, z per vertex
        /// (m, the asset's local frame), indices three vertex indices per triangle,
        /// counter-clockwise seen from outside (clockwise throughout works too; small holes are
        /// fine). desc (MeshDesc.Default() when null) gives voxel size, band width and padding;
        /// its array fields are filled here.</summary>
        public static Sdf CreateFromMesh(Context context, float[] vertices, uint[] indices, MeshDesc? desc = null)
        {
            ContextHandle contextHandle = Context.HandleOf(context, "context");
            if (vertices == null) throw new ArgumentNullException("vertices");
            if (indices == null) throw new ArgumentNullException("indices");
            if (vertices.Length % 3 != 0) throw new ArgumentException("vertices: x, y, z per vertex", "vertices");
            if (indices.Length % 3 != 0) throw new ArgumentException("indices: three per triangle", "indices");
            var d = desc ?? MeshDesc.Default();
            var pins = new List<GCHandle>();
            try
            {
                d.Vertices = Pin(vertices, pins);
                d.VertexCount = (uint)(vertices.Length / 3);
                d.VertexStride = 0;
                d.Indices = Pin(indices, pins);
                d.IndexCount = (uint)indices.Length;
                SdfHandle h;
                SphException.Check(Native.sph_sdf_create_from_mesh(contextHandle, ref d, out h), "sph_sdf_create_from_mesh");
                return new Sdf(context, h);
            }
            finally
            {
                foreach (var p in pins) p.Free();
            }
        }

        /// <summary>An asset from sampled grids (copied): distance has ni*nj*nk floats, i
        /// fastest; velocity (3 floats per voxel) and friction are optional.</summary>
        public static Sdf Create(Context context, float[] distance, uint ni, uint nj, uint nk, FixedFloat12 indexToLocal,
                                 float[] velocity = null, float[] friction = null)
        {
            ContextHandle contextHandle = Context.HandleOf(context, "context");
            if (distance == null) throw new ArgumentNullException("distance");
            ulong voxels = (ulong)ni * nj * nk;
            if ((ulong)distance.Length != voxels) throw new ArgumentException("distance: ni*nj*nk floats", "distance");
            if (velocity != null && (ulong)velocity.Length != 3 * voxels) throw new ArgumentException("velocity: 3 floats per voxel");
            if (friction != null && (ulong)friction.Length != voxels) throw new ArgumentException("friction: one float per voxel");
            var pins = new List<GCHandle>();
            try
            {
                var desc = SdfDesc.Default();
                desc.Distance = Grid(distance, 1, ni, nj, nk, indexToLocal, pins);
                if (velocity != null) desc.Velocity = Pin(new GridDesc[] { Grid(velocity, 3, ni, nj, nk, indexToLocal, pins) }, pins);
                if (friction != null) desc.Friction = Pin(new GridDesc[] { Grid(friction, 1, ni, nj, nk, indexToLocal, pins) }, pins);
                SdfHandle h;
                SphException.Check(Native.sph_sdf_create(contextHandle, ref desc, out h), "sph_sdf_create");
                return new Sdf(context, h);
            }
            finally
            {
                foreach (var p in pins) p.Free();
            }
        }

        /// <summary>An asset from grids already in memory of <paramref name="memory"/>'s kind:
        /// with <see cref="MemoryKind.CudaDevice"/> (CUDA contexts only; a CPU context throws
        /// SphException(ErrorUnsupported)) device addresses of the context's device, e.g. from
        /// the engine's own cudaMalloc. distance holds ni*nj*nk floats, i fastest; velocity (3
        /// floats per voxel) and friction are optional (IntPtr.Zero: none). The library copies
        /// them.</summary>
        public static Sdf Create(Context context, IntPtr distance, uint ni, uint nj, uint nk, FixedFloat12 indexToLocal,
                                 MemoryKind memory, IntPtr velocity = default(IntPtr), IntPtr friction = default(IntPtr))
        {
            ContextHandle contextHandle = Context.HandleOf(context, "context");
            var pins = new List<GCHandle>();
            try
            {
                var desc = SdfDesc.Default();
                desc.Distance = Grid(distance, 1, ni, nj, nk, indexToLocal, memory);
                if (velocity != IntPtr.Zero)
                    desc.Velocity = Pin(new GridDesc[] { Grid(velocity, 3, ni, nj, nk, indexToLocal, memory) }, pins);
                if (friction != IntPtr.Zero)
                    desc.Friction = Pin(new GridDesc[] { Grid(friction, 1, ni, nj, nk, indexToLocal, memory) }, pins);
                SdfHandle h;
                SphException.Check(Native.sph_sdf_create(contextHandle, ref desc, out h), "sph_sdf_create");
                return new Sdf(context, h);
            }
            finally
            {
                foreach (var p in pins) p.Free();
            }
        }

        static GridDesc Grid(IntPtr data, uint components, uint ni, uint nj, uint nk, FixedFloat12 indexToLocal, MemoryKind memory)
        {
            var g = GridDesc.Default();
            g.Dims = FixedUint3.From(new uint[] { ni, nj, nk });
            g.IndexToLocal = indexToLocal;
            g.Components = components;
            g.Memory = memory;
            g.Data = data;
            return g;
        }

        static IntPtr Pin(Array a, List<GCHandle> pins)
        {
            var h = GCHandle.Alloc(a, GCHandleType.Pinned);
            pins.Add(h);
            return h.AddrOfPinnedObject();
        }

        static GridDesc Grid(float[] data, uint components, uint ni, uint nj, uint nk, FixedFloat12 indexToLocal, List<GCHandle> pins)
        {
            var g = GridDesc.Default();
            g.Dims = FixedUint3.From(new uint[] { ni, nj, nk });
            g.IndexToLocal = indexToLocal;
            g.Components = components;
            g.Data = Pin(data, pins);
            return g;
        }

        /// <summary>Loads a level-set FloatGrid from a .vdb file (the optional helper library
        /// libsph_vdb: DllNotFoundException where it is not built). The asset's local frame is
        /// the file's world frame; gridName null takes the first float level set.</summary>
        public static Sdf LoadVdb(Context context, string path, string gridName = null)
        {
            ContextHandle contextHandle = Context.HandleOf(context, "context");
            if (path == null) throw new ArgumentNullException("path");
            SdfHandle h;
            Result r = Native.sph_vdb_load_sdf(contextHandle, Utf8.ToNative(path),
                                               gridName != null ? Utf8.ToNative(gridName) : null, out h);
            if ((int)r < 0) throw new SphException(r, "sph_vdb_load_sdf", Utf8.FromNative(Native.sph_vdb_get_last_error()));
            return new Sdf(context, h);
        }

        /// <summary>index_to_local of an axis-aligned grid: sample (i, j, k) at origin + voxelSize * (i, j, k).
        /// ArgumentOutOfRangeException for a voxelSize that is not finite and &gt; 0.</summary>
        public static FixedFloat12 GridTransform(float voxelSize, Vec3 origin)
        {
            if (!(voxelSize > 0) || float.IsInfinity(voxelSize))
                throw new ArgumentOutOfRangeException("voxelSize", voxelSize, "the voxel size must be finite and > 0 (metres)");
            return FixedFloat12.From(new float[] { voxelSize, 0, 0, origin.X, 0, voxelSize, 0, origin.Y, 0, 0, voxelSize, origin.Z });
        }

        /// <summary>Grid samples along i, j, k.</summary>
        public uint[] Dims
        {
            get
            {
                var dims = new FixedUint3();
                SphException.Check(Native.sph_sdf_get_dims(Handle, ref dims), "sph_sdf_get_dims");
                return dims.ToArray();
            }
        }

        /// <summary>Signed distance at a point of the asset's local frame, m.</summary>
        public float Sample(Vec3 localPoint)
        {
            float d;
            SphException.Check(Native.sph_sdf_sample(Handle, localPoint, out d), "sph_sdf_sample");
            return d;
        }

        /// <summary>Overwrites the box [origin, origin + size) of one channel (i fastest; 3
        /// floats per voxel for velocity). Updating a channel the asset lacks creates it. With
        /// the walls in the density, send only the box that changed: the CPU backend's next step
        /// recomputes only that box's reach of the asset's boundary map.</summary>
        public void Update(SdfChannel channel, uint[] origin, uint[] size, float[] data)
        {
            // The library reads size[0] * size[1] * size[2] * components floats from data, and
            // three indices from origin and size: arrays of other lengths never reach it.
            if (origin == null) throw new ArgumentNullException("origin");
            if (size == null) throw new ArgumentNullException("size");
            if (origin.Length != 3) throw new ArgumentException("origin: 3 grid indices (i, j, k)", "origin");
            if (size.Length != 3) throw new ArgumentException("size: 3 sample counts (i, j, k)", "size");
            if (data == null) throw new ArgumentNullException("data");
            ulong components = channel == SdfChannel.Velocity ? 3UL : 1UL;
            ulong floats;
            try
            {
                floats = checked((ulong)size[0] * size[1] * size[2] * components);
            }
            catch (OverflowException)
            {
                throw new ArgumentException("size: the box holds more than 2^64 floats");
            }
            if (floats == 0 || (ulong)data.LongLength != floats)
                throw new ArgumentException("data: " + data.LongLength + " floats for a box of " + size[0] + " x " + size[1] + " x " +
                                            size[2] + " samples of " + components + " (" + floats + " floats)");
            var o = FixedUint3.From(origin);
            var s = FixedUint3.From(size);
            SphException.Check(Native.sph_sdf_update(Handle, channel, ref o, ref s, data, MemoryKind.Host), "sph_sdf_update");
        }

        /// <summary>As <see cref="Update(SdfChannel, uint[], uint[], float[])"/> from memory of
        /// <paramref name="memory"/>'s kind: a host pointer (<see cref="MemoryKind.Host"/>: a
        /// NativeArray's, pinned memory) or, with <see cref="MemoryKind.CudaDevice"/> (CUDA
        /// contexts only; a CPU context throws SphException(ErrorUnsupported)), a device address
        /// of the context's device. data holds size[0] * size[1] * size[2] floats (3 per voxel for
        /// velocity), i fastest; the library copies them.</summary>
        public void Update(SdfChannel channel, uint[] origin, uint[] size, IntPtr data, MemoryKind memory)
        {
            if (origin == null) throw new ArgumentNullException("origin");
            if (size == null) throw new ArgumentNullException("size");
            if (origin.Length != 3) throw new ArgumentException("origin: 3 grid indices (i, j, k)", "origin");
            if (size.Length != 3) throw new ArgumentException("size: 3 sample counts (i, j, k)", "size");
            var pins = new List<GCHandle>();
            try
            {
                using (var borrowed = new Borrowed(Handle))
                {
                    SphException.Check(Native.sph_sdf_update(borrowed.Pointer, channel, Pin(origin, pins), Pin(size, pins), data, memory),
                                       "sph_sdf_update");
                }
            }
            finally
            {
                foreach (var p in pins) p.Free();
            }
        }

        public bool IsDisposed { get; private set; }

        public void Dispose()
        {
            IsDisposed = true;
            Handle.Dispose();
        }
    }

    /// <summary>A placed SDF the fluid cannot enter (World.CreateCollider; a loaded or restored
    /// world's: <see cref="World.GetCollider"/>).</summary>
    public sealed class Collider : IDisposable
    {
        public World World { get; private set; }
        public ColliderId Id { get; private set; }

        internal Collider(World world, ColliderId id) { World = world; Id = id; }

        /// <summary>The current pose.</summary>
        public Transform Transform
        {
            get
            {
                Transform t;
                SphException.Check(Native.sph_collider_get_transform(World.Handle, Id, out t), "sph_collider_get_transform");
                return t;
            }
        }

        /// <summary>Kinematic motion: reach `target` over the next Step, pushing fluid.</summary>
        public void MoveTo(Transform target)
        {
            SphException.Check(Native.sph_collider_set_target_transform(World.Handle, Id, ref target), "sph_collider_set_target_transform");
        }

        /// <summary>Moves at once, with no velocity.</summary>
        public void Teleport(Transform transform)
        {
            SphException.Check(Native.sph_collider_teleport(World.Handle, Id, ref transform), "sph_collider_teleport");
        }

        /// <summary>The surface material (restitution, friction, stickiness); setting it replaces all three.</summary>
        public ColliderMaterial Material
        {
            get
            {
                var m = ColliderMaterial.Default();
                SphException.Check(Native.sph_collider_get_material(World.Handle, Id, ref m), "sph_collider_get_material");
                return m;
            }
            set
            {
                SphException.Check(Native.sph_collider_set_material(World.Handle, Id, ref value), "sph_collider_set_material");
            }
        }

        /// <summary>As setting Material to these three coefficients.</summary>
        public void SetMaterial(float restitution, float friction, float stickiness)
        {
            var m = ColliderMaterial.Default();
            m.Restitution = restitution;
            m.Friction = friction;
            m.Stickiness = stickiness;
            Material = m;
        }

        /// <summary>The fluid's loads on the collider over the last Step (time averages of the force
        /// and of the torque about the load point, world frame); needs
        /// <see cref="FeatureFlags.ColliderLoads"/>.</summary>
        public ColliderLoads Loads
        {
            get
            {
                var l = ColliderLoads.Default();
                SphException.Check(Native.sph_collider_get_loads(World.Handle, Id, ref l), "sph_collider_get_loads");
                return l;
            }
        }

        /// <summary>The point, in the collider's own frame, that the loads' torque is taken about
        /// (default its origin; pass the body's centre of mass).</summary>
        public void SetLoadPoint(Vec3 point)
        {
            SphException.Check(Native.sph_collider_set_load_point(World.Handle, Id, ref point), "sph_collider_set_load_point");
        }

        /// <summary>After each Step whose mean force on the collider reaches <paramref name="force"/>
        /// newtons, the step reports an EventType.ColliderLoadExceeded event (count: the force in N);
        /// 0 = none.</summary>
        public void SetLoadThreshold(float force)
        {
            SphException.Check(Native.sph_collider_set_load_threshold(World.Handle, Id, force), "sph_collider_set_load_threshold");
        }

        /// <summary>Removes the collider (sph_collider_destroy). Idempotent, and never throws for an object
        /// that is already gone: after its world's Dispose (destroying the world removed it; in
        /// Unity, OnDestroy order is not fixed) or when the library calls the id stale (a Restore
        /// to a save taken before it was made): the Id is cleared and nothing happens. Other
        /// errors throw SphException and keep the Id, e.g. ErrorWorldLocked while a step that
        /// StepBegin started is in flight (StepWait, then Dispose again). A Restore may bring an
        /// object back after its Dispose: <see cref="World.GetCollider"/> with the saved id wraps it
        /// again.</summary>
        public void Dispose()
        {
            if (Id.Bits == 0) return;
            ColliderId id = Id;
            World.RemovePlaced(h => Native.sph_collider_destroy(h, id), "sph_collider_destroy");
            Id = default(ColliderId);
        }
    }

    /// <summary>Emits particles where its region SDF is negative.</summary>
    public sealed class Source : IDisposable
    {
        public World World { get; private set; }
        public SourceId Id { get; private set; }

        internal Source(World world, SourceId id) { World = world; Id = id; }

        public void SetTransform(Transform transform)
        {
            SphException.Check(Native.sph_source_set_transform(World.Handle, Id, ref transform), "sph_source_set_transform");
        }

        /// <summary>Removes the source (sph_source_destroy). Idempotent, and never throws for an object
        /// that is already gone: after its world's Dispose (destroying the world removed it; in
        /// Unity, OnDestroy order is not fixed) or when the library calls the id stale (a Restore
        /// to a save taken before it was made): the Id is cleared and nothing happens. Other
        /// errors throw SphException and keep the Id, e.g. ErrorWorldLocked while a step that
        /// StepBegin started is in flight (StepWait, then Dispose again). A Restore may bring an
        /// object back after its Dispose: <see cref="World.GetSource"/> with the saved id wraps it
        /// again.</summary>
        public void Dispose()
        {
            if (Id.Bits == 0) return;
            SourceId id = Id;
            World.RemovePlaced(h => Native.sph_source_destroy(h, id), "sph_source_destroy");
            Id = default(SourceId);
        }
    }

    /// <summary>Removes particles inside a region or outside bounds.</summary>
    public sealed class Sink : IDisposable
    {
        public World World { get; private set; }
        public SinkId Id { get; private set; }

        internal Sink(World world, SinkId id) { World = world; Id = id; }

        /// <summary>Removes the sink (sph_sink_destroy). Idempotent, and never throws for an object
        /// that is already gone: after its world's Dispose (destroying the world removed it; in
        /// Unity, OnDestroy order is not fixed) or when the library calls the id stale (a Restore
        /// to a save taken before it was made): the Id is cleared and nothing happens. Other
        /// errors throw SphException and keep the Id, e.g. ErrorWorldLocked while a step that
        /// StepBegin started is in flight (StepWait, then Dispose again). A Restore may bring an
        /// object back after its Dispose: <see cref="World.GetSink"/> with the saved id wraps it
        /// again.</summary>
        public void Dispose()
        {
            if (Id.Bits == 0) return;
            SinkId id = Id;
            World.RemovePlaced(h => Native.sph_sink_destroy(h, id), "sph_sink_destroy");
            Id = default(SinkId);
        }
    }

    /// <summary>A point probe or a gauge line, sampled inside every Step (docs/physics.md).</summary>
    public sealed class Probe : IDisposable
    {
        public World World { get; private set; }
        public ProbeId Id { get; private set; }

        internal Probe(World world, ProbeId id) { World = world; Id = id; }

        /// <summary>The reading of the last Step: density, pressure (and its maximum), velocity,
        /// the fluid fraction and, for a gauge, the water height.</summary>
        public ProbeReading Reading
        {
            get
            {
                var r = ProbeReading.Default();
                SphException.Check(Native.sph_probe_get_reading(World.Handle, Id, ref r), "sph_probe_get_reading");
                return r;
            }
        }

        /// <summary>After each Step whose reading's PressureMax reaches <paramref name="pressure"/> Pa,
        /// the step reports an EventType.ProbePressureExceeded event (count: the peak in Pa); 0 = none.</summary>
        public void SetPressureThreshold(float pressure)
        {
            SphException.Check(Native.sph_probe_set_pressure_threshold(World.Handle, Id, pressure), "sph_probe_set_pressure_threshold");
        }

        /// <summary>Removes the probe (sph_probe_destroy). Idempotent, and never throws for an object
        /// that is already gone: after its world's Dispose (destroying the world removed it; in
        /// Unity, OnDestroy order is not fixed) or when the library calls the id stale (a Restore
        /// to a save taken before it was made): the Id is cleared and nothing happens. Other
        /// errors throw SphException and keep the Id, e.g. ErrorWorldLocked while a step that
        /// StepBegin started is in flight (StepWait, then Dispose again). A Restore may bring an
        /// object back after its Dispose: <see cref="World.GetProbe"/> with the saved id wraps it
        /// again.</summary>
        public void Dispose()
        {
            if (Id.Bits == 0) return;
            ProbeId id = Id;
            World.RemovePlaced(h => Native.sph_probe_destroy(h, id), "sph_probe_destroy");
            Id = default(ProbeId);
        }
    }

    /// <summary>Adds an acceleration to particles.</summary>
    public sealed class ForceField : IDisposable
    {
        public World World { get; private set; }
        public ForceFieldId Id { get; private set; }

        internal ForceField(World world, ForceFieldId id) { World = world; Id = id; }

        public void SetTransform(Transform transform)
        {
            SphException.Check(Native.sph_force_field_set_transform(World.Handle, Id, ref transform), "sph_force_field_set_transform");
        }

        /// <summary>Removes the force field (sph_force_field_destroy). Idempotent, and never throws for an object
        /// that is already gone: after its world's Dispose (destroying the world removed it; in
        /// Unity, OnDestroy order is not fixed) or when the library calls the id stale (a Restore
        /// to a save taken before it was made): the Id is cleared and nothing happens. Other
        /// errors throw SphException and keep the Id, e.g. ErrorWorldLocked while a step that
        /// StepBegin started is in flight (StepWait, then Dispose again). A Restore may bring an
        /// object back after its Dispose: <see cref="World.GetForceField"/> with the saved id wraps it
        /// again.</summary>
        public void Dispose()
        {
            if (Id.Bits == 0) return;
            ForceFieldId id = Id;
            World.RemovePlaced(h => Native.sph_force_field_destroy(h, id), "sph_force_field_destroy");
            Id = default(ForceFieldId);
        }
    }
}
