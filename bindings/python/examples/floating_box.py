#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Two-way coupling from Python: a wooden box (500 kg/m^3) dropped onto water floats.

    SPH_LIBRARY=build/libsph.so python3 bindings/python/examples/floating_box.py [--seconds 3]

The box is a collider; a small rigid-body integrator, standing in for a game engine's, owns its
motion. Every frame it reads the fluid's force and torque on the collider (Collider.loads, the
world feature "collider_loads", the torque about the box's centre set with set_load_point), adds
gravity, integrates the body over the frame and sends the pose it reaches as the collider's
target (Collider.move_to); the library moves the collider there through the next frame's
substeps. The walls count in the density ("boundary_density"), so the pressure reaches the box.
It prints the box's height and its draft (below the still water's 20 cm) every 0.125 s; the
Archimedes draft is m / (rho0 A) = 5 cm. The same scene in C: samples/floating_box.c.

The coupling is explicit (the body sees the last frame's loads); frames of 1/120 s keep a body
half as dense as water stable. Not a validation: at 2 cm spacing the draft is 2.5 particles.
"""
import argparse
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import sph  # noqa: E402

HALF, DENSITY, RHO0, G, DT, DEPTH = 0.05, 500.0, 1000.0, 9.81, 1.0 / 120.0, 0.2


class RigidBody:
    """The engine's side: a cube's state and a symplectic Euler step over a frame."""

    def __init__(self, position):
        self.mass = DENSITY * 8 * HALF**3
        self.inertia = self.mass * (2 * HALF) ** 2 / 6.0
        self.position = np.array(position, dtype=float)
        self.velocity = np.zeros(3)
        self.rotation = np.array([0.0, 0.0, 0.0, 1.0])  # x, y, z, w
        self.angular = np.zeros(3)

    def step(self, force, torque, dt):
        self.velocity += (np.asarray(force) + [0.0, -self.mass * G, 0.0]) / self.mass * dt
        self.position += self.velocity * dt
        self.angular += np.asarray(torque) / self.inertia * dt
        x, y, z, w = self.rotation
        ox, oy, oz = self.angular
        dq = 0.5 * dt * np.array([ox * w + oy * z - oz * y, -ox * z + oy * w + oz * x,
                                  ox * y - oy * x + oz * w, -ox * x - oy * y - oz * z])
        self.rotation = (self.rotation + dq) / np.linalg.norm(self.rotation + dq)

    def pose(self):
        return (tuple(self.position), tuple(self.rotation))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seconds", type=float, default=3.0, help="simulated seconds (default 3)")
    ap.add_argument("--backend", default="auto", choices=["auto", "cpu", "cuda"])
    args = ap.parse_args()
    body = RigidBody((0.0, DEPTH + HALF + 0.01, 0.0))  # 1 cm above the water
    with sph.Context(args.backend) as ctx:
        tank = ctx.shape("box", half_extents=(0.2, 0.25, 0.2), voxel_size=0.01)
        # The box's SDF reaches 8 voxels beyond it (more than the kernel radius, as the walls in
        # the density need).
        box_sdf = ctx.shape("box", half_extents=(HALF, HALF, HALF), voxel_size=0.01, padding_voxels=8)
        world = ctx.world(capacity=12_000, particle_spacing=0.02, features="collider_loads|boundary_density")
        world.add_collider(tank, (0.0, 0.25, 0.0), inverted=True)
        box = world.add_collider(box_sdf, body.pose())
        box.set_load_point((0.0, 0.0, 0.0))  # the centre of mass, in the box's frame
        n = world.fill_box((-0.2, 0.0, -0.2), (0.2, DEPTH, 0.2))
        print(f"floating_box: {n} particles on the {ctx.backend.name} backend; Archimedes' draft "
              f"{100 * body.mass / (RHO0 * 4 * HALF * HALF):.1f} cm")
        for frame in range(1, int(round(args.seconds / DT)) + 1):
            world.step(DT)
            loads = box.loads
            body.step((loads.force.x, loads.force.y, loads.force.z),
                      (loads.torque.x, loads.torque.y, loads.torque.z), DT)
            box.move_to(body.pose())
            if frame % 15 == 0:
                print(f"t = {frame * DT:.3f} s: centre at y = {body.position[1]:.4f} m, draft "
                      f"{100 * (DEPTH - (body.position[1] - HALF)):.2f} cm, vertical speed "
                      f"{body.velocity[1]:+.3f} m/s, fluid's force {loads.force.y:.3f} N "
                      f"(weight {body.mass * G:.3f} N)")
        if not math.isfinite(body.position[1]) or abs(body.position[1] - DEPTH) > 0.1:
            print("floating_box: the box did not float", file=sys.stderr)
            return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
