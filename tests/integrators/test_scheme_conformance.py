"""Every registered scheme against the same rules, as the scene conformance suite does for scenes.

- its options are a frozen dataclass (``cls.Options``) naming the scheme; an
  option it does not take is refused naming it and the scheme's options;
- a bad value of each field is refused naming the field, before any work;
- the options object runs the same scheme as the keywords, to the bit;
- a time-stepping scheme converges with its stated order on a smooth problem
  (a unit spring-mass whose contact never closes, against ``cos t``);
- every scheme that runs on any scene keeps Newton's impact law on a ball
  dropped onto the floor: after the impact it leaves at ``-e`` times its
  arrival speed, to the scheme's accuracy.
"""

import dataclasses
import inspect
import math
import pickle

import numpy as np
import pytest

from moreau.errors import InputError
from moreau.integrators import simulate
from moreau.integrators.base import INTEGRATORS, SchemeOptions, check_options, get_integrator
from moreau.scenes import registry
from moreau.model.examples import Spring  # unit mass on a unit spring, its contact never active
from moreau.model.scene import Scene

registry.discover()
#: every registered scheme with its own options (the "event-driven" front runs one of them)
SCHEMES = sorted(k for k, cls in INTEGRATORS.items() if cls.Options is not None)
#: the schemes that run on any scene (the others are a scene's own exact scheme, and the
#: spatial reference, which refuses a planar scene: tests/integrators/test_event_driven_space.py)
GENERAL = [k for k in SCHEMES if k not in ("friction-drive-walker", "stick-slip-exact",
                                           "event-driven-space")]
#: the time-stepping schemes with a fixed step h (and a stated order)
STEPPING = [k for k in GENERAL if "h" in INTEGRATORS[k].Options.names()]


class Ball(Scene):
    """Unit point mass under gravity 1 above the floor ``q = 0``, restitution ``E``."""
    E = 0.5
    ndof, mu, restitution = 1, np.array([0.0]), np.array([E])

    def mass(self, q):
        return np.eye(1)

    def forces(self, q, v, t):
        return np.array([-1.0])

    def gaps(self, q, t):
        return np.array([q[0]])

    def contact_jacobians(self, q, t):
        return np.array([[1.0]]), np.zeros(1), np.zeros((0, 1)), np.zeros(0)

    def contact_drift(self, q, v, t):
        return np.zeros(1), np.zeros(0)


def _bad_value(field):
    """A value that breaks the field's rule, chosen by its type."""
    kind = field.type.__name__ if isinstance(field.type, type) else str(field.type)
    if "bool" in kind and "str" in kind:
        return "sometimes"
    if kind == "bool":
        return "yes"
    if kind == "str":
        return "no-such-choice"
    if kind.startswith("int"):
        return 0
    if kind.startswith("float"):
        return -1.0
    return "yes"       # an array of flags (closed0)


@pytest.mark.parametrize("name", SCHEMES)
def test_options_are_a_frozen_dataclass_naming_the_scheme(name):
    cls = get_integrator(name)
    opts = cls.Options()
    assert isinstance(opts, SchemeOptions) and opts.scheme == name
    assert opts.integrator is cls
    if opts.names():
        first = opts.names()[0]
        with pytest.raises(dataclasses.FrozenInstanceError):
            setattr(opts, first, getattr(opts, first))


@pytest.mark.parametrize("name", SCHEMES)
def test_options_travel_to_a_worker_and_match_the_constructor(name):
    cls = get_integrator(name)
    opts = cls.Options()
    assert pickle.loads(pickle.dumps(opts)) == opts
    if not cls.takes_options_object:
        # a scheme that keeps its keyword constructor: the same names and defaults
        params = list(inspect.signature(cls.__init__).parameters.values())[6:]
        assert {p.name: p.default for p in params} == opts.as_dict()


