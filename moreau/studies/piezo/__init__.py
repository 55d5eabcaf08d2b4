"""Studies of the voltage-driven friction drive: the stack's loop and the stator's resonance."""
