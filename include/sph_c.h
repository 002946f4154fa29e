/* SPDX-License-Identifier: MIT */
/*
 * sph_c.h - the C ABI of the sph fluid-simulation library.
 *
 * Smoothed Particle Hydrodynamics on the CPU and on NVIDIA GPUs, behind a C99 interface
 * that engines and any language with a C FFI can load.
 *
 * Conventions (see docs/api.md for the long form):
 * - Every fallible call returns sph_result: 0 is success, negative values are errors and
 *   positive values mean "incomplete / not ready". On error, sph_get_last_error() returns a
 *   message naming the offending argument, and the object the call was given is unchanged.
 * - Description structs start with struct_size and are filled by their *_init() function;
 *   fields are only ever appended, and zero in a new field keeps the old behaviour.
 * - Zero means default: a def or desc that is all zeros except struct_size is valid and gets
 *   the defaults, or, where a struct cannot be valid without some field (a collider needs an
 *   SDF), the error names that field; each struct's comment says which (docs/api.md lists
 *   them). Where zero is itself a value (a velocity, a restitution), it keeps its meaning.
 * - A world is used from one thread at a time. Different worlds are independent and may be
 *   stepped concurrently from different threads. Version queries, sph_result_string() and
 *   sph_get_last_error() are always thread-safe.
 * - The library never aborts the host process and never lets an exception cross this boundary.
 * - Units are SI (metres, kilograms, seconds) unless a field says otherwise.
 */
#ifndef SPH_C_H
#define SPH_C_H

#include <stddef.h>
#include <stdint.h>

/* ---- version: the one place where the library version is defined ------------------------ */
#define SPH_VERSION_MAJOR 0
#define SPH_VERSION_MINOR 2
#define SPH_VERSION_PATCH 0
/** Packed version: (major << 22) | (minor << 12) | patch. */
#define SPH_MAKE_VERSION(major, minor, patch) \
  ((((uint32_t)(major)) << 22) | (((uint32_t)(minor)) << 12) | ((uint32_t)(patch)))
#define SPH_VERSION SPH_MAKE_VERSION(SPH_VERSION_MAJOR, SPH_VERSION_MINOR, SPH_VERSION_PATCH)
/** ABI version: equals the SONAME major (libsph.so.0). */
#define SPH_ABI_VERSION 0

/* ---- export and calling-convention macros ------------------------------------------------ */
#if defined(_WIN32)
#define SPH_CALL __cdecl
#if defined(SPH_BUILDING_LIBRARY)
#define SPH_API __declspec(dllexport)
#else
#define SPH_API __declspec(dllimport)
#endif
#else
#define SPH_CALL
#if defined(SPH_BUILDING_LIBRARY)
#define SPH_API __attribute__((visibility("default")))
#else
#define SPH_API
#endif
#endif

#if defined(__cplusplus)
#define SPH_STATIC_ASSERT(cond, name) static_assert(cond, #name)
#else
#define SPH_STATIC_ASSERT(cond, name) typedef char sph_static_assert_##name[(cond) ? 1 : -1]
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* ---- results ----------------------------------------------------------------------------- */
typedef enum sph_result {
  SPH_INCOMPLETE = 1,                  /* the call did part of the work; see its doc */
  SPH_OK = 0,                          /* success */
  SPH_ERROR_INVALID_ARGUMENT = -1,     /* NULL, NaN/Inf, out-of-range value, required field left zero */
  SPH_ERROR_INVALID_HANDLE = -2,       /* a NULL, destroyed or foreign object */
  SPH_ERROR_VERSION_MISMATCH = -3,     /* struct_size or header_version not accepted */
  SPH_ERROR_UNSUPPORTED = -4,          /* not compiled in, no such device, unknown enum value */
  SPH_ERROR_FEATURE_DISABLED = -5,     /* the feature was not enabled in the world's def */
  SPH_ERROR_CAPACITY = -6,             /* a size limit: more particles than the world may hold (max_capacity),
                                          too many in one cell, a grid too large; the message names it */
  SPH_ERROR_OUT_OF_HOST_MEMORY = -7,   /* a host allocation failed */
  SPH_ERROR_OUT_OF_DEVICE_MEMORY = -8, /* a device allocation failed */
  SPH_ERROR_WORLD_LOCKED = -9,         /* the world is in use by another call */
  SPH_ERROR_BUSY = -10,                /* the object is still in use (a context with worlds) */
  SPH_ERROR_DEVICE = -11,              /* a recoverable device/driver error */
  SPH_ERROR_DEVICE_LOST = -12,         /* a sticky device error: destroy the world */
  SPH_ERROR_INTERNAL = -13,            /* an invariant failed inside the library (a bug) */
  SPH_ERROR_BUFFER_TOO_SMALL = -14,    /* a caller buffer cannot hold what was asked for */
  SPH_ERROR_NON_FINITE = -15,          /* a step produced NaN/Inf; the world was rolled back */
  SPH_ERROR_CORRUPT_DATA = -16,        /* input data (a checkpoint) is truncated, damaged or inconsistent */
  SPH_RESULT_FORCE32 = 0x7fffffff
} sph_result;

typedef uint32_t sph_bool32;

typedef struct sph_vec3 {
  float x, y, z;
} sph_vec3;

/* ---- enums ------------------------------------------------------------------------------- */
typedef enum sph_backend {
  SPH_BACKEND_AUTO = 0, /* CUDA when a device is present, else the CPU */
  SPH_BACKEND_CPU = 1,  /* the multithreaded reference solver */
  SPH_BACKEND_CUDA = 2, /* NVIDIA GPU; SPH_ERROR_UNSUPPORTED when not built or no device */
  SPH_BACKEND_FORCE32 = 0x7fffffff
} sph_backend;

/* How a CUDA world runs its frames (sph_context_def.cuda_frames; docs/cuda.md). */
typedef enum sph_cuda_frames {
  SPH_CUDA_FRAMES_GRAPH = 0,  /* default: each frame as one CUDA graph where it can (not with sinks) */
  SPH_CUDA_FRAMES_STREAM = 1, /* each frame launched kernel by kernel: for profilers and sanitizers */
  SPH_CUDA_FRAMES_FORCE32 = 0x7fffffff
} sph_cuda_frames;
/** sph_context_def.cuda_dfsph_masks: 0 = on (the default), or this = off. */
#define SPH_CUDA_DFSPH_MASKS_OFF 1u
/** sph_context_def.cuda_dfsph_masks: the masks and, written with them, neighbour lists (0.2.0). */
#define SPH_CUDA_DFSPH_NEIGHBOR_LISTS 2u

typedef enum sph_integrator {
  SPH_INTEGRATOR_SYMPLECTIC_EULER = 0, /* v += a dt, then x += v dt: one force evaluation */
  SPH_INTEGRATOR_RK4 = 1,              /* classic Runge-Kutta: four force evaluations */
  SPH_INTEGRATOR_FORCE32 = 0x7fffffff
} sph_integrator;

typedef enum sph_log_level {
  SPH_LOG_DEBUG = 0,
  SPH_LOG_INFO = 1,
  SPH_LOG_WARNING = 2,
  SPH_LOG_ERROR = 3,
  SPH_LOG_LEVEL_FORCE32 = 0x7fffffff
} sph_log_level;

typedef enum sph_attribute {
  SPH_ATTRIBUTE_POSITION = 0, /* 3 x float32, metres */
  SPH_ATTRIBUTE_VELOCITY = 1, /* 3 x float32, metres per second */
  SPH_ATTRIBUTE_DENSITY = 2,  /* float32, kg/m^3, from the last density evaluation */
  SPH_ATTRIBUTE_PRESSURE = 3, /* float32, Pa (kg m^-1 s^-2 scaled by the EOS), same evaluation;
                                 DFSPH: the pressure both its solves applied in the last substep */
  SPH_ATTRIBUTE_ID = 4,       /* uint32, persistent particle id, unique within a world */
  SPH_ATTRIBUTE_USER = 5,     /* uint32, the caller's value (SPH_FEATURE_USER_ATTRIBUTE) */
  SPH_ATTRIBUTE_COUNT = 6,
  SPH_ATTRIBUTE_FORCE32 = 0x7fffffff
} sph_attribute;

/** Stages of a substep, indices into sph_stats.stage_ms. */
typedef enum sph_stage {
  SPH_STAGE_HASH_SORT = 0,   /* cell hash, stable sort, reorder of every attribute */
  SPH_STAGE_CELL_RANGES = 1, /* start/end of each cell */
  SPH_STAGE_DENSITY = 2,     /* density and pressure */
  SPH_STAGE_FORCES = 3,      /* pressure, viscosity and external forces (DFSPH: and its two solves) */
  SPH_STAGE_INTEGRATE = 4,   /* time integration, max-speed reduction, next step size */
  SPH_STAGE_COLLIDE = 5,     /* particles against colliders (CPU; the CUDA backend does it inside
                                the forces kernel, so it counts under SPH_STAGE_FORCES there) */
  SPH_STAGE_EMIT = 6,        /* sinks removing particles; sources emit before the substeps and
                                count only in sph_stats.step_ms */
  SPH_STAGE_OTHER = 7,       /* everything else: statistics, transfers */
  SPH_STAGE_COUNT = 8,
  SPH_STAGE_FORCE32 = 0x7fffffff
} sph_stage;

/**
 * World feature bits, fixed at world creation. A feature that is off allocates nothing and
 * costs no work (docs/physics.md, docs/performance.md); its parameter calls return
 * SPH_ERROR_FEATURE_DISABLED. Unknown bits are SPH_ERROR_UNSUPPORTED.
 */
typedef uint32_t sph_feature_flags;
#define SPH_FEATURE_NONE 0u
/** Surface tension: the Morris colour field (thesis eq. 20-23) applied as a capillary stress,
 *  plus a short-range cohesion (Akinci et al. 2013) carrying 15 % of sigma; parameters in
 *  sph_surface_tension_params. sigma is the physical N/m: both parts are calibrated on the
 *  particle lattice. Measured at 10 particles per radius: Laplace pressure differences within
 *  6 %, the mode-2 Rayleigh period within 5 %; drops read a bulk pressure of about
 *  0.77 sigma / spacing above 2 sigma / R; needs about 6 or more particles per radius
 *  (docs/physics.md). */
#define SPH_FEATURE_SURFACE_TENSION 0x1u
/** Normalised density (thesis eq. 31): every particle carries a density factor (4 B of state,
 *  sorted, rolled back and saved in checkpoints) so that particles at a free surface or a
 *  collider wall read the bulk's density instead of up to half of it; eq. 31 re-normalises the
 *  carried densities on every density pass (one more gather). Fluid is assumed spawned at or
 *  above rest density; surfaces made later (sinks, splitting) read the plain deficit, and a
 *  tank at rest bends away from the hydrostatic profile near its walls (docs/physics.md). */
#define SPH_FEATURE_NORMALIZED_DENSITY 0x2u
/** Elasticity and plasticity (thesis 4.4.2.1; Clavet, Beaudoin & Poulin 2005): springs between
 *  neighbouring particles, made once per particle at its first substep (so the rest shape is
 *  the spawn shape), with rest lengths that yield and creep; sph_spring_params. Costs about 340
 *  bytes per particle of host memory on the CPU backend (lists, their reorder buffer, link
 *  candidates, acceleration), 468 of device memory on CUDA (docs/physics.md, springs' "Cost"),
 *  and a spring pass per force evaluation. */
#define SPH_FEATURE_SPRINGS 0x4u
/** Walls in the density: every collider's solid counts in the particles' density sums (a
 *  density map per SDF asset, Koschier & Bender 2017, calibrated on the particle lattice), and
 *  the wall pushes back through the pressure force, so particles at a wall no longer read low
 *  density: a resting FCC block from sph_world_fill_box reads rho0 at axis-aligned walls
 *  (77 % without), a settled tank's pressure near its walls is within 3-5 % of rho0 g d at the
 *  default stiffness (48-77 % low without). Edges and corners read high when a lattice is placed
 *  into them (docs/physics.md). The maps are computed per asset and kernel radius when a collider
 *  first steps with the asset and after sph_sdf_update of its distances (16 bytes per SDF voxel;
 *  on the device for CUDA; the CPU recomputes only the voxels within reach of the updated box).
 *  The collision response stays the no-penetration safeguard. Costs one SDF sample per particle
 *  and collider in each density pass. */
#define SPH_FEATURE_BOUNDARY_DENSITY 0x8u
/** Loads on colliders: the force and torque of the fluid on each collider over every step
 *  (sph_collider_get_loads): the collision response's contact impulses and, with
 *  SPH_FEATURE_BOUNDARY_DENSITY, the walls' pressure reactions, summed on the device per substep
 *  in a fixed order (bitwise deterministic) and averaged over the step's time. Costs, per
 *  substep, a reduction over the particles per collider (and with the boundary density one SDF
 *  sample per particle and collider per force evaluation); no host round trip inside a step.
 *  Without SPH_FEATURE_BOUNDARY_DENSITY a body the fluid holds off by its pressure feels none of
 *  it (a submerged box reads almost no buoyancy): sph_world_create logs a warning then. */
#define SPH_FEATURE_COLLIDER_LOADS 0x10u
/** A user attribute: one uint32 per particle that the caller sets and the library never reads (a
 *  colour, a phase or material id): written with sph_world_set_attribute and read with
 *  sph_world_copy_attribute (SPH_ATTRIBUTE_USER), it follows its particle through every sort,
 *  sink and checkpoint. Particles from sph_world_spawn and the fills start at 0; a source's get
 *  its sph_source_def.user_attribute. Costs 4 bytes per particle (and its copy in the rollback
 *  snapshot) and one gather per sort. */
#define SPH_FEATURE_USER_ATTRIBUTE 0x20u
/** Density diffusion (delta-SPH, Molteni & Colagrossi 2009, with the dynamic-density correction
 *  of Fourtakas et al. 2019): a diffusive, conservative term in the carried density's rate that
 *  damps the weakly compressible solver's density and pressure noise without pulling a tank's
 *  hydrostatic stratification towards uniform; sph_density_diffusion_params. Needs
 *  SPH_FEATURE_NORMALIZED_DENSITY (its carried density is the one integrated in time; the
 *  plain summation has no history to diffuse) and SPH_SOLVER_WCSPH (SPH_ERROR_UNSUPPORTED at
 *  creation otherwise); it replaces that feature's Shepard filter (eq. 31 is not applied). A
 *  settled tank's pressure noise within a layer: 65 Pa summed, 12 Pa with the diffusion, 10 Pa
 *  with the filter alone. Costs one gather per substep instead of one per density pass
 *  (docs/physics.md). */
#define SPH_FEATURE_DENSITY_DIFFUSION 0x40u

typedef enum sph_viscosity_method {
  SPH_VISCOSITY_MUELLER = 0, /* Laplacian viscosity (eq. 17), coefficient sph_world_params.viscosity */
  SPH_VISCOSITY_CLAVET = 1,  /* radial impulses between approaching pairs (eq. 18-19),
                                sph_clavet_viscosity_params */
  SPH_VISCOSITY_METHOD_FORCE32 = 0x7fffffff
} sph_viscosity_method;

