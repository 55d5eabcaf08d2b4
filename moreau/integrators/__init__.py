"""Integration schemes: the event-driven reference and time-stepping schemes.

Only scene-independent schemes live here, one module per scheme family; each
registers its schemes when the package discovers it (below). A scene's own exact reference lives
with its scene and registers itself when the scene modules are discovered
(:func:`moreau.model.registry.discover`, which :func:`simulate` calls before
it looks up a name it does not know); this package imports no scene.
"""

import importlib
import pkgutil

from ._loops import specialised_loops
from .base import (INTEGRATORS, Integrator, SchemeOptions, check_options, get_integrator,
                   register_integrator, simulate)
from .result import Event, SimulationResult

__all__ = ["INTEGRATORS", "Integrator", "SchemeOptions", "check_options", "get_integrator",
           "register_integrator", "simulate", "Event", "SimulationResult", "specialised_loops"]

# every public module here registers its scheme(s) when imported: discover them, so that a
# new scheme is one new module and no list names it
for _info in pkgutil.iter_modules(__path__):
    if not _info.name.startswith("_") and _info.name not in ("base", "result"):
        importlib.import_module(f"{__name__}.{_info.name}")
