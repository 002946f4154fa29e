// SPDX-License-Identifier: MIT
#include "substep_pipeline.h"

namespace sph {
namespace {

// The probes' samples; on a distributed rank every rank takes each point's owner's gather first.
void enqueue_probes(const DeviceProbes& probes, const GridView& grid, const ParticleArrays& a,
                    FrameState* state, cudaStream_t stream, SubstepHooks* hooks) {
  if (!hooks) return enqueue_probe_samples(probes, grid, a, state, stream);
  enqueue_probe_points(probes, grid, a, stream);
  hooks->after_probe_points(probes, stream);
  enqueue_probe_sums(probes, state, stream);
}

}  // namespace

void enqueue_frame_begin(const PipelineSetup& setup, const PipelineBuffers& b, LoopCondition cond,
                         cudaStream_t stream, bool measure_height) {
  cuda_check(cudaMemcpyAsync(b.state, b.input, sizeof(FrameInput), cudaMemcpyHostToDevice, stream),
             "copy of the frame input");
  // DFSPH's depth limit: H of the first step from the frame's positions (a distributed rank's
  // were measured and reduced over the ranks before: measure_height false).
  if (measure_height && setup.limits.depth_step_factor > 0.0f)
    enqueue_height_span(b.store->arrays().position, nullptr, setup.count, setup.limits, b.state, stream);
  enqueue_begin_frame(b.state, setup.limits, setup.max_substeps, cond, stream);
  b.store->enqueue_snapshot(setup.count, stream);
  if (setup.loads.on()) enqueue_loads_begin(setup.loads, stream);
  if (setup.probes.on()) enqueue_probes_begin(setup.probes, stream);
}

void enqueue_substep(const PipelineSetup& setup, const PipelineBuffers& b, LoopCondition cond,
                     cudaStream_t stream, SubstepHooks* hooks) {
  const ParticleArrays& a = b.store->arrays();
  uint32_t n = setup.count;  // (a distributed rank's RK4 stages gather their own halos)
  const bool rk4 = setup.integrator == Integrator::Rk4;
  const int stages = rk4 ? kRk4Stages : 1;
  if (setup.options.dfsph) {
    b.grid->enqueue_sort(a.position, n, b.state, stream, hooks ? hooks->visit : nullptr);
    b.grid->enqueue_cell_starts(n, b.state, stream);
    if (hooks) hooks->after_sort(stream);
    enqueue_reorder(a, b.grid->order(), n, Rk4Carry::None, 0, b.grid->crowd_guard(), b.state, stream);
    if (setup.options.springs) enqueue_spring_reorder(a, b.grid->order(), n, stream);
    enqueue_dfsph_density(
        setup.fluid, b.grid->view(), a, n, setup.options, setup.tuning, setup.scene,
        dfsph_divergence_warm_start_in_density_pass(setup.fluid, setup.options, hooks != nullptr), b.state,
        stream);
    // A distributed rank: the ghosts take their owners' densities and factors, then their colour
    // normals, before anything reads them (as on the CPU rank); the solves' own refreshes run
    // inside them (DfsphLoops::rank).
    if (hooks) hooks->after_dfsph_density(stream);
    if (setup.options.surface_tension) {
      enqueue_colour_normals(setup.fluid, b.grid->view(), a, n, setup.tuning, stream);
      if (hooks) hooks->after_normals(stream);
    }
    if (setup.options.springs)
      enqueue_spring_pass(setup.springs, b.grid->view(), a, n, true, b.state, stream, hooks);
    const DfsphLoops loops{cond.in_graph, b.solve_partials, b.state_output, hooks};
    const bool loads = setup.loads.on();
    enqueue_dfsph_step(setup.fluid, b.grid->view(), a, n, setup.options, setup.tuning, setup.scene, loops,
                       !loads, b.state, stream);
    // Probes sample the substep's start once the solves have found its pressure, as on the CPU.
    if (setup.probes.on()) enqueue_probes(setup.probes, b.grid->view(), a, b.state, stream, hooks);
    // Loads: the walls' reactions of both solves, the contact clamp's impulses, the contacts.
    if (loads)
      enqueue_loads(setup.fluid, a, n, setup.scene, setup.loads, setup.options.boundary_density, 0.0f, 1.0f,
                    true, false, b.state, stream);
    // DFSPH's depth limit: H of the next step from the positions this substep leaves (after the
    // loads pass's collisions), before a distributed rank's reduction over the ranks.
    if (setup.limits.depth_step_factor > 0.0f)
      enqueue_height_span(a.position, a.halo_ghost, n, setup.limits, b.state, stream);
    if (hooks) hooks->before_end(stream);
    enqueue_end_substep(b.state, setup.limits, setup.max_substeps, 1, cond, stream);
    return;
  }
  for (int stage = 0; stage < stages; ++stage) {
    if (hooks && stage > 0 && !hooks->next_stage(stage, &n, stream)) break;
    b.grid->enqueue_sort(a.position, n, b.state, stream, hooks ? hooks->visit : nullptr);
    b.grid->enqueue_cell_starts(n, b.state, stream);
    if (hooks) hooks->after_sort(stream);
    const Rk4Carry carry = !rk4 ? Rk4Carry::None : (stage == 0 ? Rk4Carry::BuildStart : Rk4Carry::Gather);
    enqueue_reorder(a, b.grid->order(), n, carry, stage & 1, b.grid->crowd_guard(), b.state, stream);
    if (setup.options.springs) enqueue_spring_reorder(a, b.grid->order(), n, stream);
    if (!hooks) {
      enqueue_density(setup.fluid, b.grid->view(), a, n, setup.options, setup.tuning, setup.scene,
                      rk4 ? rk4_stage_fraction(stage) : 0.0f, stage == 0, b.state, stream);
    } else {
      // A distributed rank: the ghosts take their owners' records after each publication of the
      // densities, as on the CPU rank (cpu_substep_kernels.cpp), before anything reads them.
      enqueue_density_summation(setup.fluid, b.grid->view(), a, n, setup.options, setup.tuning, setup.scene,
                                rk4 ? rk4_stage_fraction(stage) : 0.0f, b.state, stream);
      hooks->after_density(stream);
      if (enqueue_density_republish(setup.fluid, b.grid->view(), a, n, setup.options, setup.tuning,
                                    stage == 0, b.state, stream))
        hooks->after_density(stream);
      if (setup.options.surface_tension) {
        enqueue_colour_normals(setup.fluid, b.grid->view(), a, n, setup.tuning, stream);
        hooks->after_normals(stream);
      }
    }
    // Probes sample the substep's start (RK4: its first stage), as on the CPU.
    if (stage == 0 && setup.probes.on())
      enqueue_probes(setup.probes, b.grid->view(), a, b.state, stream, hooks);
    if (setup.options.springs)
      enqueue_spring_pass(setup.springs, b.grid->view(), a, n, stage == 0, b.state, stream, hooks);
    const bool loads = setup.loads.on();
    if (rk4)
      enqueue_forces_rk4(setup.fluid, b.grid->view(), a, n, stage, setup.options, setup.tuning, setup.scene,
                         !loads, b.state, stream);
    else
      enqueue_forces_euler(setup.fluid, b.grid->view(), a, n, setup.options, setup.tuning, setup.scene,
                           !loads, b.state, stream);
    // Loads: the walls' reactions of every force evaluation, the contacts after the last.
    const bool last = stage == stages - 1;
    if (loads && (setup.options.boundary_density || last))
      enqueue_loads(setup.fluid, a, n, setup.scene, setup.loads, setup.options.boundary_density,
                    rk4 ? rk4_stage_fraction(stage) : 0.0f, rk4 ? rk4_weight(stage) : 1.0f, last, rk4,
                    b.state, stream);
  }
  if (hooks) hooks->before_end(stream);
  enqueue_end_substep(b.state, setup.limits, setup.max_substeps, stages, cond, stream);
}

void enqueue_frame_end(const PipelineSetup& setup, const PipelineBuffers& b, cudaStream_t stream,
                       const uint32_t* counts) {
  b.statistics->enqueue(setup.fluid, b.grid->view(), b.store->arrays(), setup.count, b.state, stream, counts,
                        setup.ghosts);
  if (setup.loads.on()) enqueue_loads_end(setup.loads, stream);
  if (setup.probes.on()) enqueue_probes_end(setup.probes, stream);
  cuda_check(cudaMemcpyAsync(b.state_output, b.state, sizeof(FrameState), cudaMemcpyDeviceToHost, stream),
             "copy of the frame state");
}

}  // namespace sph