typedef enum sph_equation_of_state {
  SPH_EOS_IDEAL_GAS = 0, /* the thesis's modified ideal gas p = k (rho - rho0) (eq. 15) */
  SPH_EOS_TAIT = 1,      /* p = B ((rho / rho0)^7 - 1), B = rho0 c^2 / 7, sph_tait_params */
  SPH_EOS_FORCE32 = 0x7fffffff
} sph_equation_of_state;

/** The pressure solver, fixed at world creation (docs/physics.md, "DFSPH: the incompressible solver"). */
typedef enum sph_solver {
  SPH_SOLVER_WCSPH = 0, /* the thesis's weakly compressible SPH: pressure from the equation of
                           state, explicit steps under the acoustic ceiling 0.4 h / c */
  SPH_SOLVER_DFSPH = 1, /* divergence-free SPH (Bender & Koschier 2015, 2017): pressure from two
                           iterative solves that hold the density error below a bound
                           (sph_dfsph_params); steps bounded by the flow speed alone. No equation
                           of state: the stiffness, Tait's parameters and SPH_STEP_LIMIT_ACOUSTIC
                           have no effect. Not with SPH_INTEGRATOR_RK4, SPH_EOS_TAIT or
                           SPH_FEATURE_NORMALIZED_DENSITY (SPH_ERROR_UNSUPPORTED at creation) */
  SPH_SOLVER_FORCE32 = 0x7fffffff
} sph_solver;

/** Step-size limits beyond eq. 32, for sph_world_params.step_limits. */
#define SPH_STEP_LIMIT_ACOUSTIC                                \
  0x1u /* dt <= step_factor h / c, c the EOS's speed of sound  \
          (weakly compressible worlds only; the stability      \
          ceiling holds dt <= 0.4 h / c already, so this binds \
          only with a step_factor below 0.4) */
#define SPH_STEP_LIMIT_FORCE                                                                \
  0x2u /* dt <= step_factor sqrt(h / |a|_max), |a|_max the largest acceleration of the last \
          substep (a world's first substep, or the first after a sudden new force, is not   \
          bound by it) */

/* ---- version and diagnostics (always thread-safe) ---------------------------------------- */

/** The library's packed version (SPH_MAKE_VERSION), which may differ from SPH_VERSION. */
SPH_API uint32_t SPH_CALL sph_get_version(void);
/** The library's ABI version (SPH_ABI_VERSION when the header matches the library). */
SPH_API uint32_t SPH_CALL sph_get_abi_version(void);
/** A static string: version, git revision, compiler, backends and CUDA architectures built. */
SPH_API const char* SPH_CALL sph_get_build_info(void);
/** A static English name for a result code ("SPH_ERROR_CAPACITY: ..."); never NULL. */
SPH_API const char* SPH_CALL sph_result_string(sph_result result);
/**
 * The message of the last failed sph_ call on this thread, or "" if the last call succeeded.
 * Thread-local, UTF-8, never NULL; valid until the next sph_ call on this thread.
 */
SPH_API const char* SPH_CALL sph_get_last_error(void);
/** Number of live contexts and worlds in the process (a leak check for long-lived hosts). */
SPH_API sph_result SPH_CALL sph_get_live_object_count(uint32_t* out_count);

/* ---- context ----------------------------------------------------------------------------- */
typedef struct sph_context sph_context;

/**
 * Log callback. Called only on a thread that is inside an sph_ call on this context (never
 * from internal worker threads). message is valid for the duration of the call. It must return
 * normally: no longjmp out of it (it leaves the thread's later reports silenced and, from a
 * warning, the world locked), and a C++ exception thrown from it is caught and dropped.
 * Nothing reported while it runs reaches it again (docs/api.md, "Result codes and the last
 * error").
 */
typedef void(SPH_CALL* sph_log_fn)(void* user_data, sph_log_level level, sph_result code,
                                   const char* message);

/**
 * The engine's task system (the shape of Box2D v3's b2EnqueueTaskCallback and
 * b2FinishTaskCallback; docs/embedding.md, "Threads"). With one, a CPU context runs every
 * parallel loop of its worlds through it, and each asynchronous step (sph_world_step_begin) as
 * one task of it, and starts no thread of its own.
 *
 * sph_task_fn runs items [first, last) of a task on the calling thread; `worker` is the index
 * of the task system's worker that runs them (the library does not read it; pass what you
 * have). The library's task functions never call back into the library and never throw; they
 * may run on any thread, concurrently with each other. A loop's task never blocks; an
 * asynchronous step's task (one item: the whole frame) enqueues the frame's loops as tasks of
 * their own and waits for each with finish_task, from inside the task (nested tasks).
 *
 * sph_enqueue_task_fn schedules `task` over the items [0, item_count), split into ranges of at
 * least min_range items (the library passes 1), each range one call of task with task_context.
 * It returns a handle that the library passes to finish_task, or NULL once it has run every
 * item itself (then finish_task is not called; for an asynchronous step sph_world_step_begin
 * then returns after the frame). It is called from the thread inside an sph_ call on the world
 * (sph_world_step_begin enqueues its step from the caller's thread) and from inside an
 * asynchronous step's task, on whichever worker runs it: the task system must take tasks from
 * several threads and from its own tasks.
 *
 * sph_finish_task_fn returns once every item of the task behind user_task has run (it may run
 * items itself meanwhile). For an asynchronous step's task it is called by sph_world_step_wait,
 * on the waiting thread (not always the one that began); for a loop, on the thread that enqueued
 * it, which may be a worker inside the step's task: there it must not wait for a worker that
 * cannot come free (run items itself meanwhile, as enkiTS and Jolt's job system do, or keep a
 * worker to spare). Results are the same bits whatever the split or the worker count.
 */
typedef void(SPH_CALL* sph_task_fn)(uint32_t first, uint32_t last, uint32_t worker, void* task_context);
typedef void*(SPH_CALL* sph_enqueue_task_fn)(sph_task_fn task, uint32_t item_count, uint32_t min_range,
                                             void* task_context, void* user_context);
typedef void(SPH_CALL* sph_finish_task_fn)(void* user_task, void* user_context);

/**
 * The engine's host allocator (docs/embedding.md, "Memory"). alloc returns `size` bytes (never
 * 0) aligned to `alignment` (a power of two, at least 16), or NULL when it has none (the call
 * then fails with SPH_ERROR_OUT_OF_HOST_MEMORY and the world is unchanged). free gives back
 * memory that alloc returned, with the size that was asked for. Both may be called from any
 * thread that runs the library's work for the context (the caller's, the world's step thread,
 * a worker or the engine's tasks), concurrently: they must be thread-safe. user_context is
 * passed unchanged.
 */
typedef void*(SPH_CALL* sph_alloc_fn)(size_t size, size_t alignment, void* user_context);
typedef void(SPH_CALL* sph_free_fn)(void* memory, size_t size, void* user_context);

/** Zero means default: a zeroed def is valid (AUTO backend, device 0, every hardware thread,
 *  no logging; header_version 0 skips the header check). */
typedef struct sph_context_def {
  uint32_t struct_size;      /* sizeof(sph_context_def), set by sph_context_def_init */
  uint32_t header_version;   /* SPH_VERSION of the header the caller compiled against; 0 = unchecked */
  sph_backend backend;       /* default SPH_BACKEND_AUTO */
  int32_t device_ordinal;    /* CUDA device; -1 (default) and 0 = device 0 */
  uint32_t cpu_worker_count; /* CPU backend threads; 0 (default) = all hardware threads */
  /* (0.2.0) DFSPH's candidate masks on the CUDA backend (docs/cuda.md): 0 (default) = on: the
     density pass records which of each particle's 27-cell candidates are neighbours (48 bytes a
     particle of capacity) and the solves' passes visit only those; SPH_CUDA_DFSPH_MASKS_OFF = off:
     they walk every candidate (no memory, slower passes); SPH_CUDA_DFSPH_NEIGHBOR_LISTS = the masks
     and, written by the same walk of the density pass, each particle's list of up to 63 neighbours (256 bytes
     more a particle of capacity), which the solves' passes loop over. The same bits every way. A
     CPU context and a weakly compressible world check and ignore it; any other value is
     INVALID_ARGUMENT. */
  uint32_t cuda_dfsph_masks;
  sph_log_fn log_fn;   /* optional; NULL = no logging */
  void* log_user_data; /* passed to log_fn */
  /* Tuning of the CUDA backend (a CPU context checks and ignores it; docs/cuda.md). Results do
     not depend on it: every choice computes the same particles bit for bit, except
     cuda_particle_lanes (the order of the neighbour sums: the last bits). */
  sph_cuda_frames cuda_frames;  /* default SPH_CUDA_FRAMES_GRAPH */
  uint32_t cuda_density_block;  /* threads per block of the density kernels: 0 (default) = 128, or
                                   32, 64, 128, 256, 512, 1024 (a kernel whose registers do not
                                   fit that many runs at the most that fit) */
  uint32_t cuda_force_block;    /* threads per block of the force kernels: 0 (default) = 128, or as above */
  uint32_t cuda_particle_lanes; /* threads per particle of the density and force passes (0.2.0): 0
                                   (default) = chosen by the library from the particle count (more
                                   lanes for small worlds, docs/cuda.md), or 1, 2, 4, 8 (a
                                   measurement knob: each sums neighbours in its own fixed order) */
  /* The engine's task system (0.2.0): both or neither; NULL (default) = the library's OpenMP
     workers. A CPU context uses it for every parallel loop of its worlds and runs each
     asynchronous step as one task of it; cpu_worker_count then only decides whether a loop runs
     in parallel (1: every loop on the calling thread). A CUDA context checks and ignores it. */
  sph_enqueue_task_fn enqueue_task;
  sph_finish_task_fn finish_task;
  void* task_user_context; /* passed to enqueue_task and finish_task */
  /* The engine's host allocator (0.2.0): both or neither; NULL (default) = the system heap.
     Every host allocation for the context's worlds and SDF assets goes through it (particle
     arrays, neighbour grids, scratch, rollback snapshots, checkpoint buffers, colliders,
     sources, sinks, probes, SDF grids and assets, boundary maps, per-frame lists) except: the
     context object, each world's handle record, World and backend objects and their array
     records (15 allocations, 3.4 KB, for a plain CPU world; none in a step) and step thread, error messages
     and the last-error text, and on CUDA the page-locked staging buffers (cudaMallocHost). Device memory:
     sph_cuda_context_set_allocator. */
  sph_alloc_fn alloc_fn;
  sph_free_fn free_fn;
  void* alloc_user_context; /* passed to alloc_fn and free_fn */
} sph_context_def;
SPH_STATIC_ASSERT(sizeof(sph_context_def) == 40 + 8 * sizeof(void*), sph_context_def_size);

/** Fills def with defaults; size is sizeof(*def). Prefer sph_context_def_init. */
SPH_API sph_result SPH_CALL sph_context_def_init_sized(sph_context_def* def, uint32_t size);
static inline sph_result sph_context_def_init(sph_context_def* def) {
  sph_result r = sph_context_def_init_sized(def, (uint32_t)sizeof(*def));
  if (r == SPH_OK) def->header_version = SPH_VERSION;
  return r;
}

/**
 * Creates a context: a backend (CPU or one CUDA device) that worlds are created on.
 * Errors: INVALID_ARGUMENT (NULL, bad field: a cuda_*_block that is not 0 or a power of two from
 * 32 to 1024, say), VERSION_MISMATCH (struct_size or a newer-major header), UNSUPPORTED (CUDA
 * asked for but not built or no device; an unknown backend or cuda_frames value),
 * OUT_OF_HOST_MEMORY. *out is written only on success. Thread-safe.
 */
SPH_API sph_result SPH_CALL sph_context_create(const sph_context_def* def, sph_context** out);
/**
 * Destroys a context. NULL is a no-op. BUSY while worlds or SDF assets created on it are alive,
 * or while another thread is creating one on it.
 */
SPH_API sph_result SPH_CALL sph_context_destroy(sph_context* context);
/** The backend the context resolved to (CPU or CUDA; never AUTO). */
SPH_API sph_result SPH_CALL sph_context_get_backend(const sph_context* context, sph_backend* out_backend);

/* ---- world ------------------------------------------------------------------------------- */
typedef struct sph_world sph_world;

/** Creation-time description of a world; fixed for the world's life. Zero means default for
 *  every field: a zeroed def is the def sph_world_def_init gives. */
typedef struct sph_world_def {
  uint32_t struct_size;                    /* sizeof(sph_world_def), set by sph_world_def_init */
  uint32_t header_version;                 /* SPH_VERSION of the caller's header; 0 = unchecked */
  uint32_t capacity;                       /* particles the world has room for at creation; 0
                                              (default) = 65536; at most 2^30. A world whose
                                              max_capacity is larger grows past it on demand. */
  sph_feature_flags features;              /* SPH_FEATURE_* bits; default SPH_FEATURE_NONE */
  sph_integrator integrator;               /* default SPH_INTEGRATOR_SYMPLECTIC_EULER */
  sph_viscosity_method viscosity_method;   /* default SPH_VISCOSITY_MUELLER */
  float particle_spacing;                  /* nearest-neighbour distance of the FCC lattice, m;
                                              0 (default) = 0.02 */
  float kernel_radius;                     /* h, m; 0 (default) = 1.8 * spacing; in (spacing, 5 * spacing]:
                                              h within about 3e-6 spacings of the spacing is
                                              refused (the lattice's nearest neighbours would lie
                                              on the kernel's edge) */
  float rest_density;                      /* rho0, kg/m^3; 0 (default) = 1000 (water) */
  sph_equation_of_state equation_of_state; /* default SPH_EOS_IDEAL_GAS */
  sph_solver solver;                       /* default SPH_SOLVER_WCSPH */
  /* Most particles the world may grow to (docs/api.md, "Growable worlds"); 0 (default) =
     capacity: a fixed world, as before growable worlds. Otherwise >= capacity and at most 2^30.
     A spawn, fill or source emission that needs more room than the world has reallocates its
     particle storage to max(needed, 2 x capacity), clamped to max_capacity (amortised: a world
     grown one particle at a time reallocates O(log n) times). Checkpoints keep both. */
  uint32_t max_capacity;
} sph_world_def;
SPH_STATIC_ASSERT(sizeof(sph_world_def) == 48, sph_world_def_size);

SPH_API sph_result SPH_CALL sph_world_def_init_sized(sph_world_def* def, uint32_t size);
static inline sph_result sph_world_def_init(sph_world_def* def) {
  sph_result r = sph_world_def_init_sized(def, (uint32_t)sizeof(*def));
  if (r == SPH_OK) def->header_version = SPH_VERSION;
  return r;
}

