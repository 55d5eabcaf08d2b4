"""Integration schemes: the event-driven reference and time-stepping schemes."""

from .base import INTEGRATORS, Integrator, register_integrator, simulate
from .result import Event, SimulationResult
from . import event_driven  # noqa: F401  (registers "event-driven")
