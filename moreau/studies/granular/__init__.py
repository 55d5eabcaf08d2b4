"""Studies of the granular scenes: Janssen's law in the silo, the column's runout (issue 38)."""