/**
 * Creates an empty world on a context. The particle mass is derived here: the mass at which
 * an FCC lattice at particle_spacing has exactly rest_density (sph_world_get_particle_mass).
 * Errors: INVALID_HANDLE (context NULL or lost), INVALID_ARGUMENT (a field out of range:
 * capacity above 2^30, max_capacity non-zero and below capacity or above 2^30, spacing < 0 or
 * non-finite, kernel_radius outside (spacing, 5 * spacing], rest_density < 0),
 * UNSUPPORTED (unknown integrator, feature bit, method or solver; a combination a solver does
 * not support, see sph_solver), VERSION_MISMATCH, OUT_OF_HOST_MEMORY,
 * OUT_OF_DEVICE_MEMORY. *out is written only on success.
 */
SPH_API sph_result SPH_CALL sph_world_create(sph_context* context, const sph_world_def* def, sph_world** out);
/**
 * Destroys a world and everything in it. NULL is a no-op. It takes the world like every call
 * that takes a world: WORLD_LOCKED while another thread's call is inside it (destroy again
 * once that call returned); a call that races a destroy that won gets INVALID_HANDLE. Memory a
 * call is using is never freed.
 */
SPH_API sph_result SPH_CALL sph_world_destroy(sph_world* world);
/** The def the world was created with, with defaults resolved (zeros and kernel_radius filled in),
 *  except capacity, which reads the world's current capacity (larger than the def's once the
 *  world grew; never more than max_capacity). */
SPH_API sph_result SPH_CALL sph_world_get_def(const sph_world* world, sph_world_def* out_def);
/** Mass of every particle, kg. */
SPH_API sph_result SPH_CALL sph_world_get_particle_mass(const sph_world* world, float* out_mass);

/* ---- runtime parameters ------------------------------------------------------------------
 * Every params struct that is all zeros but for struct_size is valid. A field whose 0 was never
 * a valid value takes its default when 0 ("0 = default"); a field where 0 is itself a physical
 * value keeps it ("0 is ..."): a zeroed sph_world_params has no gravity and no viscosity.
 * sph_params_get_field_info() says the same per field. The getters return the values in use
 * (a 0 that took a default reads back as the default). */
typedef struct sph_world_params {
  uint32_t struct_size;  /* sizeof(sph_world_params), set by sph_world_params_init */
  uint32_t max_substeps; /* most substeps one sph_world_step may take; default 10000; 0 = default;
                            at most 1000000 (a bound on one call's cost; see also the step budget) */
  sph_vec3 gravity;      /* m/s^2; default (0, -9.81, 0); finite; 0 is no gravity */
  float stiffness;       /* k of p = k (rho - rho0), m^2/s^2 (the squared numerical sound speed);
                            default 100; > 0; 0 = default. Every substep is at most 0.4 h / sqrt(k)
                            whatever dt_max says (the stability ceiling, below). */
  float viscosity;       /* mu of Mueller's Laplacian viscosity (a numerical viscosity, not
                            water's 0.001 Pa s); default 1; >= 0; 0 is an inviscid fluid */
  float step_factor;     /* lambda of dt = lambda h / v_max; default 0.4; in (0, 10]; 0 = default */
  float dt_min;          /* s; default 1e-6; > 0; 0 = default */
  float dt_max;          /* s; default 1e-3; >= dt_min (after defaults); 0 = default. Whatever
                            dt_max and step_factor say, a substep is also at most the stability
                            ceiling, 0.4 h / c (c the sound speed: sqrt(stiffness) for the ideal
                            gas) and 0.05 h^2 rho0 / viscosity (Mueller's): a larger dt_max or
                            step_factor past it changes nothing; dt_min wins over it
                            (docs/physics.md, "The step controller's stability ceiling") */
  uint32_t step_limits;  /* SPH_STEP_LIMIT_* bits; default 0 (eq. 32 alone) */
  uint32_t reserved0;    /* must be 0 */
  float tension_ratio;   /* (0.2.0) tau, dimensionless: the equation of state (both laws) holds down to
                            (1 - tau) rho0 and keeps its value there below it, a bounded tension
                            (-k tau rho0 for the ideal gas); default 0, the clamp at zero below
                            rho0; in [0, 0.125]; 0 is the clamp. It lets a disturbed fluid pull
                            back instead of swelling. Use it with SPH_FEATURE_NORMALIZED_DENSITY:
                            with the plain summation density every free-surface particle sits below
                            the floor and takes the whole tension, and the surface clumps and sheds
                            (docs/physics.md, "The equation of state's floor"). No effect with DFSPH */
} sph_world_params;
SPH_STATIC_ASSERT(sizeof(sph_world_params) == 52, sph_world_params_size);

SPH_API sph_result SPH_CALL sph_world_params_init_sized(sph_world_params* params, uint32_t size);
static inline sph_result sph_world_params_init(sph_world_params* params) {
  return sph_world_params_init_sized(params, (uint32_t)sizeof(*params));
}
/** Replaces all runtime parameters at once; validated as a whole, nothing changes on error. */
SPH_API sph_result SPH_CALL sph_world_set_params(sph_world* world, const sph_world_params* params);
/** Reads all runtime parameters; out->struct_size must be set (sph_world_params_init). */
SPH_API sph_result SPH_CALL sph_world_get_params(const sph_world* world, sph_world_params* out);

/* ---- parameters of optional physics (each its own struct, set and read whole) ----------- */
typedef struct sph_surface_tension_params {
  uint32_t struct_size;   /* set by sph_surface_tension_params_init */
  float coefficient;      /* sigma, N/m; default 0.0728 (water at 20 C); >= 0; 0 is no tension */
  float normal_threshold; /* |grad c| above which a particle counts as surface, 1/m; 0 (default)
                             = 0.2 / kernel_radius; >= 0 */
  uint32_t reserved0;     /* must be 0 */
} sph_surface_tension_params;
SPH_STATIC_ASSERT(sizeof(sph_surface_tension_params) == 16, sph_surface_tension_params_size);

SPH_API sph_result SPH_CALL sph_surface_tension_params_init_sized(sph_surface_tension_params* params,
                                                                  uint32_t size);
static inline sph_result sph_surface_tension_params_init(sph_surface_tension_params* params) {
  return sph_surface_tension_params_init_sized(params, (uint32_t)sizeof(*params));
}
/** FEATURE_DISABLED unless the world has SPH_FEATURE_SURFACE_TENSION. */
SPH_API sph_result SPH_CALL sph_world_set_surface_tension_params(sph_world* world,
                                                                 const sph_surface_tension_params* params);
SPH_API sph_result SPH_CALL sph_world_get_surface_tension_params(const sph_world* world,
                                                                 sph_surface_tension_params* out);

typedef struct sph_clavet_viscosity_params {
  uint32_t struct_size; /* set by sph_clavet_viscosity_params_init */
  float linear;         /* sigma of I = dt (1 - q)(sigma u + beta u^2), 1/s; default 10; >= 0;
                           0 is no linear term (beta alone, Clavet's choice for thin fluids) */
  float quadratic;      /* beta, 1/m; default 0; >= 0; 0 is no quadratic term */
  uint32_t reserved0;   /* must be 0 */
} sph_clavet_viscosity_params;
SPH_STATIC_ASSERT(sizeof(sph_clavet_viscosity_params) == 16, sph_clavet_viscosity_params_size);

SPH_API sph_result SPH_CALL sph_clavet_viscosity_params_init_sized(sph_clavet_viscosity_params* params,
                                                                   uint32_t size);
static inline sph_result sph_clavet_viscosity_params_init(sph_clavet_viscosity_params* params) {
  return sph_clavet_viscosity_params_init_sized(params, (uint32_t)sizeof(*params));
}
/** FEATURE_DISABLED unless the world's viscosity_method is SPH_VISCOSITY_CLAVET. */
SPH_API sph_result SPH_CALL sph_world_set_clavet_viscosity_params(sph_world* world,
                                                                  const sph_clavet_viscosity_params* params);
SPH_API sph_result SPH_CALL sph_world_get_clavet_viscosity_params(const sph_world* world,
                                                                  sph_clavet_viscosity_params* out);

typedef struct sph_tait_params {
  uint32_t struct_size; /* set by sph_tait_params_init */
  float speed_of_sound; /* c, m/s; default 10; > 0; 0 = default. Use >= 10 x the fastest flow
                           speed to keep density errors near 1 %; lower dt_max (or
                           SPH_STEP_LIMIT_ACOUSTIC) so that c dt stays below about 0.4 h */
} sph_tait_params;
SPH_STATIC_ASSERT(sizeof(sph_tait_params) == 8, sph_tait_params_size);

SPH_API sph_result SPH_CALL sph_tait_params_init_sized(sph_tait_params* params, uint32_t size);
static inline sph_result sph_tait_params_init(sph_tait_params* params) {
  return sph_tait_params_init_sized(params, (uint32_t)sizeof(*params));
}
/** FEATURE_DISABLED unless the world's equation_of_state is SPH_EOS_TAIT. */
SPH_API sph_result SPH_CALL sph_world_set_tait_params(sph_world* world, const sph_tait_params* params);
SPH_API sph_result SPH_CALL sph_world_get_tait_params(const sph_world* world, sph_tait_params* out);

typedef struct sph_spring_params {
  uint32_t struct_size; /* set by sph_spring_params_init */
  float stiffness;      /* k of a = -k (1 - L/h)(r - L), 1/s^2 (acceleration per metre of
                           stretch); default 1e4; >= 0; 0 is no elastic force. Young's modulus
                           of an FCC block is about (2/3) rho0 s^2 k (1 - s/h) (s: particle
                           spacing). Stiffer springs shorten the step: dt <= 0.5 / sqrt(16 k) */
  float link_radius;    /* springs are made to neighbours closer than this, m; 0 (default) =
                           1.2 x particle_spacing (the lattice's 12 nearest neighbours);
                           <= kernel_radius. Applies to particles linked after the change */
  float yield_ratio;    /* gamma: a spring deforms plastically beyond r = L (1 +- gamma);
                           default 0.1; [0, 1]; 0 is a value (every deformation yields) */
  float plasticity;     /* alpha, 1/s: how fast rest lengths creep toward the deformed length
                           beyond the yield band; default 0 (0 is purely elastic); >= 0. A rest
                           length that grows past kernel_radius drops its spring */
  float damping;        /* c of a = -c (v_i - v_j) . r^ along each spring, 1/s; default 0 (0 is
                           no damping); >= 0. Shortens the step: dt <= 2 / (16 c) */
  uint32_t reserved0;   /* must be 0 */
} sph_spring_params;
SPH_STATIC_ASSERT(sizeof(sph_spring_params) == 28, sph_spring_params_size);

SPH_API sph_result SPH_CALL sph_spring_params_init_sized(sph_spring_params* params, uint32_t size);
static inline sph_result sph_spring_params_init(sph_spring_params* params) {
  return sph_spring_params_init_sized(params, (uint32_t)sizeof(*params));
}
/** FEATURE_DISABLED unless the world has SPH_FEATURE_SPRINGS. INVALID_ARGUMENT for a value out
 *  of range (the message names it); nothing changes on error. Springs already made keep their
 *  rest lengths; the new stiffness, damping and plasticity act from the next substep. */
SPH_API sph_result SPH_CALL sph_world_set_spring_params(sph_world* world, const sph_spring_params* params);
SPH_API sph_result SPH_CALL sph_world_get_spring_params(const sph_world* world, sph_spring_params* out);

typedef struct sph_density_diffusion_params {
  uint32_t struct_size; /* set by sph_density_diffusion_params_init */
  float delta;          /* delta of the delta-SPH term D_i = delta h c0 sum_j psi_ij . grad W_ij V_j
                           (c0 the equation of state's speed of sound); dimensionless; default
                           0.1; in (0, 1]; 0 = default */
} sph_density_diffusion_params;
SPH_STATIC_ASSERT(sizeof(sph_density_diffusion_params) == 8, sph_density_diffusion_params_size);

SPH_API sph_result SPH_CALL sph_density_diffusion_params_init_sized(sph_density_diffusion_params* params,
                                                                    uint32_t size);
static inline sph_result sph_density_diffusion_params_init(sph_density_diffusion_params* params) {
  return sph_density_diffusion_params_init_sized(params, (uint32_t)sizeof(*params));
}
/** FEATURE_DISABLED unless the world has SPH_FEATURE_DENSITY_DIFFUSION. INVALID_ARGUMENT for a
 *  value out of range (the message names it); nothing changes on error. Acts from the next
 *  substep. */
SPH_API sph_result SPH_CALL
sph_world_set_density_diffusion_params(sph_world* world, const sph_density_diffusion_params* params);
SPH_API sph_result SPH_CALL sph_world_get_density_diffusion_params(const sph_world* world,
                                                                   sph_density_diffusion_params* out);

/** sph_dfsph_params.flags */
#define SPH_DFSPH_SKIP_DIVERGENCE_SOLVE 0x1u /* no divergence solve (cheaper; a noisier pressure) */
#define SPH_DFSPH_CORRECTED_GRADIENT                                                                         \
  0x2u /* the Jacobi solves' pressure gradient corrected to first order (Bonet & Lok's L_i; docs/physics.md, \
          DFSPH): a resting fluid's pressure within 0.5 % of rho0 g d, but momentum only nearly conserved    \
          and energy not bounded in violent flow; with SPH_DFSPH_JACOBI only */
#define SPH_DFSPH_NO_DEPTH_STEP_LIMIT                                                                      \
  0x4u /* (0.2.0) the depth step limit off (sph_dfsph_params.depth_step_factor): for a scene whose step is \
          known to hold still water of its depth, or whose lowest and highest water are far apart */
/** sph_dfsph_params.linear_solver (docs/physics.md, DFSPH) */
#define SPH_DFSPH_JACOBI 1u /* the Jacobi step of Bender & Koschier (the default) */
#define SPH_DFSPH_CONJUGATE_GRADIENTS                    \
  2u /* Jacobi-preconditioned conjugate gradients on the \
         compressed particles */
#define SPH_DFSPH_CHEBYSHEV                                                                                 \
  3u /* (0.2.0) the Jacobi steps accelerated by Chebyshev's semi-iteration, an expanded particle's          \
         pressure released step by step: about half the iterations up to ~1e5 particles (measured); at      \
         1e6 on the GPU 1.5x less wall time (docs/physics.md); a solve whose error grows past its bound and \
        twice its smallest takes the plain steps for the rest of it (counted:                               \
        sph_stats.pressure_solves_guarded). CPU and CUDA backends */

