"""Time integration and its results: ``simulate`` (the C++ methods and SciPy's), ``Result``, the methods' and
options' tables (``options``), error control and error estimates, forward sensitivities. Imports the model layer
and below."""

from .integration import simulate
from .result import Result, load_npz

__all__ = ["Result", "load_npz", "simulate"]
