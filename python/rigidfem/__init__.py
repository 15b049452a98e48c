"""rigidfem: flexible multibody dynamics by the rigid finite element method.

Kinematic chains and trees in joint coordinates with homogeneous transformations,
and the equations of motion of Wittbrodt, Adamiec-Wójcik & Wojciech, *Dynamics of
Flexible Multibody Systems: Rigid Finite Element Method* (Springer 2006), with a
C++ core. SI units throughout.
"""

import importlib

from . import laws, motion, plots, samples, stages, study
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
from .simulation import Result, load_npz, simulate
from .options import integrator_options, methods  # noqa: E402 (the C++ method and option tables)
from . import display, export  # noqa: E402 (notebook displays; tables, CSV and NumPy archives)
from .state_space import NotAnEquilibriumWarning, linearize  # noqa: E402
from .sweep import sweep
from .resolution import Plan, ResolveError, resolve  # noqa: E402 (rf.resolve: elements and deformations for a tolerance)
from .error_control import ErrorEstimate  # noqa: E402
from .viewer import Viewer, view  # noqa: E402 (the 3D viewer: notebooks and HTML files)
from . import parameters, sensitivities  # noqa: E402 (named parameters; forward sensitivities)
from .parameters import Parameter  # noqa: E402
from .adjoint import Gradient, gradient  # noqa: E402 (adjoint gradients of an objective of a run)

__version__ = "0.1.0"


def __getattr__(name: str):
    """``rigidfem.animation`` and ``rigidfem.animate`` on first use: they import
    matplotlib.animation (about 0.1 s), which ``import rigidfem`` does without."""
    if name in ("animation", "animate"):
        animation = importlib.import_module(".animation", __name__)  # also sets rigidfem.animation
        return animation if name == "animation" else animation.animate
    raise AttributeError(f"module 'rigidfem' has no attribute {name!r}")


__all__ = [
    "R1",
    "R2",
    "R3",
    "Beam",
    "Body",
    "Data",
    "Equilibrium",
    "Gradient",
    "ErrorEstimate",
    "Joint",
    "JointSpec",
    "Material",
    "ForceLawError",
    "Model",
    "NotAnEquilibriumWarning",
    "Parameter",
    "Modes",
    "Plan",
    "Point",
    "Profile",
    "ResolveError",
    "Result",
    "Section",
    "SimulationError",
    "System",
    "animate",
    "animation",
    "display",
    "euler_zyx",
    "export",
    "gradient",
    "homogeneous",
    "inverse",
    "plots",
    "pseudo_inertia",
    "integrator_options",
    "methods",
    "joint_transform",
    "joint_transform_derivative",
    "joint_transform_second_derivative",
    "laws",
    "linearize",
    "load_npz",
    "modal_analysis",
    "motion",
    "parameters",
    "resolve",
    "rfe_parameters",
    "sde_parameters",
    "samples",
    "sea",
    "sensitivities",
    "simulate",
    "skew",
    "stages",
    "static_equilibrium",
    "study",
    "sweep",
    "transform",
    "view",
    "Viewer",
]
