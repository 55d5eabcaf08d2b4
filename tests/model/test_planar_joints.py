"""The joints' bilateral rows (the model side; their solution waits for the mixed LCP).

Each row against central differences along a motion: ``d/ds g(q + s v, t + s) =
W v + w``, ``w = dg/dt`` at fixed positions, and ``wbar = d/ds (W v + w)`` at
constant ``v``; and the rows vanish at the model's initial state.
"""

import numpy as np
import pytest

from moreau.errors import InputError
from moreau.model.planar import Circle, HalfPlane, Model, TimeFunction


def _mechanism():
    m = Model()
    crank = m.add_driven(x=TimeFunction(0.1, harmonics=[(0.02, 3.0, 0.1)]), y=0.05,
                         theta=TimeFunction(0.3, rate=2.0, harmonics=[(0.1, 4.0, 0.0)]))
    # a link pinned to the crank's tip, a slider pinned to the link's far end riding a
    # slot of the ground, a plate welded to the link, a pendulum on the ground
    link = m.add_body(0.5, 0.004, position=(0.3, 0.1), angle=0.2)
    slider = m.add_body(0.3, 0.001, position=(0.55, 0.0), angle=0.0)
    plate = m.add_body(0.2, 0.001, position=(0.35, 0.15), angle=0.5)
    pend = m.add_body(0.4, 0.002, position=(-0.2, -0.1), angle=1.0)
    m.add_revolute(link, (-0.1, 0.0), crank, (0.1, 0.0))
    m.add_revolute(slider, (0.0, 0.0), link, (0.1, 0.0))
    m.add_prismatic(slider, (0.0, 0.0), m.ground, (0.0, 0.0), axis=(1.0, 0.1))
    m.add_weld(plate, link)
    m.add_prismatic(pend, (0.02, 0.0), crank, (0.0, 0.0), axis=(0.3, 1.0))
    m.add_revolute(pend, (0.1, 0.0), m.ground, (-0.1, -0.1))
    m.add_shape(pend, Circle(0.05))
    m.add_shape(m.ground, HalfPlane())
    return m


def test_the_rows_against_central_differences():
    m = _mechanism()
    rows = m.joint_rows()
    assert rows.nrows == 2 + 2 + 2 + 3 + 2 + 2 == 13
    rng = np.random.default_rng(7)
    n = rows.ndof
    worst = {"rate": 0.0, "rheonomic": 0.0, "drift": 0.0}
    for _ in range(6):
        q, v, t = rng.normal(size=n), 2.0 * rng.normal(size=n), float(rng.uniform(0, 3))
        W, w = rows.jacobians(q, t)
        h = 1e-6
        rate = (rows.values(q + h * v, t + h) - rows.values(q - h * v, t - h)) / (2 * h)
        dt = (rows.values(q, t + h) - rows.values(q, t - h)) / (2 * h)

        def vel(s):
            Ws, ws = rows.jacobians(q + s * v, t + s)
            return Ws @ v + ws

        acc = (vel(h) - vel(-h)) / (2 * h)
        worst["rate"] = max(worst["rate"], np.max(np.abs(W @ v + w - rate)))
        worst["rheonomic"] = max(worst["rheonomic"], np.max(np.abs(w - dt)))
        worst["drift"] = max(worst["drift"], np.max(np.abs(rows.drift(q, v, t) - acc)))
    assert worst["rate"] <= 1e-7 and worst["rheonomic"] <= 1e-7 and worst["drift"] <= 1e-6, worst
    # the driven crank enters the rheonomic terms: not all zero
    W, w = rows.jacobians(rng.normal(size=n), 0.4)
    assert np.count_nonzero(np.abs(w) > 1e-3) >= 3


def test_the_weld_and_prismatic_rows_vanish_at_the_initial_state():
    m = _mechanism()
    rows = m.joint_rows()
    # the weld (rows 6-8) and the slots' angle rows are built from the initial poses
    q0 = np.concatenate([[b["pose"][0] / m.units()[0], b["pose"][1] / m.units()[0], b["pose"][2]]
                         for b in m.bodies if b["kind"] == 1])
    g = rows.values(q0, 0.0)
    np.testing.assert_allclose(g[[5, 6, 7, 8, 10]], 0.0, atol=1e-15)


def test_a_model_with_joints_is_built_with_its_rows_and_a_bad_joint_is_refused():
    # this mechanism's slot on body1 and pin to the ground hold body5 in a singular
    # configuration at the initial poses: its rows are dependent there, and named
    with pytest.raises(InputError, match=r"the joints are redundant: their 13 rows have rank 12 "
                                         r".*prismatic joint 4 \('body5'-'body1'\); revolute "
                                         r"joint 5 \('body5'-'ground'\)"):
        _mechanism().build()
    from moreau.scenes.slider_crank import slider_crank_model
    m = slider_crank_model()
    sc = m.build()
    rows = m.joint_rows()
    q, v = np.linspace(0.1, 0.9, sc.ndof), np.linspace(-0.5, 0.4, sc.ndof)
    assert sc.n_joint_rows == rows.nrows
    np.testing.assert_array_equal(sc.joint_residuals(q, 0.3), rows.values(q, 0.3))
    np.testing.assert_array_equal(sc.joint_jacobians(q, 0.3)[0], rows.jacobians(q, 0.3)[0])
    np.testing.assert_array_equal(sc.joint_drift(q, v, 0.3), rows.drift(q, v, 0.3))
    m = _mechanism()
    b = m.bodies[2]["body"]
    with pytest.raises(InputError, match="`body_i` and `body_j` are one body"):
        m.add_revolute(b, (0, 0), b, (0.1, 0))
    with pytest.raises(InputError, match="both fixed or driven"):
        m.add_weld(m.ground, m.bodies[1]["body"])
    with pytest.raises(InputError, match="`axis` of a prismatic joint must not be zero"):
        m.add_prismatic(b, (0, 0), m.ground, (0, 0), axis=(0, 0))
