"""Integration schemes: the event-driven reference and time-stepping schemes.

Only scene-independent schemes live here. A scene's own exact reference lives
with its scene (``moreau/scenes/friction_drive_walker.py``,
``moreau/scenes/stick_slip_exact.py``); they are imported at the end so that
the registry knows them by name.
"""

from .base import INTEGRATORS, Integrator, register_integrator, simulate
from .result import Event, SimulationResult
from . import event_driven_generic  # noqa: F401  (registers "event-driven-generic" and "event-driven")
from . import moreau_jean  # noqa: F401  (registers "moreau-jean")
from ..scenes import friction_drive_walker  # noqa: F401,E402  (registers "friction-drive-walker")
from ..scenes import stick_slip_exact  # noqa: F401,E402  (registers "stick-slip-exact")
from ..scenes.stick_slip_exact import stick_slip_steady_state  # noqa: E402
