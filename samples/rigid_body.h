// SPDX-License-Identifier: MIT
/* The engine's side of two-way coupling, as small as it can be: a rigid body with its state,
 * stepped over a frame from the fluid's loads on its collider (sph_collider_get_loads) plus its
 * weight, and its pose for sph_collider_set_target_transform. samples/floating_box.c and the
 * floating-box case of tests/physics_options/test_collider_loads.c both use it; an engine has its
 * own integrator in its place.
 *
 * The step is semi-implicit (symplectic) Euler: v += F/m dt, then x += v dt; omega += tau/I dt
 * with one scalar inertia (a cube's: m a^2 / 6 about every axis through its centre, so no
 * gyroscopic term), then the rotation q += dt/2 (omega, 0) q, renormalised. */
#ifndef SPH_SAMPLES_RIGID_BODY_H
#define SPH_SAMPLES_RIGID_BODY_H

#include <math.h>

#include "sph_c.h"

typedef struct rigid_body {
  double mass;        /* kg */
  double inertia;     /* kg m^2, about every axis through the centre of mass */
  double position[3]; /* centre of mass, m */
  double velocity[3]; /* m/s */
  double rotation[4]; /* x, y, z, w */
  double angular[3];  /* rad/s, world frame */
} rigid_body;

/* One frame of dt seconds under the fluid's loads (force, and torque about the centre of mass)
 * and gravity g (m/s^2, along -y). */
static inline void rigid_body_step(rigid_body* b, const sph_collider_loads* loads, double g, double dt) {
  const double force[3] = {loads->force.x, loads->force.y - b->mass * g, loads->force.z};
  const double torque[3] = {loads->torque.x, loads->torque.y, loads->torque.z};
  double* q = b->rotation;
  double dq[4], n;
  int k;
  for (k = 0; k < 3; ++k) {
    b->velocity[k] += force[k] / b->mass * dt;
    b->position[k] += b->velocity[k] * dt;
    b->angular[k] += torque[k] / b->inertia * dt;
  }
  dq[0] = 0.5 * dt * (b->angular[0] * q[3] + b->angular[1] * q[2] - b->angular[2] * q[1]);
  dq[1] = 0.5 * dt * (-b->angular[0] * q[2] + b->angular[1] * q[3] + b->angular[2] * q[0]);
  dq[2] = 0.5 * dt * (b->angular[0] * q[1] - b->angular[1] * q[0] + b->angular[2] * q[3]);
  dq[3] = 0.5 * dt * (-b->angular[0] * q[0] - b->angular[1] * q[1] - b->angular[2] * q[2]);
  for (k = 0; k < 4; ++k) q[k] += dq[k];
  n = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  for (k = 0; k < 4; ++k) q[k] /= n;
}

/* The body's pose as a collider transform (its origin at the centre of mass). */
static inline sph_transform rigid_body_pose(const rigid_body* b) {
  sph_transform t;
  t.position.x = (float)b->position[0];
  t.position.y = (float)b->position[1];
  t.position.z = (float)b->position[2];
  t.rotation.x = (float)b->rotation[0];
  t.rotation.y = (float)b->rotation[1];
  t.rotation.z = (float)b->rotation[2];
  t.rotation.w = (float)b->rotation[3];
  return t;
}

#endif /* SPH_SAMPLES_RIGID_BODY_H */
