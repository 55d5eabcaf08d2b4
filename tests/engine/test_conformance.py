"""One conformance suite over every registered scene: a new scene gets all of it by registering.

For each scene, at its default parameters:

* ``check_scene`` passes: shapes, a symmetric positive definite mass
  matrix, the contact rows and drift terms against central differences of
  the gaps, force Jacobians against differences of the forces, and the
  compiled model against the Python one to 1e-12;
* the default initial state is admissible (no penetration);
* Moreau–Jean agrees with the scene's reference within the scene's stated
  tolerance (``mj_tolerance`` of its entry), on the scene's comparison case.
"""

import numpy as np
import pytest

from moreau.check import check_scene
from moreau.model.scene import is_spatial
from moreau.analysis.compare import make_case
from moreau.scenes import registry

NAMES = registry.scene_names()

#: the granular scenes: the registered Scene is a disk system's start with its contacts fixed
#: (moreau.model.granular.DiskScene, no compiled model), while their physics runs with the
#: broad phase every step (moreau.integrators.granular), where no event-driven reference
#: reaches (hundreds of contacts that open and close); their studies are tested in
#: tests/scenes/test_granular_scenes.py and tests/model/test_granular.py
GRANULAR = {"granular-column", "silo"}
_NO_REFERENCE = pytest.mark.skip(reason="a granular scene: no comparison case (see GRANULAR)")
#: scenes with a compiled model but no comparison case: the masonry arch, 2 (n + 1) frictional
#: contacts closed at once, every one sticking while it stands and a four-hinge mechanism
#: opening some when it collapses, beyond the event-driven reference (a mode per contact);
#: its dynamics is held instead to an independent statics, the thrust-line LP of the safe
#: theorem (tests/scenes/test_masonry_arch.py)
NO_CASE = {"masonry-arch"}
_NO_CASE_MARK = pytest.mark.skip(reason="no comparison case (see NO_CASE)")


@pytest.mark.parametrize("name", NAMES)
def test_check_scene_passes(name):
    scene = registry.make_scene(name)
    report = check_scene(scene)
    assert report.ok, report.summary()
    if is_spatial(scene):
        # no compiled model; the rows against differences along the exponential map
        assert report.errors["slip rates (WT, wT)"] <= 1e-6
    elif name not in GRANULAR:
        assert report.errors["compiled model"] <= 1e-12
    assert report.errors["gap rates (WN, wN)"] <= 1e-6


@pytest.mark.parametrize("name", NAMES)
def test_initial_state_is_admissible(name):
    scene = registry.make_scene(name)
    q0, v0 = scene.initial_state()
    assert np.all(np.isfinite(q0)) and np.all(np.isfinite(v0))
    assert np.all(scene.gaps(q0, 0.0) >= -1e-12)


# the flexible rod's reference resolves its 17 kHz bending mode inside a 185 Hz period
# (130 s on 2 cores, a tenth of the default run): it runs with the long checks (-m slow)
HEAVY = {"flexible-rod-drive",
         # 1000 Python steps of three resting cubes on the exact cone, whose Delassus operator
         # is singular at rest (8.7 CPU s of steps; 32 s with its reference, loaded)
         "box-stack-3d"}


@pytest.mark.parametrize("name", [pytest.param(n, marks=pytest.mark.slow) if n in HEAVY else
                                  pytest.param(n, marks=_NO_REFERENCE) if n in GRANULAR else
                                  pytest.param(n, marks=_NO_CASE_MARK) if n in NO_CASE else n
                                  for n in NAMES])
def test_moreau_jean_agrees_with_the_reference_within_the_stated_tolerance(name):
    entry = registry.get_entry(name)
    case = make_case(name)
    ref, _ = case.reference(case.tight_rtol)
    value, _ = case.mj(1000, 1.0, None)
    scale = max(abs(ref), 1e-300)
    assert abs(value - ref) / scale <= entry.mj_tolerance


# -- every registered scheme on every registered scene --------------------------------------
#
# Each pair runs at the scheme's default options (a time-stepping scheme at 1000 steps a
# drive period, or a thousandth of the window without a drive: the step `moreau run` takes)
# from the scene's initial state. The outcome is success, or one of these named ones:
#
# * a scene's own reference scheme on another scene: refused before any work (InputError);
# * a scene with joints (slider-crank) and a scheme that solves none: refused before any
#   work, naming the scheme;
# * a spatial scene (sphere-incline, ...) and a scheme that steps none (all but
#   Moreau–Jean): refused before any work, naming the scheme;
# * a planar scene, or a spatial one with several contacts, and the spatial event-driven
#   reference (`event-driven-space`): refused before any work, naming the scheme;
# * the Painlevé rod: its default start slides, the rod falls flat and phi crosses 0 at
#   t = 1.2955 (measured: every scheme's last sample lies in 1.290 .. 1.300), where every
#   scheme stops with status -6 naming the region 0 < phi < pi.
#
# Measured over the default windows (2 shared cores): each non-compliant pair takes 0.01 to
# 3.3 s, but the event-driven schemes on the flexible rod 23-27 s (all 90: 80 s), and
# the compliant schemes 15-40 s on each non-periodic scene (Radau on the sliding block and
# box more than 120 s) and 15-85 s over half a period of a drive (2.4e5 steps of 0.5-1 ms a
# window: 5-30 min each). The default run takes a twentieth of each window, without the
# compliant schemes, without three of the five drives (the friction drive and the
# stick-slip motor, with their own references, stay) and without the granular scenes (their
# twentieth is free fall; 20 pairs, 7 s on the loaded machine, kept out of the default run's
# budget), nor the masonry arch (NO_CASE: a degenerate friction LCP every step, 50 steps of
# each scheme, with the long checks); the full matrix runs with the long checks (-m slow), the
# compliant schemes over
# one period of a drive (not ten).

