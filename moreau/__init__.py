"""moreau: simulation of non-smooth mechanics (unilateral contact, Coulomb friction, impacts).

The package is built in floors. A module imports only from its own floor and
the floors below it, and the imports form no cycle (``tests/test_layers.py``
holds every import to this list, lowest floor first):

1. ``base``: this module, ``errors``, ``_validate``, ``_log``, ``_jit_cache``,
   ``outputs``, ``provenance``, ``regimes``, ``modes``;
2. ``model``: ``model/`` (the scene interface, the scene registry, units) and
   ``compiled`` (a scene's compiled model);
3. ``contact``: ``lcp/``, ``contact/`` (the contact problems and their solvers);
4. ``integrators``: ``integrators/`` (the schemes and their compiled loops);
5. ``analysis``: ``analysis/``, ``check`` (steady states, comparison cases,
   sweeps, the scene checker);
6. ``scenes``: ``scenes/`` (a scene with its own reference or analyses is a
   package, e.g. ``scenes/friction_drive/``);
7. ``studies``: ``studies/``, ``suite/`` (studies of particular scenes, which
   register their own sweep and atlas hooks; the benchmark suite);
8. ``cli``: ``cli``, ``__main__``.

A scene sits above the analyses because it may bring its own reference
scheme, steady-state solver and comparison case; the schemes and analyses
find scenes by name through :mod:`moreau.model.registry`, which imports the
scene and study packages by name when it first needs them.
"""

import importlib

from .errors import (
    ContactLostError,
    ConvergenceError,
    IllPosedError,
    InputError,
    LCPError,
    MoreauError,
    PainleveError,
)

__version__ = "0.1.0"

#: the public front ends, imported on first use so that ``import moreau`` stays light
_LAZY = {
    "simulate": "moreau.integrators",
    "compare": "moreau.analysis.compare",
    "find_steady_state": "moreau.analysis.steady_state",
    "check_scene": "moreau.check",
    "Scene": "moreau.model.scene",
}


def __getattr__(name):
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'moreau' has no attribute {name!r}")
    # PEP 562 lazy attribute: the front end's module is imported on first use only
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value
