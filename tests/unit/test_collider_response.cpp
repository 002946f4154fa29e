// SPDX-License-Identifier: MIT
// The collision response's push-out (src/physics/collider_response.h, push_out) against the exact
// box it samples: a particle inside a solid box, near a face, an edge or a corner, must leave on
// the box's surface. The box is test_collider_loads.c's submerged cube (half side 3 cm, 5 mm
// voxels, its faces on the samples, so the trilinear field's zero level is the exact surface).
// Inside an edge the trilinear field is flat (-voxel (1 - fx) (1 - fy) in the edge's cell), so a
// single step of -distance along the normal left such particles inside, where they stayed caught
// (docs/validation.md, "The submerged box: particles caught inside its edges").
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
extern "C" {
#include <cmocka.h>
}

#include <cmath>
#include <cstdio>

#include "core/sdf_shapes.h"
#include "physics/collider_response.h"

namespace {

const float kHalf = 0.03f, kVoxel = 0.005f;

sph::ShapeSpec box_spec() {
  sph::ShapeSpec spec;
  spec.kind = sph::ShapeKind::Box;
  spec.half_extents = sph::Vec3{kHalf, kHalf, kHalf};
  spec.voxel_size = kVoxel;
  spec.padding_voxels = 8;
  return spec;
}

sph::ColliderView static_box(const sph::SdfAsset& asset) {
  sph::ColliderView c{};
  c.sdf = asset.host_view();
  c.pose_start = c.pose_end =
      sph::RigidTransform{sph::Vec3{0.0f, 0.0f, 0.0f}, sph::Quat{0.0f, 0.0f, 0.0f, 1.0f}};
  c.sign = 1.0f;
  return c;
}

// A particle that starts the substep at x (already inside: the path's contact is skipped, as for
// a particle left inside by the substep before) and rests. Returns the exact distance of where the
// response puts it, and its distance in the sampled field through *sampled.
double resolve(const sph::ColliderView& c, const sph::ShapeSpec& spec, sph::Vec3 x, float* sampled) {
  const sph::SubstepTime t{0.0f, 1.0f, 0.0f, 1e-3f, 1e-3f};
  sph::Vec3 v{0.0f, 0.0f, 0.0f};
  const bool touched = sph::collide_particle(c, t, 0.025f, x, x, v);
  assert_true(touched);
  *sampled = sph::sample_collider(c, x, 1.0f, 1e-3f).distance;
  return sph::shape_distance(spec, x);
}

// Depths below the faces, from a hundredth of a voxel to most of one: the flat field's range.
const float kDepths[] = {5e-5f, 2e-4f, 5e-4f, 1e-3f, 2e-3f, 4e-3f};

// Out of an edge and of a corner: on the surface (the sampled field >= 0; the exact distance
// >= -1e-6 m, float rounding, and within the last bisection bracket of it, 2e-5 m).
void test_edges_and_corners(void**) {
  const sph::ShapeSpec spec = box_spec();
  const auto asset = sph::build_shape_sdf(spec, 1u << 24);
  const sph::ColliderView c = static_box(*asset);
  double worst = 0.0, farthest = 0.0;
  int cases = 0;
  for (float a : kDepths)
    for (float b : kDepths)
      for (float along : {0.0f, 0.0113f, -0.021f}) {
        // Below the +x and +y faces (an edge along z), and below +x, +y and +z (a corner).
        const sph::Vec3 edge{kHalf - a, kHalf - b, along};
        const sph::Vec3 corner{kHalf - a, kHalf - b, kHalf - 0.5f * (a + b) - std::fabs(along) * 0.1f};
        for (const sph::Vec3& x : {edge, corner}) {
          float sampled = 0.0f;
          const double exact = resolve(c, spec, x, &sampled);
          if (sampled < 0.0f || exact < -1e-6 || exact > 2e-5)
            std::printf("from (%.5f, %.5f, %.5f): sampled %.3g m, exact %.3g m\n", x.x, x.y, x.z, sampled,
                        exact);
          assert_true(sampled >= 0.0f);
          assert_true(exact >= -1e-6 && exact <= 2e-5);
          worst = std::fmin(worst, exact);
          farthest = std::fmax(farthest, exact);
          ++cases;
        }
      }
  std::printf(
      "%d particles inside an edge or a corner: the exact distance after the push-out %.3g to %.3g m\n",
      cases, worst, farthest);
}

// A face's middle, where the field is a distance: one step, onto the face within float rounding.
void test_face(void**) {
  const sph::ShapeSpec spec = box_spec();
  const auto asset = sph::build_shape_sdf(spec, 1u << 24);
  const sph::ColliderView c = static_box(*asset);
  for (float d : kDepths) {
    float sampled = 0.0f;
    const double exact = resolve(c, spec, sph::Vec3{0.004f, kHalf - d, -0.007f}, &sampled);
    if (std::fabs(exact) > 1e-6)
      std::printf("face, %.3g m deep: sampled %.3g m, exact %.3g m\n", d, sampled, exact);
    assert_true(std::fabs(exact) <= 1e-6);
  }
}

}  // namespace

int main() {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_edges_and_corners),
      cmocka_unit_test(test_face),
  };
  return cmocka_run_group_tests(tests, nullptr, nullptr);
}
