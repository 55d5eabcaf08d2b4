"""``t_eval`` and user events (as in solve_ivp) on every registered scheme."""

import math

import numpy as np
import pytest

from moreau.errors import InputError
from moreau.integrators import INTEGRATORS, get_integrator, simulate
from moreau.integrators.base import scheme_options
from moreau.scenes import registry
from moreau.scenes.bouncing_ball import BouncingBall

registry.discover()
#: every registered scheme, "event-driven" (a front for the others) included
SCHEMES = sorted(INTEGRATORS)
#: the step of the fixed-step schemes (the ball falls 1 in sqrt(2) ~ 1.41)
H = 0.01


def _options(name):
    params = scheme_options(get_integrator(name)) or ()
    opts = {"h": H} if "h" in params else {}
    if "max_step" in params and name != "event-driven-space":
        # a compliant contact's default step is a tenth of a contact's duration: the
        # intervals here end before the first contact
        opts["max_step"] = 0.05
    if "fast" in params and name != "moreau-jean":
        # t_eval and events work on the recorded step states, which the compiled loops
        # record as the generic steps do (each scheme's tests hold them equal); Moreau-Jean
        # keeps its compiled loop here, and the others save a ball loop's compile (15-20 s)
        opts["fast"] = False
    return opts


def _exact(name):
    # "event-driven" is a front: the scheme it picks for the scene decides
    cls = get_integrator(name)
    if hasattr(cls, "resolve"):
        cls = cls.resolve(_case(name)[0])
    return cls.exact_motion


def _case(name):
    """A scene the scheme runs, its initial state and an interval.

    The ball for every scene-independent scheme but the spatial reference; a
    scene's own reference runs the scene that names it in the registry.
    """
    if name == "event-driven-space":
        # the spatial reference runs spatial scenes only: a billiard ball struck without
        # spin, which starts rolling at t = 1.08
        from moreau.scenes.billiard_backspin import billiard_backspin
        scene = billiard_backspin(speed=0.5, spin=0.0)
        return scene, scene.initial_state(), 1.5
    owner = [e for e in registry.entries() if e.reference == name]
    if owner:
        scene = registry.make_scene(owner[0].name)
        period = scene.period or 1.0
        return scene, scene.initial_state(), 1.5 * period
    return BouncingBall(), ([1.0], [0.0]), 1.3     # before the impact, at 1.34


def _half_down(t, y):
    return y[0] - 0.5


_half_down.terminal = True
_half_down.direction = -1


