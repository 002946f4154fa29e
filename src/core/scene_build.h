// SPDX-License-Identifier: MIT
// The rules of a world's scene objects, written once for every way in: the world's entry
// points (World::add_collider and the like, which the C layer calls) and the checkpoint
// reader. Each make_* validates a spec, resolves its zero defaults (against the world's
// configuration where they depend on it) and returns the object the world keeps. Errors are
// FieldErrors naming the spec's field as the public def names it; a caller puts its own path
// in front (with_field_prefix).
#pragma once

#include "config.h"
#include "scene_objects.h"

namespace sph {

// restitution in [0, 1], friction and stickiness >= 0, all finite.
void check_collider_material(const ColliderMaterial& material);

Collider make_collider(const ColliderSpec& spec);
// Without its lattice: World::add_source computes it, the checkpoint reader reads it.
Source make_source(const SourceSpec& spec, const WorldConfig& config);
Sink make_sink(const SinkSpec& spec);
ForceField make_force_field(const ForceFieldSpec& spec);

}  // namespace sph
