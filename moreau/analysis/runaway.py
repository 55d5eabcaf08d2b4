"""One runaway detector for every analysis of a driven scene with a cyclic coordinate.

A rotor (or slider) runs away when its speed grows without bound: past a
motor's stall load, or with a load larger than the friction can ever
transmit. Every analysis that runs a driven scene period after period
(the statistical steady state, the classification of an atlas point, the
bifurcation diagram, and through them ``steady``, ``atlas`` and
``characteristic``) asks the same two questions here:

* :func:`certain_runaway`: does the scene's physics already say so, before
  any run? A scene may define ``certain_runaway()`` returning the reason
  (the stick–slip motor: a load above the sliding friction ``mu N`` makes
  the slider's speed change by at least ``2 pi (|F_L| - mu N)`` every
  period, whatever it does).
* :func:`runaway_in`: does a run's series of displacements per period
  ``d_k`` (the period-mean velocity of the cyclic coordinate times ``2 pi``)
  show it? The test (:data:`TEST`):

  1. the last ``m`` entries are cut into ``B = min(20, m // 2)`` batches
     (``B >= 5``) and the batch means are regressed on their index by least
     squares; the slope is significant when ``|b| / se(b)`` exceeds the
     Student t quantile ``t_{B-2, 1 - ALPHA/2}`` (:data:`ALPHA` = 1e-3);
  2. the trend leads away from rest: ``b`` has the sign of the mean and the
     last batch is faster than the first;
  3. it does not slow down: the slope over the second half of the batches
     is at least :data:`MIN_SLOPE_RATIO` times that over the first half (a
     transient relaxing onto a bounded motion slows down; a constant
     mean force does not);
  4. the motion is already faster than the drive can carry it: the last
     batch's mean speed exceeds the drive's speed bound (the rod tip's
     largest speed, or the scene's ``velocity_scale``; with neither, this
     condition is not applied). Beyond it, friction at the drive contact
     keeps one sign, so a significant acceleration there is not undone.

  A non-finite displacement is a runaway too (the state overflowed).

Examples
--------
>>> import numpy as np
>>> from moreau.scenes.friction_drive import FrictionDrive
>>> sc = FrictionDrive(frequency=185.0, load=0.005)
>>> runaway_in(-0.2 * np.arange(1.0, 101.0), sc)[:48]
'no steady state: past stall (load F_L = 0.005 N)'
>>> runaway_in(np.full(100, 0.01), sc) is None
True
"""

import math

import numpy as np
from scipy.special import stdtrit

__all__ = ["certain_runaway", "runaway_in", "runaway_side", "drive_speed_bound", "TEST",
           "ALPHA", "MIN_SLOPE_RATIO", "MIN_SAMPLES"]

TWO_PI = 2.0 * math.pi
#: significance level of the trend test (two-sided)
ALPHA = 1e-3
#: the second half's slope over the first half's, at least, for a trend that does not slow
MIN_SLOPE_RATIO = 0.5
#: displacements per period needed for a test (5 batches of 2)
MIN_SAMPLES = 10
#: largest number of batch means
MAX_BATCHES = 20
#: the test, as a result states it
TEST = (f"least-squares slope of up to {MAX_BATCHES} batch means of the displacement per "
        f"period, significant at {ALPHA:g} (Student t), leading away from rest, not slowing "
        f"(second-half slope >= {MIN_SLOPE_RATIO:g} x first-half), with the speed beyond the "
        f"drive's speed bound")


def runaway_side(scene, displacement):
    """The phrase naming the load (if any) and the direction of a runaway.

    Examples
    --------
    >>> from moreau.scenes.friction_drive import FrictionDrive
    >>> runaway_side(FrictionDrive(frequency=185.0, load=0.01), -1.0)
    'past stall (load F_L = 0.01 N); the rotor runs away backwards, '
    """
    load = getattr(getattr(scene, "params", None), "load", 0.0) or 0.0
    direction = "forwards" if displacement > 0 else "backwards"
    return (f"past stall (load F_L = {load:g} N); the rotor runs away {direction}, "
            if load else f"the rotor runs away {direction} with no load to drive it, ")


