"""Integration schemes: the event-driven reference and time-stepping schemes."""

from .base import INTEGRATORS, Integrator, register_integrator, simulate
from .result import Event, SimulationResult
from . import event_driven  # noqa: F401  (registers "friction-drive-walker")
from . import event_driven_generic  # noqa: F401  (registers "event-driven-generic" and "event-driven")
from . import moreau_jean  # noqa: F401  (registers "moreau-jean")
from . import stick_slip_reference  # noqa: F401  (registers "stick-slip-exact")
from .stick_slip_reference import stick_slip_steady_state
