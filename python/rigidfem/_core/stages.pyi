"""
The named stages of forward dynamics, each writing into a Data.
"""
from __future__ import annotations
import numpy
import numpy.typing
import rigidfem._core
import typing
__all__: list[str] = ['accelerations', 'driving_forces', 'generalized_forces', 'kinematics', 'mass_matrix', 'set_state']
def accelerations(system: rigidfem._core._System, data: rigidfem._core.Data) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
    """
    => data.qdd solving A qdd = f; returns it.
    """
def driving_forces(system: rigidfem._core._System, data: rigidfem._core.Data) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
    """
    => data.tau (needs accelerations); returns it.
    """
def generalized_forces(system: rigidfem._core._System, data: rigidfem._core.Data) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
    """
    => data.f (loads, velocity terms, springs, dampers); returns it.
    """
def kinematics(system: rigidfem._core._System, data: rigidfem._core.Data) -> None:
    """
    (qa, qda, qdda) => data.T, Td, Tdd, U.
    """
def mass_matrix(system: rigidfem._core._System, data: rigidfem._core.Data) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
    """
    => data.A; returns it.
    """
def set_state(system: rigidfem._core._System, data: rigidfem._core.Data, t: typing.SupportsFloat | typing.SupportsIndex, q: typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], qd: typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]) -> None:
    """
    (t, q, qd) => data.qa, qda, qdda (drives evaluated).
    """
