"""The stick–slip motor, with its own exact reference.

:mod:`~moreau.scenes.stick_slip_motor.scene`
    the scene (:class:`StickSlipMotor`, its drives and comparison case);
:mod:`~moreau.scenes.stick_slip_motor.exact`
    its exact event-driven reference scheme, ``"stick-slip-exact"``, and steady state.

Importing the package registers the scene and its reference scheme.
"""

from .scene import SawtoothDrive, SineDrive, StickSlipCase, StickSlipMotor, StickSlipMotorParams
from .exact import StickSlipReference, stick_slip_period_map, stick_slip_steady_state

__all__ = ["StickSlipMotorParams", "StickSlipMotor", "SineDrive", "SawtoothDrive",
           "StickSlipReference", "stick_slip_steady_state", "stick_slip_period_map"]