typedef struct sph_dfsph_params {
  uint32_t struct_size;               /* set by sph_dfsph_params_init */
  float density_error;                /* bound on the density solve's mean error, the mean over the
                                         particles of max(rho* - rho0, 0) / rho0 (rho*: the density
                                         the step would give); dimensionless; default 0.001
                                         (0.1 %); in (0, 1]; 0 = default */
  float divergence_error;             /* bound on the divergence solve's mean of
                                         max(D rho / Dt, 0) / rho0, 1/s; default 1; > 0; 0 = default.
                                         The solve stops at the looser of this and
                                         divergence_error_per_step / dt */
  uint32_t max_iterations;            /* cap of the density solve per substep; default 100; >= 2;
                                         0 = default. A solve that stops here above its bound is
                                         counted in sph_stats and reported as an event */
  uint32_t max_divergence_iterations; /* cap of the divergence solve; default 100; >= 1; 0 = default */
  uint32_t flags;                     /* SPH_DFSPH_* bits; default 0 */
  uint32_t linear_solver;             /* how the density solve iterates: SPH_DFSPH_JACOBI (the default),
                                         SPH_DFSPH_CONJUGATE_GRADIENTS or SPH_DFSPH_CHEBYSHEV (the
                                         divergence solve is always Jacobi); 0 = default; any other value
                                         is INVALID_ARGUMENT. Chebyshev runs on the CPU and CUDA
                                         backends, not with SPH_DFSPH_CORRECTED_GRADIENT
                                         (INVALID_ARGUMENT). Conjugate gradients run on the CPU and
                                         CUDA backends, distributed worlds included; with
                                         SPH_FEATURE_BOUNDARY_DENSITY or SPH_FEATURE_COLLIDER_LOADS
                                         setting it (or loading a checkpoint with it) is
                                         UNSUPPORTED, the world unchanged */
  float density_error_max;            /* (0.2.0) bound on the density solve's largest error, max(rho* -
                                         rho0, 0) / rho0 of any one particle: the density solve (Jacobi
                                         or conjugate gradients) iterates while this or the mean is
                                         above its bound (then the cap); default
                                         0.05 (5 %); in (0, 1]; 0 = default; a value below
                                         density_error acts as density_error. Without it a small
                                         violent region of a large world (a splash at a wall) stays
                                         compressed by 50-100 %, as it barely moves the mean */
  float depth_step_factor;            /* (0.2.0) f of the depth step limit dt <= f h / sqrt(|g| H), H the
                                         fluid's extent along gravity (its highest particle's height
                                         above its lowest), measured every substep: still water held
                                         by DFSPH blows apart above about 0.37 h / sqrt(|g| depth)
                                         (docs/physics.md, DFSPH, Limits); default 0.3; in (0, 1];
                                         0 = default. No limit without gravity or with
                                         SPH_DFSPH_NO_DEPTH_STEP_LIMIT; dt_min still wins */
  float divergence_error_per_step;    /* (0.2.0) the divergence solve's bound as a share of rho0 a
                                         step, the mean of max(D rho / Dt, 0) / rho0 times dt: the
                                         solve stops once its mean rate is below divergence_error or
                                         below this over dt, whichever is looser (at the defaults the
                                         rate governs steps above 1 ms, which only a dt_max raised
                                         above its default 1 ms allows; this share shorter ones, where
                                         a fixed rate alone made the divergence solve the costlier
                                         one: docs/physics.md, DFSPH); default 0.001 (0.1 %, as
                                         SPlisHSPlasH); in (0, 1]; 0 = default. A tiny value (1e-9)
                                         leaves the rate alone, a tiny divergence_error this alone */
} sph_dfsph_params;
SPH_STATIC_ASSERT(sizeof(sph_dfsph_params) == 40, sph_dfsph_params_size);

SPH_API sph_result SPH_CALL sph_dfsph_params_init_sized(sph_dfsph_params* params, uint32_t size);
static inline sph_result sph_dfsph_params_init(sph_dfsph_params* params) {
  return sph_dfsph_params_init_sized(params, (uint32_t)sizeof(*params));
}
/** FEATURE_DISABLED unless the world's solver is SPH_SOLVER_DFSPH. INVALID_ARGUMENT for a value
 *  out of range (the message names it); nothing changes on error. Acts from the next substep. */
SPH_API sph_result SPH_CALL sph_world_set_dfsph_params(sph_world* world, const sph_dfsph_params* params);
SPH_API sph_result SPH_CALL sph_world_get_dfsph_params(const sph_world* world, sph_dfsph_params* out);

/* ---- every params struct by kind, and what tools need to know about them ----------------
 * The physics methods and their parameters described as data (after SPlisHSPlasH's parameter
 * objects), so that a tool (a scene format, an editor, a binding) can list, read, range-check
 * and set every method's parameters without code of its own per method; sph-run's scene files
 * use nothing else (docs/scenes.md, "physics"). The descriptions are static: they need no
 * world, are thread-safe and name the same rules the set calls apply. */
typedef enum sph_params_kind {
  SPH_PARAMS_WORLD = 0,             /* sph_world_params */
  SPH_PARAMS_SURFACE_TENSION = 1,   /* sph_surface_tension_params */
  SPH_PARAMS_CLAVET_VISCOSITY = 2,  /* sph_clavet_viscosity_params */
  SPH_PARAMS_TAIT = 3,              /* sph_tait_params */
  SPH_PARAMS_SPRINGS = 4,           /* sph_spring_params */
  SPH_PARAMS_DFSPH = 5,             /* sph_dfsph_params */
  SPH_PARAMS_DENSITY_DIFFUSION = 6, /* sph_density_diffusion_params */
  SPH_PARAMS_KIND_COUNT = 7,
  SPH_PARAMS_KIND_FORCE32 = 0x7fffffff
} sph_params_kind;

/**
 * Replaces the params struct of `kind` at once, as its typed set call does (sph_world_set_params,
 * sph_world_set_tait_params, ...): params points to that struct, struct_size first.
 * Errors: those of the typed call; UNSUPPORTED for an unknown kind.
 */
SPH_API sph_result SPH_CALL sph_world_set_physics_params(sph_world* world, sph_params_kind kind,
                                                         const void* params);
/** Reads the params struct of `kind`, as its typed get call does; out->struct_size must be set. */
SPH_API sph_result SPH_CALL sph_world_get_physics_params(const sph_world* world, sph_params_kind kind,
                                                         void* out);

typedef struct sph_params_info {
  uint32_t struct_size;  /* set by sph_params_info_init */
  uint32_t params_size;  /* sizeof the params struct in this library */
  uint32_t field_count;  /* its described fields (reserved fields are not described) */
  uint32_t reserved0;    /* 0 */
  const char* name;      /* "tait", "world": a scene file's key; static, never NULL */
  const char* type_name; /* "sph_tait_params"; static, never NULL */
} sph_params_info;
SPH_STATIC_ASSERT(sizeof(sph_params_info) == 16 + 2 * sizeof(void*), sph_params_info_size);

SPH_API sph_result SPH_CALL sph_params_info_init_sized(sph_params_info* info, uint32_t size);
static inline sph_result sph_params_info_init(sph_params_info* info) {
  return sph_params_info_init_sized(info, (uint32_t)sizeof(*info));
}
/** Describes the params struct of `kind`. UNSUPPORTED for an unknown kind. */
SPH_API sph_result SPH_CALL sph_params_get_info(sph_params_kind kind, sph_params_info* out);

typedef enum sph_param_type {
  SPH_PARAM_FLOAT = 0,  /* float, finite */
  SPH_PARAM_VEC3 = 1,   /* sph_vec3, every component finite */
  SPH_PARAM_UINT32 = 2, /* uint32_t count */
  SPH_PARAM_FLAGS = 3,  /* uint32_t bit set: only the bits of upper may be set */
  SPH_PARAM_TYPE_FORCE32 = 0x7fffffff
} sph_param_type;

typedef enum sph_param_bound {
  SPH_BOUND_NONE = 0,      /* no bound on this side */
  SPH_BOUND_INCLUSIVE = 1, /* the value may equal it */
  SPH_BOUND_EXCLUSIVE = 2, /* the value must pass it */
  SPH_BOUND_FORCE32 = 0x7fffffff
} sph_param_bound;

/** What a 0 in a field asks for (the zero rule at "runtime parameters" above). */
typedef enum sph_param_zero {
  SPH_PARAM_ZERO_IS_VALUE = 0,   /* 0 is itself a value (no gravity, no damping) */
  SPH_PARAM_ZERO_IS_DEFAULT = 1, /* 0 takes default_value */
  SPH_PARAM_ZERO_IS_DERIVED = 2, /* 0 asks for a value derived from the world (see the field's doc) */
  SPH_PARAM_ZERO_FORCE32 = 0x7fffffff
} sph_param_zero;

typedef struct sph_param_field_info {
  uint32_t struct_size;        /* set by sph_param_field_info_init */
  uint32_t offset;             /* byte offset of the field in its params struct */
  sph_param_type type;         /* how to read it at offset */
  sph_param_zero zero;         /* what a 0 in it asks for */
  sph_param_bound lower_bound; /* the range of valid values (not for SPH_PARAM_VEC3) */
  sph_param_bound upper_bound;
  double lower;
  double upper;           /* SPH_PARAM_FLAGS: the bits this library knows */
  float default_value[3]; /* the default ([0] only, but for SPH_PARAM_VEC3) */
  uint32_t reserved0;     /* 0 */
  const char* name;       /* "speed_of_sound": the struct's field name; static, never NULL */
  const char* unit;       /* SI unit ("m/s"), "" when dimensionless; static, never NULL */
} sph_param_field_info;
SPH_STATIC_ASSERT(sizeof(sph_param_field_info) == 56 + 2 * sizeof(void*), sph_param_field_info_size);

SPH_API sph_result SPH_CALL sph_param_field_info_init_sized(sph_param_field_info* info, uint32_t size);
static inline sph_result sph_param_field_info_init(sph_param_field_info* info) {
  return sph_param_field_info_init_sized(info, (uint32_t)sizeof(*info));
}
/**
 * Describes field `index` (0 .. field_count - 1, in the order of the struct) of the params
 * struct of `kind`. Cross-field rules (dt_max >= dt_min; a spring link radius at most h) are
 * checked by the set calls only. UNSUPPORTED for an unknown kind, INVALID_ARGUMENT for an index
 * past the last field.
 */
SPH_API sph_result SPH_CALL sph_params_get_field_info(sph_params_kind kind, uint32_t index,
                                                      sph_param_field_info* out);

/** How a world turns a method on: which field of sph_world_def selects it. */
typedef enum sph_method_switch {
  SPH_METHOD_SWITCH_FEATURE = 1,           /* a bit of sph_world_def.features (value) */
  SPH_METHOD_SWITCH_VISCOSITY = 2,         /* sph_world_def.viscosity_method == value */
  SPH_METHOD_SWITCH_EQUATION_OF_STATE = 3, /* sph_world_def.equation_of_state == value */
  SPH_METHOD_SWITCH_SOLVER = 4,            /* sph_world_def.solver == value */
  SPH_METHOD_SWITCH_FORCE32 = 0x7fffffff
} sph_method_switch;

typedef struct sph_physics_method_info {
  uint32_t struct_size;        /* set by sph_physics_method_info_init */
  uint32_t method_count;       /* how many methods this library has (index runs below it) */
  sph_method_switch switch_by; /* the sph_world_def field that selects it */
  uint32_t value;              /* the SPH_FEATURE_* bit, sph_viscosity_method, sph_equation_of_state or
                                  sph_solver */
  uint32_t has_params;         /* 1 when its parameters are in the struct of params_kind */
  sph_params_kind params_kind; /* SPH_PARAMS_WORLD for the thesis's defaults (stiffness, viscosity) */
  const char* name;            /* "clavet", "surface_tension": a scene file's name; static */
} sph_physics_method_info;
SPH_STATIC_ASSERT(sizeof(sph_physics_method_info) == 24 + sizeof(void*), sph_physics_method_info_size);

SPH_API sph_result SPH_CALL sph_physics_method_info_init_sized(sph_physics_method_info* info, uint32_t size);
static inline sph_result sph_physics_method_info_init(sph_physics_method_info* info) {
  return sph_physics_method_info_init_sized(info, (uint32_t)sizeof(*info));
}
/** Describes method `index` (0 .. method_count - 1; index 0 always exists and tells how many
 *  there are). INVALID_ARGUMENT past the last one. */
SPH_API sph_result SPH_CALL sph_get_physics_method_info(uint32_t index, sph_physics_method_info* out);

/* ---- particles in -------------------------------------------------------------------------- */
/** Zero means default: a zeroed desc spawns nothing (count 0); positions is required once
 *  count > 0 (INVALID_ARGUMENT naming desc->positions). */
typedef struct sph_spawn_desc {
  uint32_t struct_size;     /* sizeof(sph_spawn_desc), set by sph_spawn_desc_init */
  uint32_t count;           /* particles to add; 0 is allowed and adds nothing */
  const float* positions;   /* count x (x, y, z) float32, caller-owned, copied; required when count > 0 */
  const float* velocities;  /* count x (x, y, z) float32, or NULL for zero velocity */
  uint64_t position_stride; /* bytes between particles; 0 = 12 (packed) */
  uint64_t velocity_stride; /* bytes between particles; 0 = 12 (packed) */
} sph_spawn_desc;
SPH_STATIC_ASSERT(sizeof(sph_spawn_desc) == 24 + 2 * sizeof(void*), sph_spawn_desc_size);

SPH_API sph_result SPH_CALL sph_spawn_desc_init_sized(sph_spawn_desc* desc, uint32_t size);
static inline sph_result sph_spawn_desc_init(sph_spawn_desc* desc) {
  return sph_spawn_desc_init_sized(desc, (uint32_t)sizeof(*desc));
}

/**
 * Adds particles from caller arrays (copied before return). All-or-nothing: on any error
 * (non-finite value, a speed of 1.8e19 m/s or more, whose square float32 cannot hold; strides
 * whose span overflows 64 bits; more particles than max_capacity leaves room for:
 * SPH_ERROR_CAPACITY, naming the limit; a growth the host or device cannot allocate:
 * OUT_OF_HOST_MEMORY / OUT_OF_DEVICE_MEMORY) nothing is added and the capacity is as it was.
 * A world with room up to its max_capacity grows first (sph_world_def.max_capacity).
 * out_first_id (optional) receives the id of the first new particle; ids are consecutive.
 */
SPH_API sph_result SPH_CALL sph_world_spawn(sph_world* world, const sph_spawn_desc* desc,
                                            uint32_t* out_first_id);

/** Zero means default: a zeroed desc is an empty box and fills nothing. */
typedef struct sph_fill_box_desc {
  uint32_t struct_size; /* set by sph_fill_box_desc_init */
  uint32_t reserved0;   /* must be 0 */
  sph_vec3 min;         /* box corner, m */
  sph_vec3 max;         /* opposite corner, m; every component >= min's (equal: an empty box) */
  sph_vec3 velocity;    /* initial velocity of every particle; default 0 */
} sph_fill_box_desc;
SPH_STATIC_ASSERT(sizeof(sph_fill_box_desc) == 44, sph_fill_box_desc_size);

SPH_API sph_result SPH_CALL sph_fill_box_desc_init_sized(sph_fill_box_desc* desc, uint32_t size);
static inline sph_result sph_fill_box_desc_init(sph_fill_box_desc* desc) {
  return sph_fill_box_desc_init_sized(desc, (uint32_t)sizeof(*desc));
}

/**
 * Fills an axis-aligned box with particles on an FCC lattice at the world's particle_spacing
 * (points at least spacing/2 inside each face), at rest density. All-or-nothing:
 * SPH_ERROR_CAPACITY if they do not fit in max_capacity (the world grows as a spawn does).
 * out_count (optional) receives the number added.
 */
SPH_API sph_result SPH_CALL sph_world_fill_box(sph_world* world, const sph_fill_box_desc* desc,
                                               uint32_t* out_count);

