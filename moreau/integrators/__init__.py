"""Integration schemes: the event-driven reference and time-stepping schemes.

Only scene-independent schemes live here. A scene's own exact reference lives
with its scene and registers itself when the scene modules are discovered
(:func:`moreau.scenes.registry.discover`, which :func:`simulate` calls before
it looks up a name it does not know); this package imports no scene.
"""

from .base import INTEGRATORS, Integrator, check_options, get_integrator, register_integrator, simulate
from .result import Event, SimulationResult
from . import event_driven_generic  # noqa: F401  (registers "event-driven-generic" and "event-driven")
from . import moreau_jean  # noqa: F401  (registers "moreau-jean")
