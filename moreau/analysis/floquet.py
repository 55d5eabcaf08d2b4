"""Floquet multipliers of periodic steady states: the eigenvalues of the period map's Jacobian.

A periodic steady state is a fixed point ``x*`` of the period map ``P``
(the state at the Poincaré section mapped one drive period, or ``k``
periods for a period-``k`` orbit, on). Its Floquet multipliers are the
eigenvalues of the monodromy matrix ``M = DP(x*)`` restricted to the free
directions of the state: the cyclic coordinate (a rotor position) is
removed, and so are the directions a touching contact pins (its gap and
normal velocity). The orbit is asymptotically stable when every multiplier
lies inside the unit circle; ``1 - max |lambda|`` is its distance from the
circle, the stability margin.

Two ways to get ``M`` are used in the package:

* the saltation matrices of an event-driven walk (the friction drive's
  walker, :mod:`moreau.scenes.friction_drive.floquet`): the smooth pieces'
  variational equations joined by the jump of the variation at every event;
* finite differences of the period map itself (:func:`period_map_jacobian`),
  for any scene and scheme: the generic shooting and Moreau–Jean's discrete
  map.

Examples
--------
>>> m = sorted_multipliers([0.5, -0.9 + 0.1j, -0.9 - 0.1j])
>>> multiplier_pairs(m)[0], multiplier_pairs(m)[2]
([-0.9, 0.1], [0.5, 0.0])
>>> stability(m)[0], round(stability(m)[1], 6)
(True, 0.094461)
"""

import numpy as np

from ..errors import InputError

__all__ = ["period_map_jacobian", "sorted_multipliers", "multiplier_pairs", "stability",
           "floquet_report"]


def period_map_jacobian(fun, z, steps, f0=None, central=True):
    """Finite-difference Jacobian of a map ``fun`` at ``z``.

    Parameters
    ----------
    fun : callable
        ``fun(z) -> array``, the period map (or its residual) in the free
        coordinates ``z``.
    z : array_like
        Point of evaluation.
    steps : float or array_like
        Perturbation of each coordinate.
    f0 : array_like, optional
        ``fun(z)``; needed by forward differences (computed if omitted).
    central : bool
        Central differences (two maps per coordinate, error ``O(step^2)``)
        or forward ones (one map per coordinate).

    Returns
    -------
    ndarray, shape (len(fun(z)), len(z))

    Examples
    --------
    >>> A = np.array([[0.5, 1.0], [0.0, -0.25]])
    >>> np.allclose(period_map_jacobian(lambda z: A @ z, np.zeros(2), 1e-3), A)
    True
    """
    z = np.asarray(z, float)
    steps = np.broadcast_to(np.asarray(steps, float), z.shape)
    if np.any(~(steps > 0.0)):
        raise InputError("`steps` must be positive finite-difference steps")
    if not central and f0 is None:
        f0 = np.asarray(fun(z), float)
    cols = []
    for k in range(z.size):
        dz = np.zeros_like(z)
        dz[k] = steps[k]
        fp = np.asarray(fun(z + dz), float)
        if central:
            cols.append((fp - np.asarray(fun(z - dz), float)) / (2.0 * steps[k]))
        else:
            cols.append((fp - f0) / steps[k])
    if not cols:
        return np.zeros((0, 0))
    return np.column_stack(cols)


def sorted_multipliers(values):
    """Multipliers as a complex array, largest modulus first (ties: larger real part first)."""
    m = np.asarray(values, dtype=complex).ravel()
    order = np.lexsort((-m.imag, -m.real, -np.abs(m)))
    return m[order]


def multiplier_pairs(multipliers):
    """``[[re, im], ...]`` of the multipliers (JSON has no complex numbers)."""
    return [[float(z.real), float(z.imag)] for z in np.asarray(multipliers, dtype=complex)]


def stability(multipliers):
    """``(stable, margin)``: every ``|lambda| < 1``, and ``1 - max |lambda|``.

    A map without free directions (everything pinned) has no multiplier and
    margin 1: a perturbation cannot survive one period.
    """
    m = np.asarray(multipliers, dtype=complex)
    top = float(np.max(np.abs(m))) if m.size else 0.0
    return bool(top < 1.0), 1.0 - top


def floquet_report(ss):
    """The JSON fields of a steady state's multipliers (``None`` where it has none).

    Returns ``floquet_multipliers`` (``[re, im]`` pairs, largest modulus
    first), ``max_multiplier`` (the largest modulus), ``stable``,
    ``stability_margin`` and ``floquet_method``.
    """
    m = getattr(ss, "floquet_multipliers", None)
    if m is None:
        return {"floquet_multipliers": None, "max_multiplier": None, "stable": None,
                "stability_margin": None, "floquet_method": None}
    stable, margin = stability(m)
    return {"floquet_multipliers": multiplier_pairs(m), "max_multiplier": 1.0 - margin,
            "stable": stable, "stability_margin": margin,
            "floquet_method": getattr(ss, "floquet_method", None)}
