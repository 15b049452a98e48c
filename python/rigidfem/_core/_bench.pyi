"""
Maintainers' timing helpers for benchmarks/ (not public API).
"""
from __future__ import annotations
import numpy
import numpy.typing
import rigidfem._core
import typing
__all__: list[str] = ['dense_lu_solutions', 'forward_dynamics_seconds', 'implicit_step_parts_seconds']
def dense_lu_solutions(S: typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, n]"], b: typing.Annotated[numpy.typing.ArrayLike, numpy.complex128, "[m, 1]"]) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, 1]"], typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, 1]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], typing.Annotated[numpy.typing.NDArray[numpy.complex128], "[m, 1]"]]:
    """
    The dense Newton matrices' LU (dense_lu.hpp), for the tests: (x, x_T, z, z_T, u, u_c) with Re S x = Re b,
    Re Sᵀ x_T = Re b, S z = b, Sᵀ z_T = b and the pivots of Re S and of S.
    """
def forward_dynamics_seconds(system: rigidfem._core._System, t: typing.SupportsFloat | typing.SupportsIndex, q: typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], qd: typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], calls: typing.SupportsInt | typing.SupportsIndex) -> float:
    """
    Seconds per forward-dynamics call, timed in C++ on one workspace after a warm-up call.
    """
def implicit_step_parts_seconds(system: rigidfem._core._System, t: typing.SupportsFloat | typing.SupportsIndex, q: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], qd: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], qdd: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], calls: typing.SupportsInt | typing.SupportsIndex) -> dict[str, float]:
    """
    Seconds per call of the parts of an implicit step (residual, tangent, LU factor and solve, the O(n)
    armature factor and solve), timed in C++.
    """