@pytest.mark.parametrize("name", SCHEMES)
def test_t_eval_samples_agree_with_the_schemes_own_samples(name):
    scene, (q0, v0), t1 = _case(name)
    opts = _options(name)
    own = simulate(scene, (0.0, t1), q0, v0, name, **opts)
    assert own.status == 0, own.message
    # interior samples that are not event times (an event's sample is the state after it)
    ev = np.array([e.t for e in own.events])
    inner = own.t[(own.t > 0.0) & (own.t < t1)]
    inner = inner[np.all(np.abs(inner[:, None] - ev[None, :]) > 1e-9, axis=1)] if ev.size else inner
    inner = np.unique(inner)[:: max(1, len(np.unique(inner)) // 12)]
    res = simulate(scene, (0.0, t1), q0, v0, name, t_eval=inner, **opts)
    assert res.status == 0 and np.array_equal(res.t, inner)
    idx = np.searchsorted(own.t, inner)
    scale = 1.0 + np.max(np.abs(own.q))
    assert np.max(np.abs(res.q - own.q[idx])) <= 1e-9 * scale, name
    assert np.max(np.abs(res.v - own.v[idx])) <= 1e-9 * (1.0 + np.max(np.abs(own.v))), name


@pytest.mark.parametrize("name", [n for n in SCHEMES if _exact(n)
                                  and isinstance(_case(n)[0], BouncingBall)])
def test_event_driven_t_eval_samples_the_exact_motion(name):
    scene, (q0, v0), t1 = _case(name)
    # in free flight, before the first impact at sqrt(2 (1 - r)): q = 1 - t^2 / 2, v = -t
    ts = np.linspace(0.0, 1.2, 7)
    res = simulate(scene, (0.0, t1), q0, v0, name, t_eval=ts, **_options(name))
    assert np.max(np.abs(res.q[:, 0] - (1.0 - ts ** 2 / 2))) <= 1e-10
    assert np.max(np.abs(res.v[:, 0] + ts)) <= 1e-10
    assert np.max(np.abs(res.gap[:, 0] - (res.q[:, 0] - scene.r))) <= 1e-12


@pytest.mark.parametrize("name", [n for n in SCHEMES if not _exact(n)])
def test_time_stepping_t_eval_interpolates_between_step_ends(name):
    scene, (q0, v0), t1 = BouncingBall(), ([1.0], [0.0]), 0.5
    own = simulate(scene, (0.0, t1), q0, v0, name, **_options(name))
    mids = 0.5 * (own.t[1:] + own.t[:-1])
    res = simulate(scene, (0.0, t1), q0, v0, name, t_eval=mids, **_options(name))
    assert np.allclose(res.q[:, 0], np.interp(mids, own.t, own.q[:, 0]), rtol=0, atol=1e-14)
    assert np.allclose(res.v[:, 0], np.interp(mids, own.t, own.v[:, 0]), rtol=0, atol=1e-14)
    # the regime and the forces are those of the step that contains the time
    assert np.array_equal(res.force_N, own.force_N[1:])


@pytest.mark.parametrize("name", [n for n in SCHEMES if _case(n)[0].__class__ is BouncingBall])
def test_a_terminal_event_stops_every_scheme(name):
    ball = BouncingBall()
    res = simulate(ball, (0.0, 3.0), [1.0], [0.0], name, events=_half_down, **_options(name))
    assert res.status == 1 and res.success
    assert res.message.startswith("A terminal event occurred.")
    (te,), (ye,) = res.t_events[0], res.y_events[0]
    exact = 1.0         # 1 - t^2 / 2 = 0.5
    if _exact(name):
        assert abs(te - exact) <= 1e-10
        assert res.t[-1] == te and abs(ye[0] - 0.5) <= 1e-12
        assert "dense output" in res.message
    else:
        # within one step: the run ends at the end of the step over which the sign changed
        step = np.diff(res.t).max()
        assert abs(te - exact) <= step and res.t[-2] <= te <= res.t[-1]
        assert res.q[-2, 0] > 0.5 >= res.q[-1, 0]
        assert "to within one step" in res.message


def test_non_terminal_events_are_counted_and_terminal_counts_as_solve_ivp():
    def apex(t, y):         # the ball's velocity turning from up to down
        return y[1]
    apex.direction = -1
    apex.terminal = 2       # stop at the second apex
    ball = BouncingBall(restitution=0.5)
    res = simulate(ball, (0.0, 20.0), [1.0], [0.0], "event-driven", events=[_free(_half_down), apex])
    # impacts at sqrt(2 (1 - r)) = T, then every flight 2 e^k sqrt(2 (1 - r)) long; apexes mid-flight
    T = math.sqrt(2.0 * (1.0 - ball.r))
    apexes = [T + 0.5 * T, T + T + 0.5 * 0.5 * T]
    assert np.allclose(res.t_events[1], apexes, atol=1e-9)
    assert res.status == 1 and abs(res.t[-1] - apexes[1]) <= 1e-9
    # height 0.5 going down: once, in the first fall (the rebounds stay below it)
    first = res.t_events[0]
    assert abs(first[0] - 1.0) <= 1e-10 and np.all(first <= res.t[-1])


def _free(f):
    def g(t, y):
        return f(t, y)
    g.direction = f.direction
    return g


def test_an_event_at_a_jump_is_located_at_the_impact():
    # the velocity jumps from negative to positive at the impact: its sign change is there
    def up(t, y):
        return y[1]
    up.terminal, up.direction = True, 1
    ball = BouncingBall(restitution=0.5)
    res = simulate(ball, (0.0, 3.0), [1.0], [0.0], "event-driven", events=up)
    T = math.sqrt(2.0 * (1.0 - ball.r))
    assert res.status == 1 and abs(res.t_events[0][0] - T) <= 1e-10


@pytest.mark.parametrize("t_eval, match", [
    ([0.0, 0.5, 0.4], r"`t_eval` must be sorted in increasing order; t_eval\[2\] = 0.4 follows 0.5"),
    ([0.0, 4.0], r"`t_eval` must lie inside `t_span` = \(0.0, 3.0\); t_eval\[1\] = 4.0"),
    ([-0.1], r"`t_eval` must lie inside `t_span`"),
    ([0.0, float("nan")], r"`t_eval` must be finite; t_eval\[1\] = nan"),
    ([[0.0, 1.0]], r"`t_eval` must be one-dimensional"),
    ("abc", r"`t_eval` must be an array of times"),
])
def test_bad_t_eval_is_a_named_error(t_eval, match):
    with pytest.raises(InputError, match=match):
        simulate(BouncingBall(), (0.0, 3.0), [1.0], [0.0], "moreau-jean", h=0.1, t_eval=t_eval)


def test_bad_events_are_named_errors():
    def f(t, y):
        return y[0]
    with pytest.raises(InputError, match=r"`events\[0\]` must be a callable"):
        simulate(BouncingBall(), (0.0, 1.0), [1.0], [0.0], "moreau-jean", h=0.1, events=[1.0])
    f.terminal = -1
    with pytest.raises(InputError, match=r"`events\[0\].terminal` must be a bool or a count"):
        simulate(BouncingBall(), (0.0, 1.0), [1.0], [0.0], "moreau-jean", h=0.1, events=f)
    f.terminal, f.direction = True, "down"
    with pytest.raises(InputError, match=r"`events\[0\].direction` must be a real number"):
        simulate(BouncingBall(), (0.0, 1.0), [1.0], [0.0], "moreau-jean", h=0.1, events=f)


@pytest.mark.parametrize("name", [n for n in SCHEMES if _exact(n)])
def test_an_event_located_by_an_exact_scheme_is_a_zero_of_its_motion(name):
    # independent of the root finder: a second run that simply ends at the event time
    # must end on the event's zero
    scene, (q0, v0), t1 = _case(name)
    opts = _options(name)
    own = simulate(scene, (0.0, t1), q0, v0, name, **opts)
    target = float(own.q[len(own.t) // 2, 0])
    scale = float(np.ptp(own.q[:, 0])) or 1.0

    def cross(t, y):
        return y[0] - target
    cross.terminal = True
    res = simulate(scene, (0.0, t1), q0, v0, name, events=cross, **opts)
    assert res.status == 1, res.message
    te = float(res.t_events[0][0])
    assert res.t[-1] == te and abs(res.q[-1, 0] - target) <= 1e-12 * scale + 1e-15
    again = simulate(scene, (0.0, te), q0, v0, name, **opts)
    assert abs(again.q[-1, 0] - target) <= 1e-9 * scale