registry.discover()
from moreau.integrators import INTEGRATORS, simulate  # noqa: E402
from moreau.integrators.base import get_integrator, scheme_options  # noqa: E402
from moreau.errors import InputError  # noqa: E402

SCHEMES = sorted(INTEGRATORS)
#: a scene's own reference scheme -> the scene it integrates
OWN_SCHEME = {"friction-drive-walker": "friction-drive", "stick-slip-exact": "stick-slip-motor"}
OWN_REFUSAL = {"friction-drive-walker": "`scene` must be a FrictionDrive",
               "stick-slip-exact": "`scene` must be a StickSlipMotor"}
#: scene -> (the time it leaves its valid region from its initial state, a text of the region)
LEAVES = {"painleve-rod": (1.2955, "0 < phi < pi")}


def _refuses_joints(scene, scheme):
    # a scene with joints (bilateral rows) is refused, before any work, by each scheme that
    # solves none (its class says so: `solves_joints`); the message names the scheme
    from moreau.model.scene import joint_row_count
    cls = get_integrator(scheme)
    cls = cls.resolve(scene) if hasattr(cls, "resolve") else cls
    return joint_row_count(scene) > 0 and not cls.solves_joints


def _refuses_space(scene, scheme):
    # a spatial scene is refused, before any work, by each scheme that steps none
    # (`solves_space`); the message names the scheme
    cls = get_integrator(scheme)
    cls = cls.resolve(scene) if hasattr(cls, "resolve") else cls
    return is_spatial(scene) and not getattr(cls, "solves_space", False)


def _default_options(scene, scheme):
    cls = get_integrator(scheme)
    cls = cls.resolve(scene) if hasattr(cls, "resolve") else cls
    if "h" in (scheme_options(cls) or ()):
        return {"h": (scene.period or scene.default_span()) / 1000}
    return {}


def _run_pair(name, scheme, fraction):
    scene = registry.make_scene(name)
    q0, v0 = scene.initial_state()
    span = fraction * scene.default_span()
    joints = "scheme '[a-z0-9-]+' solves no joints"
    space = "scheme '[a-z0-9-]+' steps no spatial scene"
    if scheme == "event-driven-space" and (not is_spatial(scene) or scene.ncontacts != 1):
        # the spatial reference keeps one persistent contact of a spatial scene
        with pytest.raises(InputError, match="'event-driven-space' steps spatial scenes only"
                                             "|keeps one persistent contact"):
            simulate(scene, (0.0, span), q0, v0, scheme)
        return
    if _refuses_space(scene, scheme):
        # (a scene's own reference scheme may refuse it first, as another scene)
        match = space + (f"|{OWN_REFUSAL[scheme]}" if scheme in OWN_SCHEME else "")
        with pytest.raises(InputError, match=match):
            simulate(scene, (0.0, span), q0, v0, scheme, **_default_options(scene, scheme))
        return
    if _refuses_joints(scene, scheme) and scheme not in OWN_SCHEME:
        with pytest.raises(InputError, match=joints):
            simulate(scene, (0.0, span), q0, v0, scheme, **_default_options(scene, scheme))
        return
    if scheme in OWN_SCHEME and OWN_SCHEME[scheme] != name:
        # (on a scene with joints, either refusal may come first)
        match = OWN_REFUSAL[scheme] + (f"|{joints}" if _refuses_joints(scene, scheme) else "")
        with pytest.raises(InputError, match=match):
            simulate(scene, (0.0, span), q0, v0, scheme, **_default_options(scene, scheme))
        return
    res = simulate(scene, (0.0, span), q0, v0, scheme, **_default_options(scene, scheme))
    inside = scene.inside_valid_region(res.t, res.q, res.v)
    if name in LEAVES and span > LEAVES[name][0] + 0.01:
        t_out, region = LEAVES[name]
        assert res.status == -6, res.message
        assert region in res.message and f"t = {res.t[-1]:.6g}" in res.message
        # the run ends on its first sample outside; every one before lies inside
        assert not inside[-1] and inside[:-1].all()
        assert abs(res.t[-1] - t_out) < 0.01
    else:
        assert res.status == 0, res.message
        assert res.t[-1] == span and inside.all()
    assert np.all(np.isfinite(res.q)) and np.all(np.isfinite(res.v))