/** Zero means default: a zeroed desc (radius 0) fills nothing. */
typedef struct sph_fill_sphere_desc {
  uint32_t struct_size; /* set by sph_fill_sphere_desc_init */
  uint32_t reserved0;   /* must be 0 */
  sph_vec3 center;      /* m; a lattice point sits at the centre */
  float radius;         /* m; >= 0; points with |p - center| <= radius are filled; 0 = none */
  sph_vec3 velocity;    /* initial velocity; default 0 */
} sph_fill_sphere_desc;
SPH_STATIC_ASSERT(sizeof(sph_fill_sphere_desc) == 36, sph_fill_sphere_desc_size);

SPH_API sph_result SPH_CALL sph_fill_sphere_desc_init_sized(sph_fill_sphere_desc* desc, uint32_t size);
static inline sph_result sph_fill_sphere_desc_init(sph_fill_sphere_desc* desc) {
  return sph_fill_sphere_desc_init_sized(desc, (uint32_t)sizeof(*desc));
}
/** Fills a sphere on an FCC lattice; as sph_world_fill_box otherwise. */
SPH_API sph_result SPH_CALL sph_world_fill_sphere(sph_world* world, const sph_fill_sphere_desc* desc,
                                                  uint32_t* out_count);

/* ---- stepping ---------------------------------------------------------------------------- */

/**
 * Advances the world by frame_dt seconds (> 0, finite) in adaptive substeps: each substep's
 * dt = step_factor * h / v_max clamped to [dt_min, dt_max], the frame's remaining time spread
 * evenly over the fewest such substeps, so that they add up to frame_dt exactly (they may be
 * shorter than dt_min; docs/api.md, "Stepping").
 * Blocks until the frame is done. Returns SPH_INCOMPLETE if max_substeps ran out first, or
 * the step budget (sph_world_set_step_budget) or a cancel (sph_world_cancel_step) stopped it:
 * the world is then as after its last whole substep, consistent and ready to step again
 * (sph_stats.frame_time and substeps say how far it got). SPH_ERROR_NON_FINITE if a substep
 * produced a NaN/Inf, SPH_ERROR_CAPACITY if more particles than 64 times the rest density
 * allows piled into one cell of side h (the neighbour work would grow with their square; the
 * message says where): the world is restored to its state before this call.
 */
SPH_API sph_result SPH_CALL sph_world_step(sph_world* world, float frame_dt);

/**
 * Builds now what the next sph_world_step would otherwise build before its first substep, so
 * that a program pays for it when it chooses (a loading screen) rather than in its first frame,
 * where the step budget cannot bound it: the boundary-density maps of the colliders' SDF assets
 * (SPH_FEATURE_BOUNDARY_DENSITY: a ray integral per voxel, seconds for a large container on the
 * CPU) and, on CUDA, the device copies of the assets and of the scene. A world needs it again
 * after a collider gets an asset it has not stepped with, after sph_sdf_update of an asset its
 * colliders use, after sph_world_load (a loaded world holds its own copies of the assets) and
 * on CUDA after sph_world_restore. Optional: a step builds whatever is missing. Changes nothing a step or a
 * checkpoint sees (the next step gives the same bits with or without it); sph_stats.memory_bytes
 * counts what it built. Errors: INVALID_HANDLE, WORLD_LOCKED, OUT_OF_HOST_MEMORY,
 * OUT_OF_DEVICE_MEMORY, DEVICE_LOST. (0.2.0)
 */
SPH_API sph_result SPH_CALL sph_world_prepare(sph_world* world);
/**
 * Bounds the wall-clock time of each later sph_world_step of this world: a step still running
 * max_seconds after it began stops at its next substep boundary and returns SPH_INCOMPLETE
 * (one substep may overrun the budget). Both backends check it between substeps: the CUDA
 * backend runs a frame with a budget on its stream driver instead of its device graph (one host
 * synchronisation a substep). 0 (the default) is no budget. Not saved in checkpoints: it belongs
 * to the handle, so sph_world_restore keeps it and a loaded world has none. Errors: INVALID_HANDLE,
 * INVALID_ARGUMENT (NaN, negative or above 86400), WORLD_LOCKED.
 */
SPH_API sph_result SPH_CALL sph_world_set_step_budget(sph_world* world, double max_seconds);
/** The step budget in seconds (0: none). Errors: INVALID_HANDLE, INVALID_ARGUMENT (NULL). */
SPH_API sph_result SPH_CALL sph_world_get_step_budget(const sph_world* world, double* out_seconds);

/**
 * Asks the world's step to stop at its next substep boundary (it returns SPH_INCOMPLETE with
 * the world consistent; on the CUDA backend a frame on the device graph, which is every frame
 * without a step budget or sinks, sees it only at its end). The one call that may run on another thread while
 * a step holds the world: it never blocks and never answers WORLD_LOCKED. A request made while no step runs
 * stops the next step before its first substep (that step changes nothing and reports 0
 * substeps); a step that stops for it clears it. It belongs to the handle, as the step budget
 * does: sph_world_restore keeps a pending request. Errors: INVALID_HANDLE (NULL or destroyed:
 * safe to call racing sph_world_destroy).
 */
SPH_API sph_result SPH_CALL sph_world_cancel_step(sph_world* world);

/**
 * Asynchronous steps: sph_world_step_begin starts the frame that sph_world_step would run and
 * returns at once; the frame runs on the world's own thread (started by its first asynchronous
 * step and kept until sph_world_destroy; on the CPU backend it leads the OpenMP workers), or, on
 * a CPU context with the engine's task system, as one task of it, enqueued by begin (no thread
 * is started; if enqueue_task runs it at once and returns NULL, begin returns after the frame),
 * so the caller's frame overlaps the simulation. Until sph_world_step_wait collects it, the
 * world is held by that step: every other call on the world answers SPH_ERROR_WORLD_LOCKED
 * (destroy included), except sph_world_cancel_step and sph_world_step_poll. Each begin needs
 * one wait, also before the process exits; the wait may come from any thread.
 * Errors of begin: INVALID_HANDLE, INVALID_ARGUMENT (frame_dt not > 0 and finite), WORLD_LOCKED,
 * OUT_OF_HOST_MEMORY (no thread could be started, or a host allocation failed). Nothing runs
 * when begin fails.
 */
SPH_API sph_result SPH_CALL sph_world_step_begin(sph_world* world, float frame_dt);
/**
 * Waits for the step that sph_world_step_begin started (through the task system's finish_task
 * when it runs as a task) and returns what sph_world_step would have returned for it (SPH_OK,
 * SPH_INCOMPLETE, or its error, with its message in this thread's sph_get_last_error and the
 * world rolled back as sph_world_step does); the world is free again. Errors of the call itself:
 * INVALID_HANDLE, INVALID_ARGUMENT (no step begun, or it was already waited for), WORLD_LOCKED
 * (another call holds the world, e.g. another thread's wait).
 */
SPH_API sph_result SPH_CALL sph_world_step_wait(sph_world* world);
/**
 * Whether the step sph_world_step_begin started has finished (*out_done 1: sph_world_step_wait
 * will not block). Never blocks. Errors: INVALID_HANDLE, INVALID_ARGUMENT (out_done NULL, or no
 * step begun), WORLD_LOCKED (a synchronous call holds the world).
 */
SPH_API sph_result SPH_CALL sph_world_step_poll(const sph_world* world, sph_bool32* out_done);

/* ---- particles out ----------------------------------------------------------------------- */

/** Number of particles in the world. */
SPH_API sph_result SPH_CALL sph_world_get_particle_count(const sph_world* world, uint32_t* out_count);

/**
 * Copies particles [first, first + count) of one attribute into caller memory. Particles come
 * in the world's current order (cell order after the last step): use SPH_ATTRIBUTE_ID to
 * match particles between calls. Each element is written at dst + i * dst_stride
 * (dst_stride 0 = the element's size: 12 bytes for vectors, 4 for scalars); dst_size is the
 * size of the buffer at dst in bytes. count is clamped to the particles available;
 * out_written (optional) receives how many were written. Blocks until the data is ready.
 * Errors: INVALID_ARGUMENT (NULL dst, stride smaller than the element, first > particle
 * count, a span (n - 1) * dst_stride + element that overflows 64 bits or exceeds PTRDIFF_MAX),
 * BUFFER_TOO_SMALL (dst_size cannot hold count elements), UNSUPPORTED (unknown attribute),
 * FEATURE_DISABLED (SPH_ATTRIBUTE_USER without SPH_FEATURE_USER_ATTRIBUTE). Nothing is written
 * on error.
 */
SPH_API sph_result SPH_CALL sph_world_copy_attribute(const sph_world* world, sph_attribute attribute,
                                                     void* dst, uint64_t dst_size, uint64_t dst_stride,
                                                     uint32_t first, uint32_t count, uint32_t* out_written);

/* ---- writing particles ------------------------------------------------------------------- */

/**
 * Overwrites particles [first, first + count) of one attribute from caller memory (copied
 * before return), in the order sph_world_copy_attribute reads them (the world's current order:
 * read SPH_ATTRIBUTE_ID over the same range to know which particles they are). Writable:
 * SPH_ATTRIBUTE_POSITION and SPH_ATTRIBUTE_VELOCITY (3 x float32) and SPH_ATTRIBUTE_USER
 * (uint32, needs SPH_FEATURE_USER_ATTRIBUTE). Element i is read at src + i * src_stride
 * (src_stride 0 = the element's size); src_size is the size of the buffer at src in bytes.
 * Positions must be finite and within 65536 particle spacings of the origin (as spawned ones),
 * or equal to the particle's current position bit for bit (a step may carry a particle beyond
 * the bound: writing every position back still succeeds); velocities finite with a speed below
 * 1.8e19 m/s. A written particle keeps everything else
 * (its id, density, the methods' state); the next step starts from the written values, its
 * first substep sized from the new speeds. All-or-nothing: every element is checked before
 * anything is written; on any error the world is unchanged. Blocks; O(particle count) work and,
 * on a CUDA world, a copy of the particle state to the host and back (batch writes into one call).
 * Errors: INVALID_HANDLE, INVALID_ARGUMENT (NULL src with count > 0, stride smaller than the
 * element, first + count beyond the particle count, a span that overflows, a value out of range:
 * the message names the element, e.g. "src[3]"; DENSITY, PRESSURE or ID, which are not writable),
 * BUFFER_TOO_SMALL (src_size cannot hold count elements), UNSUPPORTED (unknown attribute),
 * FEATURE_DISABLED (SPH_ATTRIBUTE_USER without SPH_FEATURE_USER_ATTRIBUTE), WORLD_LOCKED,
 * OUT_OF_HOST_MEMORY, DEVICE.
 */
SPH_API sph_result SPH_CALL sph_world_set_attribute(sph_world* world, sph_attribute attribute,
                                                    const void* src, uint64_t src_size, uint64_t src_stride,
                                                    uint32_t first, uint32_t count);

/**
 * Removes the particles with the given ids (SPH_ATTRIBUTE_ID; caller array, read during the
 * call). The particles left keep their relative order and their ids. The removed ids are added,
 * in the order given, to those sph_world_get_removed_ids reports (which the next sph_world_step
 * clears), as if a sink had removed them; no event is added. count 0 removes nothing (ids may
 * then be NULL). All-or-nothing: on any error nothing is removed. Blocks; O(particle count) work
 * and, on a CUDA world, a copy of the particle state to the host and back.
 * Errors: INVALID_HANDLE, INVALID_ARGUMENT (NULL ids with count > 0; an id that names no
 * particle of the world or appears twice: the message names the first such, e.g. "ids[4]: 17
 * appears twice (first at ids[1])"), WORLD_LOCKED, OUT_OF_HOST_MEMORY, DEVICE.
 */
SPH_API sph_result SPH_CALL sph_world_remove_particles(sph_world* world, const uint32_t* ids, uint32_t count);

/* ---- statistics -------------------------------------------------------------------------- */
typedef struct sph_stats {
  uint32_t struct_size;    /* set by sph_stats_init */
  uint32_t particle_count; /* particles after the last step */
  uint32_t substeps;       /* substeps of the last sph_world_step */
  uint32_t neighbors_max;  /* most neighbours (r < h, self excluded) of any particle */
  double simulated_time;   /* seconds simulated since the world was created */
  float frame_time;        /* seconds the last sph_world_step advanced */
  float dt_min;            /* smallest substep of the last step, s */
  float dt_max;            /* largest substep of the last step, s */
  float max_speed;         /* largest particle speed at the end of the last step, m/s */
  float density_min;       /* density statistics of the last density evaluation, kg/m^3 */
  float density_mean;
  float density_max;
  float neighbors_mean;             /* mean neighbours per particle (self excluded) */
  float stage_ms[SPH_STAGE_COUNT];  /* wall milliseconds per stage over the last step */
  float step_ms;                    /* wall milliseconds of the whole last sph_world_step */
  uint32_t pressure_solves_guarded; /* (0.2.0) DFSPH with SPH_DFSPH_CHEBYSHEV: substeps whose density
                                       solve its guard turned to plain Jacobi steps, as its error had
                                       grown (docs/physics.md, "The guard"); the solve still meets its
                                       bound or counts as capped. 0 for every other solver (before
                                       0.2.0: reserved, 0) */
  uint64_t memory_bytes;            /* bytes the world holds for particles and grids (device memory on
                                       the CUDA backend) */
  /* DFSPH's two solves over the substeps of the last step (all zero on a WCSPH world). An
     iteration is one velocity update and one new residual, after the warm start's. */
  uint32_t pressure_iterations;       /* the density solve's iterations, summed */
  uint32_t pressure_iterations_max;   /* most in one substep */
  uint32_t divergence_iterations;     /* the divergence solve's iterations, summed */
  uint32_t divergence_iterations_max; /* most in one substep */
  float density_error_mean;           /* the density solve's achieved mean error (see
                                         sph_dfsph_params.density_error), averaged over the
                                         substeps */
  float density_error_max;            /* the largest of any substep */
  float divergence_error_mean;        /* the divergence solve's achieved mean error, 1/s */
  float divergence_error_max;         /* the largest of any substep */
  uint32_t pressure_solves_capped;    /* substeps whose density solve stopped at its cap above
                                         its bound (also SPH_EVENT_PRESSURE_SOLVE_CAPPED) */
  uint32_t divergence_solves_capped;  /* likewise (SPH_EVENT_DIVERGENCE_SOLVE_CAPPED) */
  uint32_t capacity;                  /* particles the world has room for now (always current) */
  uint32_t max_capacity;              /* most it may grow to (always current) */
  uint32_t capacity_growths;          /* times the world reallocated its particle storage since
                                         it was created or loaded (always current) */
  float density_error_largest;        /* (0.2.0) the largest error of one particle, max(rho* - rho0,
                                         0) / rho0, that any density solve of the last step ended
                                         with: within sph_dfsph_params.density_error_max unless the
                                         solve was capped (before 0.2.0: reserved, 0) */
} sph_stats;
SPH_STATIC_ASSERT(sizeof(sph_stats) == 160, sph_stats_size);

