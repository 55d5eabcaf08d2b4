"""moreau: simulation of non-smooth mechanics (unilateral contact, Coulomb friction, impacts).

The package is built in floors, each importing only from itself and the floors
below (``docs/architecture.md``; held by ``tests/test_layers.py``): base (this
module, ``errors``, ...) < ``model`` < ``lcp``, ``contact`` < ``integrators`` <
``analysis`` < ``scenes`` < ``studies``, ``suite`` < ``cli``.
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
