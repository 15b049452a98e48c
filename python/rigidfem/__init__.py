"""rigidfem: flexible multibody dynamics by the rigid finite element method.

Kinematic chains and trees in joint coordinates with homogeneous transformations,
and the equations of motion of Wittbrodt, Adamiec-Wójcik & Wojciech, *Dynamics of
Flexible Multibody Systems: Rigid Finite Element Method* (Springer 2006), with a
C++ core. SI units throughout.
"""

import importlib
import sys

from . import _load_core

_load_core.load(__name__)  # the core built for this processor, as rigidfem._core: before the imports below

# The layers, bottom to top (tests/test_structure.py holds their imports downwards): base, model, simulation,
# analysis, viz, studies. Every public name is here, and the modules users reach as rf.<module>.
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
from .base import display, export  # notebook displays; tables, CSV and NumPy archives
from .model import laws, loops, motion, parameters, samples, sea, shapes, stages
from .model.beams import Beam, rfe_parameters, sde_parameters
from .model.frames import transform
from .model.joints import Joint
from .model.materials import Material, Section
from .model.model import Model, System
from .model.parameters import Parameter
from .simulation import options, sensitivities  # the C++ method and option tables; forward sensitivities
from .simulation.error_control import ErrorEstimate
from .simulation.events import Event
from .simulation.integration import simulate
from .simulation.options import integrator_options, methods
from .simulation.result import Result, load_npz
from .analysis import Equilibrium, Gradient, Modes, NotAnEquilibriumWarning, gradient, linearize, modal_analysis
from .analysis import static_equilibrium
from .viz import plots
from .viz.viewer import Viewer, view  # the 3D viewer: notebooks and HTML files
from .studies import study
from .studies.resolution import Plan, ResolveError, resolve  # elements and deformations for a tolerance
from .studies.sweep import sweep

# The public modules keep their short paths: `import rigidfem.motion`, `from rigidfem.laws import Rope`, and the
# documentation's pages (rigidfem.animation, lazy, is reached as rf.animation).
for _module in (display, export, laws, loops, motion, parameters, samples, sea, shapes, stages, options, sensitivities, plots,
                study):
    sys.modules.setdefault(f"{__name__}.{_module.__name__.rsplit('.', 1)[1]}", _module)
del _module

__version__ = "0.1.0"


def __getattr__(name: str):
    """``rigidfem.animation`` and ``rigidfem.animate`` on first use: they import
    matplotlib.animation (about 0.1 s), which ``import rigidfem`` does without."""
    if name in ("animation", "animate"):
        animation = importlib.import_module(".viz.animation", __name__)
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
    "Event",
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
    "shapes",
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
