"""The contact problem of one time step: its data, its solvers (issue 35)."""
