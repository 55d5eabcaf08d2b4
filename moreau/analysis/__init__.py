"""Analysis on top of the integrators: steady states, operation modes, sweeps."""