SPH_API sph_result SPH_CALL sph_stats_init_sized(sph_stats* stats, uint32_t size);
static inline sph_result sph_stats_init(sph_stats* stats) {
  return sph_stats_init_sized(stats, (uint32_t)sizeof(*stats));
}
/**
 * Statistics of the last sph_world_step: before the first step its fields are zero, except
 * particle_count, simulated_time and memory_bytes, which are always current.
 * out->struct_size must be set (sph_stats_init); only that many bytes are written.
 */
SPH_API sph_result SPH_CALL sph_world_get_stats(const sph_world* world, sph_stats* out);

/* ---- SDF assets ------------------------------------------------------------------------
 * A signed-distance grid (negative inside) shared by colliders, sources, sinks and force
 * fields in any world of its context. Samples sit at voxel centres with integer indices, as in
 * OpenVDB: local = index_to_local * (i, j, k, 1), so a VDB's index-to-world map can be passed
 * unchanged. Sampling is trilinear; normals are the normalised gradient; outside the grid the
 * boundary value grows by the distance to the grid's box. */
typedef struct sph_sdf sph_sdf;

typedef enum sph_memory_kind {
  SPH_MEMORY_HOST = 0,        /* ordinary host memory */
  SPH_MEMORY_CUDA_DEVICE = 1, /* device memory of the context's CUDA device (CUDA contexts only) */
  SPH_MEMORY_KIND_FORCE32 = 0x7fffffff
} sph_memory_kind;

/** Zero means default, except that a grid cannot be empty: dims and data are required (the
 *  error names the first of them that is zero). */
typedef struct sph_grid_desc {
  uint32_t struct_size;     /* set by sph_grid_desc_init */
  uint32_t dims[3];         /* samples along i, j, k (i fastest); each >= 1; required */
  float index_to_local[12]; /* row-major 3x4 affine map; default (and all zeros): identity (1 m voxels) */
  sph_memory_kind memory;   /* where data lives; default SPH_MEMORY_HOST */
  uint32_t components;      /* floats per voxel: 1 (distance, friction) or 3 (velocity, force
                               field accelerations); 0 (default) = the channel's own count */
  const float* data;        /* dims[0] * dims[1] * dims[2] * components floats, copied; required */
} sph_grid_desc;
SPH_STATIC_ASSERT(sizeof(sph_grid_desc) == 72 + sizeof(void*), sph_grid_desc_size);

SPH_API sph_result SPH_CALL sph_grid_desc_init_sized(sph_grid_desc* desc, uint32_t size);
static inline sph_result sph_grid_desc_init(sph_grid_desc* desc) {
  return sph_grid_desc_init_sized(desc, (uint32_t)sizeof(*desc));
}

/** A zeroed desc is refused: the distance grid is required (INVALID_ARGUMENT naming
 *  desc->distance.dims, then desc->distance.data). The embedded grid's struct_size may be 0. */
typedef struct sph_sdf_desc {
  uint32_t struct_size;          /* set by sph_sdf_desc_init */
  uint32_t reserved0;            /* must be 0 */
  sph_grid_desc distance;        /* required, 1 component, metres in the local frame */
  const sph_grid_desc* velocity; /* optional: surface velocity (3 components, m/s, local
                                    frame) for deforming colliders and source velocities */
  const sph_grid_desc* friction; /* optional: per-voxel friction coefficient (1 component) */
} sph_sdf_desc;
SPH_STATIC_ASSERT(sizeof(sph_sdf_desc) == 80 + 3 * sizeof(void*), sph_sdf_desc_size);

SPH_API sph_result SPH_CALL sph_sdf_desc_init_sized(sph_sdf_desc* desc, uint32_t size);
static inline sph_result sph_sdf_desc_init(sph_sdf_desc* desc) {
  return sph_sdf_desc_init_sized(desc, (uint32_t)sizeof(*desc));
}

/**
 * Creates an SDF asset from grids (copied). The optional grids must have the same dims as
 * the distance grid (their index_to_local is ignored). Errors: INVALID_ARGUMENT (NULL data,
 * zero dims, non-finite values, a singular index_to_local or one whose inverse overflows float,
 * wrong components), CAPACITY (more than 2^31 voxels), UNSUPPORTED (device memory on a CPU
 * context), OUT_OF_HOST_MEMORY.
 * Thread-safe with respect to other SDF calls on the context.
 */
SPH_API sph_result SPH_CALL sph_sdf_create(sph_context* context, const sph_sdf_desc* desc, sph_sdf** out);

typedef enum sph_shape {
  SPH_SHAPE_PLANE = 0,    /* solid below y = 0; half_extents.x/.z its size, .y its thickness */
  SPH_SHAPE_BOX = 1,      /* half_extents; wall_thickness > 0 makes a hollow box (a tank) whose
                             cavity is half_extents, walls outside it */
  SPH_SHAPE_SPHERE = 2,   /* radius */
  SPH_SHAPE_CAPSULE = 3,  /* radius around the segment y in [-half_height, half_height] */
  SPH_SHAPE_CYLINDER = 4, /* radius, half_height, axis y */
  SPH_SHAPE_CUP = 5,      /* an open cylinder: radius is the cavity's, the wall (wall_thickness)
                             lies outside it and the floor inside half_height */
  SPH_SHAPE_FORCE32 = 0x7fffffff
} sph_shape;

#define SPH_SHAPE_FLAG_OPEN_TOP 0x1u /* hollow box: no lid (a tank open at +y) */

/** Zero means default for every size; shape 0 is SPH_SHAPE_PLANE (zero keeps its meaning), so
 *  a zeroed desc is a plane of the default sizes, and sph_shape_desc_init picks SPH_SHAPE_BOX. */
typedef struct sph_shape_desc {
  uint32_t struct_size;    /* set by sph_shape_desc_init */
  sph_shape shape;         /* sph_shape_desc_init: SPH_SHAPE_BOX; 0 = SPH_SHAPE_PLANE */
  sph_vec3 half_extents;   /* m; each component 0 (default) = 0.5 */
  float radius;            /* m; 0 (default) = 0.5 */
  float half_height;       /* m; 0 (default) = 0.5 */
  float wall_thickness;    /* m; default 0 (solid); a cup has no default: it needs walls > 0 */
  float voxel_size;        /* m; 0 (default) = 0.01 */
  uint32_t flags;          /* SPH_SHAPE_FLAG_* */
  uint32_t padding_voxels; /* grid margin around the shape; 0 (default) = 4 */
} sph_shape_desc;
SPH_STATIC_ASSERT(sizeof(sph_shape_desc) == 44, sph_shape_desc_size);

SPH_API sph_result SPH_CALL sph_shape_desc_init_sized(sph_shape_desc* desc, uint32_t size);
static inline sph_result sph_shape_desc_init(sph_shape_desc* desc) {
  return sph_shape_desc_init_sized(desc, (uint32_t)sizeof(*desc));
}
/** Samples an analytic shape (centred at its local origin, y up) into an SDF asset. */
SPH_API sph_result SPH_CALL sph_sdf_create_shape(sph_context* context, const sph_shape_desc* desc,
                                                 sph_sdf** out);

/** A triangle mesh to turn into an SDF asset (sph_sdf_create_from_mesh). Triangles are
 *  counter-clockwise seen from outside (clockwise throughout works too: the inside is where the
 *  winding number is at least 1/2 in magnitude). The mesh need not be closed or manifold: holes
 *  narrower than about twice band_width voxels still leave a signed inside. Zero means default,
 *  except that the arrays and their counts are required (the error names the first missing). */
typedef struct sph_mesh_desc {
  uint32_t struct_size;    /* set by sph_mesh_desc_init */
  uint32_t vertex_count;   /* required, >= 3 */
  uint32_t vertex_stride;  /* bytes from one vertex to the next; 0 (default) = 12 (packed
                              x, y, z floats); otherwise >= 12 */
  uint32_t index_count;    /* three per triangle; required, a multiple of 3 */
  const float* vertices;   /* x, y, z (m, the asset's local frame) per vertex; finite; copied */
  const uint32_t* indices; /* vertex indices, each < vertex_count; copied */
  float voxel_size;        /* m; 0 (default) = 0.01 */
  float band_width;        /* voxels of exact point-triangle distance on each side of the
                              surface, in [1, 64]; 0 (default) = 3. Beyond it the closest
                              triangle is swept outward (distances within a voxel or so) */
  uint32_t padding_voxels; /* grid margin around the mesh's bounds, <= 1024; 0 (default) = 4 */
  uint32_t reserved0;      /* must be 0 */
} sph_mesh_desc;
SPH_STATIC_ASSERT(sizeof(sph_mesh_desc) == 32 + 2 * sizeof(void*), sph_mesh_desc_size);

SPH_API sph_result SPH_CALL sph_mesh_desc_init_sized(sph_mesh_desc* desc, uint32_t size);
static inline sph_result sph_mesh_desc_init(sph_mesh_desc* desc) {
  return sph_mesh_desc_init_sized(desc, (uint32_t)sizeof(*desc));
}
/**
 * Builds an SDF asset from a triangle mesh (the arrays are read during the call, not kept): a
 * grid of voxel_size over the mesh's bounds plus padding, axis-aligned, voxel (0, 0, 0) centred
 * at the bounds' minimum corner less padding_voxels voxels (index_to_local is a scale by
 * voxel_size and that translation); exact distances to the nearest triangle within band_width
 * voxels of the surface, the nearest triangle swept outward beyond; negative inside by the
 * generalised winding number. Host memory only; no OpenVDB needed.
 * Blocking; costs about (triangles * (2 band_width + 1)^3 + voxels) distance evaluations.
 * Thread-safe with respect to other SDF calls on the context. Errors: INVALID_ARGUMENT (NULL
 * arrays, counts, an index out of range, a non-finite vertex, a size out of range, reserved0,
 * a grid (bounds plus padding) reaching past +-3.4e38 or over 1.7e38 across, where float
 * distances overflow, a voxel_size whose inverse overflows float),
 * CAPACITY (more than 2^31 voxels: a larger voxel_size is needed), OUT_OF_HOST_MEMORY.
 */
SPH_API sph_result SPH_CALL sph_sdf_create_from_mesh(sph_context* context, const sph_mesh_desc* desc,
                                                     sph_sdf** out);

typedef enum sph_sdf_channel {
  SPH_SDF_CHANNEL_DISTANCE = 0,
  SPH_SDF_CHANNEL_VELOCITY = 1, /* 3 floats per voxel */
  SPH_SDF_CHANNEL_FRICTION = 2,
  SPH_SDF_CHANNEL_FORCE32 = 0x7fffffff
} sph_sdf_channel;

/**
 * Overwrites the box [origin, origin + size) of one channel with data (size[0] * size[1] *
 * size[2] * components floats, i fastest, copied). Updating the velocity or friction channel
 * of an asset created without it creates it (zero elsewhere). Do not update an asset while a
 * world that uses it is inside sph_world_step on another thread. With SPH_FEATURE_BOUNDARY_DENSITY
 * a change of the distances makes the next step recompute the asset's boundary map: on the CPU
 * backend only the voxels within about a kernel radius of the box (send the box that changed: a
 * dug terrain then pays for the dig alone; an asset re-sent whole every frame is compared with
 * the last values, 4 bytes a voxel, to find what moved; a velocity or friction update costs
 * nothing), on CUDA the whole map. Errors: INVALID_ARGUMENT
 * (box outside the grid, NULL or non-finite data), UNSUPPORTED (unknown channel or memory).
 */
SPH_API sph_result SPH_CALL sph_sdf_update(sph_sdf* sdf, sph_sdf_channel channel, const uint32_t origin[3],
                                           const uint32_t size[3], const float* data, sph_memory_kind memory);
/** Grid dimensions of an asset. */
SPH_API sph_result SPH_CALL sph_sdf_get_dims(const sph_sdf* sdf, uint32_t out_dims[3]);
/** Samples the signed distance at a point of the asset's local frame (for tools and tests). */
SPH_API sph_result SPH_CALL sph_sdf_sample(const sph_sdf* sdf, sph_vec3 local_point, float* out_distance);
/**
 * Releases the caller's reference; colliders and the like keep the asset alive, and so do calls
 * on the handle that other threads are in. NULL: no-op.
 */
SPH_API sph_result SPH_CALL sph_sdf_destroy(sph_sdf* sdf);

/* ---- placement --------------------------------------------------------------------------- */
typedef struct sph_quat {
  float x, y, z, w; /* a rotation; normalised by the library; (0, 0, 0, 1) is identity, and so
                       is (0, 0, 0, 0), the quaternion of a zeroed struct */
} sph_quat;

typedef struct sph_transform {
  sph_vec3 position; /* m */
  sph_quat rotation;
} sph_transform;
SPH_STATIC_ASSERT(sizeof(sph_transform) == 28, sph_transform_size);

/** The identity transform (exported twin of a constant, for bindings). */
SPH_API sph_transform SPH_CALL sph_transform_identity(void);

/* ---- ids of objects inside a world --------------------------------------------------------
 * Colliders, sources, sinks, force fields and probes are generational ids: a struct holding 64
 * bits, opaque. {0} is null: no call ever returns it, destroying it is a no-op, and every other
 * call refuses it with SPH_ERROR_INVALID_HANDLE, as it refuses the id of a destroyed object (a
 * world never issues an id twice, across sph_world_restore too) or of another world or kind.
 * "Another world" is told by a 16-bit world tag in every id: the n-th world sph_world_create
 * makes on a context has tag n, wrapping after 65535 worlds (two worlds 65535 apart on one
 * context share ids, and so do worlds of different contexts that were made n-th on each). A
 * world loaded from a checkpoint, or restored from one, takes the saved world's tag and so shares
 * its ids, by design: the saved ids work there (docs/api.md, "Handles and ownership"). */

/** True when an id (any sph_*_id) is null. */
#define SPH_ID_IS_NULL(id) ((id).bits == 0)

/* ---- colliders --------------------------------------------------------------------------- */
typedef struct sph_collider_id {
  uint64_t bits; /* {0} is null (SPH_ID_IS_NULL) */
} sph_collider_id;

#define SPH_COLLIDER_FLAG_INVERTED 0x1u /* solid where the SDF is positive: a container */

/** Zero means default, but a collider needs its SDF: a zeroed def is refused with
 *  INVALID_ARGUMENT naming def->sdf, and with sdf set it is a static collider at the identity
 *  pose with the default material (sph_collider_material). */
typedef struct sph_collider_def {
  uint32_t struct_size;    /* set by sph_collider_def_init */
  uint32_t flags;          /* SPH_COLLIDER_FLAG_* */
  sph_sdf* sdf;            /* required; the collider keeps a reference */
  sph_transform transform; /* initial pose; default identity */
  float restitution;       /* share of the normal approach speed returned, [0, 1]; default 0 */
  float friction;          /* Coulomb coefficient >= 0 (ignored where the SDF has a friction
                              channel); default 0 */
  float stickiness;        /* pull toward the surface within one kernel radius, m/s^2 >= 0;
                              default 0 */
  uint32_t reserved0;      /* must be 0 */
  uint32_t reserved1;      /* must be 0 */
} sph_collider_def;
SPH_STATIC_ASSERT(sizeof(sph_collider_def) == 56 + sizeof(void*), sph_collider_def_size);

