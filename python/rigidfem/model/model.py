"""Model (the mutable description) and System (the compiled, immutable system).

Build a Model body by body, then ``compile()`` it into a System whose methods
evaluate the book's equations of motion A(q) q̈ = f(q, q̇, t). SI units throughout.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from ..base import _checks, display
import rigidfem._core as _core  # the compiled core, by its absolute name
from . import force_elements, handles, joints, laws, loops, parameters, shapes
from ..base import persistence
from .motion import constant as _constant
from .._core import Body, JointSpec, Point, Profile
from .beams import add_beam
from .frames import transform  # noqa: F401 (re-exported: rigidfem.model.transform)
from ..base.persistence import recorded


def _inertia(inertia) -> np.ndarray:
    try:
        a = np.asarray(inertia, dtype=float)
    except (TypeError, ValueError):
        raise _checks.refuse(f"inertia: expected principal moments (3,) or a tensor (3, 3) in kg·m², got {inertia!r}") from None
    if a.shape == (3,):
        a = np.diag(a)
    if a.shape != (3, 3):
        raise _checks.refuse(
            f"inertia: expected principal moments (3,) or a tensor (3, 3) in kg·m², got shape {np.shape(inertia)}"
        )
    return _checks.reals(a, (3, 3), "inertia")


# A moving base's degrees of freedom: ship names and the free joint's coordinates (ZYX angles:
# yaw ψ = rz, pitch θ = ry, roll φ = rx), in the joint's order x, y, z, rz, ry, rx.
BASE_DOFS = {"surge": "x", "sway": "y", "heave": "z", "yaw": "rz", "pitch": "ry", "roll": "rx"}


def _base_profiles(motion) -> dict[str, Profile]:
    """The six profiles of a moving base, by coordinate name ("x" ... "rx"), from ``motion``: a
    dict of ship names or coordinate names to profiles or numbers; missing ones are held at 0."""
    if motion is None:
        motion = {}
    if not isinstance(motion, dict):
        raise _checks.refuse(f"motion: expected a dict of degrees of freedom to profiles, got {motion!r}")
    coordinate_of = {**BASE_DOFS, **{c: c for c in BASE_DOFS.values()}}
    out: dict[str, Profile] = {}
    for dof, value in motion.items():
        if dof not in coordinate_of:
            raise _checks.refuse(f"motion: expected keys from {list(BASE_DOFS)} or {list(BASE_DOFS.values())}, "
                             f"got {dof!r}")
        c = coordinate_of[dof]
        if c in out:
            raise _checks.refuse(f"motion: expected one motion per coordinate, got a second motion of coordinate {c!r} "
                                 f"from {dof!r}")
        if not isinstance(value, Profile):
            value = _constant(_checks.scalar(value, f"motion[{dof!r}]"))
        out[c] = value
    return {c: out[c] if c in out else _constant(0.0) for c in BASE_DOFS.values()}


def _scale(scale):
    if scale is not None and not isinstance(scale, Profile):
        raise _checks.refuse(f"scale: expected None or a profile from rigidfem.motion, got {scale!r}")
    return scale


class Model(_core._Model):
    """A multibody system under construction.

    Parameters
    ----------
    gravity : (3,) array or None
        Gravitational acceleration in m/s², global frame; ``None`` for none.
        Default ``(0, 0, -9.81)``.

    Bodies are added after their parents, so the compiled system has parent[p] < p.

    Examples
    --------
    >>> import rigidfem as rf
    >>> model = rf.Model()
    >>> link = model.add_body("link", model.ground, rf.Joint.revolute("y"), mass=1.0,
    ...                       inertia=(0.1, 0.1, 0.1), com=(0.0, 0.0, -0.5))
    >>> model.compile().coordinate_names
    ['link.ry']
    """

    def __init__(self, gravity=(0.0, 0.0, -9.81)):
        g = np.zeros(3) if gravity is None else _checks.reals(gravity, (3,), "gravity")
        super().__init__(g)
        self._gravity0, self._calls, self._building = np.array(g, dtype=float), [], False  # the recipe (pickling)
        self._parameter_groups = {}  # prefix -> parameters.Group: the named parameters the builders declared
        self._beams = []  # the Beam handles add_beam returned (the viewer draws them)
        self._names = set()  # the names of shapes and contacts (the others': bodies, parameters' groups)

    @property
    def gravity(self) -> np.ndarray:
        """Gravitational acceleration (3,) in m/s², global frame."""
        return _core._Model.gravity.fget(self)

    @gravity.setter
    def gravity(self, g) -> None:
        self._set_gravity(g)

    @recorded
    def _set_gravity(self, g) -> None:
        _core._Model.gravity.fset(self, _checks.reals(g, (3,), "gravity"))

    def __reduce__(self):
        """Pickled as its recipe (rigidfem.base.persistence): unpickling replays the builder calls."""
        return _model_from_state, (persistence.model_state(self),)

    @property
    def ground(self) -> Body:
        """The ground (global frame), parent of the first bodies."""
        return Body()

    def body(self, name: str) -> Body:
        """The handle of the body called ``name``.

        Examples
        --------
        >>> import rigidfem as rf
        >>> model = rf.Model()
        >>> link = model.add_body("link", model.ground, rf.Joint.revolute("y"), mass=1.0,
        ...                       inertia=(0.1, 0.1, 0.1), com=(0.0, 0.0, -0.5))
        >>> model.body("link").index == link.index
        True
        """
        if not isinstance(name, str):
            raise _checks.refuse(f"name: expected the name (str) of a body of this model or 'ground', got {name!r}")
        try:
            index = self._body_index(name)
        except ValueError:
            raise _checks.refuse(f"name: expected the name of a body of this model or 'ground', got {name!r}") from None
        return Body() if index < 0 else self._handle(index)

    def _handle(self, index: int) -> Body:
        return Body(index, self._body_name(index), self.id)

    def _owns(self, body: Body) -> bool:
        """Whether the handle names a body of this model (or the ground): made by this model, or,
        for a handle of unknown origin (built by hand), with the name of the body at its index."""
        if body.index == -1:
            return True
        if not 0 <= body.index < self.nbodies:
            return False
        return body.model == self.id if body.model else self._body_name(body.index) == body.name

    def _parent_index(self, parent) -> int:
        if isinstance(parent, Body):
            if not self._owns(parent):
                raise _checks.refuse(f"parent: expected a body of this model, got {parent!r}")
            return parent.index
        if isinstance(parent, str):
            return self._body_index(parent)
        raise _checks.refuse(f"parent: expected a Body handle or a body name, got {parent!r}")

    @recorded
    def add_body(
        self,
        name: str,
        parent,
        joint: JointSpec,
        mass: float,
        inertia,
        com=(0.0, 0.0, 0.0),
        placement=None,
    ) -> Body:
        """Add a rigid body hanging from ``parent`` through ``joint``.

        Parameters
        ----------
        name : str
            Unique name.
        parent : Body or str
            ``model.ground`` or an earlier body (handle or name).
        joint : JointSpec
            From ``rigidfem.Joint``: how the body moves relative to the joint frame.
        mass : float
            Mass in kg, positive.
        inertia : (3,) or (3, 3) array
            Principal moments (Ixx, Iyy, Izz) or the full tensor about the centre of
            mass in body axes, kg·m². Positive definite, triangle inequality.
        com : (3,) array
            Centre of mass in the body frame, m.
        placement : (4, 4) array, optional
            Pose of the joint frame in the parent's frame (``rigidfem.transform``);
            identity by default. The body frame is the joint frame moved by the joint.

        Examples
        --------
        >>> import rigidfem as rf
        >>> model = rf.Model()
        >>> link = model.add_body("link", model.ground, rf.Joint.revolute("y"), mass=1.0,
        ...                       inertia=(0.1, 0.1, 0.1), com=(0.0, 0.0, -0.5))
        >>> link
        <rigidfem Body 'link' #0>
        >>> model.compile().nq
        1
        """
        name = self._new_name(name)
        if not isinstance(joint, JointSpec):
            raise _checks.refuse(f"joint: expected a joint from rigidfem.Joint, got {joint!r}")
        B = np.eye(4) if placement is None else _checks.reals(placement, (4, 4), "placement")
        mass, com, inertia = _checks.real(mass, "mass", "a mass in kg"), _checks.reals(com, (3,), "com"), _inertia(inertia)
        body = self._add_body(name, self._parent_index(parent), joint, B, mass, com, inertia)
        parameters.register(self, parameters.BodyGroup(body.name, body.index, mass, com, inertia))
        self._declare_coordinates(body, joint)
        return body

    def _declare_coordinates(self, body: Body, joint: JointSpec) -> None:
        """The named parameters of each coordinate's own spring-damping law (stiffness, damping, force)."""
        info = laws.SpringDamping.info
        for slot, c in enumerate(joint.coordinates):
            values = {"stiffness": joint.stiffness[slot], "rest": joint.rest[slot], "damping": joint.damping[slot],
                      "force": 0.0}
            parameters.register(self, parameters.LawGroup(f"{body.name}.{c}", ("coordinate", body.index, slot, -1),
                                                          info, values, rotation=c.startswith("r")))

    def _coordinate(self, body: Body, coordinate: str | None) -> int:
        if not isinstance(body, Body) or body.index < 0 or not self._owns(body):
            raise _checks.refuse(f"body: expected a body of this model, got {body!r}")
        if coordinate is not None and not isinstance(coordinate, str):
            raise _checks.refuse(f"coordinate: expected None or a coordinate name such as 'x' or 'rz', got {coordinate!r}")
        return -1 if coordinate is None else self._coordinate_index(body.index, coordinate)

    @recorded
    def prescribe(self, body: Body, motion: Profile, coordinate: str | None = None) -> handles.Coordinate:
        """Drive a coordinate of ``body``'s joint by ``motion`` (``rigidfem.motion.*``).

        The coordinate leaves the unknowns q; ``System.driving_forces`` reports the
        force (N) or torque (N·m) the drive must exert. ``coordinate`` names it
        ("x", ..., "rx") when the joint has more than one. A coordinate takes one motion:
        prescribing it again is a ValueError. Returns the coordinate's handle ("<body>.<axis>", kind "drive"); the
        drive's numbers are the parameters ``"<body>.<axis>.drive.<path>"``.

        Examples
        --------
        >>> import rigidfem as rf
        >>> model = rf.Model()
        >>> link = model.add_body("link", model.ground, rf.Joint.revolute("y"), mass=1.0,
        ...                       inertia=(0.1, 0.1, 0.1), com=(0.0, 0.0, -0.5))
        >>> _ = model.prescribe(link, rf.motion.ramp(1.0, 0.0, 1.0))
        >>> system = model.compile()
        >>> system.nq, system.prescribed_names
        (0, ['link.ry'])
        """
        if not isinstance(motion, Profile):
            raise _checks.refuse(f"motion: expected a profile from rigidfem.motion, got {motion!r}")
        k = self._coordinate(body, coordinate)
        self._prescribe(body.index, k, motion)
        name = self._coordinate_name(body.index, k)
        parameters.register(self, parameters.ProfileGroup(f"{name}.drive", "drive", body.index, max(k, 0), motion,
                                                          "the drive's (m or rad, s, rad/s: rigidfem.motion)"))
        return handles.Coordinate(name, "drive", max(k, 0))

    @recorded
    def add_moving_base(self, name: str, motion=None, *, mass: float = 1e-6, inertia=(1e-6, 1e-6, 1e-6),
                        com=(0.0, 0.0, 0.0), placement=None) -> Body:
        """Add a base body moving with a prescribed 6-DOF motion; returns its ``Body``.

        The base hangs from the ground by ``Joint.free()``, T̃ = Trans(x, y, z) R3(ψ) R2(θ) R1(φ),
        whose six coordinates are all prescribed, so the bodies added on it feel its motion as a
        known base acceleration (both engines), and ``System.driving_forces`` reports the
        forces (N) and torques (N·m) that drive it.

        Parameters
        ----------
        name : str
            The base body's name.
        motion : dict
            Degree of freedom -> ``rigidfem.motion`` profile (or a number: held constant). Keys are
            ship names — ``"surge"`` x, ``"sway"`` y, ``"heave"`` z (m), ``"yaw"`` ψ = rz,
            ``"pitch"`` θ = ry, ``"roll"`` φ = rx (rad; ZYX angles) — or the coordinate names
            themselves. Missing ones are held at 0. ``rigidfem.sea.Waves.motion`` makes such a dict
            from a sea state.
        mass, inertia, com
            The base's own mass (kg, positive; default 1e-6, negligible), inertia (kg·m²) and
            centre of mass (m), as in ``add_body``; they only enter the driving forces.
        placement : (4, 4) array, optional
            Pose of the frame in which the motion is given (the base's rest pose), in the global
            frame; identity by default.

        Examples
        --------
        >>> import rigidfem as rf
        >>> model = rf.Model()
        >>> ship = model.add_moving_base("ship", {"heave": rf.motion.harmonic(0.5, 0.1)})
        >>> model.compile().prescribed_names
        ['ship.x', 'ship.y', 'ship.z', 'ship.rz', 'ship.ry', 'ship.rx']
        """
        profiles = _base_profiles(motion)
        base = self.add_body(name, self.ground, joints.Joint.free(), mass=mass, inertia=inertia, com=com,
                             placement=placement)
        for coordinate, profile in profiles.items():
            self.prescribe(base, profile, coordinate=coordinate)
        return base

    @recorded
    def add_generalized_force(
        self, body: Body, force: float | Callable[[float, float, float], float], coordinate: str | None = None
    ) -> handles.Coordinate:
        """Apply a generalised force (N or N·m) on a joint coordinate of ``body``; returns the coordinate's handle
        ("<body>.<axis>", kind "force").

        ``force`` is a constant or a Python function ``Q(t, q, qd)`` of that
        coordinate's own value and rate (slow path: called from C++ under the GIL). The
        function must return a finite number: anything else (None, a string, an array, NaN,
        inf) raises a ValueError naming the law, the coordinate, the value and the time where
        a System method calls it, and ``rigidfem.SimulationError`` at that time in a simulation
        (both are ``rigidfem._core.ForceLawError``). Exceptions the function raises propagate.

        Examples
        --------
        >>> import rigidfem as rf
        >>> model = rf.Model()
        >>> link = model.add_body("link", model.ground, rf.Joint.revolute("y"), mass=1.0,
        ...                       inertia=(0.1, 0.1, 0.1), com=(0.0, 0.0, -0.5))
        >>> _ = model.add_generalized_force(link, 1.0)
        >>> round(float(model.compile().forward_dynamics(0.0, [0.0], [0.0])[0]), 4)
        2.8571
        """
        k = self._coordinate(body, coordinate)
        if callable(force):
            self._add_generalized_force(body.index, k, 0.0, force)
        else:
            value = _checks.scalar(force, "force")
            self._add_generalized_force(body.index, k, value, None)
            group = self._parameter_groups.get(self._coordinate_name(body.index, k))
            if group is not None:  # the total constant force on the coordinate
                parameters.register(self, group.with_values(force=group.values["force"] + value))
        return handles.Coordinate(self._coordinate_name(body.index, k), "force", max(k, 0))

    @recorded
    def add_maxwell_arm(self, body: Body, stiffness: float, tau: float,
                        coordinate: str | None = None) -> handles.Coordinate:
        """Add a Maxwell arm — a spring ``stiffness`` k (N/m or N·m/rad) in series with a dashpot k τ
        (``tau``: the relaxation time, s) — on a free joint coordinate of ``body``, in parallel with
        its spring and damper: the standard linear solid (Zener) with one arm, a generalised Maxwell
        model (Prony series) with several.

        The arm's force s (N or N·m) is an internal variable of the state, ṡ = k q̇ − s/τ, acting as
        Q = −s on the coordinate; it stores s²/(2k) and dissipates s²/(kτ). A mode of the joint's
        stiffness c with one arm has its eigenvalues at the roots of (1 + λτ)(m λ² + c) + k τ λ = 0.
        ``rigidfem.simulate`` integrates s (initial value ``s0``, zero by default) and returns it
        as ``Result.arm_forces``; ``rigidfem.Material(prony=...)`` puts arms in every sde of a beam. Returns the
        coordinate's handle ("<body>.<axis>", kind "arm").

        Examples
        --------
        >>> import rigidfem as rf
        >>> model = rf.Model(gravity=None)
        >>> block = model.add_body("block", model.ground, rf.Joint.prismatic("x", stiffness=100.0), mass=1.0,
        ...                        inertia=(1e-3,) * 3)
        >>> _ = model.add_maxwell_arm(block, 50.0, 0.1)
        >>> res = rf.simulate(model.compile(), 0.1, q0=[0.01])
        >>> res.arm_forces.shape[1]
        1
        """
        k = self._coordinate(body, coordinate)
        stiffness = _checks.real(stiffness, "stiffness", "an arm stiffness in N/m or N·m/rad")
        tau = _checks.real(tau, "tau", "a relaxation time in s")
        self._add_maxwell_arms([body.index], [k], [stiffness], [tau])
        return handles.Coordinate(self._coordinate_name(body.index, k), "arm", max(k, 0))

    @recorded
    def add_force(self, name: str, point, force, *, follower: bool = False,
                  scale: Profile | None = None) -> handles.Load:
        """Apply a point force (N) at ``point`` (a ``Point`` or a ``Body``'s origin).

        ``force`` has global components, or body components turning with the body
        when ``follower=True``. ``scale`` (a ``rigidfem.motion`` profile) multiplies
        it by its value q(t). ``name`` (new among the model's names) names its parameter
        ``"<name>.force"``, its magnitude (``System.parameters``). Returns its handle.

        Examples
        --------
        >>> import rigidfem as rf
        >>> model = rf.Model()
        >>> link = model.add_body("link", model.ground, rf.Joint.revolute("y"), mass=1.0,
        ...                       inertia=(0.1, 0.1, 0.1), com=(0.0, 0.0, -0.5))
        >>> load = model.add_force("push", link.point((0.0, 0.0, -1.0)), (1.0, 0.0, 0.0))
        >>> system = model.compile()
        >>> round(float(system.forward_dynamics(0.0, [0.0], [0.0])[0]), 4)
        -2.8571
        """
        name = self._new_name(name)
        p = self._point(point)
        return self._load(name, "force", p.body, p.r, _checks.reals(force, (3,), "force"), np.zeros(3), follower,
                          scale)

    @recorded
    def add_torque(self, name: str, body: Body, torque, *, follower: bool = False,
                   scale: Profile | None = None) -> handles.Load:
        """Apply a torque (N·m) on ``body``: global components, or body ones if ``follower``. ``name`` names its
        parameter ``"<name>.torque"``, its magnitude. Returns its handle.

        Examples
        --------
        >>> import rigidfem as rf
        >>> model = rf.Model()
        >>> link = model.add_body("link", model.ground, rf.Joint.revolute("y"), mass=1.0,
        ...                       inertia=(0.1, 0.1, 0.1), com=(0.0, 0.0, -0.5))
        >>> _ = model.add_torque("motor", link, (0.0, 2.0, 0.0))
        >>> round(float(model.compile().forward_dynamics(0.0, [0.0], [0.0])[0]), 4)
        5.7143
        """
        name = self._new_name(name)
        p = self._point(body)
        return self._load(name, "torque", p.body, np.zeros(3), np.zeros(3), _checks.reals(torque, (3,), "torque"), follower,
                          scale)

    def _load(self, name, kind, body, r, force, torque, follower, scale) -> handles.Load:
        self._add_load(body, r, force, torque, _checks.boolean(follower, "follower"), _scale(scale))
        parameters.register(self, parameters.LoadGroup(name, self._nloads - 1, force, torque))
        if scale is not None:
            parameters.register(self, parameters.ProfileGroup(f"{name}.scale", "load", -1, self._nloads - 1, scale,
                                                              "the scale's (rigidfem.motion)"))
        return handles.Load(name, kind, self._nloads - 1)

    def _new_name(self, name) -> str:
        """``name`` if it is a non-empty str not yet given to a body (an rfe included), coordinate, load, element,
        law, shape or contact (the names of the bodies, of the parameters' groups, of the shapes and contacts); whether
        a loop's or an element's name is new among its kind is judged by the core."""
        name = _checks.name(name)
        try:
            taken = name in self._parameter_groups or name in self._names or self._body_index(name) >= -1  # -1: ground
        except ValueError:  # not a body's name
            taken = False
        if taken:
            raise _checks.refuse(f"name: expected a name not yet given to a body, coordinate, load, element, law, shape "
                                 f"or contact, got {name!r}")
        return name

    def _point(self, point) -> Point:
        if isinstance(point, Body):
            if not self._owns(point):
                raise _checks.refuse(f"point: expected a Point or Body of this model, got {point!r}")
            point = point.origin
        if not isinstance(point, Point) or not 0 <= point.body < self.nbodies or point.model not in (0, self.id):
            raise _checks.refuse(f"point: expected a Point or Body of this model, got {point!r}")
        return point

    @recorded
    def add_loop_joint(self, name: str, kind: str, a, b, *, frame_a=None, frame_b=None,
                       length: float | None = None) -> handles.Loop:
        """Close a kinematic loop: a joint of ``kind`` between ``a`` and ``b`` (book ch. 2.6).

        Parameters
        ----------
        name : str
            Names its reaction in ``System.loop_names`` (new among the loops' names).
        kind : str
            One of ``rigidfem.loops.KINDS`` ("revolute", "spherical", "universal", "prismatic",
            "cylindrical", "fixed", "planar", "distance": ``rigidfem.loops`` tabulates what each leaves
            free; axes are those of frame A, z for revolute, prismatic, cylindrical and planar joints).
        a, b : Body, Point or ``model.ground``
            The two bodies (rigid bodies or rfes of a beam). A Point places the joint frame at
            that point with the body's axes; a Body at its frame.
        frame_a, frame_b : (4, 4) array, optional
            Pose of the joint frame in the body's frame (``rigidfem.transform``), for a Body.
            Frames A and B coincide when the loop is closed (distance: their origins are
            ``length`` apart).
        length : float
            m, distance loops only.

        Returns the loop's handle. The initial coordinates of a simulation must close every loop:
        ``System.assemble`` finds them from a guess.

        Examples
        --------
        >>> import rigidfem as rf
        >>> model, h = rf.samples.four_bar()
        >>> system = model.compile()
        >>> system.loop_names, system.nq
        (['C'], 3)
        """
        name = loops.add_loop_joint(self, self._new_name(name), kind, a, b, frame_a=frame_a, frame_b=frame_b,
                                    length=length)
        return handles.Loop(name, kind, self._nloops - 1)

    @recorded
    def add_actuator(self, name: str, a, b, length) -> handles.Loop:
        """A linear actuator (hydraulic cylinder under position control) between the points ``a``
        and ``b`` (Point or Body): their distance is held at ``length`` (m), a number or a
        ``rigidfem.motion`` profile l(t). Its force (N, positive pushing the points apart) is the
        loop's reaction, column 0 of ``System.loop_reactions``; ``name`` names it in ``System.loop_names``. Returns its
        handle.

        Examples
        --------
        >>> import rigidfem as rf
        >>> model = rf.Model(gravity=None)
        >>> arm = model.add_body("arm", model.ground, rf.Joint.revolute("y"), mass=1.0, inertia=(0.1,) * 3,
        ...                      com=(0.5, 0.0, 0.0))
        >>> _ = model.add_actuator("jack", model.ground.point((0.0, 0.0, -0.5)), arm.point((0.5, 0.0, 0.0)), 0.7)
        >>> system = model.compile()
        >>> system.loop_names
        ['jack']
        """
        return handles.Loop(loops.add_actuator(self, self._new_name(name), a, b, length), "actuator", self._nloops - 1)

    @recorded
    def add_force_element(self, name: str, a, b, law) -> handles.Element:
        """A force element of ``law`` (``rigidfem.laws``: ``SpringDamper``, ``Rope``, ...) between the points ``a``
        and ``b`` (Point, Body or ``model.ground``; rigid bodies or rfes of a beam), acting along the line between
        them with the law's axial force F(t, l, l̇) (N, > 0 pushing the points apart). No constraint: it acts on
        trees and closed chains alike (``rigidfem.model.force_elements``). Its constants marked as parameters become
        ``"<name>.<constant>"`` (``System.parameters``); ``System.element_names`` lists ``name``. Returns its handle.

        Examples
        --------
        >>> import rigidfem as rf
        >>> model = rf.Model(gravity=None)
        >>> block = model.add_body("block", model.ground, rf.Joint.prismatic("x"), mass=2.0, inertia=(1e-3,) * 3)
        >>> _ = model.add_force_element("s", model.ground, block, rf.laws.SpringDamper(stiffness=50.0, length=0.0))
        >>> round(float(model.compile().forward_dynamics(0.0, [0.1], [0.0])[0]), 4)
        -2.5
        """
        return force_elements.add_force_element(self, self._new_name(name), a, b, law)

    @recorded
    def add_spring_damper(self, name: str, a, b, *, stiffness: float, length: float,
                          damping: float = 0.0) -> handles.Element:
        """A linear spring-damper between the points ``a`` and ``b`` (Point, Body or
        ``model.ground``; rigid bodies or rfes of a beam): axial force
        F = −k (l − l₀) − c l̇ (N, > 0 pushing the points apart) with ``stiffness`` k (N/m),
        rest ``length`` l₀ (m) and ``damping`` c (N·s/m): ``add_force_element(name, a, b,
        rf.laws.SpringDamper(stiffness=k, length=l₀, damping=c))``. ``System.element_names`` lists ``name``. Returns
        its handle.

        Examples
        --------
        >>> import rigidfem as rf
        >>> model = rf.Model(gravity=None)
        >>> block = model.add_body("block", model.ground, rf.Joint.prismatic("x"), mass=2.0, inertia=(1e-3,) * 3)
        >>> _ = model.add_spring_damper("s", model.ground, block, stiffness=50.0, length=0.0, damping=1.0)
        >>> modes = rf.modal_analysis(model.compile(), [0.1])
        >>> modes.omega.round(3)
        array([5.])
        """
        name = self._new_name(name)
        force_elements.points(self, a, b)  # named before the law's constants
        law = laws.SpringDamper(stiffness=stiffness, length=length, damping=damping)
        return force_elements.add_force_element(self, name, a, b, law)

    @recorded
    def add_cylinder(self, name: str, a, b, force, *, damping: float = 0.0) -> handles.Element:
        """A hydraulic cylinder under force control between the points ``a`` and ``b``: it pushes
        them apart with ``force`` (N; negative pulls) — a number, a ``rigidfem.motion`` profile
        F(t) or a Python function ``force(t, l, ld)`` of time (s), length (m) and its rate (m/s)
        (the slow path: called under the GIL at every evaluation) — less its ``damping`` c l̇
        (N·s/m): a ``rf.laws.SpringDamper`` without a spring. Position control is ``add_actuator``. Returns its
        handle; ``System.element_states`` and ``Result.element_forces`` give its force.

        Examples
        --------
        >>> import rigidfem as rf
        >>> model = rf.Model(gravity=None)
        >>> block = model.add_body("block", model.ground, rf.Joint.prismatic("x"), mass=2.0, inertia=(1e-3,) * 3)
        >>> _ = model.add_cylinder("jack", model.ground, block, 10.0)
        >>> round(float(model.compile().forward_dynamics(0.0, [0.5], [0.0])[0]), 4)
        5.0
        """
        name = self._new_name(name)
        force_elements.points(self, a, b)  # named before the law's constants
        law = laws.SpringDamper(damping=damping, **force_elements.cylinder_force(force))
        return force_elements.add_force_element(self, name, a, b, law)

    @recorded
    def add_rope(self, name: str, a, b, *, EA: float, length, DA: float = 0.0, drum=None,
                 radius: float | None = None, mass_per_length: float = 0.0) -> handles.Element:
        """A rope between the points ``a`` and ``b`` (book ch. 7.1: a hoisting rope): it
        only pulls, with the tension T = (EA (l − l_u) + DA (l̇ − l̇_u))/l_u while positive, 0 when
        slack. ``EA`` (N) is its axial stiffness, ``DA`` (N·s) its axial damping, and ``length`` its unstretched
        length l_u (m): a number or a ``rigidfem.motion`` profile l_u(t) paid out by a winch
        (``rf.laws.Rope``). Returns its handle; ``System.element_states`` gives its force F = −T (N).

        ``mass_per_length`` μ (kg per m of unstretched rope; 0, massless, by default) gives its free span the weight
        μ l_u g, half on each point, taken as a straight span: its potential −½ μ l_u g·(r_a + r_b). Wound on a drum,
        the rope the drum pays out, μ r φ, is taken from the drum's weight at the point ``a`` where it leaves (give
        the drum's body the mass it has at φ = 0), and the drum takes the span's pull ½ μ g·(r_b − r_a) besides the
        rope's: a load hanging on l_u of rope holds the drum with r (m + μ l_u) g, as the continuum does. The span's
        kinetic energy is not modelled (its weight is): the whole rope moving at the drum's surface speed adds μ L r²
        to the drum's inertia, which its body may hold.

        ``drum`` winds it on a drum of ``radius`` r (m): a body whose joint's rotation φ (rad; its only coordinate,
        or ``(body, "ry")`` to name one) pays it out, l_u = ``length`` + r φ. (A translation x pays out r x: a
        linear winch, r then a ratio.) Its coordinate may be free (the drum's
        inertia, driven by a torque or a law of the state: ``add_torque``, ``add_joint_law``) or prescribed (a speed:
        ``prescribe``). The drum takes the generalised force r P, P = T + ½ EA ε² while taut (ε = (l − l_u)/l_u):
        −∂/∂(r φ) of the energy the rope stores and dissipates, so that the energy balance holds to the last term.
        The point ``a`` is where the rope leaves the drum (or a sheave it runs over), fixed on ``a``'s body.

        Examples
        --------
        >>> import rigidfem as rf
        >>> model = rf.Model()
        >>> load = model.add_body("load", model.ground, rf.Joint.prismatic("z"), mass=10.0, inertia=(1e-3,) * 3)
        >>> _ = model.add_rope("rope", model.ground.point((0.0, 0.0, 2.0)), load, EA=1e5, length=2.0)
        >>> eq = rf.static_equilibrium(model.compile(), [-0.01])
        >>> round(float(eq.q[0]), 6)
        -0.001962
        """
        name = self._new_name(name)
        force_elements.points(self, a, b)  # named before the law's constants
        wound = None
        if drum is not None or radius is not None:
            body, coordinate = drum if isinstance(drum, tuple) and len(drum) == 2 else (drum, None)
            if not isinstance(body, Body) or body.index < 0 or not self._owns(body):
                raise _checks.refuse(f"drum: expected a body of this model whose joint's rotation pays the rope out, "
                                     f"or (body, coordinate), got {drum!r}")
            k = self._coordinate(body, coordinate)
            self._coordinate_name(body.index, k)  # a joint of several coordinates needs one named: judged before adding
            r = _checks.real(radius, "radius", "a positive drum radius in m")
            if not (r > 0.0 and math.isfinite(r)):
                raise _checks.refuse(f"radius: expected a positive finite drum radius in m, got {radius!r}")
            if isinstance(length, Profile):
                raise _checks.refuse(f"length: expected a number l0 in m for a rope wound on a drum (the drum pays it "
                                     f"out: l_u = l0 + r phi), got {length!r}")
            wound = (body.index, k, r)
        law = laws.Rope(EA=EA, DA=DA, mass_per_length=mass_per_length, **force_elements.unstretched(length))
        handle = force_elements.add_force_element(self, name, a, b, law)
        if wound is not None:
            self._wind(handle.index, *wound)
        return handle

    @recorded
    def add_sheave(self, name: str, into: handles.Element, out_of: handles.Element, *, mu: float, wrap: float,
                   mass: float = 1.0, smoothing: float = 1e-3) -> Body:
        """A rope running over a fixed sheave (or a bollard, a capstan) with friction: the ropes ``into`` and
        ``out_of`` (``add_rope`` handles, the two spans on either side, each at its own constant length or on its
        drum) exchange rope through a slip coordinate u (m, the coordinate ``"<name>.rz"``): l_u of ``into`` gains u,
        that of ``out_of`` loses it. The rope slips towards the side that pulls harder once the tensions' ratio reaches
        Euler's e^{μθ} (``mu`` μ, ``wrap`` θ in rad), regularised over the slip speed ``smoothing`` v_ε (m/s): the
        slip takes P_into − P_out e^{μθ tanh(u̇/v_ε)}, so below that ratio the rope creeps at about v_ε and at it slides.
        ``mass`` (kg) is the rope's mass that slips, the slip's inertia (a small one keeps u an ordinary coordinate:
        ``"<name>"`` is a point mass 1 m from an axis along gravity, turning about it: u in rad = m of rope, and
        gravity does no work on it; its named parameter ``"<name>.mass"`` sets that inertia). The friction's power is
        in ``dissipated_power``. Returns the body.

        Examples
        --------
        >>> import rigidfem as rf
        >>> model = rf.Model()
        >>> heavy = model.add_body("heavy", model.ground, rf.Joint.prismatic("z"), 30.0, (1.0, 1.0, 1.0),
        ...                        placement=rf.transform((-0.5, 0.0, 0.0)))
        >>> light = model.add_body("light", model.ground, rf.Joint.prismatic("z"), 10.0, (1.0, 1.0, 1.0),
        ...                        placement=rf.transform((0.5, 0.0, 0.0)))
        >>> left = model.add_rope("left", model.ground.point((-0.5, 0.0, 5.0)), heavy, EA=1e8, length=5.0)
        >>> right = model.add_rope("right", model.ground.point((0.5, 0.0, 5.0)), light, EA=1e8, length=5.0)
        >>> _ = model.add_sheave("sheave", left, right, mu=0.3, wrap=3.14, mass=0.1)
        >>> model.compile().coordinate_names
        ['heavy.z', 'light.z', 'sheave.rz']
        """
        name = self._new_name(name)
        ropes = []
        for argument, rope in (("into", into), ("out_of", out_of)):
            if not (isinstance(rope, handles.Element) and self._owns_element(rope) and
                    self._element_law(rope.index)[0] == "Rope"):
                raise _checks.refuse(f"{argument}: expected a rope of this model (Model.add_rope's handle), got {rope!r}")
            if f"{rope}.length" in self._parameter_groups:  # its unstretched length a winch's profile
                raise _checks.refuse(f"{argument}: expected a rope of constant unstretched length (a sheave passes rope "
                                     f"from one span to the other), got {rope!r}, paid out by a winch's profile")
            ropes.append(rope)
        if ropes[0].index == ropes[1].index:
            raise _checks.refuse(f"out_of: expected a rope other than into, got {out_of!r} twice")
        mu_ = _checks.real(mu, "mu", "a friction coefficient >= 0")
        wrap_ = _checks.real(wrap, "wrap", "a wrap angle in rad >= 0")
        for argument, value in (("mu", mu_), ("wrap", wrap_)):
            if not (value >= 0.0 and math.isfinite(value)):
                raise _checks.refuse(f"{argument}: expected a finite number >= 0, got {value!r}")
        m = _checks.real(mass, "mass", "the slipping rope's mass in kg")
        if not (m > 0.0 and math.isfinite(m)):
            raise _checks.refuse(f"mass: expected a positive finite mass in kg (the slip's inertia), got {mass!r}")
        v = _checks.real(smoothing, "smoothing", "a regularising slip speed in m/s")
        if not (v > 0.0 and math.isfinite(v)):
            raise _checks.refuse(f"smoothing: expected a positive finite slip speed in m/s, got {smoothing!r}")
        # a point mass (its own inertia a millionth of m r²) 1 m from an axis along gravity: I = m (1 + 1e-6) kg·m²
        axis = -self._gravity0 / np.linalg.norm(self._gravity0) if np.any(self._gravity0) else np.array([0.0, 0.0, 1.0])
        x = np.cross(axis, [1.0, 0.0, 0.0] if abs(axis[0]) < 0.9 else [0.0, 1.0, 0.0])
        x /= np.linalg.norm(x)
        frame = np.eye(4)
        frame[:3, :3] = np.column_stack([x, np.cross(axis, x), axis])
        slip = self.add_body(name, self.ground, joints.Joint.revolute("z"), m, (1e-6 * m,) * 3, com=(1.0, 0.0, 0.0),
                             placement=frame)
        self._wind(ropes[0].index, slip.index, -1, 1.0)
        self._wind(ropes[1].index, slip.index, -1, -1.0, mu_ * wrap_, v)
        return slip

    def _owns_element(self, handle) -> bool:
        """Whether ``handle`` names a force element of this model."""
        group = self._parameter_groups.get(str(handle))
        return isinstance(group, parameters.LawGroup) and group.target == ("element", handle.index)

    @recorded
    def add_shape(self, name: str, body, shape) -> handles.Shape:
        """Fix a shape (``rigidfem.shapes``: ``Sphere``, ``Capsule``, ``Box``, ``HalfSpace``) on ``body`` (a Body or
        ``model.ground``), or one capsule on each rigid finite element of a beam (``body`` a ``Beam``, ``shape``
        ``rigidfem.shapes.Capsules()``: the shapes ``"<name>[k]"``). Lengths in m, in the body's frame. Shapes touch
        only through ``add_contact``. Returns the shape's handle (``.shapes``: the indices of its shapes).

        Examples
        --------
        >>> import rigidfem as rf
        >>> model = rf.Model()
        >>> ball = model.add_body("ball", model.ground, rf.Joint.prismatic("z"), mass=0.1, inertia=(1e-5,) * 3)
        >>> shape = model.add_shape("sphere", ball, rf.shapes.Sphere(0.05))
        >>> shape.shapes
        (0,)
        """
        handle = shapes.add_shape(self, self._new_name(name), body, shape)
        self._names.add(handle.name)
        return handle

    @recorded
    def add_contact(self, name: str, a, b, law) -> handles.Contact:
        """Make the shapes ``a`` and ``b`` (handles from ``add_shape``, or lists of them) push each other apart where
        they overlap, by the compliant ``law`` (``rigidfem.laws.Contact``: a normal force of the penetration with
        Hunt–Crossley dissipation set by a coefficient of restitution, and regularised Coulomb friction with a
        Stribeck fall). Every shape of ``a`` meets every shape of ``b`` (none on one body): spheres and capsules each
        other and half-spaces, boxes half-spaces only. A half-space against n shapes costs O(n) an evaluation; a
        model without contacts pays nothing. The law's stiffness, restitution, mu_s and mu_k become the named parameters
        ``"<name>.stiffness"``, ... (``System.parameters``). Returns the contact's handle.

        Examples
        --------
        >>> import rigidfem as rf
        >>> model = rf.Model()
        >>> ball = model.add_body("ball", model.ground, rf.Joint.prismatic("z"), mass=0.1, inertia=(1e-5,) * 3)
        >>> b = model.add_shape("sphere", ball, rf.shapes.Sphere(0.05))
        >>> floor = model.add_shape("floor", model.ground, rf.shapes.HalfSpace())
        >>> _ = model.add_contact("hit", b, floor, rf.laws.Contact(stiffness=1e5, restitution=0.8))
        >>> model.compile().contact_names
        ['hit']
        """
        name = self._new_name(name)
        if not isinstance(law, laws.Law) or law.info["acts_on"] != "contact":
            raise _checks.refuse(f"law: expected a contact law (Contact from rigidfem.laws), got {law!r}")
        index = self._add_contact(name, shapes.shape_indices(self, a, "a"), shapes.shape_indices(self, b, "b"),
                                  law.kind, law.values)
        self._names.add(name)
        parameters.register(self, parameters.LawGroup(name, ("contact", index), law.info, law.values))
        return handles.Contact(name, law.kind, index)

    @recorded
    def add_joint_law(self, name: str, body: Body, law, coordinate: str | None = None) -> handles.JointLaw:
        """A law of a joint coordinate (``rigidfem.laws``: ``Friction``, ``ForceFunction``) on the coordinate
        ``coordinate`` ("x", ..., "rx"; None: the joint's only one) of ``body``'s joint, adding its generalised
        force Q(t, q, q̇) (N or N·m) to the coordinate's own spring-damping law. Its constants marked as parameters
        become ``"<name>.<constant>"`` (``System.parameters``, in the coordinate's units: N or N·m for a rotation's
        forces). Returns its handle.

        Examples
        --------
        >>> import rigidfem as rf
        >>> model = rf.Model(gravity=None)
        >>> block = model.add_body("block", model.ground, rf.Joint.prismatic("x"), mass=2.0, inertia=(1e-3,) * 3)
        >>> _ = model.add_joint_law("friction", block, rf.laws.Friction(breakaway=3.0, coulomb=2.0))
        >>> model.compile().nq
        1
        """
        name = self._new_name(name)
        if not isinstance(law, laws.Law) or law.info["acts_on"] != "coordinate" or not law.info["addable"]:
            kinds = [k for k, i in laws.kinds().items() if i["acts_on"] == "coordinate" and i["addable"]]
            raise _checks.refuse(f"law: expected a law of a joint coordinate ({', '.join(kinds)} from rigidfem.laws), "
                             f"got {law!r}")
        k = self._coordinate(body, coordinate)
        axis = self._coordinate_name(body.index, k)
        index = self._add_coordinate_law(body.index, k, law.kind, law.values, law.function)
        group = parameters.LawGroup(name, ("coordinate", body.index, max(k, 0), index), law.info, law.values,
                                    rotation=axis.rsplit(".", 1)[1].startswith("r"))
        parameters.register(self, group)
        return handles.JointLaw(group.prefix, law.kind, index)

    @recorded
    def add_beam(self, name: str, parent, length, material, section, elements: int,
                 formulation: str = "modified", deform=None, linear: bool = False, joint=None, placement=None,
                 tip_mass: float = 0.0, tip_inertia=(0.0, 0.0, 0.0), tip_offset=(0.0, 0.0, 0.0)):
        """Add a flexible beam divided into ``elements`` sdes and ``elements + 1`` rfes.

        Parameters
        ----------
        name : str
            The rfes are named ``name.rfe0`` ... ``name.rfe<m>``.
        parent : Body or str
            What the beam's first rfe hangs from.
        length : float or rigidfem.motion profile
            L, m; the beam lies along the x axis of its frame. A profile L(t) makes a link of
            varying free length sliding out of (L̇ > 0) or into its guide, the beam's frame
            (the equations in ``cpp/include/rigidfem/flows.hpp``: uniform beams without axial deformation, tip mass or the
            linear model).
        material : Material, function of s, or list of m
            ``rigidfem.Material`` (constant), a function of the arc length s (m), or one
            per segment (stepped beams).
        section : Section, function of s, or list of m
            ``rigidfem.Section``, likewise (tapered beams).
        elements : int
            1 <= m <= 100 000 (``rigidfem.model.beams.MAX_ELEMENTS``), the number of sdes (primary division).
        formulation : "classical" or "modified"
            Classical: rfes with up to 6 relative coordinates (axial, shear, torsion,
            bending); modified: spherical joints, 3 rotations at most.
        deform : sequence of str
            Deformations given coordinates, from ``axial, shear_y, shear_z, torsion,
            bend_y, bend_z`` (modified: the last three only); the rest are rigid.
            Default: all the formulation allows. ``bend_z`` bends in the x–y plane.
        linear : bool
            The book's linear model: each sde's relative transformation is linearised to
            first order in its coordinates (sin φ ≈ φ, cos φ ≈ 1, products dropped:
            T̃ = [[1 + S(φ1, φ2, φ3), (x, y, z)], [0, 1]]); the equations are then
            derived exactly from these transformations, and the beam's rigid motion
            (its joint on the parent) stays exact. Loses geometric stiffening.
        joint : JointSpec
            How rfe 0 sits on the parent; default ``Joint.fixed()`` (clamped root).
        placement : (4, 4) array
            Pose of that joint's frame on the parent.
        tip_mass, tip_inertia, tip_offset
            A concentrated body (kg; kg·m² about its c.o.m.; offset in m of its c.o.m.
            from the tip, beam axes) merged into the last rfe.

        Returns
        -------
        Beam
            Handle with ``tip``, ``point(s)``, ``rfes``, ``centerline(system, q)``, and
            the rfe/sde parameters ``rfe`` and ``sde``.

        Examples
        --------
        >>> import rigidfem as rf
        >>> model = rf.Model()
        >>> beam = model.add_beam("beam", model.ground, 1.0, rf.Material(E=2.1e11, rho=7850.0),
        ...                       rf.Section.rectangle(0.02, 0.005), 4, deform="bend_z")
        >>> model.compile().coordinate_names
        ['beam.rfe1.rz', 'beam.rfe2.rz', 'beam.rfe3.rz', 'beam.rfe4.rz']
        """
        beam = add_beam(self, name, parent, length, material, section, elements, formulation, deform, linear,
                        joint, placement, tip_mass, tip_inertia, tip_offset)
        self._beams.append(beam)
        return beam

    @classmethod
    def from_urdf(cls, path, flexible: dict | None = None, *, base: str = "fixed",
                  gravity=(0.0, 0.0, -9.81), package_dirs=None) -> Model:
        """A robot from its URDF file: links as bodies, joints as joints, and the links named in ``flexible`` as
        beams (``rigidfem.model.urdf`` says how each element of the file is read).

        Parameters
        ----------
        path : str or os.PathLike
            The URDF file (XML; an xacro file must be expanded first).
        flexible : dict, optional
            Link name -> a dict of ``add_beam``'s arguments for the beam that replaces it: ``elements``,
            ``material``, ``section`` (required), ``formulation``, ``deform``, ``linear``, ``tip_mass``,
            ``tip_inertia``, ``tip_offset``; ``to`` (the child joint at the beam's end; default the farthest)
            and ``match_mass`` (True: the density set so the beam has the link's mass in the file). The beam
            runs from the link's joint frame to that joint's origin, its x axis along the link and its z axis
            along the joint's axis (``bend_z`` bends it in the plane the joint turns in). Its mass and inertia
            are the material's and section's: the file's inertial of that link is dropped.
        base : "fixed" or "free"
            The root link fixed to the ground (default; as Pinocchio's ``buildModelFromUrdf`` without a root
            joint), or joined to it by ``Joint.free()`` (six coordinates: x, y, z in m, ZYX angles in rad).
        gravity : (3,) array or None
            m/s², global frame, as ``Model(gravity=...)``.
        package_dirs : str, os.PathLike, a sequence of them, or a dict, optional
            Where ``package://pkg/...`` mesh files are looked for: folders holding packages (``<folder>/pkg/...``,
            or ``<folder>/...`` for a folder named pkg), or a dict of package name -> its folder; then the URDF's
            folder and those above it. The viewer draws the meshes found (STL and Collada .dae) and the visuals'
            boxes, cylinders and spheres; a mesh file not found or not read is a note in ``model.urdf.notes``.

        Returns
        -------
        Model
            Bodies named after their links (a flexible link's rfes ``<link>.rfe0 ...``), coordinates in the
            file's depth-first order of links; ``model.urdf`` (``rigidfem.model.urdf.UrdfModel``) maps the file's
            links and joints to bodies, frames and coordinate names and lists what was not used (joint limits
            are not enforced).

        Examples
        --------
        >>> import pathlib, tempfile
        >>> import rigidfem as rf
        >>> urdf = '''<robot name="arm">
        ...   <link name="base"/>
        ...   <joint name="shoulder" type="revolute"><parent link="base"/><child link="arm"/>
        ...     <axis xyz="0 0 1"/></joint>
        ...   <link name="arm"><inertial><origin xyz="0.5 0 0"/><mass value="2"/>
        ...     <inertia ixx="0.01" iyy="0.2" izz="0.2" ixy="0" ixz="0" iyz="0"/></inertial></link>
        ...   <joint name="elbow" type="revolute"><parent link="arm"/><child link="hand"/>
        ...     <origin xyz="1 0 0"/><axis xyz="0 0 1"/></joint>
        ...   <link name="hand"><inertial><mass value="0.5"/>
        ...     <inertia ixx="1e-3" iyy="1e-3" izz="1e-3" ixy="0" ixz="0" iyz="0"/></inertial></link>
        ... </robot>'''
        >>> path = pathlib.Path(tempfile.mkdtemp()) / "arm.urdf"
        >>> _ = path.write_text(urdf)
        >>> steel = rf.Material(E=2.1e11, rho=7850.0)
        >>> model = rf.Model.from_urdf(path, flexible={"arm": dict(elements=4, material=steel,
        ...                                                        section=rf.Section.tube(0.05, 0.04))})
        >>> model.urdf.coordinates
        {'shoulder': ('arm.rfe0.rz',), 'elbow': ('hand.rz',)}
        >>> model.compile().nq
        14
        """
        from . import urdf

        model = cls(gravity=gravity)
        model._keep_urdf(urdf.from_urdf(model, path, flexible, base, package_dirs))
        return model

    @recorded
    def _keep_urdf(self, description) -> None:
        """Keep what ``from_urdf`` made of the file (recorded, so a pickled model keeps it)."""
        self._urdf = description

    @property
    def urdf(self):
        """What ``Model.from_urdf`` made of its file (``rigidfem.model.urdf.UrdfModel``: the links' bodies and
        frames, the joints' coordinates, the flexible links' beams, the visuals, notes); None for a model built
        in code."""
        return getattr(self, "_urdf", None)

    def compile(self, algorithm: str = "recursive") -> System:
        """Freeze the model into an immutable ``System``.

        ``algorithm``: "recursive" (default; O(n) forward dynamics by the articulated-body
        algorithm, RNEA and CRBA for the right-hand side and mass matrix) or "lagrange" (the
        book's formulation, kept as the reference). Systems with linear joints (the linear
        beam model) always use Lagrange.

        Examples
        --------
        >>> import rigidfem as rf
        >>> model = rf.Model()
        >>> link = model.add_body("link", model.ground, rf.Joint.revolute("y"), mass=1.0,
        ...                       inertia=(0.1, 0.1, 0.1), com=(0.0, 0.0, -0.5))
        >>> system = model.compile()
        >>> system
        <rigidfem System: 1 bodies, nq=1, 0 prescribed>
        >>> model.compile("lagrange").algorithm
        'lagrange'
        """
        return System(self, algorithm)

    def _repr_html_(self) -> str:
        """Notebook display: bodies, parents, joints, coordinates, beams, loops (``rigidfem.display``)."""
        return display.model_html(self)


