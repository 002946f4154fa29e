// SPDX-License-Identifier: MIT
#include "dam_break.h"

#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "cell_grid.h"
#include "support.h"

/* Martin & Moyce (1952), Table 2, n^2 = 2 (../shared/data/martin_moyce_1952_front_n2.csv). */
const double dam_break_measured_T[DAM_BREAK_MEASUREMENTS] = {0.00, 0.41, 0.84, 1.19, 1.43, 1.63, 1.83, 1.98,
                                                             2.20, 2.32, 2.51, 2.65, 2.83, 2.98, 3.11, 3.33};
const double dam_break_measured_Z[DAM_BREAK_MEASUREMENTS] = {1.00, 1.11, 1.22, 1.44, 1.67, 1.89, 2.11, 2.33,
                                                             2.56, 2.78, 3.00, 3.22, 3.44, 3.67, 3.89, 4.11};

#define GRAVITY 9.81

void dam_break_config_default(dam_break_config* config, uint32_t layers_across) {
  const double a = DAM_BREAK_COLUMN_WIDTH;
  memset(config, 0, sizeof *config);
  config->layers_across = layers_across;
  /* Six layers across the slab, 2.35 kernel radii (h = 1.8 spacings = 2.55 layers): the two
   * middle layers, 3 layers from the first missing one beyond either wall, see a full
   * neighbourhood in z. */
  config->slab_layers = 6;
  config->integrator = SPH_INTEGRATOR_SYMPLECTIC_EULER;
  config->step_factor = 0.4f;
  /* Ten times the free-fall speed from the column's height, sqrt(2 g 2a) = 1.50 m/s: Tait's
   * density error goes as (u / c)^2, so 1 %. */
  config->speed_of_sound = (float)(10.0 * sqrt(2.0 * GRAVITY * 2.0 * a));
  config->viscosity = 0.05f;
  config->friction = 0.0f;
  config->end_T = DAM_BREAK_T_LAST + DAM_BREAK_MAX_SHIFT;
  /* A sample every 0.025 in T (1.35 ms), fine enough that the linear interpolation between
   * samples adds nothing visible. Frames are then a few substeps long at the coarsest
   * resolutions, and the landing rule that ends each frame exactly caps lambda = 0.8 at what
   * lambda = 0.4 takes there (docs/validation.md). */
  config->sample_T = 0.025;
}

