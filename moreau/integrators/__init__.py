"""Integration schemes: the event-driven reference and time-stepping schemes."""

from .base import INTEGRATORS, Integrator, register_integrator, simulate
from .result import Event, SimulationResult
