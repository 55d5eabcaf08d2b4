"""Runs read once a drive period: the states at the Poincaré sections of a long run.

The statistical steady state (:mod:`moreau.analysis.statistical`) and the
classification of a point without an orbit (:mod:`moreau.analysis.classify`)
run a scheme for hundreds to tens of thousands of drive periods and need its
state at the end of each. :func:`section_states` does that for any scheme
through :func:`moreau.integrators.simulate`, sampled once a period. A scheme
that can do it more cheaply registers its own run here
(:func:`register_section_run`): the friction drive's walker reads its walk
at the sections without recording every event and sample.

Examples
--------
>>> section_run_names()
['friction-drive-walker']
"""

import math

import numpy as np

from ..errors import MoreauError
from ..integrators import simulate
from ..model import registry

__all__ = ["register_section_run", "section_states", "section_run_names"]

TWO_PI = 2.0 * math.pi

#: scheme name -> its own section run
_SECTION_RUNS = {}


def register_section_run(scheme):
    """Decorator registering a scheme's own run from section to section.

    The registered function is called as ``fn(scene, q, v, tau0, periods,
    options)`` with the options :func:`section_states` was given, and
    returns ``(qs, vs)``, the states at ``tau0 + 2 pi k`` for ``k = 0 ..
    periods`` (arrays of shape ``(periods + 1, ndof)``), or raises a
    :class:`~moreau.errors.MoreauError` naming why the run failed.
    """
    def deco(fn):
        _SECTION_RUNS[scheme] = fn
        return fn
    return deco


def section_run_names():
    """Sorted names of the schemes with a section run of their own."""
    registry.discover()
    return sorted(_SECTION_RUNS)


def section_states(scene, scheme, options, tau0, q, v, periods):
    """The states at the ends of ``periods`` drive periods from ``(q, v)`` at ``tau0``.

    Parameters
    ----------
    scene : Scene
    scheme : str
        A registered scheme.
    options : dict
        Its options for :func:`~moreau.integrators.simulate`, sampling the
        run at least once a drive period (a section run of the scheme's own
        ignores the sampling).
    tau0 : float
    q, v : ndarray
    periods : int

    Returns
    -------
    qs, vs : ndarray, shape (periods + 1, ndof)
    vmax : float
        The largest velocity component among the states the run recorded.

    Raises
    ------
    MoreauError
        The run failed, or did not sample the ends of the periods.
    """
    registry.discover()
    own = _SECTION_RUNS.get(scheme)
    if own is None and scheme == "event-driven":
        # "event-driven" runs a scene's own reference where it has one (simulate does so)
        own = _SECTION_RUNS.get(getattr(scene, "reference_integrator", None))
    if own is not None:
        qs, vs = own(scene, q, v, tau0, periods, options)
        return qs, vs, float(np.max(np.abs(vs))) if vs.size else 0.0
    res = simulate(scene, (tau0, tau0 + periods * TWO_PI), q, v, scheme, **options)
    if not res.success:
        raise MoreauError(f"{scheme}: {res.message}")
    bounds = tau0 + TWO_PI * np.arange(periods + 1)
    tol = 1e-9 * (1.0 + np.abs(bounds))
    # the last sample at each period's end (an event exactly there records it twice)
    idx = np.searchsorted(res.t, bounds + tol, side="right") - 1
    if np.any(idx < 0) or np.any(np.abs(res.t[idx] - bounds) > tol):
        raise MoreauError(f"scheme {scheme!r} did not sample the run at the ends of the drive "
                          "periods")
    vmax = float(np.max(np.abs(res.v))) if res.v.size else 0.0
    return res.q[idx], res.v[idx], vmax