/* splitmix64's finaliser: every input bit reaches every output bit. */
static uint64_t mix64(uint64_t x) {
  x ^= x >> 30;
  x *= 0xbf58476d1ce4e5b9ull;
  x ^= x >> 27;
  x *= 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

/* The sum (mod 2^64) of a mix of each particle's three coordinates' bits: the same for the same
   bits in any order. */
static uint64_t position_digest(const float* positions, uint32_t count) {
  uint64_t sum = 0;
  for (uint32_t i = 0; i < count; ++i) {
    uint32_t b[3];
    memcpy(b, positions + 3 * (size_t)i, sizeof b);
    sum += mix64(mix64(((uint64_t)b[0] << 32) | b[1]) ^ b[2]);
  }
  return sum;
}

static double time_scale(void) { return sqrt(2.0 * GRAVITY / DAM_BREAK_COLUMN_WIDTH); }

static int descending(const void* a, const void* b) {
  const float x = *(const float*)a, y = *(const float*)b;
  return (x < y) - (x > y);
}

/* The surge front: the furthest x reached by the bulk along the floor. Particles in a floor
 * layer two lattice layers thick are ranked by x; the front is the k-th furthest, k = the
 * particles of one full lattice slice of that layer (slab_layers of them), plus half a layer
 * (the extent of a particle's volume beyond its centre). A single particle that splashes
 * ahead is not the front the measurements followed; a slice of the layer is. At t = 0 this
 * gives exactly the column's face, Z = 1. */
static double surge_front(const float* positions, uint32_t n, float* scratch, double step,
                          uint32_t slab_layers) {
  uint32_t m = 0;
  const double floor_layer = 2.0 * step;
  for (uint32_t i = 0; i < n; ++i)
    if (positions[3 * i + 1] < floor_layer) scratch[m++] = positions[3 * i];
  if (m == 0) return 0.0;
  qsort(scratch, m, sizeof(float), descending);
  {
    const uint32_t k = slab_layers < m ? slab_layers : m;
    return (double)scratch[k - 1] + 0.5 * step;
  }
}

/* Each particle's neighbours within h (itself included), by the host cell grid (cell_grid.h).
 * The interior measure needs to tell the particles with a full neighbourhood from those at a
 * surface or a collision-only wall, whose density reads low for want of neighbours, not for
 * expansion. Returns 0 when out of memory. */
static int count_neighbors(const float* positions, uint32_t n, double h, uint32_t* counts) {
  support_cell_grid grid;
  if (!support_cell_grid_build(&grid, positions, n, h)) return 0;
  for (uint32_t i = 0; i < n; ++i) {
    const float* p = positions + 3 * i;
    const double q[3] = {p[0], p[1], p[2]};
    const uint32_t near = support_cell_grid_near(&grid, q);
    uint32_t count = 0;
    for (uint32_t k = 0; k < near; ++k) {
      const float* o = positions + 3 * grid.candidates[k];
      const double dx = q[0] - o[0], dy = q[1] - o[1], dz = q[2] - o[2];
      if (dx * dx + dy * dy + dz * dz < h * h) ++count;
    }
    counts[i] = count;
  }
  support_cell_grid_free(&grid);
  return 1;
}

/* One line of a frame's statistics and where its densest particle is (config->frame_log). */
static void log_frame(FILE* log, const dam_break_result* result, const sph_stats* stats,
                      const float* positions, const float* density, uint32_t count, double a) {
  uint32_t densest = 0;
  for (uint32_t i = 1; i < count; ++i)
    if (density[i] > density[densest]) densest = i;
  fprintf(log,
          "frame T %.3f substeps %u dt %.2e..%.2e vmax %.3f rho %.1f..%.1f nbrs %.1f (max %u) it %u (max %u) "
          "div %u (max %u) err %.5f (max %.5f) capped %u densest %u at (%.3f, %.3f, %.3f) a\n",
          result->simulated_seconds * time_scale(), stats->substeps, stats->dt_min, stats->dt_max,
          stats->max_speed, stats->density_min, stats->density_max, stats->neighbors_mean,
          stats->neighbors_max, stats->pressure_iterations, stats->pressure_iterations_max,
          stats->divergence_iterations, stats->divergence_iterations_max, stats->density_error_mean,
          stats->density_error_max, stats->pressure_solves_capped, densest,
          count ? positions[3 * densest] / a : 0.0, count ? positions[3 * densest + 1] / a : 0.0,
          count ? positions[3 * densest + 2] / a : 0.0);
  fflush(log);
}

/* Saves `world` to memory, loads it into a second world of `context` and sets *equal to whether the
 * loaded world's solver statistics are `saved`'s, bit for bit (the checkpoint carries the last
 * step's report, docs/checkpoint.md, TIME). */
static sph_result reload_and_compare(sph_context* context, const sph_world* world, const sph_stats* saved,
                                     int* equal) {
  uint64_t size = 0;
  uint8_t* buffer = NULL;
  sph_world* loaded = NULL;
  sph_stats got;
  sph_result r = sph_world_save(world, NULL, 0, &size);
  if (r != SPH_OK) return r;
  buffer = (uint8_t*)malloc((size_t)size);
  if (!buffer) return SPH_ERROR_OUT_OF_HOST_MEMORY;
  if ((r = sph_world_save(world, buffer, size, &size)) == SPH_OK &&
      (r = sph_world_load(context, buffer, size, &loaded)) == SPH_OK) {
    sph_stats_init(&got);
    if ((r = sph_world_get_stats(loaded, &got)) == SPH_OK) {
      /* pressure_iterations through divergence_solves_capped, then the two fields apart from them */
      const size_t first = offsetof(sph_stats, pressure_iterations);
      const size_t end = offsetof(sph_stats, capacity);
      *equal = memcmp((const char*)&got + first, (const char*)saved + first, end - first) == 0 &&
               memcmp(&got.density_error_largest, &saved->density_error_largest, sizeof(float)) == 0 &&
               got.pressure_solves_guarded == saved->pressure_solves_guarded;
    }
    sph_world_destroy(loaded);
  }
  free(buffer);
  return r;
}

sph_result dam_break_run(sph_context* context, const dam_break_config* config, dam_break_result* result,
                         void (*trace)(void* user, double T, double Z), void* trace_user) {
  const double a = DAM_BREAK_COLUMN_WIDTH;
  /* The lattice step (layer distance of the FCC lattice, spacing / sqrt 2) divides a exactly,
   * so the particles tile the column with no gap at its faces: the column holds exactly the
   * mass of a x 2a x slab at rest density. */
  const double step = a / config->layers_across;
  const double spacing = step * sqrt(2.0);
  const double slab = step * config->slab_layers;
  const double tank_length = 6.0 * a, tank_height = 3.0 * a;
  const uint32_t layers[3] = {config->layers_across, 2 * config->layers_across, config->slab_layers};
  /* With the walls in the density they stand spacing/2 (step/sqrt 2) beyond the lattice's outer
   * layers, where the boundary calibration puts a first layer at rest (physics_boundary_density's
   * tank); at step/2 (0.35 spacings) the walls' share over-reads and the slab starts compressed
   * against them. The column still spans x in [0, a] and the front is still measured from x = 0:
   * the gap, 0.21 steps, is 1 % of a at 20 layers. Without the walls in the density the walls
   * stand at the lattice's faces. */
  const double gap = (config->features & SPH_FEATURE_BOUNDARY_DENSITY) ? 0.5 * step * (sqrt(2.0) - 1.0) : 0.0;
  const double tank_min[3] = {-gap, -gap, -gap};
  const double tank_max[3] = {tank_length, tank_height, slab + gap};
  sph_world_def def;
  sph_world_params params;
  sph_tait_params tait;
  sph_world* world = NULL;
  sph_sdf* tank = NULL;
  float* positions = NULL;
  float* density = NULL;
  float* scratch = NULL;
  uint32_t n = 0;
  double compression_sum = 0.0;
  double density_error_sum = 0.0;
  double above_share_sum = 0.0;
  double interior_error_sum = 0.0, interior_expansion_sum = 0.0, interior_share_sum = 0.0;
  uint32_t sampled = 0, interior_sampled = 0; /* frames measured; of them, frames with an interior */
  uint32_t full_neighbor_count = 0; /* the most neighbours a particle of the lattice has at the start */
  uint32_t* neighbor_counts = NULL;
  sph_result r;

  memset(result, 0, sizeof *result);
  result->spacing = spacing;
  /* FCC: the simple-cubic points with an even index sum, half a step inside every face. */
  r = support_fcc_box(layers, step, NULL, &positions, &n);
  density = (float*)malloc(sizeof(float) * ((size_t)n + 1));
  scratch = (float*)malloc(sizeof(float) * ((size_t)n + 1));
  neighbor_counts = (uint32_t*)malloc(sizeof(uint32_t) * ((size_t)n + 1));
  if (r != SPH_OK || !density || !scratch || !neighbor_counts) {
    free(positions);
    free(density);
    free(scratch);
    free(neighbor_counts);
    return SPH_ERROR_OUT_OF_HOST_MEMORY;
  }
  result->particles = n;

  sph_world_def_init(&def);
  def.capacity = n;
  def.particle_spacing = (float)spacing;
  if (config->kernel_ratio > 0.0f) def.kernel_radius = config->kernel_ratio * (float)spacing;
  def.integrator = config->integrator;
  def.solver = config->solver;
  def.features |= config->features;
  /* DFSPH has no equation of state (Tait is refused with it). */
  def.equation_of_state = config->solver == SPH_SOLVER_DFSPH ? SPH_EOS_IDEAL_GAS : SPH_EOS_TAIT;
  r = sph_world_create(context, &def, &world);
  if (r != SPH_OK) goto done;
  sph_world_params_init(&params);
  params.gravity.x = 0.0f;
  params.gravity.y = (float)-GRAVITY;
  params.gravity.z = 0.0f;
  params.viscosity = config->viscosity;
  params.step_factor = config->step_factor;
  params.step_limits = SPH_STEP_LIMIT_ACOUSTIC;
  params.max_substeps = 100000;
  /* Only lambda limits the step (its speed and acoustic limits), not dt_max. */
  params.dt_max = 0.01f;
  if ((r = sph_world_set_params(world, &params)) != SPH_OK) goto done;
  if (config->solver == SPH_SOLVER_DFSPH) {
    sph_dfsph_params dfsph;
    sph_dfsph_params_init(&dfsph);
    if (config->density_error > 0.0f) dfsph.density_error = config->density_error;
    if (config->density_error_max > 0.0f) dfsph.density_error_max = config->density_error_max;
    if (config->divergence_error > 0.0f) dfsph.divergence_error = config->divergence_error;
    if (config->divergence_error_per_step > 0.0f)
      dfsph.divergence_error_per_step = config->divergence_error_per_step;
    if (config->max_iterations > 0) dfsph.max_iterations = config->max_iterations;
    dfsph.flags = config->dfsph_flags;
    dfsph.linear_solver = config->dfsph_linear_solver;
    if ((r = sph_world_set_dfsph_params(world, &dfsph)) != SPH_OK) goto done;
  } else {
    sph_tait_params_init(&tait);
    tait.speed_of_sound = config->speed_of_sound;
    if ((r = sph_world_set_tait_params(world, &tait)) != SPH_OK) goto done;
  }

  /* The tank: closed on every side (nothing leaves), long enough that the front never reaches
   * the end. */
  r = support_tank_between(context, world, tank_min, tank_max, 0.5 * step, config->friction, &tank, NULL);
  if (r != SPH_OK) goto done;
  if ((r = support_spawn(world, positions, NULL, n)) != SPH_OK) goto done;

  if ((r = sph_world_get_def(world, &def)) != SPH_OK) goto done;
  {
    const double kernel_radius = def.kernel_radius;
    const double scale = time_scale();
    const double frame = config->sample_T / scale;
    const uint32_t frames = (uint32_t)ceil(config->end_T / config->sample_T);
    const double rest = 1000.0;
    for (uint32_t f = 0; f <= frames && result->samples < DAM_BREAK_MAX_SAMPLES; ++f) {
      sph_stats stats;
      uint32_t count = 0;
      if (f > 0) {
        if ((r = sph_world_step(world, (float)frame)) != SPH_OK) goto done;
        sph_stats_init(&stats);
        if ((r = sph_world_get_stats(world, &stats)) != SPH_OK) goto done;
        result->wall_seconds += 1e-3 * stats.step_ms;
        result->substeps += stats.substeps;
        result->simulated_seconds += stats.frame_time;
        if (stats.density_max / rest - 1.0 > result->max_compression)
          result->max_compression = stats.density_max / rest - 1.0;
        result->pressure_iterations += stats.pressure_iterations;
        result->divergence_iterations += stats.divergence_iterations;
        if (stats.pressure_iterations_max > result->pressure_iterations_max)
          result->pressure_iterations_max = stats.pressure_iterations_max;
        result->density_error_mean += (double)stats.density_error_mean * stats.substeps;
        if (stats.density_error_max > result->density_error_max)
          result->density_error_max = stats.density_error_max;
        if (stats.density_error_largest > result->density_error_largest)
          result->density_error_largest = stats.density_error_largest;
        result->capped_substeps += stats.pressure_solves_capped;
        result->guarded_substeps += stats.pressure_solves_guarded;
        if (config->check_reload && stats.pressure_solves_guarded > 0 && !result->reload_checked) {
          if ((r = reload_and_compare(context, world, &stats, &result->reload_stats_equal)) != SPH_OK)
            goto done;
          result->reload_checked = 1;
        }
        for (int k = 0; k < SPH_STAGE_COUNT; ++k) result->stage_ms[k] += stats.stage_ms[k];
        result->neighbors_mean += (double)stats.neighbors_mean * stats.substeps;
        {
          sph_event events[8];
          uint32_t event_count = 0;
          if ((r = sph_world_get_events(world, events, 8, &event_count)) != SPH_OK && r != SPH_INCOMPLETE)
            goto done;
          for (uint32_t e = 0; e < event_count && e < 8; ++e)
            if (events[e].type == SPH_EVENT_PRESSURE_SOLVE_CAPPED) result->capped_events += events[e].count;
        }
      }
      if ((r = sph_world_get_particle_count(world, &count)) != SPH_OK) goto done;
      if ((r = sph_world_copy_attribute(world, SPH_ATTRIBUTE_POSITION, positions, sizeof(float) * 3 * n, 0, 0,
                                        count, NULL)) != SPH_OK)
        goto done;
      if (config->measure_interior) {
        if (!count_neighbors(positions, count, kernel_radius, neighbor_counts)) {
          r = SPH_ERROR_OUT_OF_HOST_MEMORY;
          goto done;
        }
        if (f == 0)
          for (uint32_t i = 0; i < count; ++i)
            if (neighbor_counts[i] > full_neighbor_count) full_neighbor_count = neighbor_counts[i];
      }
      if (f > 0) {
        double sum = 0.0, interior_error = 0.0, interior_expansion = 0.0;
        uint32_t above = 0, interior = 0;
        if ((r = sph_world_copy_attribute(world, SPH_ATTRIBUTE_DENSITY, density, sizeof(float) * n, 0, 0,
                                          count, NULL)) != SPH_OK)
          goto done;
        for (uint32_t i = 0; i < count; ++i) {
          const double e = density[i] / rest - 1.0;
          if (e > 0.0) {
            sum += e;
            ++above;
          }
          /* (DAM_BREAK_FULL_NEIGHBORHOOD_SHARE says which particles count, and why.) */
          if (config->measure_interior && full_neighbor_count > 0 &&
              neighbor_counts[i] >= DAM_BREAK_FULL_NEIGHBORHOOD_SHARE * full_neighbor_count) {
            interior_error += fabs(e);
            interior_expansion += e < 0.0 ? -e : 0.0;
            ++interior;
          }
        }
        ++sampled;
        compression_sum += above ? sum / above : 0.0;
        density_error_sum += count ? sum / count : 0.0;
        above_share_sum += count ? (double)above / count : 0.0;
        if (interior) {
          ++interior_sampled;
          interior_error_sum += interior_error / interior;
          interior_expansion_sum += interior_expansion / interior;
        }
        interior_share_sum += count ? (double)interior / count : 0.0;
        if (config->frame_log) log_frame(config->frame_log, result, &stats, positions, density, count, a);
      }
      result->T[result->samples] = result->simulated_seconds * scale;
      result->Z[result->samples] = surge_front(positions, count, scratch, step, config->slab_layers) / a;
      if (trace) trace(trace_user, result->T[result->samples], result->Z[result->samples]);
      ++result->samples;
      if (f == frames) {
        const float tol = (float)(0.5 * step);
        result->state_digest = position_digest(positions, count);
        for (uint32_t i = 0; i < count; ++i) {
          const float* p = positions + 3 * i;
          if (p[0] < tank_min[0] - tol || p[0] > tank_max[0] + tol || p[1] < tank_min[1] - tol ||
              p[1] > tank_max[1] + tol || p[2] < tank_min[2] - tol || p[2] > tank_max[2] + tol)
            ++result->escaped;
        }
      }
    }
    /* Over the frames measured (the samples' cap can end the loop early). */
    result->mean_compression = sampled ? compression_sum / sampled : 0.0;
    result->mean_density_error = sampled ? density_error_sum / sampled : 0.0;
    result->above_share = sampled ? above_share_sum / sampled : 0.0;
    result->interior_error = interior_sampled ? interior_error_sum / interior_sampled : 0.0;
    result->interior_expansion = interior_sampled ? interior_expansion_sum / interior_sampled : 0.0;
    result->interior_share = sampled ? interior_share_sum / sampled : 0.0;
    if (result->substeps > 0) result->density_error_mean /= (double)result->substeps;
    if (result->substeps > 0) result->neighbors_mean /= (double)result->substeps;
  }

  /* The one allowed shift, fitted by minimising the mean error on a 0.005 grid. */
  dam_break_compare(result, 0.0, &result->mean_error_unshifted, &result->max_error_unshifted,
                    &result->compared);
  result->shift_T = 0.0;
  result->mean_error = result->mean_error_unshifted;
  result->max_error = result->max_error_unshifted;
  for (int s = -40; s <= 40; ++s) {
    double mean, worst;
    uint32_t compared;
    const double shift = 0.005 * s;
    dam_break_compare(result, shift, &mean, &worst, &compared);
    if (mean < result->mean_error) {
      result->mean_error = mean;
      result->max_error = worst;
      result->shift_T = shift;
    }
  }
  r = SPH_OK;

done:
  if (r != SPH_OK) {
    /* Keep the failing call's message: the clean-up calls below reset the last error. */
    strncpy(result->message, sph_get_last_error(), sizeof result->message - 1);
    result->message[sizeof result->message - 1] = '\0';
  }
  if (world) sph_world_destroy(world);
  if (tank) sph_sdf_destroy(tank);
  free(positions);
  free(density);
  free(scratch);
  free(neighbor_counts);
  return r;
}

void dam_break_compare(const dam_break_result* result, double shift_T, double* mean_error, double* max_error,
                       uint32_t* compared) {
  double sum = 0.0, worst = 0.0;
  uint32_t count = 0;
  for (int m = 0; m < DAM_BREAK_MEASUREMENTS; ++m) {
    const double T = dam_break_measured_T[m], Zm = dam_break_measured_Z[m];
    const double t = T + shift_T;
    double Zs = 0.0, error;
    if (T < DAM_BREAK_T_FIRST || T > DAM_BREAK_T_LAST) continue;
    if (result->samples < 2 || t < result->T[0] || t > result->T[result->samples - 1]) {
      error = 1.0; /* not simulated that far: count it as a 100 % miss */
    } else {
      uint32_t i = 1;
      while (i < result->samples - 1 && result->T[i] < t) ++i;
      {
        const double w = (t - result->T[i - 1]) / (result->T[i] - result->T[i - 1]);
        Zs = result->Z[i - 1] + w * (result->Z[i] - result->Z[i - 1]);
      }
      error = fabs(Zs - Zm) / Zm;
    }
    sum += error;
    if (error > worst) worst = error;
    ++count;
  }
  *mean_error = count ? sum / count : 1.0;
  *max_error = worst;
  *compared = count;
}
