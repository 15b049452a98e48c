"""Analyses about an operating point and gradients: statics (``static_equilibrium``), modes (``modal_analysis``)
and their sensitivities, linearisation (``linearize``), adjoint gradients of a run (``gradient``). Imports the
simulation layer and below."""

from .adjoint import Gradient, gradient
from .modes import Modes, modal_analysis
from .state_space import NotAnEquilibriumWarning, linearize
from .statics import Equilibrium, static_equilibrium

__all__ = ["Equilibrium", "Gradient", "Modes", "NotAnEquilibriumWarning", "gradient", "linearize", "modal_analysis",
           "static_equilibrium"]
