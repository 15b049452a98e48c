"""rigidfem: flexible multibody dynamics by the rigid finite element method.

Kinematic chains and trees in joint coordinates with homogeneous transformations,
and the equations of motion of Wittbrodt, Adamiec-Wójcik & Wojciech, *Dynamics of
Flexible Multibody Systems: Rigid Finite Element Method* (Springer 2006), with a
C++ core. SI units throughout.
"""

from . import motion, samples, stages, study
from ._core import (
    R1,
    R2,
    R3,
    Body,
    Data,
    ForceLawError,
    JointSpec,
    Point,
    Profile,
    SimulationError,
    euler_zyx,
    homogeneous,
    inverse,
    pseudo_inertia,
    joint_transform,
    joint_transform_derivative,
    joint_transform_second_derivative,
    skew,
)
from .analysis import Equilibrium, Modes, modal_analysis, static_equilibrium
from .beams import Beam, rfe_parameters, sde_parameters
from . import loops  # noqa: E402 (rigidfem.loops: the loop kinds)
from .joints import Joint
from .materials import Material, Section
from .frames import transform
from .model import Model, System
from . import sea  # noqa: E402 (rigidfem.sea: sea states for a moving base)
from .simulation import Result, simulate

__version__ = "0.1.0"

__all__ = [
    "R1",
    "R2",
    "R3",
    "Beam",
    "Body",
    "Data",
    "Equilibrium",
    "Joint",
    "JointSpec",
    "Material",
    "ForceLawError",
    "Model",
    "Modes",
    "Point",
    "Profile",
    "Result",
    "Section",
    "SimulationError",
    "System",
    "euler_zyx",
    "homogeneous",
    "inverse",
    "pseudo_inertia",
    "joint_transform",
    "joint_transform_derivative",
    "joint_transform_second_derivative",
    "modal_analysis",
    "motion",
    "rfe_parameters",
    "sde_parameters",
    "samples",
    "sea",
    "simulate",
    "skew",
    "stages",
    "static_equilibrium",
    "study",
    "transform",
]
