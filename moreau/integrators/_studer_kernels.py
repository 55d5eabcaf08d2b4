NOT_FINITE = -5
TOO_MANY = -8
STUDER_COUNTERS = ("macro_steps", "base_steps", "rejected_steps", "smooth_steps", "forced_steps")
def studer_loop(*a):
    pass
