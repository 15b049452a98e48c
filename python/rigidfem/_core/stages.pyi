"""
The named stages of forward dynamics, each writing into a Data.
"""
from __future__ import annotations
import numpy
import numpy.typing
import typing
__all__: list[str] = ['accelerations', 'driving_forces', 'generalized_forces', 'kinematics', 'mass_matrix', 'set_state']
def accelerations(system: typing.Any, data: typing.Any) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
    """
    => data.qdd solving A qdd = f; returns it.
    """
def driving_forces(system: typing.Any, data: typing.Any) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
    """
    => data.tau (needs accelerations); returns it.
    """
def generalized_forces(system: typing.Any, data: typing.Any) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
    """
    => data.f (loads, velocity terms, springs, dampers); returns it.
    """
def kinematics(system: typing.Any, data: typing.Any) -> None:
    """
    (qa, qda, qdda) => data.T, Td, Tdd, U.
    """
def mass_matrix(system: typing.Any, data: typing.Any) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
    """
    => data.A; returns it.
    """
def set_state(system: typing.Any, data: typing.Any, t: float, q: numpy.typing.ArrayLike, qd: numpy.typing.ArrayLike) -> None:
    """
    (t, q, qd) => data.qa, qda, qdda (drives evaluated).
    """
