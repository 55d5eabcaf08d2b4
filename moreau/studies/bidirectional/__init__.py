"""Studies of the two-rod bidirectional drive: direction control (balance and phase) and its sweeps."""