def drive_speed_bound(scene):
    """The largest speed the drive gives the rotor directly (scene units), or None.

    The rod tip's largest speed over a period where the scene gives it
    (``tip_velocity``, or the tips on the contact manifolds of
    ``rest_state``), else the scene's ``velocity_scale``.

    Examples
    --------
    >>> from moreau.scenes.friction_drive import FrictionDrive
    >>> round(drive_speed_bound(FrictionDrive(frequency=185.0)), 6)
    0.001989
    """
    tau = np.linspace(0.0, TWO_PI, 257)
    if hasattr(scene, "tip_velocity"):
        return float(np.max(np.abs(scene.tip_velocity(tau))))
    if hasattr(scene, "rest_state"):
        tip = 0.0
        for t in tau:
            q, v = scene.rest_state(t)
            tip = max(tip, float(np.max(np.abs(np.sin(q[:2]) * v[:2]))))
        if tip > 0.0:
            return tip
    vs = getattr(scene, "velocity_scale", None)
    if vs is not None and float(np.max(np.abs(vs))) > 0.0:
        return float(np.max(np.abs(vs)))
    return None


def certain_runaway(scene):
    """The scene's own statement that its rotor must run away, or None (no run needed).

    Examples
    --------
    >>> from moreau.scenes.stick_slip_motor import StickSlipMotor
    >>> print(certain_runaway(StickSlipMotor(frequency=1000.0, load=0.3)))  # doctest: +ELLIPSIS
    no steady state: the load |F_L| = 0.3 N exceeds the sliding friction mu N = 0.2 N...
    """
    fn = getattr(scene, "certain_runaway", None)
    return fn() if callable(fn) else None


def _slope(y):
    # least-squares slope of y on 0..n-1 and its standard error (n - 2 degrees of freedom)
    n = y.size
    x = np.arange(n, dtype=float) - 0.5 * (n - 1)
    sxx = float(x @ x)
    b = float(x @ (y - y.mean())) / sxx
    r = y - y.mean() - b * x
    s2 = float(r @ r) / (n - 2) if n > 2 else math.inf
    return b, math.sqrt(s2 / sxx)


def runaway_in(d, scene, bound=None):
    """Why the series of displacements per period ``d`` is a runaway, or None (see the module doc).

    Parameters
    ----------
    d : array_like
        Displacements of the cyclic coordinate over consecutive periods
        (scene units), the window to judge (the caller drops a start it
        knows to be transient).
    scene : Scene
        Names the load and gives the drive's speed bound.
    bound : float, optional
        The drive's speed bound (scene units); :func:`drive_speed_bound` by
        default.

    Returns
    -------
    str or None
        The reason, naming the load, the direction, the growth and the test.
    """
    d = np.asarray(d, dtype=float).reshape(-1)
    if d.size == 0:
        return None
    if not np.all(np.isfinite(d)):
        return (f"no steady state: {runaway_side(scene, 1.0)}its state is not finite after "
                f"{d.size} periods")
    if d.size < MIN_SAMPLES:
        return None
    nb = min(MAX_BATCHES, d.size // 2)
    size = d.size // nb
    y = d[d.size - nb * size:].reshape(nb, size).mean(axis=1)
    b, se = _slope(y)
    mean = float(y.mean())
    crit = float(stdtrit(nb - 2, 1.0 - 0.5 * ALPHA))
    if not (b != 0.0 and abs(b) > crit * se):
        return None
    if not (b * mean > 0.0 and abs(y[-1]) > abs(y[0])):
        return None
    h = nb // 2
    b1, _ = _slope(y[:h])
    b2, _ = _slope(y[nb - h:])
    if not (b2 * b > 0.0 and abs(b2) >= MIN_SLOPE_RATIO * abs(b1)):
        return None
    speed = abs(float(y[-1])) / TWO_PI
    if bound is None:
        bound = drive_speed_bound(scene)
    if bound is not None and not speed > bound:
        return None
    t = abs(b) / se if se > 0.0 else math.inf
    beyond = ("" if bound is None else
              f", {speed / bound:.3g} times the drive's largest speed")
    to_si = getattr(scene, "velocity_to_si", None)
    grow = abs(b) / size / TWO_PI
    grow = f"{to_si(grow):.3g} m/s" if to_si else f"{grow:.3g} (scene units)"
    now = f"{to_si(speed):.3g} m/s" if to_si else f"{speed:.3g}"
    return (f"no steady state: {runaway_side(scene, mean)}its mean speed grows by {grow} "
            f"every period over the last {nb * size} periods (trend t = {t:.3g} > {crit:.3g}, "
            f"not slowing; mean speed {now}{beyond})")