SPH_API sph_result SPH_CALL sph_collider_def_init_sized(sph_collider_def* def, uint32_t size);
static inline sph_result sph_collider_def_init(sph_collider_def* def) {
  return sph_collider_def_init_sized(def, (uint32_t)sizeof(*def));
}

/**
 * Places an SDF asset in the world as a collider. A collider whose pose never changes and
 * whose SDF has no moving surface is static and costs the least. Errors: INVALID_HANDLE,
 * INVALID_ARGUMENT (NULL sdf, an asset of another context, non-finite transform, coefficient
 * out of range), CAPACITY (more than 65,536 colliders).
 */
SPH_API sph_result SPH_CALL sph_collider_create(sph_world* world, const sph_collider_def* def,
                                                sph_collider_id* out_id);
/** Removes a collider. A null id is a no-op; a stale id is INVALID_HANDLE. */
SPH_API sph_result SPH_CALL sph_collider_destroy(sph_world* world, sph_collider_id id);
/**
 * Kinematic motion: the collider moves from its current pose to `target` over the next
 * sph_world_step, placed at every substep by interpolation; its velocity is derived from the
 * motion. After that step the target is its pose; a step that returns SPH_INCOMPLETE leaves the
 * collider where its last whole substep placed it, the target still pending (the next step moves
 * it the rest of the way). A rotation read back (sph_collider_get_transform) and given again is
 * kept bit for bit, so a collider told to stay where it is does not move.
 */
SPH_API sph_result SPH_CALL sph_collider_set_target_transform(sph_world* world, sph_collider_id id,
                                                              const sph_transform* target);
/** Moves a collider at once, with no velocity (nothing is pushed). A target still pending
 * (sph_collider_set_target_transform) is dropped: the collider stays at `transform` until it is
 * given a new target. */
SPH_API sph_result SPH_CALL sph_collider_teleport(sph_world* world, sph_collider_id id,
                                                  const sph_transform* transform);
SPH_API sph_result SPH_CALL sph_collider_get_transform(const sph_world* world, sph_collider_id id,
                                                       sph_transform* out_transform);
/**
 * How a collider's surface answers particles that reach it. Zero means default: a zeroed
 * struct (struct_size set) is what sph_collider_material_init gives, a surface that returns
 * no normal speed, has no friction and pulls nothing.
 */
typedef struct sph_collider_material {
  uint32_t struct_size; /* set by sph_collider_material_init */
  float restitution;    /* share of the normal approach speed returned, [0, 1]; default 0 */
  float friction;       /* Coulomb coefficient >= 0 (ignored where the SDF has a friction
                           channel); default 0 */
  float stickiness;     /* pull toward the surface within one kernel radius, m/s^2 >= 0;
                           default 0 */
} sph_collider_material;
SPH_STATIC_ASSERT(sizeof(sph_collider_material) == 16, sph_collider_material_size);

SPH_API sph_result SPH_CALL sph_collider_material_init_sized(sph_collider_material* material, uint32_t size);
static inline sph_result sph_collider_material_init(sph_collider_material* material) {
  return sph_collider_material_init_sized(material, (uint32_t)sizeof(*material));
}
/**
 * Replaces a collider's material; acts from the next substep. Errors: INVALID_HANDLE (world;
 * a null, stale or foreign id), INVALID_ARGUMENT (NULL material; a coefficient out of range or
 * not finite, named), VERSION_MISMATCH (struct_size), WORLD_LOCKED. Nothing changes on error.
 */
SPH_API sph_result SPH_CALL sph_collider_set_material(sph_world* world, sph_collider_id id,
                                                      const sph_collider_material* material);
/**
 * Reads a collider's material (as the def or the last set call gave it). out->struct_size
 * must be set (sph_collider_material_init); only that many bytes are written.
 * Errors: INVALID_HANDLE, INVALID_ARGUMENT (NULL out), VERSION_MISMATCH, WORLD_LOCKED.
 */
SPH_API sph_result SPH_CALL sph_collider_get_material(const sph_world* world, sph_collider_id id,
                                                      sph_collider_material* out);

/**
 * The fluid's loads on a collider over the last sph_world_step (SPH_FEATURE_COLLIDER_LOADS):
 * the time averages over the step's substeps of the force and of the torque about the collider's
 * load point, in world coordinates. What counts: the momentum the collision response took from
 * particles (contacts, friction, stickiness) and, with SPH_FEATURE_BOUNDARY_DENSITY, the walls'
 * pressure reactions (on a DFSPH world: what both its solves applied, and the impulses of its
 * solves' contact clamp; not with SPH_DFSPH_CONJUGATE_GRADIENTS, whose step is then UNSUPPORTED);
 * force times frame_time is the impulse the fluid gave the collider. The
 * torque of each impulse is taken about the load point posed at the impulse's time (it moves
 * with the collider). Zero before the first step (frame_time 0). docs/physics.md "Loads".
 */
typedef struct sph_collider_loads {
  uint32_t struct_size; /* set by sph_collider_loads_init */
  uint32_t reserved0;   /* written as 0 */
  sph_vec3 force;       /* N, world frame */
  sph_vec3 torque;      /* N m, world frame, about point */
  sph_vec3 point;       /* the load point in the world at the end of the step, m */
  double frame_time;    /* s: the time the step advanced, over which force and torque are averaged */
} sph_collider_loads;
SPH_STATIC_ASSERT(sizeof(sph_collider_loads) == 56, sph_collider_loads_size);

SPH_API sph_result SPH_CALL sph_collider_loads_init_sized(sph_collider_loads* loads, uint32_t size);
static inline sph_result sph_collider_loads_init(sph_collider_loads* loads) {
  return sph_collider_loads_init_sized(loads, (uint32_t)sizeof(*loads));
}
/**
 * Reads a collider's loads of the last step. Non-blocking (the step brought them to the host).
 * out->struct_size must be set (sph_collider_loads_init); only that many bytes are written.
 * Errors: INVALID_HANDLE (world; a null, stale or foreign id), INVALID_ARGUMENT (NULL out),
 * VERSION_MISMATCH, FEATURE_DISABLED (the world lacks SPH_FEATURE_COLLIDER_LOADS), WORLD_LOCKED.
 */
SPH_API sph_result SPH_CALL sph_collider_get_loads(const sph_world* world, sph_collider_id id,
                                                   sph_collider_loads* out);
/**
 * Sets the point, in the collider's own frame, that its loads' torque is taken about (default
 * its origin; an engine passes the body's centre of mass). Acts from the next step. Errors:
 * INVALID_HANDLE, INVALID_ARGUMENT (NULL point; a non-finite component, named),
 * FEATURE_DISABLED, WORLD_LOCKED. Nothing changes on error.
 */
SPH_API sph_result SPH_CALL sph_collider_set_load_point(sph_world* world, sph_collider_id id,
                                                        const sph_vec3* point);
/**
 * A threshold on a collider's loads, for engines that react to a hit rather than poll: after
 * every sph_world_step whose mean force on the collider (sph_collider_loads.force) has a
 * magnitude of at least `force` newtons, the step reports SPH_EVENT_COLLIDER_LOAD_EXCEEDED
 * (object: the collider; count: the magnitude in N, rounded down). 0 (the default) = no event.
 * Acts from the next step; checkpoints carry it (format 7). Errors: INVALID_HANDLE,
 * INVALID_ARGUMENT (negative or not finite), FEATURE_DISABLED, WORLD_LOCKED. Nothing changes on
 * error.
 */
SPH_API sph_result SPH_CALL sph_collider_set_load_threshold(sph_world* world, sph_collider_id id,
                                                            float force);

/* ---- sources ----------------------------------------------------------------------------- */
typedef struct sph_source_id {
  uint64_t bits; /* {0} is null (SPH_ID_IS_NULL) */
} sph_source_id;

typedef enum sph_source_mode {
  SPH_SOURCE_FILL_ONCE = 0,  /* fill the region at the next step, then stay idle */
  SPH_SOURCE_CONTINUOUS = 1, /* refill the region at every step, at most `rate` particles/s */
  SPH_SOURCE_MODE_FORCE32 = 0x7fffffff
} sph_source_mode;

#define SPH_SOURCE_FLAG_VELOCITY_FROM_FIELD 0x1u /* initial velocity from the SDF's velocity */

/** Zero means default, but a source needs its region: a zeroed def is refused with
 *  INVALID_ARGUMENT naming def->region; with region set it fills the region once, at the
 *  world's spacing, at rest. */
typedef struct sph_source_def {
  uint32_t struct_size;    /* set by sph_source_def_init */
  sph_source_mode mode;    /* default SPH_SOURCE_FILL_ONCE */
  sph_sdf* region;         /* required: particles fill where the SDF is negative */
  sph_transform transform; /* default identity */
  float spacing;           /* FCC lattice spacing, m; 0 (default) = the world's spacing; at least a
                              quarter of the world's */
  float min_distance;      /* skip lattice points closer than this to a particle, m; 0 (default)
                              = 0.9 x spacing or the kernel radius, the smaller; at most the
                              source's spacing and at most the kernel radius */
  sph_vec3 velocity;       /* initial velocity (unless VELOCITY_FROM_FIELD); default 0 */
  uint32_t flags;          /* SPH_SOURCE_FLAG_* */
  float rate;              /* CONTINUOUS: most particles per second; 0 (default) = no limit.
                              What the region or the world could not take is emitted later,
                              but at most one region's worth is owed */
  uint32_t user_attribute; /* the user attribute of the particles it emits; default 0; non-zero
                              needs SPH_FEATURE_USER_ATTRIBUTE (else FEATURE_DISABLED) */
  uint32_t reserved1;      /* must be 0 */
} sph_source_def;
SPH_STATIC_ASSERT(sizeof(sph_source_def) == 72 + sizeof(void*), sph_source_def_size);

SPH_API sph_result SPH_CALL sph_source_def_init_sized(sph_source_def* def, uint32_t size);
static inline sph_result sph_source_def_init(sph_source_def* def) {
  return sph_source_def_init_sized(def, (uint32_t)sizeof(*def));
}
/**
 * Adds a source (thesis 3.3). Emission happens at the start of each sph_world_step. A growable
 * world grows for it (SPH_EVENT_CAPACITY_GROWN; a growth that cannot be allocated fails the
 * step with OUT_OF_*_MEMORY, world unchanged). When max_capacity runs out, the source emits
 * what fits and the step reports an SPH_EVENT_SOURCE_CAPACITY_REACHED event; nothing else
 * changes (likewise once the world's 2^32 particle ids are used up: ids are never reused).
 * Errors: INVALID_ARGUMENT (a bad field, named; a region whose lattice, at this transform,
 * reaches farther than 65536 particle spacings from the origin, where no particle may be),
 * CAPACITY (the region holds more than 2^28 lattice points). sph_source_set_transform refuses a
 * transform that would move the lattice out of that reach likewise (INVALID_ARGUMENT naming
 * transform), the source unchanged. A region's velocity channel (VELOCITY_FROM_FIELD) holds
 * speeds below 1.8e19 m/s, as particles do (sph_sdf_create and sph_sdf_update check it).
 */
SPH_API sph_result SPH_CALL sph_source_create(sph_world* world, const sph_source_def* def,
                                              sph_source_id* out_id);
SPH_API sph_result SPH_CALL sph_source_destroy(sph_world* world, sph_source_id id);
SPH_API sph_result SPH_CALL sph_source_set_transform(sph_world* world, sph_source_id id,
                                                     const sph_transform* transform);

/* ---- sinks ------------------------------------------------------------------------------- */
typedef struct sph_sink_id {
  uint64_t bits; /* {0} is null (SPH_ID_IS_NULL) */
} sph_sink_id;

typedef enum sph_sink_mode {
  SPH_SINK_REGION = 0,         /* remove particles where the region's SDF is negative */
  SPH_SINK_OUTSIDE_BOUNDS = 1, /* remove particles outside [bounds_min, bounds_max] (world) */
  SPH_SINK_MODE_FORCE32 = 0x7fffffff
} sph_sink_mode;

/** Zero means default: a zeroed def is a REGION sink and needs its region (INVALID_ARGUMENT
 *  naming def->region); an OUTSIDE_BOUNDS sink with zero bounds keeps only particles at the
 *  origin. */
typedef struct sph_sink_def {
  uint32_t struct_size;    /* set by sph_sink_def_init */
  sph_sink_mode mode;      /* default SPH_SINK_REGION */
  sph_sdf* region;         /* REGION: required */
  sph_transform transform; /* REGION: placement; default identity */
  sph_vec3 bounds_min;     /* OUTSIDE_BOUNDS: the box particles may stay in */
  sph_vec3 bounds_max;     /* OUTSIDE_BOUNDS: every component >= bounds_min's */
  uint32_t reserved0;      /* must be 0 */
} sph_sink_def;
SPH_STATIC_ASSERT(sizeof(sph_sink_def) == 64 + sizeof(void*), sph_sink_def_size);

SPH_API sph_result SPH_CALL sph_sink_def_init_sized(sph_sink_def* def, uint32_t size);
static inline sph_result sph_sink_def_init(sph_sink_def* def) {
  return sph_sink_def_init_sized(def, (uint32_t)sizeof(*def));
}
/** Adds a sink (thesis 4.4.2.3); it acts at every substep. See sph_world_get_removed_ids. */
SPH_API sph_result SPH_CALL sph_sink_create(sph_world* world, const sph_sink_def* def, sph_sink_id* out_id);
SPH_API sph_result SPH_CALL sph_sink_destroy(sph_world* world, sph_sink_id id);

/* ---- force fields ------------------------------------------------------------------------ */
typedef struct sph_force_field_id {
  uint64_t bits; /* {0} is null (SPH_ID_IS_NULL) */
} sph_force_field_id;

typedef enum sph_force_field_kind {
  SPH_FORCE_FIELD_UNIFORM = 0, /* acceleration `vector` (field frame) */
  SPH_FORCE_FIELD_RADIAL = 1,  /* `strength` m/s^2 away from the origin (negative attracts) */
  SPH_FORCE_FIELD_VORTEX = 2,  /* `strength` m/s^2 around the axis `vector` through the origin */
  SPH_FORCE_FIELD_GRID = 3,    /* accelerations from a user grid (3 components, field frame) */
  SPH_FORCE_FIELD_KIND_FORCE32 = 0x7fffffff
} sph_force_field_kind;

/** Zero means default: a zeroed def is a UNIFORM field of zero acceleration acting everywhere
 *  (valid, and it changes nothing). A VORTEX needs a non-zero def->vector and a GRID def->grid;
 *  the errors name them. */