#: single pairs with the long checks: the spatial reference spends 1.4 s on the tippe top's
#: twentieth (3100 evaluations through its fast spin)
SLOW_PAIRS = {("tippe-top", "event-driven-space")}


def _pairs(slow_schemes=(), slow_scenes=()):
    out = []
    for name in NAMES:
        for scheme in SCHEMES:
            slow = scheme.startswith(slow_schemes) if slow_schemes else False
            slow = slow or name in slow_scenes or (slow_scenes and (name, scheme) in SLOW_PAIRS)
            out.append(pytest.param(name, scheme, marks=pytest.mark.slow) if slow
                       else (name, scheme))
    return out


@pytest.mark.parametrize("name, scheme", _pairs(
    slow_schemes=("compliant",),
    slow_scenes=("bidirectional-drive", "flexible-rod-drive", "piezo-drive") + tuple(GRANULAR)
    + tuple(NO_CASE)))
def test_every_scheme_runs_every_scene_over_a_twentieth_of_its_window(name, scheme):
    _run_pair(name, scheme, 0.05)


#: pairs whose full window is out of reach: Radau on the block and the box, which come to
#: rest sticking, ran more than 20 min (the block) without ending; they run a twentieth
SHORT = {("sliding-block", "compliant-radau"), ("sliding-box", "compliant-radau")}


@pytest.mark.slow
@pytest.mark.parametrize("name, scheme", _pairs())
def test_every_scheme_runs_every_scene_over_its_default_window(name, scheme):
    periodic = registry.make_scene(name).period is not None
    if (name, scheme) in SHORT:
        fraction = 0.05
    else:
        fraction = 0.1 if periodic and scheme.startswith("compliant") else 1.0
    _run_pair(name, scheme, fraction)


@pytest.mark.parametrize("scheme", [pytest.param(s, marks=pytest.mark.slow)
                                    if s.startswith("compliant") else s
                                    for s in SCHEMES if s not in OWN_SCHEME])
def test_the_painleve_rods_default_run_stops_where_it_leaves_its_model(scheme):
    # issue 34: the event-driven default run ended with status 0 at phi = -0.866, the rod's
    # centre 0.381 m below the floor; the time-stepping schemes went on to t = 1.81
    _run_pair("painleve-rod", scheme, 1.0)


# -- energy, where the scene conserves it -------------------------------------------------
#
# Frictionless and elastic, no forcing: the ball chain at its defaults (e = 1, no gravity
# along the line) and the bouncing ball with e = 1. No sample may gain energy beyond the
# scheme's accuracy: h (2 h E0) for the time-stepping schemes, first order across impacts;
# 1e3 times the tolerance for the adaptive ones. Measured gains: Moreau-Jean 2.8e-3 at
# h = 4e-3 on the ball, TDG 1.1e-14, NSGA 0, Studer 6e-14, event-driven 1.1e-15, compliant
# 3e-8 (Radau 9e-9); 0 to 2.2e-16 on the chain. Schatzman-Paoli's recorded velocity at an
# impact step gains 1.41 (ball) and 0.79 (chain), its end state does not: issue 34's
# velocity item, on its own branch.

def _ball_energy(scene, q, v):
    return q[:, 0] + 0.5 * v[:, 0] ** 2


def _chain_energy(scene, q, v):
    return 0.5 * (v ** 2) @ scene.masses


CONSERVATIVE = {"ball-chain": ({}, _chain_energy),
                "bouncing-ball": ({"restitution": 1.0}, _ball_energy)}
ADAPTIVE_TOL = {"studer-extrapolation": 1e-6, "event-driven": 1e-12,
                "event-driven-generic": 1e-12, "compliant-radau": 1e-8, "compliant-rk45": 1e-8}


def _energy_param(name, scheme):
    marks = []
    if scheme.startswith("compliant"):
        marks.append(pytest.mark.slow)
    return pytest.param(name, scheme, marks=marks)


@pytest.mark.parametrize("name, scheme", [_energy_param(n, s) for n in sorted(CONSERVATIVE)
                                          for s in SCHEMES if s not in OWN_SCHEME
                                          # both scenes are planar: the spatial reference
                                          # refuses them (test_every_scheme_runs_or_refuses...)
                                          and s != "event-driven-space"])
def test_no_energy_is_gained_where_the_scene_conserves_it(name, scheme):
    params, energy = CONSERVATIVE[name]
    scene = registry.make_scene(name, **params)
    q0, v0 = scene.initial_state()
    span = scene.default_span()
    opts = _default_options(scene, scheme)
    res = simulate(scene, (0.0, span), q0, v0, scheme, **opts)
    assert res.status == 0, res.message
    e = energy(scene, res.q, res.v)
    allowed = 2.0 * opts["h"] if "h" in opts else 1e3 * ADAPTIVE_TOL[scheme]
    assert np.max(e - e[0]) <= allowed * e[0]
    # and the motion is not a rest: the impacts happened
    assert np.ptp(e) > 0.0 or np.ptp(res.v) > 0.1
