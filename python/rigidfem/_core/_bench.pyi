"""
Maintainers' timing helpers for benchmarks/ (not public API).
"""
from __future__ import annotations
import numpy
import numpy.typing
import rigidfem._core
import typing
__all__: list[str] = ['forward_dynamics_seconds']
def forward_dynamics_seconds(system: rigidfem._core._System, t: typing.SupportsFloat | typing.SupportsIndex, q: typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], qd: typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], calls: typing.SupportsInt | typing.SupportsIndex) -> float:
    """
    Seconds per forward-dynamics call, timed in C++ on one workspace after a warm-up call.
    """
