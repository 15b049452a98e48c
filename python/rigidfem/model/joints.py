"""Joint types. A joint's motion is Trans(x, y, z) R3(φ3) R2(φ2) R1(φ1) restricted to
its active coordinates (Wittbrodt, Adamiec-Wójcik & Wojciech 2006, ch. 2.1); coordinate
names are ``"x"``, ``"y"``, ``"z"`` (translations, m) and ``"rz"``, ``"ry"``, ``"rx"``
(rotations φ3, φ2, φ1, rad), always ordered as the book orders them: x, y, z, rz, ry, rx.

Every constructor takes optional ``stiffness`` (N/m or N·m/rad), ``damping``
(N·s/m or N·m·s/rad) and ``rest`` (m or rad): a linear spring and viscous damper
on each coordinate, a scalar for all or one value per coordinate.
"""

from __future__ import annotations

from collections.abc import Sequence

from ..base import _checks
from .._core import JointSpec

_AXES = ("x", "y", "z")
_ROTATION = {"x": "rx", "y": "ry", "z": "rz"}


def _axis(axis: str) -> str:
    if axis not in _AXES:
        raise _checks.refuse(f"axis: expected 'x', 'y' or 'z', got {axis!r}")
    return axis


def _make(kind: str, coordinates: Sequence[str], stiffness=0.0, damping=0.0, rest=0.0) -> JointSpec:
    """A joint spec; per-coordinate values follow ``coordinates`` as given and are
    reordered with them into the book's order."""
    spec = JointSpec(kind, list(coordinates))
    n = spec.ncoords
    given = [JointSpec(kind, [c]).coordinates[0] for c in coordinates]  # canonical names, caller's order
    order = [given.index(c) for c in spec.coordinates]
    spec.stiffness = [_checks.per_coordinate(stiffness, n, "stiffness", nonnegative=True)[k] for k in order]
    spec.damping = [_checks.per_coordinate(damping, n, "damping", nonnegative=True)[k] for k in order]
    spec.rest = [_checks.per_coordinate(rest, n, "rest")[k] for k in order]
    return spec


class Joint:
    """Factory of joints: ``Joint.revolute("z", stiffness=10.0)`` etc.

    Examples
    --------
    >>> import rigidfem as rf
    >>> rf.Joint.revolute("z", stiffness=10.0).coordinates
    ['rz']
    >>> rf.Joint.free().coordinates
    ['x', 'y', 'z', 'rz', 'ry', 'rx']
    """

    @staticmethod
    def fixed() -> JointSpec:
        """No relative motion (a rigid connection)."""
        return _make("fixed", [])

    @staticmethod
    def revolute(axis: str = "z", **springs) -> JointSpec:
        """Rotation about the joint frame's ``axis`` (one coordinate, rad)."""
        return _make("revolute", [_ROTATION[_axis(axis)]], **springs)

    @staticmethod
    def prismatic(axis: str = "x", **springs) -> JointSpec:
        """Translation along the joint frame's ``axis`` (one coordinate, m)."""
        return _make("prismatic", [_axis(axis)], **springs)

    @staticmethod
    def cylindrical(axis: str = "z", **springs) -> JointSpec:
        """Translation along and rotation about ``axis`` (m, rad)."""
        a = _axis(axis)
        return _make("cylindrical", [a, _ROTATION[a]], **springs)

    @staticmethod
    def universal(axes: tuple[str, str] = ("z", "y"), **springs) -> JointSpec:
        """Two rotations about two of the joint frame's axes (book order: rz, ry, rx)."""
        if len(axes) != 2 or len(set(axes)) != 2:
            raise _checks.refuse(f"axes: expected two different axes of 'x', 'y', 'z', got {axes!r}")
        return _make("universal", [_ROTATION[_axis(a)] for a in axes], **springs)

    @staticmethod
    def spherical(**springs) -> JointSpec:
        """Euler ZYX rotations φ3, φ2, φ1 (rad). Singular at φ2 = ±π/2."""
        return _make("spherical", ["rz", "ry", "rx"], **springs)

    @staticmethod
    def planar(plane: str = "xy", **springs) -> JointSpec:
        """Two translations in ``plane`` ("xy", "yz" or "zx") and the rotation about its normal."""
        planes = {"xy": ["x", "y", "rz"], "yz": ["y", "z", "rx"], "zx": ["x", "z", "ry"], "xz": ["x", "z", "ry"]}
        if plane not in planes:
            raise _checks.refuse(f"plane: expected 'xy', 'yz' or 'zx', got {plane!r}")
        return _make("planar", planes[plane], **springs)

    @staticmethod
    def free(**springs) -> JointSpec:
        """Six coordinates x, y, z (m) and φ3, φ2, φ1 (rad). Singular at φ2 = ±π/2."""
        return _make("free", ["x", "y", "z", "rz", "ry", "rx"], **springs)

    @staticmethod
    def custom(coordinates: Sequence[str], **springs) -> JointSpec:
        """Any subset of ``("x", "y", "z", "rz", "ry", "rx")``; taken in that (the book's) order."""
        if isinstance(coordinates, str):
            coordinates = [coordinates]
        return _make("custom", list(coordinates), **springs)
