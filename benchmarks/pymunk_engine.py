"""The benchmark walls in pymunk (Chipmunk2D), a game engine, for the solver benchmark's comparison row.

pymunk is an optional benchmark extra (``pip install -e ".[bench]"``), never a dependency of masonry.
The wall is the same: the blocks of ``geometry_library.builders.build_wall`` with their mass and
inertia from ``mass_properties`` (ρ = 2500 kg/m³, 1 m thick), Coulomb μ = 0.6 (pymunk multiplies the two
shapes' coefficients: each gets √0.6), a kinematic ground moving at 1 m/s · sin(2π · 2 Hz · t),
gravity −9.81, dt = 1e-3, a fixed number of solver passes (``iterations``, 100 by default).
Chipmunk is a sequential-impulse solver with soft contacts: it lets contacts overlap by up to
``collision_slop`` and pushes them apart with a bias velocity, none of which masonry does; the slop is
set to 0.1 mm here (its default, 0.1, is in the scene's length unit: 10 cm) and the accuracy row
says how far it lands from masonry's tight solve.
"""

from __future__ import annotations

import math
import time

import numpy as np

from geometry_library.builders import BUILDERS
from geometry_library.mass import mass_properties

from .solver_cases import CASES, course_of, slips

MU = 0.6
SLOP = 1e-4


def available() -> bool:
    try:
        import pymunk  # noqa: F401
    except ImportError:
        return False
    return True


def run_wall(case: str, duration: float, iterations: int = 100, sample_steps=(100, 200)) -> dict:
    """Simulate ``case`` (a wall of solver_cases.CASES) for ``duration`` s; CPU time of the stepping loop,
    and (top-course, mean) slip at each step of ``sample_steps``."""
    import pymunk

    builder, options, _, motions = CASES[case]
    if builder != "wall":
        raise ValueError(f"{case}: pymunk runs the walls only")
    assembly = BUILDERS[builder](**options).build()
    motion = motions["ground"]
    dt = 1e-3
    space = pymunk.Space()
    space.gravity = (0.0, -9.81)
    space.iterations = iterations
    space.collision_slop = SLOP
    friction = math.sqrt(MU)
    ground_poly = assembly.supports[0].vertices
    ground = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
    shape = pymunk.Poly(ground, [tuple(p) for p in ground_poly], radius=0.0)
    shape.friction = friction
    space.add(ground, shape)
    bodies = []
    for block in assembly.blocks:
        verts = block.vertices
        props = mass_properties(verts, density=2500.0, thickness=1.0)
        centroid = np.asarray(props.centroid)
        body = pymunk.Body(props.mass, props.inertia)
        body.position = tuple(centroid)
        poly = pymunk.Poly(body, [tuple(p) for p in verts - centroid], radius=0.0)
        poly.friction = friction
        space.add(body, poly)
        bodies.append(body)
    x0 = np.array([b.position.x for b in bodies])
    course = course_of([b.name for b in assembly.blocks])
    omega = 2.0 * math.pi * motion.frequency
    steps = round(duration / dt)
    samples = {}
    cpu = 0.0
    for k in range(steps):
        t_next = (k + 1) * dt
        # Same imposed velocity as masonry's supports over the step: v(t_n+1).
        ground.velocity = (motion.amplitude * math.sin(omega * t_next), 0.0)
        t = time.process_time()
        space.step(dt)
        cpu += time.process_time() - t
        if k + 1 in sample_steps:
            ground_dx = ground.position.x
            x = np.array([b.position.x for b in bodies])
            samples[k + 1] = slips(x0, x, ground_dx, course)
    return {"cpu_s": cpu, "sim_s": steps * dt, "slips": samples, "blocks": len(bodies)}
