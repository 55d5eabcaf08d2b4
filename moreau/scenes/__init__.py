"""Mechanical systems ("scenes") that the integrators run."""

from .base import Scene
from .bidirectional_drive import BidirectionalDrive, BidirectionalDriveParams
from .bouncing_ball import BouncingBall, BouncingBallParams
from .friction_drive import FrictionDrive, FrictionDriveParams
from .painleve_rod import PAINLEVE_MU_MIN, PainleveRod, PainleveRodParams, painleve_critical_mu
from .sliding_block import SlidingBlock, SlidingBlockParams
from .sliding_box import SlidingBox, SlidingBoxParams
from .stick_slip_motor import SawtoothDrive, SineDrive, StickSlipMotor, StickSlipMotorParams