class System(_core._System):
    """A compiled multibody system: the book's A(q) q̈ = f(q, q̇, t).

    q holds the free joint coordinates (``coordinate_names``; m and rad), body by
    body in the order the bodies were added, within a joint in the order x, y, z,
    rz, ry, rx. Prescribed coordinates are not part of q; their drives are
    evaluated at time t (s), which is why some methods take ``t``.

    Examples
    --------
    >>> import rigidfem as rf
    >>> model, h = rf.samples.pendulum()
    >>> system = model.compile()
    >>> system
    <rigidfem System: 1 bodies, nq=1, 0 prescribed>
    >>> system.nq, system.coordinate_names
    (1, ['link.ry'])
    """

    def __init__(self, model, algorithm: str = "recursive"):
        if not isinstance(algorithm, str):
            raise _checks.refuse(f"algorithm: expected 'recursive' or 'lagrange', got {algorithm!r}")
        super().__init__(model, algorithm)
        self._model_id = model.id  # handles of other models are refused (_checks.same_model)
        self._state = {"rigidfem_state": persistence.STATE_VERSION, "model": persistence.model_state(model),
                       "algorithm": algorithm, "parameters": {}}
        self._parameters = parameters.Parameters(model._parameter_groups)
        self._beams = tuple(model._beams)  # the model's Beam handles at compile time

    @property
    def parameters(self) -> dict:
        """The named parameters (``rigidfem.parameters``: ``"<beam>.E"``, ``"<body>.mass"``, ...) with their
        values at which this system was made, units and what they set: a dict of name to ``Parameter``."""
        return self._parameters.listing()

    def with_parameters(self, values: dict) -> System:
        """This system with the named parameters ``values`` ({name: value}, units of ``System.parameters``)
        changed: a new System (O(n), the model is not compiled again) that simulates exactly as the model
        built with those values. ValueError naming an unknown parameter or a value out of its range.

        Examples
        --------
        >>> import rigidfem as rf
        >>> model, h = rf.samples.spring_mass()
        >>> system = model.compile()
        >>> heavy = system.with_parameters({"block.mass": 4.0})
        >>> round(float(rf.modal_analysis(system).omega[0] / rf.modal_analysis(heavy).omega[0]), 6)
        1.414214
        """
        values = self._parameters.checked(values)
        new = System.__new__(System)
        changes = self._parameters.changes(values)
        _core._System.__init__(new, self, *changes.arguments())
        new._model_id = self._model_id
        new._state = {**self._state, "parameters": {**self._state["parameters"], **values}}
        new._parameters = self._parameters.updated(values)
        new._beams = self._beams
        return new

    def __reduce__(self):
        """Pickled as its model's recipe at compile time and the algorithm; compiled again when
        unpickled (bitwise identical results in any process)."""
        return _system_from_state, (self._state,)

    def position(self, point, t, q) -> np.ndarray:
        """Global position (3,) in m of a ``Point`` (or a ``Body``'s origin) of this system's model at
        time ``t`` (s) and coordinates ``q`` (m, rad).

        Examples
        --------
        >>> import rigidfem as rf
        >>> model, h = rf.samples.pendulum()
        >>> system = model.compile()
        >>> system.position(h["tip"], 0.0, [0.0])
        array([ 0.,  0., -1.])
        """
        _checks.same_model(point, self, "point")
        return self._position(point, t, q)

    def velocity(self, point, t, q, qd) -> np.ndarray:
        """Global velocity (3,) in m/s of a ``Point`` (or a ``Body``'s origin) at time ``t`` (s),
        coordinates ``q`` and rates ``qd`` (m/s, rad/s).

        Examples
        --------
        >>> import rigidfem as rf
        >>> model, h = rf.samples.pendulum()
        >>> system = model.compile()
        >>> system.velocity(h["tip"], 0.0, [0.0], [2.0]).round(3)
        array([-2.,  0.,  0.])
        """
        _checks.same_model(point, self, "point")
        return self._velocity(point, t, q, qd)

    def transform(self, body, t, q) -> np.ndarray:
        """Pose T_p (4, 4) in the global frame of a body (a ``Body`` handle or its index) at time ``t``
        (s) and coordinates ``q``.

        Examples
        --------
        >>> import rigidfem as rf
        >>> model, h = rf.samples.pendulum()
        >>> system = model.compile()
        >>> system.transform(h["link"], 0.0, [0.0]).round(3)
        array([[1., 0., 0., 0.],
               [0., 1., 0., 0.],
               [0., 0., 1., 0.],
               [0., 0., 0., 1.]])
        """
        if isinstance(body, Body):
            _checks.same_model(body, self, "body", "a Body of the model this system was compiled from")
        return _core._System.transform(self, body, t, q)

    def assemble(self, q, qd=None, *, t: float | None = None, tol: float = 1e-12, max_iterations: int = 50):
        """(q, qd) closing every loop, nearest to the guess: Gauss–Newton on g(q, t) = 0 with
        mass-weighted least-norm corrections M⁻¹Gᵀ(G M⁻¹Gᵀ)⁺g while they gain (max |g| <= ``tol``
        required, m or the cosine of direction rows; up to 1e-9 accepted where G has lost rank), then
        the velocities projected onto G q̇ + ∂g/∂t = 0 in the mass metric (the kinetic energy never rises). Raises ``SimulationError`` naming the
        loop that cannot be closed from this guess. ``t`` (s, keyword) for prescribed motions; q in m
        and rad, qd per s (zero by default).

        Examples
        --------
        >>> import numpy as np, rigidfem as rf
        >>> model, h = rf.samples.four_bar()
        >>> system = model.compile()
        >>> q, qd = system.assemble([0.4, -1.9, 4.6])
        >>> g, gd, G = system.loop_constraints(0.0, q, qd)
        >>> bool(np.abs(g).max() < 1e-10), G.shape
        (True, (5, 3))
        """
        return loops.assemble(self, q, qd, t=t, tol=tol, max_iterations=max_iterations)

    def coordinate_index(self, name: str) -> int:
        """Index in q of the coordinate called ``name`` (e.g. ``"link1.rz"``).

        Examples
        --------
        >>> import rigidfem as rf
        >>> model, h = rf.samples.double_pendulum()
        >>> model.compile().coordinate_index("link2.ry")
        1
        """
        names = self.coordinate_names
        if name not in names:
            raise _checks.refuse(f"name: expected one of {names}, got {name!r}")
        return names.index(name)

    def __repr__(self) -> str:
        loops_ = f", {len(self.loop_names)} loops ({self.nl} constraints)" if self.nl else ""
        return f"<rigidfem System: {self.nbodies} bodies, nq={self.nq}, {self.np} prescribed{loops_}>"

    def _repr_html_(self) -> str:
        """Notebook display: bodies, parents, joints, coordinates, beams, loops (``rigidfem.display``)."""
        return display.system_html(self)


def _model_from_state(state: dict) -> Model:
    """Unpickling: a Model made again from its recipe (``persistence.model_state``)."""
    persistence.check_version(state, "Model")
    return persistence.replay(Model(gravity=state["gravity"]), state)


def _system_from_state(state: dict) -> System:
    """Unpickling: a System compiled again from the recipe of its model at compile time."""
    persistence.check_version(state, "System")
    system = _model_from_state(state["model"]).compile(state["algorithm"])
    return system.with_parameters(state["parameters"]) if state.get("parameters") else system

