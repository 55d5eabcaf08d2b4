"""The registry of steady-state solvers: one per scheme that can find a periodic steady state.

:func:`moreau.analysis.steady_state.find_steady_state` looks a scheme's
solver up here. A solver registers itself where it is defined: the generic
event-driven shooting (:mod:`moreau.analysis.periodic_shooting`), the
discrete Moreau–Jean map (:mod:`moreau.analysis.mj_steady_state`), and a
scene's own reference with its scene (the friction drive's walker). With
``scheme="event-driven"``, a scene whose ``reference_integrator`` has a
solver of its own gets that one.

A solver is called as ``solver(scene, rtol=..., v_guess=..., max_iter=...,
**options)`` and returns a :class:`~moreau.integrators.result.SteadyState`.

Examples
--------
>>> from moreau.analysis import steady_state   # registers the package's solvers
>>> "moreau-jean" in steady_solver_names()
True
>>> get_steady_solver("euler")
Traceback (most recent call last):
...
moreau.errors.InputError: `scheme` has no steady-state solver: 'euler'; the schemes with one: ...
"""

from ..errors import InputError
from ..model import registry

__all__ = ["register_steady_solver", "get_steady_solver", "steady_solver_names", "has_solver"]

_SOLVERS = {}


def register_steady_solver(scheme):
    """Decorator registering a steady-state solver for the scheme named ``scheme``."""
    def deco(fn):
        _SOLVERS[scheme] = fn
        return fn
    return deco


def has_solver(scheme):
    """Whether ``scheme`` has a steady-state solver (scenes discovered first)."""
    registry.discover()
    return scheme in _SOLVERS


def steady_solver_names():
    """Sorted names of the schemes with a steady-state solver."""
    registry.discover()
    return sorted(_SOLVERS)


def get_steady_solver(scheme):
    """The solver of ``scheme``; an unknown name lists the schemes that have one."""
    if has_solver(scheme):
        return _SOLVERS[scheme]
    raise InputError(f"`scheme` has no steady-state solver: {scheme!r}; the schemes with one: "
                     + ", ".join(steady_solver_names()))
