"""The paper's friction drive, with its own reference and analyses.

:mod:`~moreau.scenes.friction_drive.scene`
    the scene (:class:`FrictionDrive`, its derivation and comparison case);
:mod:`~moreau.scenes.friction_drive.walker`
    its event-driven reference scheme, ``"friction-drive-walker"``;
:mod:`~moreau.scenes.friction_drive.steady`
    the reference's steady state, section runs and energy audit;
:mod:`~moreau.scenes.friction_drive.floquet`
    the Floquet multipliers of the walker's period map;
:mod:`~moreau.scenes.friction_drive.rod`
    the rod's compiled pieces (also the two-rod drive's);
``_flight_taylor``
    the walker's compiled Taylor series of a flight.

Importing the package registers the scene, its reference scheme and that
scheme's steady-state solver.
"""

from .scene import (PAPER_DEFAULTS, FrictionDrive, FrictionDriveCase, FrictionDriveParams,
                    params_from_kwargs)
from .walker import ContactState, EventDriven, FrictionDriveWalker, impact_impulses
from .floquet import GrazingEvent, walker_monodromy, walker_period_map_slope
from .steady import walker_energy_audit, walker_steady_state

__all__ = ["FrictionDriveParams", "FrictionDrive", "PAPER_DEFAULTS", "EventDriven", "ContactState",
           "FrictionDriveWalker", "impact_impulses", "walker_monodromy", "walker_period_map_slope",
           "GrazingEvent", "walker_steady_state", "walker_energy_audit"]
