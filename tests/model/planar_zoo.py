"""A planar model with every contact kind, body kind and force of the builder (for the tests)."""


import numpy as np

from moreau.model.planar import Circle, HalfPlane, Model, Point, Polygon, Segment, TimeFunction


def zoo(units=None):
    """Three free bodies, a driven one and the ground; every contact kind and force.

    Returns ``(scene, model)``.
    """
    m = Model(gravity=(0.3, -9.81), **(units or {}))
    floor = m.add_shape(m.ground, HalfPlane((0.0, -0.05), (0.1, 1.0)))
    # far enough that the random states' paths do not cross it: a two-sided segment's gap
    # (the distance) has a kink where a point passes through it
    wall = m.add_shape(m.ground, Segment((2.4, -0.2), (2.5, 0.8)))
    box = m.add_body(1.5, 0.02, position=(0.0, 0.2), angle=0.1, velocity=(0.3, -0.2),
                     angular_velocity=1.0, name="box")
    disk = m.add_body(0.7, 0.004, position=(0.5, 0.3), angle=-0.3, velocity=(-0.1, 0.4),
                      angular_velocity=-2.0, name="disk")
    rod = m.add_body(0.4, 0.003, position=(0.9, 0.5), angle=0.7, name="rod")
    crank = m.add_driven(x=TimeFunction(1.0, harmonics=[(0.02, 7.0, 0.3)]),
                         y=TimeFunction(0.1, rate=0.2, accel=-0.4),
                         theta=TimeFunction(0.2, rate=3.0, harmonics=[(0.1, 5.0, 1.0)]),
                         name="crank")
    sbox = m.add_shape(box, Polygon([(-0.1, -0.08), (0.12, -0.1), (0.1, 0.09), (-0.11, 0.1)]))
    sdisk = m.add_shape(disk, Circle(0.08, centre=(0.01, -0.02)))
    srod = m.add_shape(rod, Segment((-0.15, 0.0), (0.15, 0.01)))
    stip = m.add_shape(rod, Point((0.15, 0.01)))
    scrank = m.add_shape(crank, Polygon([(-0.05, -0.05), (0.2, -0.04), (0.0, 0.06)]))
    scrank_disk = m.add_shape(crank, Circle(0.03, centre=(0.2, -0.04)))
    crank_floor = m.add_shape(crank, HalfPlane((0.0, -0.3), (0.2, 1.0)))
    m.add_contact(sbox, floor, mu=0.4, restitution=0.2)            # polygon-halfplane: 4
    m.add_contact(sdisk, floor, mu=0.6)                            # circle-halfplane
    m.add_contact(sdisk, sbox, mu=0.3, restitution=0.5)            # circle-polygon
    m.add_contact(sdisk, wall, mu=0.2)                             # circle-segment
    m.add_contact(srod, floor, mu=0.1)                             # segment-halfplane: 2
    m.add_contact(stip, wall)                                      # point-segment, frictionless
    m.add_contact(sbox, scrank, mu=0.5, vertices=(1, 2))           # polygon-polygon (driven)
    m.add_contact(scrank_disk, sdisk, mu=0.3)                      # circle-circle (driven)
    m.add_contact(stip, crank_floor, mu=0.7)                       # point-halfplane of a driven body
    m.add_contact(srod, sbox, mu=0.25)                             # segment-polygon: 2 + 4
    m.add_contact(sdisk, m.add_shape(rod, Circle(0.02)), mu=0.1)   # circle-circle (free)
    m.add_spring(box, (0.05, 0.05), disk, (0.0, 0.02), stiffness=40.0, damping=0.7)
    m.add_spring(disk, (0.02, 0.0), crank, (0.1, 0.0), stiffness=10.0, rest_length=0.2,
                 damping=0.3)
    m.add_damper(rod, (0.1, 0.0), m.ground, (1.0, 1.0), damping=0.5)
    m.add_torsion_spring(box, disk, stiffness=0.8, damping=0.05)
    m.add_torsion_spring(rod, crank, stiffness=0.3, rest_angle=0.1, damping=0.02)
    m.add_force(box, (TimeFunction(0.5, harmonics=[(1.0, 4.0, 0.2)]), -0.3), point=(0.05, 0.02))
    m.add_torque(disk, TimeFunction(0.01, rate=0.02))
    return m.build("planar-zoo"), m


def random_states(scene, count, seed):
    """States around the initial one: positions by 0.3, angles by 1, velocities by 2 (scene units)."""
    rng = np.random.default_rng(seed)
    q0, v0 = scene.initial_state()
    scale = np.tile([0.3, 0.3, 1.0], scene.ndof // 3)
    return [(q0 + scale * rng.standard_normal(scene.ndof), v0 + 2.0 * rng.standard_normal(scene.ndof))
            for _ in range(count)]


def mini_zoo(units=None):
    """One contact of each kind (line, polygon, point to point, segment of a driven body), each force once.

    The default run's model: it compiles in about 15 s with an empty cache, the full zoo in 50 s.
    Returns ``(scene, model)``.
    """
    m = Model(gravity=(0.3, -9.81), **(units or {}))
    floor = m.add_shape(m.ground, HalfPlane((0.0, -0.05), (0.1, 1.0)))
    box = m.add_body(1.5, 0.02, position=(0.0, 0.2), angle=0.1, velocity=(0.3, -0.2),
                     angular_velocity=1.0)
    disk = m.add_body(0.7, 0.004, position=(0.5, 0.3), angle=-0.3, velocity=(-0.1, 0.4),
                      angular_velocity=-2.0)
    crank = m.add_driven(x=TimeFunction(1.0, harmonics=[(0.02, 7.0, 0.3)]),
                         y=TimeFunction(0.1, rate=0.2, accel=-0.4),
                         theta=TimeFunction(0.2, rate=3.0, harmonics=[(0.1, 5.0, 1.0)]))
    sbox = m.add_shape(box, Polygon([(-0.1, -0.08), (0.12, -0.1), (0.1, 0.09), (-0.11, 0.1)]))
    sdisk = m.add_shape(disk, Circle(0.08, centre=(0.01, -0.02)))
    sseg = m.add_shape(crank, Segment((-0.15, 0.0), (0.15, 0.01)))
    scirc = m.add_shape(crank, Circle(0.03, centre=(0.2, -0.04)))
    m.add_contact(sdisk, floor, mu=0.6)               # plane
    m.add_contact(sdisk, sbox, mu=0.3)                # polygon
    m.add_contact(scirc, sdisk, mu=0.3)               # points, driven
    m.add_contact(sbox, sseg, mu=0.2, vertices=(2,))  # segment of a driven body
    m.add_spring(box, (0.05, 0.05), disk, (0.0, 0.02), stiffness=40.0, damping=0.7)
    m.add_torsion_spring(disk, crank, stiffness=0.3, rest_angle=0.1, damping=0.02)
    m.add_force(box, (TimeFunction(0.5, harmonics=[(1.0, 4.0, 0.2)]), -0.3), point=(0.05, 0.02))
    m.add_torque(disk, TimeFunction(0.01, rate=0.02))
    return m.build("planar-mini-zoo"), m