@pytest.mark.parametrize("name", SCHEMES)
def test_an_unknown_option_is_refused_by_name(name):
    listed = ", ".join(get_integrator(name).Options.names())
    with pytest.raises(InputError, match=rf"`warp` is not an option of scheme '{name}'; its "
                                         rf"options: {listed}$"):
        check_options(name, {"warp": 1})
    with pytest.raises(InputError, match=rf"`warp` is not an option of scheme '{name}'"):
        simulate(Ball(), (0.0, 1.0), [1.0], [0.0], name, warp=1)
    with pytest.raises(InputError, match=rf"`warp` is not an option of scheme '{name}'"):
        get_integrator(name).Options().replace(warp=1)


FIELDS = [(name, f) for name in SCHEMES for f in dataclasses.fields(INTEGRATORS[name].Options)]


@pytest.mark.parametrize("name, field", FIELDS, ids=[f"{n}-{f.name}" for n, f in FIELDS])
def test_a_bad_value_of_each_field_is_refused_naming_it(name, field):
    bad = _bad_value(field)
    cls = get_integrator(name)
    with pytest.raises(InputError, match=rf"^`{field.name}` "):
        cls.Options(**{field.name: bad})
    # and through simulate, before any work (the ball is not the scene of a scene's own
    # scheme, which would refuse it only later)
    if name in GENERAL:
        with pytest.raises(InputError, match=rf"^`{field.name}` "):
            simulate(Ball(), (0.0, 1.0), [1.0], [0.0], name, **{field.name: bad})


#: the compliant contact's stiffness in the ball runs: a contact lasting pi / sqrt(k) = 0.03
STIFFNESS = 1e4


def _ball_options(name):
    """Options for a drop of about 2 time units: a step of 1e-2 or a tight tolerance."""
    names = INTEGRATORS[name].Options.names()
    if "h" in names:
        return {"h": 1e-2}
    if "tol" in names:
        return {"tol": 1e-8}
    if name.startswith("compliant"):
        return {"stiffness": STIFFNESS, "rtol": 1e-9, "atol": 1e-12}
    return {}


@pytest.mark.parametrize("name", GENERAL)
def test_an_options_object_runs_the_scheme_of_its_keywords(name):
    cls = get_integrator(name)
    kw = _ball_options(name)
    span, q0, v0 = (0.0, 0.5), [1.0], [0.0]
    by_name = simulate(Ball(), span, q0, v0, name, **kw)
    by_object = simulate(Ball(), span, q0, v0, cls.Options(**kw))
    np.testing.assert_array_equal(by_object.q, by_name.q)
    np.testing.assert_array_equal(by_object.v, by_name.v)
    assert by_object.scheme == name


def test_keywords_beside_an_options_object_replace_its_fields():
    from moreau.integrators.moreau_jean import MoreauJean
    a = simulate(Spring(), (0.0, 1.0), [1.0], [0.0], MoreauJean.Options(h=0.1), theta=0.5)
    b = simulate(Spring(), (0.0, 1.0), [1.0], [0.0], "moreau-jean", h=0.1, theta=0.5)
    np.testing.assert_array_equal(a.q, b.q)
    with pytest.raises(InputError, match="`theta` must be in"):
        simulate(Spring(), (0.0, 1.0), [1.0], [0.0], MoreauJean.Options(h=0.1), theta=2.0)


def _spring_error(name, h, extra):
    res = simulate(Spring(), (0.0, 2.0), [1.0], [0.0], name, h=h, **extra)
    assert res.success and res.t[-1] == 2.0
    return max(abs(res.q[-1, 0] - math.cos(2.0)), abs(res.v[-1, 0] + math.sin(2.0)))


# each scheme with the settings of its stated orders (Moreau-Jean's two thetas, TDG's degrees)
ORDER_CASES = [(name, extra) for name in STEPPING
               for extra in ({"theta": 1.0}, {"theta": 0.5}) if name == "moreau-jean"] + \
              [(name, extra) for name in STEPPING
               for extra in ({"degree": 1}, {"degree": 2}) if name == "time-discontinuous-galerkin"] + \
              [(name, {}) for name in STEPPING
               if name not in ("moreau-jean", "time-discontinuous-galerkin")]


