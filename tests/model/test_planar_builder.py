"""The planar builder refuses bad models by name, and shares generated code between models of one structure."""


import numpy as np
import pytest

from moreau.errors import InputError
from moreau.model.planar import (Circle, HalfPlane, Model, Point, Polygon, Segment, TimeFunction,
                                 _codegen)


def _ball():
    m = Model()
    ball = m.add_body(1.0, 0.004, position=(0.0, 0.1))
    return m, ball, m.add_shape(ball, Circle(0.1)), m.add_shape(m.ground, HalfPlane())


@pytest.mark.parametrize("build, message", [
    (lambda m, b, c, f: m.add_body(0.0, 1.0), r"`mass` of a body must be > 0, got 0.0 \(a body without mass"),
    (lambda m, b, c, f: m.add_body(1.0, -1.0), r"`inertia` must be > 0"),
    (lambda m, b, c, f: Polygon([(0, 0), (1, 0), (2, 0)]), r"`vertices` must make a convex polygon of nonzero area"),
    (lambda m, b, c, f: Polygon([(0, 0), (0, 1), (1, 0)]), r"counter-clockwise"),
    (lambda m, b, c, f: Polygon([(0, 0), (2, 0), (1, 0.2), (1, 1), (0, 1)]), r"convex"),
    (lambda m, b, c, f: Segment((1, 1), (1, 1)), r"`a` and `b` of a segment must differ"),
    (lambda m, b, c, f: HalfPlane((0, 0), (0, 0)), r"`normal` of a half-plane must not be zero"),
    (lambda m, b, c, f: m.add_contact(f, m.add_shape(m.add_fixed(), Circle(0.1))), r"one must be free"),
    (lambda m, b, c, f: m.add_contact(c, m.add_shape(b, Point())), r"shapes of one body"),
    (lambda m, b, c, f: m.add_contact(m.add_shape(b, Point()), m.add_shape(m.add_body(1, 1), Point())), r"two points do not make a contact"),
    (lambda m, b, c, f: m.add_contact(c, f, mu=-0.1), r"`mu` must be >= 0"),
    (lambda m, b, c, f: m.add_contact(c, f, restitution=1.5), r"`restitution`"),
    (lambda m, b, c, f: m.add_contact(c, f, vertices=(0,)), r"`vertices` selects vertices of a polygon or segment; Circle has none"),
    (lambda m, b, c, f: m.add_contact(m.add_shape(b, Polygon.box(0.1, 0.1)), f, vertices=(4,)), r"`vertices` must be indices in \[0, 4\), got 4"),
    (lambda m, b, c, f: m.add_spring(b, (0, 0), b, (0.1, 0), 1.0), r"`body_i` and `body_j` are one body"),
    (lambda m, b, c, f: m.add_torsion_spring(b, b, 1.0), r"`body_i` and `body_j` are one body"),
    (lambda m, b, c, f: m.add_force(m.ground, (1.0, 0.0)), r"`body` must be a free body"),
    (lambda m, b, c, f: m.add_torque(Model().ground, 1.0), r"`body` must be a body of this model"),
    (lambda m, b, c, f: m.add_driven(x=TimeFunction(harmonics=[(1.0, 2.0)])), r"`harmonics\[0\]` must be \(amplitude, angular_frequency, phase\)"),
    (lambda m, b, c, f: m.add_spring(b, (0, 0), m.ground, (0.0, 0.1), 1.0), r"`rest_length` must be > 0"),
    (lambda m, b, c, f: m.build(valid_region="y > 0"), r"`valid_region` and `inside` go together"),
    (lambda m, b, c, f: Model().build(), r"the model has no free body"),
])
def test_a_bad_model_is_refused_naming_the_part(build, message):
    m, ball, circle, floor = _ball()
    with pytest.raises(InputError, match=message):
        build(m, ball, circle, floor)


def test_models_of_one_structure_share_their_generated_code():
    # a block of another size and friction: the same source, the same module; a third
    # contact changes the structure
    from moreau.scenes.rocking_block_built import rocking_block_built, rocking_block_model
    a, b = rocking_block_built(width=0.2, mu=1.0), rocking_block_built(width=0.3, mu=0.1)
    assert a._fn is b._fn and not np.array_equal(a.par, b.par)
    m = rocking_block_model()
    m.add_contact(m.shapes[1], m.shapes[0], vertices=(2,))
    assert _codegen.source_of(m.pack()[0]) != _codegen.source_of(a.par)
    # a different width moves the second corner's gap at the same state
    q0, _ = a.initial_state()
    assert a.gaps(q0, 0.0)[1] != b.gaps(q0, 0.0)[1]


def test_the_contact_list_of_a_polygon_pair():
    def pair():
        m = Model()
        b1 = m.add_body(1.0, 0.01)
        b2 = m.add_body(1.0, 0.01, position=(0.0, 0.3))
        return (m, m.add_shape(b1, Polygon.box(0.2, 0.2)),
                m.add_shape(b2, Polygon([(-0.1, -0.1), (0.1, -0.1), (0.0, 0.1)])))

    # each vertex of each against the other: 4 + 3; a selection: those vertices of a only
    m, s1, s2 = pair()
    assert m.add_contact(s1, s2) == list(range(7))
    assert m.add_contact(s2, s1, vertices=(0, 1)) == [7, 8]
    m, s1, s2 = pair()
    m.add_contact(s2, s1, vertices=(0, 1))
    sc = m.build()
    # the triangle's bottom vertices sit 0.1 above the box's top face
    gaps = sc.gaps(sc.initial_state()[0], 0.0) * sc.length
    np.testing.assert_allclose(gaps, [0.1, 0.1], rtol=1e-12)


def test_a_built_scene_pickles_for_worker_processes():
    import pickle

    from moreau.scenes.rocking_block_built import rocking_block_built
    sc = rocking_block_built(width=0.3)
    again = pickle.loads(pickle.dumps(sc))
    q0, v0 = sc.initial_state()
    np.testing.assert_array_equal(again.gaps(q0, 0.0), sc.gaps(q0, 0.0))
    assert again.compiled_model().contacts is sc.compiled_model().contacts