typedef struct sph_force_field_def {
  uint32_t struct_size;      /* set by sph_force_field_def_init */
  sph_force_field_kind kind; /* default SPH_FORCE_FIELD_UNIFORM */
  sph_sdf* region;           /* optional: acts only where this SDF is negative; NULL = everywhere */
  const sph_grid_desc* grid; /* GRID: the acceleration grid (3 components), copied */
  sph_transform transform;   /* field frame (and the region's placement); default identity */
  sph_vec3 vector;           /* UNIFORM: m/s^2; VORTEX: the axis (normalised by the library) */
  float strength;            /* RADIAL, VORTEX: m/s^2 */
  float falloff_radius;      /* RADIAL, VORTEX: linear fade to 0 at this distance, m; 0 = none */
  uint32_t reserved0;        /* must be 0 */
  uint32_t reserved1;        /* must be 0 */
} sph_force_field_def;
SPH_STATIC_ASSERT(sizeof(sph_force_field_def) == 64 + 2 * sizeof(void*), sph_force_field_def_size);

SPH_API sph_result SPH_CALL sph_force_field_def_init_sized(sph_force_field_def* def, uint32_t size);
static inline sph_result sph_force_field_def_init(sph_force_field_def* def) {
  return sph_force_field_def_init_sized(def, (uint32_t)sizeof(*def));
}
/** Adds a force field (thesis 4.4.2.4); its acceleration adds to gravity at every substep. */
SPH_API sph_result SPH_CALL sph_force_field_create(sph_world* world, const sph_force_field_def* def,
                                                   sph_force_field_id* out_id);
SPH_API sph_result SPH_CALL sph_force_field_destroy(sph_world* world, sph_force_field_id id);
SPH_API sph_result SPH_CALL sph_force_field_set_transform(sph_world* world, sph_force_field_id id,
                                                          const sph_transform* transform);

/* ---- probes and gauges ------------------------------------------------------------------- */
typedef struct sph_probe_id {
  uint64_t bits; /* {0} is null (SPH_ID_IS_NULL) */
} sph_probe_id;

typedef enum sph_probe_kind {
  SPH_PROBE_POINT = 0, /* samples density, pressure and velocity at `position` */
  SPH_PROBE_GAUGE = 1, /* a line from `position` along `direction`, `length` long: the water height
                          (column integral) and the column's mean density, pressure and velocity */
  SPH_PROBE_KIND_FORCE32 = 0x7fffffff
} sph_probe_kind;

typedef enum sph_probe_sampling {
  SPH_PROBE_EVERY_FRAME = 0,   /* the last substep of each step is sampled */
  SPH_PROBE_EVERY_SUBSTEP = 1, /* every substep is sampled; the reading is the time average */
  SPH_PROBE_SAMPLING_FORCE32 = 0x7fffffff
} sph_probe_sampling;

/** Zero means default: a zeroed def (after sph_probe_def_init) is a point probe at the origin
 *  sampled once a frame. The values are the SPH interpolant (docs/physics.md "Probes and
 *  gauges"): A(x) = sum_j V_j A_j W(|x - x_j|) / sum_j V_j W(|x - x_j|), V_j = m / rho_j, with
 *  W_poly6 at the world's kernel radius, over the particles of the substep's density pass. */
typedef struct sph_probe_def {
  uint32_t struct_size;        /* set by sph_probe_def_init */
  sph_probe_kind kind;         /* default SPH_PROBE_POINT */
  sph_probe_sampling sampling; /* default SPH_PROBE_EVERY_FRAME */
  sph_vec3 position;           /* POINT: where; GAUGE: the line's start (put it below the floor), m */
  sph_vec3 direction;          /* GAUGE: the line's direction (normalised by the library: any
                                  finite non-zero vector, however short or long);
                                  {0,0,0} = up, against the world's gravity at each step (+y
                                  without gravity) */
  float length;                /* GAUGE: the line's length, m; > 0 */
  float sample_spacing;        /* GAUGE: the column integral's step, m; 0 = kernel radius / 8; at
                                  most 65536 steps along the line */
  uint32_t reserved0;          /* must be 0 */
} sph_probe_def;
SPH_STATIC_ASSERT(sizeof(sph_probe_def) == 48, sph_probe_def_size);

SPH_API sph_result SPH_CALL sph_probe_def_init_sized(sph_probe_def* def, uint32_t size);
static inline sph_result sph_probe_def_init(sph_probe_def* def) {
  return sph_probe_def_init_sized(def, (uint32_t)sizeof(*def));
}
/**
 * Adds a probe or gauge; it is sampled inside every following sph_world_step on the world's
 * backend (on the device for CUDA, with no host copy per substep). Errors: INVALID_HANDLE
 * (world), INVALID_ARGUMENT (NULL def or out_id; a non-finite position or direction, a gauge's
 * length not > 0 or too many steps, a negative sample_spacing, non-zero reserved0, each named),
 * UNSUPPORTED (an unknown kind or sampling), VERSION_MISMATCH, CAPACITY (65536 probes, or more
 * than 2^22 = 4194304 sample points of all probes together: a point probe samples one, a gauge
 * its steps), WORLD_LOCKED. On a DFSPH world the pressure sampled is the one both its solves applied in the
 * substep (SPH_ATTRIBUTE_PRESSURE's), at the substep's start positions. Nothing changes on
 * error. Checkpoints of format 6 and later carry the probes (readings start again); restoring an
 * older one keeps the world's own (docs/api.md).
 */
SPH_API sph_result SPH_CALL sph_probe_create(sph_world* world, const sph_probe_def* def,
                                             sph_probe_id* out_id);
/** Removes a probe; id {0} is a no-op. Errors: INVALID_HANDLE (world; stale or foreign id),
 *  WORLD_LOCKED. */
SPH_API sph_result SPH_CALL sph_probe_destroy(sph_world* world, sph_probe_id id);

/**
 * A probe's reading of the last sph_world_step. EVERY_FRAME: the sample of the step's last
 * substep; EVERY_SUBSTEP: the average of the step's substeps, each weighted by its length. A
 * sample is taken at the substep's density pass (the positions and velocities the substep starts
 * from, the densities and pressures its forces use). Where no particle is within the kernel
 * radius (kernel_sum 0) a sample reads 0.
 */
typedef struct sph_probe_reading {
  uint32_t struct_size; /* set by sph_probe_reading_init */
  uint32_t samples;     /* samples in the reading; 0 before the first step */
  float density;        /* kg/m^3, Shepard-normalised */
  float pressure;       /* Pa (the equation of state's, relative to the free surface) */
  sph_vec3 velocity;    /* m/s */
  float pressure_max;   /* Pa: the largest pressure of the samples (the peak of an impact) */
  float kernel_sum;     /* sum_j V_j W: the fluid fraction, about 1 inside water, 0 in air;
                           GAUGE: its mean over the line */
  float water_height;   /* GAUGE: the column integral along the line of the mass interpolant over
                           the rest density (the mass per unit area as a height at rho0), m;
                           POINT: 0 */
  double time;          /* s: the span of the reading (the last substep's length, or the step's) */
} sph_probe_reading;
SPH_STATIC_ASSERT(sizeof(sph_probe_reading) == 48, sph_probe_reading_size);

SPH_API sph_result SPH_CALL sph_probe_reading_init_sized(sph_probe_reading* reading, uint32_t size);
static inline sph_result sph_probe_reading_init(sph_probe_reading* reading) {
  return sph_probe_reading_init_sized(reading, (uint32_t)sizeof(*reading));
}
/**
 * Reads a probe's reading of the last step. Non-blocking (the step brought it to the host).
 * out->struct_size must be set (sph_probe_reading_init); only that many bytes are written.
 * Errors: INVALID_HANDLE (world; a null, stale or foreign id), INVALID_ARGUMENT (NULL out),
 * VERSION_MISMATCH, WORLD_LOCKED.
 */
SPH_API sph_result SPH_CALL sph_probe_get_reading(const sph_world* world, sph_probe_id id,
                                                  sph_probe_reading* out);
/**
 * A threshold on a probe's pressure (an impact alarm): after every sph_world_step whose reading
 * has a pressure_max of at least `pressure` Pa, the step reports SPH_EVENT_PROBE_PRESSURE_EXCEEDED
 * (object: the probe; count: pressure_max in Pa, rounded down). 0 (the default) = no event. Acts
 * from the next step; checkpoints carry it (format 7). Errors: INVALID_HANDLE (world; a null,
 * stale or foreign id), INVALID_ARGUMENT (negative or not finite), WORLD_LOCKED. Nothing changes
 * on error.
 */
SPH_API sph_result SPH_CALL sph_probe_set_pressure_threshold(sph_world* world, sph_probe_id id,
                                                             float pressure);

/* ---- events of the last step ------------------------------------------------------------- */
typedef enum sph_event_type {
  SPH_EVENT_SOURCE_CAPACITY_REACHED = 1, /* object: the source; count: particles not emitted */
  SPH_EVENT_SINK_REMOVED = 2,            /* object: the sink; count: particles removed */
  SPH_EVENT_PRESSURE_SOLVE_CAPPED = 3,   /* DFSPH; object: none (0); count: substeps whose density
                                            solve stopped at max_iterations above its bound */
  SPH_EVENT_DIVERGENCE_SOLVE_CAPPED = 4, /* DFSPH; object: none (0); count: substeps whose
                                            divergence solve stopped at its cap above its bound */
  SPH_EVENT_CAPACITY_GROWN = 5,          /* a source's emission grew the world; object: the
                                            source; count: the new capacity */
  SPH_EVENT_COLLIDER_LOAD_EXCEEDED = 6,  /* the step's mean force on a collider reached its
                                            threshold (sph_collider_set_load_threshold); object:
                                            the collider; count: the force's magnitude, N */
  SPH_EVENT_PROBE_PRESSURE_EXCEEDED = 7, /* a probe's peak pressure of the step reached its
                                            threshold (sph_probe_set_pressure_threshold); object:
                                            the probe; count: the peak pressure, Pa */
  SPH_EVENT_TYPE_FORCE32 = 0x7fffffff
} sph_event_type;

typedef struct sph_event {
  sph_event_type type;
  uint32_t count;
  uint64_t object_bits; /* the bits of the source/sink/collider/probe id */
} sph_event;
SPH_STATIC_ASSERT(sizeof(sph_event) == 16, sph_event_size);

/**
 * Events of the last sph_world_step (two-call pattern): writes up to `capacity` events and
 * sets *out_count to the number there are; SPH_INCOMPLETE when capacity was too small.
 * events may be NULL when capacity is 0.
 */
SPH_API sph_result SPH_CALL sph_world_get_events(const sph_world* world, sph_event* events, uint32_t capacity,
                                                 uint32_t* out_count);
/** Ids of the particles sinks removed during the last sph_world_step, then those
 *  sph_world_remove_particles removed since (two-call pattern). */
SPH_API sph_result SPH_CALL sph_world_get_removed_ids(const sph_world* world, uint32_t* ids,
                                                      uint32_t capacity, uint32_t* out_count);

/* ---- checkpoints ---------------------------------------------------------------------------
 * A checkpoint is a world's whole state as a self-contained byte string: the def, the
 * parameters (those of the physics options included), the clock, the id counters, every
 * particle in the world's storage order, and the scene (colliders with their pose and pending
 * target, sources with their emission state, sinks, force fields, and every SDF asset they use,
 * embedded once each). Object ids stay valid: a loaded world accepts the ids of the saved one.
 * Loading and stepping continues bit for bit as the saved world would have, when both run on
 * the same backend (CPU -> CPU, or CUDA -> CUDA on the same device model and library build);
 * any checkpoint loads on any backend, then agreeing to float tolerance. The format is
 * versioned and checksummed (docs/checkpoint.md); little-endian on every platform. The
 * statistics, events and removed ids of the last step come along too. */

/**
 * Saves a world into caller memory. Size query: buffer NULL and buffer_size 0 set *out_size to
 * the bytes needed and return SPH_OK. Otherwise the checkpoint is written when it fits
 * (*out_size: the bytes written), else SPH_ERROR_BUFFER_TOO_SMALL with *out_size the bytes
 * needed and nothing written. The size can change whenever the world does. Blocks (a CUDA
 * world copies its particles to the host). Errors: INVALID_HANDLE, INVALID_ARGUMENT (NULL
 * out_size, NULL buffer with a non-zero size), BUFFER_TOO_SMALL, WORLD_LOCKED,
 * OUT_OF_HOST_MEMORY, DEVICE.
 */
SPH_API sph_result SPH_CALL sph_world_save(const sph_world* world, void* buffer, uint64_t buffer_size,
                                           uint64_t* out_size);
/**
 * Saves a world into a file, atomically: the checkpoint goes to a new file next to `path`
 * (path + ".tmp-" + a unique suffix), is flushed to the disk (fsync), and is then renamed to
 * `path`, replacing any file there. A crash leaves either the old file or the new one, never
 * a partial one; on any error the temporary file is removed and a file at `path` is untouched.
 * Each save first removes the temporary files of killed saves to `path` on this host (those
 * whose process is gone; docs/checkpoint.md).
 * path is UTF-8 (a narrow path on POSIX). Errors: INVALID_HANDLE, INVALID_ARGUMENT (NULL or
 * empty path; the file cannot be created, written or renamed: the message says why),
 * WORLD_LOCKED, OUT_OF_HOST_MEMORY, DEVICE.
 */
SPH_API sph_result SPH_CALL sph_world_save_file(const sph_world* world, const char* path);
/**
 * Creates a new world on `context` from a checkpoint in memory (data is read only during the
 * call). The context decides the backend, whichever backend saved it. The whole checkpoint is
 * validated before anything is created: on any error no world is created and *out is not
 * written. Errors: INVALID_HANDLE (context), INVALID_ARGUMENT (NULL data or out),
 * CORRUPT_DATA (truncated, damaged or inconsistent data; the message names the section and
 * what is wrong), VERSION_MISMATCH (a checkpoint format this library does not read),
 * OUT_OF_HOST_MEMORY, OUT_OF_DEVICE_MEMORY.
 */
SPH_API sph_result SPH_CALL sph_world_load(sph_context* context, const void* data, uint64_t size,
                                           sph_world** out);
/**
 * sph_world_load from a file. INVALID_ARGUMENT also when the file cannot be opened or read, is
 * not a regular file (a FIFO, a device such as /dev/zero, a directory: refused without reading)
 * or is larger than 256 GiB.
 */
SPH_API sph_result SPH_CALL sph_world_load_file(sph_context* context, const char* path, sph_world** out);
/**
 * Replaces a world's whole state with a checkpoint's (undo, retry): afterwards the world is as
 * a world loaded from it on the same context, and keeps its handle, with one difference: a
 * collider, source, sink or force field whose asset in the checkpoint holds the same bits as the
 * caller's asset the same object uses now keeps the caller's asset (it follows sph_sdf_update
 * again, and on the CPU keeps its boundary-density maps); one the restore brings back (an undo of
 * its deletion) takes the caller's asset of the same bits that another object uses now; one whose
 * asset changed since the save holds the checkpoint's copy, as a loaded world does (so does one
 * whose asset no object uses now: the world no longer knows it). All-or-nothing: on any
 * error the world is unchanged. Errors: as sph_world_load, and WORLD_LOCKED.
 */
SPH_API sph_result SPH_CALL sph_world_restore(sph_world* world, const void* data, uint64_t size);

#ifdef __cplusplus
}
#endif

#endif /* SPH_C_H */