@pytest.mark.parametrize("name, extra", ORDER_CASES, ids=lambda x: x if isinstance(x, str) else
                         ",".join(f"{k}={v}" for k, v in x.items()))
def test_a_time_stepping_scheme_converges_with_its_stated_order(name, extra):
    stated = get_integrator(name).Options(**extra).smooth_order()
    assert stated in (1, 2, 3)
    # steps small enough for the asymptotic regime, large enough to stay clear of rounding
    hs = (0.02, 0.01, 0.005) if stated < 3 else (0.08, 0.04, 0.02)
    errs = [_spring_error(name, h, extra) for h in hs]
    orders = [math.log2(errs[i] / errs[i + 1]) for i in range(2)]
    assert all(abs(p - stated) < 0.15 for p in orders), (errs, orders)


# the adaptive continuous-time schemes take a second or two each: under -m slow
BALL_CASES = [pytest.param(n, marks=pytest.mark.slow) if n.startswith("compliant")
              or n == "event-driven-generic" else n for n in GENERAL]


@pytest.mark.parametrize("name", BALL_CASES)
def test_the_ball_keeps_newtons_impact_law(name):
    # dropped from 1 at rest it arrives at t = sqrt(2) with speed -sqrt(2) and leaves at
    # e sqrt(2); the velocities a distance d before and after it, carried back to the impact
    # along the free flight (gravity 1), are the arrival and departure speeds
    e, s2, d = Ball.E, math.sqrt(2.0), 0.05
    opts = _ball_options(name)
    res = simulate(Ball(), (0.0, 1.5 * s2), [1.0], [0.0], name, t_eval=[s2 - d, s2 + d], **opts)
    assert res.success and res.t.tolist() == [s2 - d, s2 + d]
    arrive, leave = res.v[0, 0] - d, res.v[1, 0] + d
    if "h" in opts:
        # a fixed step puts the impact within a step h of its time: the speeds move by O(h)
        tol = 3.0 * opts["h"]
    elif name.startswith("compliant"):
        # the model's own error: gravity acts through the contact's duration pi / sqrt(k)
        tol = 2.0 * math.pi / math.sqrt(STIFFNESS)
    else:
        tol = 1e-6
    assert abs(arrive + s2) <= 1e-12 or "h" in opts, arrive
    assert abs(leave - e * s2) <= tol, leave
    assert abs(-leave / arrive - e) <= tol / s2, leave / arrive
    # and not the other laws: a plastic (e = 0) or elastic (e = 1) impact is far off
    assert tol / s2 < 0.25


def test_a_subclass_with_its_own_keyword_constructor_keeps_it(monkeypatch):
    # a test double or a user's variant of a scheme: its constructor states its options
    from moreau.integrators.base import scheme_options
    from moreau.integrators.moreau_jean import MoreauJean

    class Trapezoidal(MoreauJean):
        def __init__(self, scene, t0, q0, v0, t_bound, h=None):
            super().__init__(scene, t0, q0, v0, t_bound, h=h, theta=0.5)

    monkeypatch.setitem(INTEGRATORS, "trapezoidal-double", Trapezoidal)
    assert scheme_options(Trapezoidal) == ("h",)
    a = simulate(Spring(), (0.0, 1.0), [1.0], [0.0], "trapezoidal-double", h=0.1)
    b = simulate(Spring(), (0.0, 1.0), [1.0], [0.0], "moreau-jean", h=0.1, theta=0.5)
    np.testing.assert_array_equal(a.q, b.q)
    with pytest.raises(InputError, match="`theta` is not an option of scheme 'trapezoidal-double'"):
        simulate(Spring(), (0.0, 1.0), [1.0], [0.0], "trapezoidal-double", h=0.1, theta=1.0)
