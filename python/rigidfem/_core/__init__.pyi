"""
rigidfem C++ core: transforms, models, kinematics, the Lagrange and recursive formulations, integrators.
"""
from __future__ import annotations
import collections.abc
import numpy
import numpy.typing
import typing
from . import stages
from . import _bench
__all__: list[str] = ['Body', 'Data', 'ForceLawError', 'IntegratorOptions', 'JointSpec', 'Point', 'Profile', 'R1', 'R2', 'R3', 'SimulationError', 'build', 'callback_profile', 'euler_zyx', 'homogeneous', 'inverse', 'joint_transform', 'joint_transform_derivative', 'joint_transform_second_derivative', 'pseudo_inertia', 'skew', 'stages']
class SimulationError(RuntimeError):
    """
    A numerical failure, a RuntimeError whose message names the time (s) and the cause: a singular mass or iteration matrix, a step size below the minimum, a NaN or inf state, Newton divergence in a step or a load step of the statics, max_steps, gimbal lock of ZYX Euler angles. Its `time` (s) and `cause` say when and why.
    
    Examples
    --------
    >>> import rigidfem as rf
    >>> issubclass(rf.SimulationError, RuntimeError)
    True
    """
class Profile:
    """
    A prescribed motion q(t) with its rates (see rigidfem.motion).
    
    Examples
    --------
    >>> import rigidfem as rf
    >>> p = rf.motion.ramp(2.0, 0.0, 1.0)
    >>> [round(x, 6) for x in p(0.5)]
    [0.148679, 1.0, 4.0]
    >>> p.sample([0.0, 1.0]).round(3)
    array([[0., 0., 0.],
           [1., 2., 0.]])
    """
    __array_ufunc__ = None
    def __add__(self, arg0: typing.Any) -> typing.Any:
        ...
    def __call__(self, t: typing.Any) -> tuple[float, float, float]:
        """
        (q, qd, qdd) at time t (s).
        """
    def __mul__(self, arg0: typing.Any) -> typing.Any:
        ...
    def __neg__(self) -> typing.Any:
        ...
    def __pos__(self) -> typing.Any:
        ...
    def __radd__(self, arg0: typing.Any) -> typing.Any:
        ...
    def __reduce__(self) -> tuple:
        ...
    def __repr__(self) -> str:
        ...
    def __rmul__(self, arg0: typing.Any) -> typing.Any:
        ...
    def __rsub__(self, arg0: typing.Any) -> typing.Any:
        ...
    def __sub__(self, arg0: typing.Any) -> typing.Any:
        ...
    def __truediv__(self, arg0: typing.Any) -> typing.Any:
        ...
    def sample(self, times: typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        (q, qd, qdd) at each of the times (s): an array (len(times), 3), one call for many.
        """
    def shifted(self, delay: typing.Any) -> typing.Any:
        """
        The same motion `delay` s later: q(t − delay), with its rates.
        """
class ForceLawError(SimulationError, ValueError):
    """
    A Python force law returned no finite number (None, a string, an array, NaN or inf): a ValueError
    (and a SimulationError, with `time` and `cause`), raised by System methods; simulate() raises it as
    the SimulationError at that time.
    
    Examples
    --------
    >>> import rigidfem as rf
    >>> issubclass(rf.ForceLawError, rf.SimulationError), issubclass(rf.ForceLawError, ValueError)
    (True, True)
    """
class JointSpec:
    """
    Active coordinates of a joint with their springs and dampers.
    
    Examples
    --------
    >>> import rigidfem as rf
    >>> spec = rf.Joint.revolute("y", stiffness=5.0, damping=0.1)
    >>> type(spec).__name__, spec.kind, spec.coordinates
    ('JointSpec', 'revolute', ['ry'])
    >>> spec.stiffness, spec.damping
    ([5.0], [0.1])
    """
    def __getstate__(self) -> tuple[str, list[str], list[float], list[float], list[float], bool, list]:
        ...
    def __init__(self, kind: str, coordinates: collections.abc.Sequence[str]) -> None:
        ...
    def __setstate__(self, arg0: tuple) -> None:
        ...
    def add_coupling(self, body: typing.Any, slot: typing.Any, G: typing.Any) -> None:
        """
        Let coordinate `slot` of an earlier body (index) also move this linear joint, with generator G (4, 4)
        in this joint's frame: T = 1 + sum G q (used by the linear model of beams).
        """
    @property
    def coordinates(self) -> list[str]:
        ...
    @property
    def damping(self) -> list[float]:
        ...
    @damping.setter
    def damping(self, arg0: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex]) -> None:
        ...
    @property
    def kind(self) -> str:
        ...
    @property
    def linear(self) -> bool:
        """
        The book's linear model: T = [[1 + S(phi), r], [0, 1]].
        """
    @linear.setter
    def linear(self, arg0: bool) -> None:
        ...
    @property
    def ncoords(self) -> int:
        ...
    @property
    def rest(self) -> list[float]:
        ...
    @rest.setter
    def rest(self, arg0: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex]) -> None:
        ...
    @property
    def stiffness(self) -> list[float]:
        ...
    @stiffness.setter
    def stiffness(self, arg0: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex]) -> None:
        ...
class Body:
    """
    Handle of a body of a Model (index -1 is the ground).
    
    Examples
    --------
    >>> import rigidfem as rf
    >>> model, h = rf.samples.pendulum()
    >>> system = model.compile()
    >>> h["link"]
    <rigidfem Body 'link' #0>
    >>> h["link"].index, h["link"].name
    (0, 'link')
    >>> model.ground.index
    -1
    """
    def __getstate__(self) -> tuple[int, str, int]:
        ...
    @typing.overload
    def __init__(self) -> None:
        """
        The ground.
        """
    @typing.overload
    def __init__(self, index: typing.SupportsInt | typing.SupportsIndex, name: str, model: typing.SupportsInt | typing.SupportsIndex = 0) -> None:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, arg0: tuple) -> None:
        ...
    def point(self, r: typing.Any) -> ...:
        """
        The material point at r (m, body frame).
        """
    @property
    def index(self) -> int:
        ...
    @property
    def model(self) -> int:
        """
        Id of the Model that made the handle (0: unknown).
        """
    @property
    def name(self) -> str:
        ...
    @property
    def origin(self) -> ...:
        """
        The point at the body frame's origin.
        """
class Point:
    """
    A material point: body index and position r (m) in the body frame.
    
    Examples
    --------
    >>> import rigidfem as rf
    >>> model, h = rf.samples.pendulum()
    >>> system = model.compile()
    >>> p = h["link"].point((0.0, 0.0, -1.0))
    >>> p
    <rigidfem Point on body #0 at r = (0, 0, -1) m>
    >>> system.position(p, 0.0, [0.0])
    array([ 0.,  0., -1.])
    """
    def __getstate__(self) -> tuple[int, typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"], int]:
        ...
    @typing.overload
    def __init__(self, body: typing.Any, r: typing.Any) -> None:
        ...
    @typing.overload
    def __init__(self, body: Body) -> None:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, arg0: tuple) -> None:
        ...
    @property
    def body(self) -> int:
        ...
    @property
    def model(self) -> int:
        """
        Id of the Model whose body the point is on (0: unknown).
        """
    @property
    def r(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
class _Model:
    @staticmethod
    def _check_law(kind: str, values: dict, profile: Profile) -> list[float]:
        """
        The constants' values of a law of `kind` (defaults for those not given), each converted and judged
        against its bounds (ValueError naming the first out of them).
        """
    @staticmethod
    def _law_kinds() -> list:
        """
        Every kind of law, each a dict: kind, acts_on ('element', 'coordinate' or 'contact'), doc, constants (name, unit,
        rotation_unit, default, lower, positive, doc, parameter, linear, upper), profile, profile_name, profile_units, function,
        addable (False: every coordinate's own spring-damping law).
        """
    @staticmethod
    def _loop_kind_table() -> list:
        """
        The loop kinds, each a dict: kind, rows (constraint equations), free (what it leaves free).
        """
    @staticmethod
    def _loop_kinds() -> dict:
        """
        The loop kinds and their numbers of constraint rows.
        """
    def __init__(self, gravity: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]) -> None:
        ...
    def _add_bodies(self, names: collections.abc.Sequence[str], parents: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], joint: JointSpec, stiffness: typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]", "flags.c_contiguous"], damping: typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]", "flags.c_contiguous"], placements: typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]", "flags.c_contiguous"], masses: typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], coms: typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]", "flags.c_contiguous"], inertias: typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]", "flags.c_contiguous"]) -> list[Body]:
        """
        Adds bodies in order, each with `joint` but its own row of stiffness and damping; all are checked
        before any is added. placements and inertias are row-major 4x4 and 3x3 per row.
        """
    def _add_body(self, name: str, parent: typing.SupportsInt | typing.SupportsIndex, joint: JointSpec, placement: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[4, 4]"], mass: typing.SupportsFloat | typing.SupportsIndex, com: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"], inertia: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 3]"]) -> Body:
        ...
    def _add_contact(self, name: str, a: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], b: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], kind: str, values: dict) -> int:
        """
        Adds a contact of the law `kind` between the shapes `a` and `b` (indices); returns its index.
        """
    def _add_coordinate_law(self, body: typing.SupportsInt | typing.SupportsIndex, coordinate: typing.SupportsInt | typing.SupportsIndex, kind: str, values: dict, function: typing.Any) -> int:
        """
        Adds a law of `kind` on a joint coordinate (-1: the joint's only one); returns its index among the
        coordinate's laws.
        """
    def _add_flow(self, length: Profile, first: typing.SupportsInt | typing.SupportsIndex, elements: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def _add_force_element(self, name: str, a: typing.SupportsInt | typing.SupportsIndex, point_a: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"], b: typing.SupportsInt | typing.SupportsIndex, point_b: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"], kind: str, values: dict, profile: Profile, function: typing.Any) -> str:
        """
        Adds a force element of the law `kind` (its constants' values by name, the rest their defaults), with its
        profile and Python function where the kind takes them; returns its name.
        """
    def _add_generalized_force(self, body: typing.SupportsInt | typing.SupportsIndex, coordinate: typing.SupportsInt | typing.SupportsIndex, value: typing.SupportsFloat | typing.SupportsIndex, law: typing.Any) -> None:
        ...
    def _add_load(self, body: typing.SupportsInt | typing.SupportsIndex, point: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"], force: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"], torque: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"], follower: bool, scale: Profile) -> None:
        ...
    def _add_loop(self, name: str, kind: str, a: typing.SupportsInt | typing.SupportsIndex, frame_a: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[4, 4]"], b: typing.SupportsInt | typing.SupportsIndex, frame_b: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[4, 4]"], length: typing.SupportsFloat | typing.SupportsIndex, drive: Profile, actuator: bool = False) -> str:
        ...
    def _add_maxwell_arms(self, bodies: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], coordinates: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], stiffness: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], tau: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex]) -> None:
        """
        Adds Maxwell arms (k in N/m or N·m/rad, tau in s) on joint coordinates (-1: the joint's only one).
        """
    def _add_shape(self, name: str, body: typing.SupportsInt | typing.SupportsIndex, kind: str, a: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"], b: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"], normal: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"], half_extents: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"], rotation: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 3]"], radius: typing.SupportsFloat | typing.SupportsIndex) -> int:
        """
        Adds a shape fixed on `body` (-1: the ground; rigidfem/contact.hpp); returns its index.
        """
    def _adopt_id(self, id: typing.SupportsInt | typing.SupportsIndex) -> None:
        """
        Takes the id of the model this one copies (unpickling).
        """
    def _body_index(self, name: str) -> int:
        ...
    def _body_name(self, index: typing.SupportsInt | typing.SupportsIndex) -> str:
        ...
    def _coordinate_index(self, body: typing.SupportsInt | typing.SupportsIndex, coordinate: str) -> int:
        ...
    def _coordinate_name(self, body: typing.SupportsInt | typing.SupportsIndex, coordinate: typing.SupportsInt | typing.SupportsIndex) -> str:
        """
        'body.axis' of coordinate `coordinate` (-1: the joint's only one) of a body's joint.
        """
    def _element_law(self, element: typing.SupportsInt | typing.SupportsIndex) -> tuple[str, list[float], str]:
        """
        (kind, the constants' values, how it is drawn) of force element k's law.
        """
    def _prescribe(self, body: typing.SupportsInt | typing.SupportsIndex, coordinate: typing.SupportsInt | typing.SupportsIndex, motion: Profile) -> None:
        ...
    def _truncate(self, n: typing.SupportsInt | typing.SupportsIndex) -> None:
        """
        Removes the bodies n, n + 1, ... (undo of a failed builder).
        """
    def _wind(self, element: typing.SupportsInt | typing.SupportsIndex, body: typing.SupportsInt | typing.SupportsIndex, coordinate: typing.SupportsInt | typing.SupportsIndex, radius: typing.SupportsFloat | typing.SupportsIndex, capstan: typing.SupportsFloat | typing.SupportsIndex = 0.0, smoothing: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> None:
        """
        Winds force element `element` (a rope) on coordinate `coordinate` (-1: the only one) of body `body`'s
        joint, of radius `radius` (m): l_u gains r q, and the coordinate takes r P c, c the capstan's friction
        exp(-sgn(r) capstan tanh(qd/smoothing)).
        """
    @property
    def _nelements(self) -> int:
        ...
    @property
    def _nflows(self) -> int:
        ...
    @property
    def _nloads(self) -> int:
        ...
    @property
    def _nloops(self) -> int:
        ...
    @property
    def _shape_table(self) -> list:
        """
        The shapes, each a dict: name, body, kind, a, b, normal, half_extents, rotation, radius.
        """
    @property
    def body_names(self) -> list[str]:
        ...
    @property
    def gravity(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        """
        Gravitational acceleration (m/s^2), global.
        """
    @gravity.setter
    def gravity(self, arg1: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]) -> None:
        ...
    @property
    def id(self) -> int:
        """
        Unique id of this model, carried by its Body and Point handles.
        """
    @property
    def nbodies(self) -> int:
        ...
class Data:
    """
    Workspace of the algorithms; after each stage it holds that stage's results.
    
    Examples
    --------
    >>> import rigidfem as rf
    >>> model, h = rf.samples.pendulum()
    >>> system = model.compile()
    >>> data = system.make_data()
    >>> rf.stages.set_state(system, data, 0.0, [0.5], [0.0])
    >>> rf.stages.kinematics(system, data)
    >>> len(data.T), data.qa
    (1, array([0.5]))
    """
    @property
    def A(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        Mass matrix (nq, nq).
        """
    @property
    def Hbar(self) -> list[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[4, 4]"]]:
        """
        Subtree sums of T_p H_p T_p^T.
        """
    @property
    def T(self) -> list[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[4, 4]"]]:
        """
        Global pose T_p (4, 4) of every body.
        """
    @property
    def Td(self) -> list[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[4, 4]"]]:
        """
        dT_p/dt.
        """
    @property
    def Tdd(self) -> list[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[4, 4]"]]:
        """
        d2T_p/dt2 (with the free accelerations zero unless driving_forces ran).
        """
    @property
    def U(self) -> list[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[4, 4]"]]:
        """
        U (4, 4) of every coordinate use: dT_p/dq_i = U_i T_p for the bodies p below
        coordinate i (without linear-model couplings, use i is coordinate i).
        """
    @property
    def Wbar(self) -> list[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[4, 4]"]]:
        """
        Subtree sums of T_p H_p Tdd_p^T.
        """
    @property
    def Zbar(self) -> list[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[4, 4]"]]:
        """
        Subtree sums of the load moments.
        """
    @property
    def f(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Right-hand side (nq,).
        """
    @property
    def qa(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        All coordinates (nc,), free and prescribed.
        """
    @property
    def qda(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def qdd(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Accelerations (nq,).
        """
    @property
    def qdda(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def t(self) -> float:
        ...
    @property
    def tau(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Driving forces (np,).
        """
class _System:
    @typing.overload
    def __init__(self, model: _Model, algorithm: str) -> None:
        ...
    @typing.overload
    def __init__(self, base: _System, coordinates: collections.abc.Sequence[tuple[typing.SupportsInt | typing.SupportsIndex, typing.SupportsInt | typing.SupportsIndex, typing.SupportsInt | typing.SupportsIndex, str, typing.SupportsFloat | typing.SupportsIndex]], bodies: collections.abc.Sequence[tuple[typing.SupportsInt | typing.SupportsIndex, typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[4, 4]"]]], elements: collections.abc.Sequence[tuple[typing.SupportsInt | typing.SupportsIndex, str, typing.SupportsFloat | typing.SupportsIndex]], loads: collections.abc.Sequence[tuple[typing.SupportsInt | typing.SupportsIndex, typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"], typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]]], profiles: collections.abc.Sequence[tuple[str, typing.SupportsInt | typing.SupportsIndex, typing.SupportsInt | typing.SupportsIndex, Profile]], contacts: collections.abc.Sequence[tuple[typing.SupportsInt | typing.SupportsIndex, str, typing.SupportsFloat | typing.SupportsIndex]]) -> None:
        ...
    def _assemble(self, t: float, q: numpy.typing.ArrayLike, qd: numpy.typing.ArrayLike, tol: typing.SupportsFloat | typing.SupportsIndex, max_iterations: typing.SupportsInt | typing.SupportsIndex) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]]:
        ...
    def _assemble_and_accelerate(self, t: float, q: numpy.typing.ArrayLike, qd: numpy.typing.ArrayLike, tol: typing.SupportsFloat | typing.SupportsIndex, max_iterations: typing.SupportsInt | typing.SupportsIndex, stage: tuple[numpy.typing.ArrayLike, numpy.typing.ArrayLike] | None = None) -> tuple:
        """
        (q, q̇, q̈): _assemble, then the forward dynamics at the state it reached, on the projection's own factorisation (what the integrators do after each step on loops); with stage = (q_s, q̇_s), also q̈ there with the same workspace, as a step's stages evaluate it (the rank kept on the loops).
        """
    def _inverse_dynamics_direction(self, t: float, q: numpy.typing.ArrayLike, qd: numpy.typing.ArrayLike, qdd: numpy.typing.ArrayLike, dq: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], dqd: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], dqdd: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        (dr/dq) dq + (dr/dqd) dqd + A dqdd (nq): the RNEA's forward-mode derivative along one direction (recursive:
        exact, O(n)), central differences (lagrange).
        """
    def _inverse_dynamics_vjp(self, t: float, q: numpy.typing.ArrayLike, qd: numpy.typing.ArrayLike, qdd: numpy.typing.ArrayLike, mu: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]]:
        """
        ((dr/dq)^T mu, (dr/dqd)^T mu, A mu), each (nq), and d(mu^T r)/d of the prescribed coordinates' q, qd,
        qdd, each (np): the RNEA's reverse mode (recursive systems), O(n).
        """
    def _position(self, point: Point, t: float, q: numpy.typing.ArrayLike) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    def _positions(self, points: list[Point], t: float, q: numpy.typing.ArrayLike) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        ...
    def _velocity(self, point: Point, t: float, q: numpy.typing.ArrayLike, qd: numpy.typing.ArrayLike) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    def acceleration_derivatives(self, t: float, q: numpy.typing.ArrayLike, qd: numpy.typing.ArrayLike) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]]:
        """
        (dqdd/dq, dqdd/dqd), each (nq, nq): -A^-1 (dr/dq, dr/dqd) at the forward-dynamics qdd; with loop
        closures, of the constrained qdd (multipliers and constraint Jacobian varying too), by central differences.
        
        Examples
        --------
        >>> import rigidfem as rf
        >>> model, h = rf.samples.pendulum()
        >>> system = model.compile()
        >>> dq, dqd = system.acceleration_derivatives(0.0, [0.0], [0.0])
        >>> dq.round(4), dqd.round(4) + 0.0
        (array([[-14.715]]), array([[0.]]))
        """
    def contact_states(self, t: float, q: numpy.typing.ArrayLike, qd: numpy.typing.ArrayLike) -> list:
        """
        Every overlap of two shapes of a contact at (t, q, qd), each a dict: contact (its name), a and b (the
        bodies' indices, -1 the ground), point (the contact point, m), normal (from a to b), gap (m, < 0: the
        penetration), gap_rate (m/s), normal_force (N), force (on b, N; -force on a), slip (m/s).
        
        Examples
        --------
        >>> import rigidfem as rf
        >>> model = rf.Model()
        >>> ball = model.add_body("ball", model.ground, rf.Joint.prismatic("z"), mass=0.1,
        ...                       inertia=(1e-5,) * 3)
        >>> b = model.add_shape("sphere", ball, rf.shapes.Sphere(0.05))
        >>> floor = model.add_shape("floor", model.ground, rf.shapes.HalfSpace())
        >>> _ = model.add_contact("hit", b, floor, rf.laws.Contact(stiffness=1e5, restitution=0.8))
        >>> system = model.compile()
        >>> system.contact_states(0.0, [0.1], [0.0])
        []
        >>> (c,) = system.contact_states(0.0, [0.04], [0.0])
        >>> c["contact"], round(c["gap"], 4), round(c["normal_force"], 1)
        ('hit', -0.01, 100.0)
        """
    def dissipated_power(self, t: float, q: numpy.typing.ArrayLike, qd: numpy.typing.ArrayLike) -> float:
        """
        Power dissipated by the joint dampers, sum b qd^2, and by the force elements' dampers,
        sum c (dl/dt)^2 (W).
        
        Examples
        --------
        >>> import rigidfem as rf
        >>> model = rf.Model(gravity=None)
        >>> block = model.add_body("block", model.ground, rf.Joint.prismatic("x"), mass=2.0,
        ...                        inertia=(1e-3,) * 3)
        >>> _ = model.add_spring_damper("s", model.ground, block, stiffness=50.0, length=0.0, damping=1.0)
        >>> system = model.compile()
        >>> round(system.dissipated_power(0.0, [0.1], [1.0]), 4)
        1.0
        """
    def driving_forces(self, t: float, q: numpy.typing.ArrayLike, qd: numpy.typing.ArrayLike) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Forces/torques (np,) the drives exert on the prescribed coordinates (N or N m).
        
        Examples
        --------
        >>> import rigidfem as rf
        >>> model = rf.Model()
        >>> arm = model.add_body("arm", model.ground, rf.Joint.revolute("y"), mass=1.0,
        ...                      inertia=(0.1, 0.1, 0.1), com=(0.5, 0.0, 0.0))
        >>> _ = model.prescribe(arm, rf.motion.ramp(1.0, 0.0, 1.0))
        >>> system = model.compile()
        >>> system.prescribed_names
        ['arm.ry']
        >>> system.driving_forces(0.0, [], []).round(4)
        array([-4.905])
        """
    def elastic_energy(self, t: float, q: numpy.typing.ArrayLike) -> float:
        """
        Energy of the joint springs 1/2 sum c (q - q_rest)^2 and of the force elements' springs
        1/2 sum k (l - l0)^2 (J).
        
        Examples
        --------
        >>> import rigidfem as rf
        >>> model = rf.Model(gravity=None)
        >>> block = model.add_body("block", model.ground, rf.Joint.prismatic("x"), mass=2.0,
        ...                        inertia=(1e-3,) * 3)
        >>> _ = model.add_spring_damper("s", model.ground, block, stiffness=50.0, length=0.0, damping=1.0)
        >>> system = model.compile()
        >>> round(system.elastic_energy(0.0, [0.1]), 4)
        0.25
        """
    def element_states(self, t: float, q: numpy.typing.ArrayLike, qd: numpy.typing.ArrayLike) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        Length l (m), rate dl/dt (m/s) and axial force F (N, positive pushing the two points apart) of every
        force element (nelements, 3).
        
        Examples
        --------
        >>> import rigidfem as rf
        >>> model = rf.Model(gravity=None)
        >>> block = model.add_body("block", model.ground, rf.Joint.prismatic("x"), mass=2.0,
        ...                        inertia=(1e-3,) * 3)
        >>> _ = model.add_spring_damper("s", model.ground, block, stiffness=50.0, length=0.0, damping=1.0)
        >>> system = model.compile()
        >>> system.element_names
        ['s']
        >>> system.element_states(0.0, [0.1], [0.0]).round(4)
        array([[ 0.1,  0. , -5. ]])
        """
    def force_jacobians(self, t: float, q: numpy.typing.ArrayLike, qd: numpy.typing.ArrayLike, load_factor: float = 1.0, static: bool = False) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]]:
        """
        (df/dq, df/dqd), each (nq, nq): analytic for recursive systems, central differences for
        algorithm='lagrange'. -df/dq is the tangent stiffness K,
        -df/dqd the damping and gyroscopic matrix C. static=True holds the prescribed coordinates at t.
        
        Examples
        --------
        >>> import rigidfem as rf
        >>> model, h = rf.samples.pendulum()
        >>> system = model.compile()
        >>> dfdq, dfdqd = system.force_jacobians(0.0, [0.0], [0.0])
        >>> dfdq.round(4), dfdqd.round(4) + 0.0
        (array([[-4.905]]), array([[0.]]))
        """
    def forward_dynamics(self, t: float, q: numpy.typing.ArrayLike, qd: numpy.typing.ArrayLike) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Accelerations qdd (nq,) solving A(q) qdd = f(q, qd, t); t in s, q in m/rad, qd in m/s, rad/s.
        
        Examples
        --------
        >>> import rigidfem as rf
        >>> model, h = rf.samples.pendulum()
        >>> system = model.compile()
        >>> system.forward_dynamics(0.0, [0.5], [0.0]).round(4)
        array([-7.0547])
        """
    def generalized_forces(self, t: float, q: numpy.typing.ArrayLike, qd: numpy.typing.ArrayLike, load_factor: float = 1.0) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Right-hand side f (nq,) of A qdd = f: loads, gravity, springs, dampers minus velocity terms (N, N m).
        load_factor scales gravity, loads and applied generalised forces.
        
        Examples
        --------
        >>> import rigidfem as rf
        >>> model, h = rf.samples.pendulum()
        >>> system = model.compile()
        >>> system.generalized_forces(0.0, [0.5], [0.0]).round(4)
        array([-2.3516])
        """
    def gravity_energy(self, t: float, q: numpy.typing.ArrayLike) -> float:
        """
        Potential energy of gravity -sum m g^T r_C (J).
        
        Examples
        --------
        >>> import rigidfem as rf
        >>> model, h = rf.samples.pendulum()
        >>> system = model.compile()
        >>> round(system.gravity_energy(0.0, [0.0]), 4)
        -4.905
        """
    def inverse_dynamics(self, t: float, q: numpy.typing.ArrayLike, qd: numpy.typing.ArrayLike, qdd: numpy.typing.ArrayLike) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        r = A(q) qdd - f(q, qd, t) (nq,): the generalised forces (N or N m) the free coordinates
        need besides the loads, springs and dampers to move with qdd (the residual of the
        equations of motion; zero at the forward-dynamics accelerations).
        
        Examples
        --------
        >>> import rigidfem as rf
        >>> model, h = rf.samples.pendulum()
        >>> system = model.compile()
        >>> qdd = system.forward_dynamics(0.0, [0.5], [0.0])
        >>> bool(abs(system.inverse_dynamics(0.0, [0.5], [0.0], qdd)).max() < 1e-12)
        True
        """
    def inverse_dynamics_derivatives(self, t: float, q: numpy.typing.ArrayLike, qd: numpy.typing.ArrayLike, qdd: numpy.typing.ArrayLike) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]]:
        """
        (dr/dq, dr/dqd), each (nq, nq), of r = A qdd - f: analytic through the RNEA for recursive
        systems (O(n) per column), central differences for algorithm='lagrange'.
        
        Examples
        --------
        >>> import rigidfem as rf
        >>> model, h = rf.samples.pendulum()
        >>> system = model.compile()
        >>> drdq, drdqd = system.inverse_dynamics_derivatives(0.0, [0.0], [0.0], [0.0])
        >>> drdq.round(4), drdqd.round(4) + 0.0
        (array([[4.905]]), array([[0.]]))
        """
    def jacobian(self, t: float, y: numpy.typing.ArrayLike) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        d(rhs)/dy (2 nq, 2 nq) for solve_ivp(jac=...): analytic for recursive systems (see
        acceleration_derivatives), central differences for algorithm='lagrange'.
        
        Examples
        --------
        >>> import rigidfem as rf
        >>> model, h = rf.samples.pendulum()
        >>> system = model.compile()
        >>> system.jacobian(0.0, [0.0, 0.0]).round(4) + 0.0
        array([[  0.   ,   1.   ],
               [-14.715,   0.   ]])
        """
    def kinetic_energy(self, t: float, q: numpy.typing.ArrayLike, qd: numpy.typing.ArrayLike) -> float:
        """
        Kinetic energy 1/2 sum tr(dT H dT^T) (J).
        
        Examples
        --------
        >>> import rigidfem as rf
        >>> model, h = rf.samples.pendulum()
        >>> system = model.compile()
        >>> round(system.kinetic_energy(0.0, [0.0], [2.0]), 4)
        0.6667
        """
    def loop_constraints(self, t: float, q: numpy.typing.ArrayLike, qd: numpy.typing.ArrayLike) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]]:
        """
        (g, gd, G): the loop closures' constraint equations g(q, t) (nl,) (m, or the cosine for direction
        rows), their rates gd = G qd + dg/dt (nl,) and the Jacobian G = dg/dq (nl, nq).
        
        Examples
        --------
        >>> import rigidfem as rf
        >>> model, h = rf.samples.four_bar()
        >>> system = model.compile()
        >>> q, qd = system.assemble([0.4, -1.9, 4.6])
        >>> g, gd, G = system.loop_constraints(0.0, q, qd)
        >>> bool(abs(g).max() < 1e-10), G.shape
        (True, (5, 3))
        """
    def loop_multipliers(self, t: float, q: numpy.typing.ArrayLike, qd: numpy.typing.ArrayLike) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Multipliers lambda (nl,) of M qdd = f + G^T lambda at the forward-dynamics accelerations.
        
        Examples
        --------
        >>> import rigidfem as rf
        >>> model, h = rf.samples.four_bar()
        >>> system = model.compile()
        >>> q, qd = system.assemble([0.4, -1.9, 4.6])
        >>> system.loop_multipliers(0.0, q, qd).shape, system.nl
        ((5,), 5)
        """
    def loop_reactions(self, t: float, q: numpy.typing.ArrayLike, qd: numpy.typing.ArrayLike) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        Reaction of every loop closure on its body b (nloops, 6): force (N) and torque (N m, about frame B's
        origin) in frame A's axes; for a distance loop (an actuator) the force along the line in column 0,
        positive pushing b away from a.
        
        Examples
        --------
        >>> import rigidfem as rf
        >>> model, h = rf.samples.four_bar()
        >>> system = model.compile()
        >>> q, qd = system.assemble([0.4, -1.9, 4.6])
        >>> system.loop_names, system.loop_reactions(0.0, q, qd).shape
        (['C'], (1, 6))
        """
    def make_data(self) -> Data:
        """
        A fresh workspace for the stage functions (allocated in place: a Data is never copied or moved).
        
        Examples
        --------
        >>> import rigidfem as rf
        >>> model, h = rf.samples.pendulum()
        >>> system = model.compile()
        >>> data = system.make_data()
        >>> type(data).__name__
        'Data'
        """
    def mass_matrix(self, t: float, q: numpy.typing.ArrayLike) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        Mass matrix A(q) (nq, nq), a_ij = sum_p tr(T_p,i H_p T_p,j^T).
        
        Examples
        --------
        >>> import rigidfem as rf
        >>> model, h = rf.samples.pendulum()
        >>> system = model.compile()
        >>> system.mass_matrix(0.0, [0.0]).round(4)
        array([[0.3333]])
        """
    def potential_energy(self, t: float, q: numpy.typing.ArrayLike) -> float:
        """
        Gravity plus elastic energy (J).
        
        Examples
        --------
        >>> import rigidfem as rf
        >>> model, h = rf.samples.pendulum()
        >>> system = model.compile()
        >>> round(system.potential_energy(0.0, [0.0]), 4)
        -4.905
        """
    def rhs(self, t: float, y: numpy.typing.ArrayLike) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        dy/dt = [qd, qdd] for y = [q, qd] (2 nq,): the signature of scipy's solve_ivp.
        With loop closures qdd holds them at the acceleration level only: g(q) = 0 drifts under solve_ivp
        (rigidfem.simulate's methods project onto the loops).
        
        Examples
        --------
        >>> import rigidfem as rf
        >>> model, h = rf.samples.pendulum()
        >>> system = model.compile()
        >>> system.rhs(0.0, [0.5, 1.0]).round(4)
        array([ 1.    , -7.0547])
        """
    def static_forces(self, t: float, q: numpy.typing.ArrayLike, load_factor: float = 1.0) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Static residual f(q) (nq,): generalised forces at rest, prescribed coordinates held at their values at t.
        
        Examples
        --------
        >>> import rigidfem as rf
        >>> model, h = rf.samples.pendulum()
        >>> system = model.compile()
        >>> system.static_forces(0.0, [0.5]).round(4)
        array([-2.3516])
        """
    def transform(self, body: Body | int, t: float, q: numpy.typing.ArrayLike) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[4, 4]"]:
        """
        Pose T_p (4, 4) of a body (by index) in the global frame.
        """
    @property
    def _segments(self) -> list:
        """
        (how it is drawn, body a, point on a (m), body b, point on b) of every force element and loop.
        """
    @property
    def _shapes(self) -> list:
        """
        (kind, body, a, b, normal, half_extents, rotation, radius) of every shape (contact.hpp).
        """
    @property
    def algorithm(self) -> str:
        """
        'recursive' (O(n): RNEA, CRBA, ABA) or 'lagrange' (the book's formulation; always for linear joints).
        """
    @property
    def arms(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        The Maxwell arms (nz, 3): free coordinate index, stiffness k (N/m or N·m/rad), relaxation time tau (s).
        """
    @property
    def body_names(self) -> list[str]:
        ...
    @property
    def centres_of_mass(self) -> list[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]]:
        """
        Centre of mass of every body in its own frame (m).
        """
    @property
    def contact_names(self) -> list[str]:
        """
        Names of the contacts (Model.add_contact).
        """
    @property
    def coordinate_names(self) -> list[str]:
        """
        Names 'body.axis' of the free coordinates, in the order of q.
        """
    @property
    def damping(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Damping coefficient b_i of each free coordinate (nq,), N s/m or N m s/rad.
        """
    @property
    def element_names(self) -> list[str]:
        """
        Names of the force elements (spring-dampers, cylinders, ropes), in the order of element_states().
        """
    @property
    def gravity(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        """
        Gravitational acceleration (m/s^2), global.
        """
    @property
    def inertias(self) -> list[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 3]"]]:
        """
        Inertia tensor (3, 3) of every body about its centre of mass, body axes (kg m^2).
        """
    @property
    def loop_kinds(self) -> list[str]:
        """
        Kind of every loop closure ('revolute', ..., 'distance').
        """
    @property
    def loop_names(self) -> list[str]:
        """
        Names of the loop closures, in the order of loop_reactions().
        """
    @property
    def masses(self) -> list[float]:
        """
        Mass of every body (nbodies), kg.
        """
    @property
    def nbodies(self) -> int:
        ...
    @property
    def nc(self) -> int:
        """
        Number of all joint coordinates, nq + np.
        """
    @property
    def nl(self) -> int:
        """
        Number of constraint equations of the loop closures (multipliers).
        """
    @property
    def np(self) -> int:
        """
        Number of prescribed (driven) coordinates.
        """
    @property
    def nq(self) -> int:
        """
        Number of free joint coordinates (the unknowns).
        """
    @property
    def nz(self) -> int:
        """
        Number of Maxwell arms: internal variables s (their forces, N or N·m).
        """
    @property
    def parent(self) -> list[int]:
        """
        Parent index of every body (-1: ground), parent[p] < p.
        """
    @property
    def placements(self) -> list[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[4, 4]"]]:
        """
        Constant joint placements B_p (4, 4) in the parent frame.
        """
    @property
    def prescribed_names(self) -> list[str]:
        """
        Names of the prescribed coordinates, in the order of driving_forces().
        """
    @property
    def pseudo_inertias(self) -> list[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[4, 4]"]]:
        """
        Pseudo-inertia H_p = int r r^T dm (4, 4) of every body, body frame (kg, kg m, kg m^2).
        """
    @property
    def rest(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Spring rest value q_i^0 of each free coordinate (nq,), m or rad.
        """
    @property
    def stiffness(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Spring stiffness c_i of each free coordinate (nq,), N/m or N m/rad.
        """
class IntegratorOptions:
    """
    Options of the C++ integrators (see rigidfem.simulate): each option of the table (_option_table) through set and get; the method, s0 and stiff_method as attributes.
    """
    method: str
    stiff_method: str
    def __init__(self) -> None:
        ...
    def add_event(self, kind: str, name: str, index: typing.SupportsInt | typing.SupportsIndex, r: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"], axis: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"], value: typing.SupportsFloat | typing.SupportsIndex, direction: typing.SupportsInt | typing.SupportsIndex, terminal: bool, restarts: bool, function: typing.Any) -> None:
        """
        An event of the run (events.hpp): its kind, name, index (coordinate, body or contact), r and axis (a point's), the value g crosses, direction, terminal, restarts, and function(t, q, qd) for 'function'.
        """
    def add_sensitivity(self, plus: _System, minus: _System, h: typing.SupportsFloat | typing.SupportsIndex, S0: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> None:
        """
        A direction of the forward sensitivities: the system at p + h and, for a central difference, at p - h (None, None: an initial value), and [dq0/dp, dqd0/dp] (2 nq).
        """
    def get(self, name: str) -> typing.Any:
        """
        The option `name` as Python shows it.
        """
    def set(self, name: str, value: typing.Any) -> None:
        """
        Sets the option `name` from a Python value of its type (integrator_options: ValueError naming it otherwise).
        """
    def set_error_on(self, outputs: collections.abc.Sequence[tuple[str, typing.SupportsInt | typing.SupportsIndex, typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]]]) -> None:
        """
        The outputs the error is measured on: (kind, index, r) each; [] for the state.
        """
    @property
    def s0(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        (nz) the Maxwell arms' initial forces (N or N·m); empty: zero
        """
    @s0.setter
    def s0(self, arg0: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> None:
        ...
class _Adjoint:
    def __init__(self, system: _System, options: IntegratorOptions, outputs: collections.abc.Sequence[tuple[str, typing.SupportsInt | typing.SupportsIndex, typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]]], memory: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    def backward(self, ybar: typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]", "flags.c_contiguous"]) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], dict]:
        """
        (dJ/dp, dJ/dq0, dJ/dqd0, stats) for ybar = dJ/dy (N + 1, K).
        """
    def forward(self, t0: typing.SupportsFloat | typing.SupportsIndex, t_end: typing.SupportsFloat | typing.SupportsIndex, q0: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], qd0: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]]:
        """
        (t (N + 1), y (N + 1, K)) of the run.
        """
def R1(phi1: typing.Any) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 3]"]:
    """
    Rotation matrix about x by phi1 (rad), (3, 3).
    
    Examples
    --------
    >>> import rigidfem as rf
    >>> rf.R1(0.5).round(3)
    array([[ 1.   ,  0.   ,  0.   ],
           [ 0.   ,  0.878, -0.479],
           [ 0.   ,  0.479,  0.878]])
    """
def R2(phi2: typing.Any) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 3]"]:
    """
    Rotation matrix about y by phi2 (rad), (3, 3).
    
    Examples
    --------
    >>> import rigidfem as rf
    >>> rf.R2(0.5).round(3)
    array([[ 0.878,  0.   ,  0.479],
           [ 0.   ,  1.   ,  0.   ],
           [-0.479,  0.   ,  0.878]])
    """
def R3(phi3: typing.Any) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 3]"]:
    """
    Rotation matrix about z by phi3 (rad), (3, 3).
    
    Examples
    --------
    >>> import rigidfem as rf
    >>> rf.R3(0.5).round(3)
    array([[ 0.878, -0.479,  0.   ],
           [ 0.479,  0.878,  0.   ],
           [ 0.   ,  0.   ,  1.   ]])
    """
def _auto_stiff_method(system: _System, iteration_matrix: str) -> str:
    """
    The implicit method method='auto' hands over to.
    """
def _body_poses(system: _System, t: typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], q: typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]", "flags.c_contiguous"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
    """
    (len(t) nbodies, 12): each body's rotation row by row and origin (m) at each (t_k, q_k).
    """
def _check_options(system: _System, t0: typing.SupportsFloat | typing.SupportsIndex, t_end: typing.SupportsFloat | typing.SupportsIndex, q0: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], qd0: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], t_eval: typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], options: IntegratorOptions) -> None:
    """
    integrate's checks of the options alone (ValueError naming the first bad one).
    """
def _evaluate_outputs(system: _System, t: typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], q: typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]", "flags.c_contiguous"], qd: typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]", "flags.c_contiguous"], s: typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]", "flags.c_contiguous"], lambda_: typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]", "flags.c_contiguous"]) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]]:
    ...
def _integer(x: typing.Any, name: str, expected: str, lo: typing.SupportsInt | typing.SupportsIndex, hi: typing.SupportsInt | typing.SupportsIndex) -> int:
    """
    x as an int in [lo, hi]: a Python or numpy integer (not a bool or float), else the ValueError.
    """
def _integrate(system: _System, t0: typing.SupportsFloat | typing.SupportsIndex, t_end: typing.SupportsFloat | typing.SupportsIndex, q0: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], qd0: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], t_eval: typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], options: IntegratorOptions, keep_going: typing.Any) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"], dict, bool, typing.Any, typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"], list]:
    ...
def _least_norm_symmetric(A: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], b: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], rank: typing.SupportsInt | typing.SupportsIndex = -1) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
    """
    x = A⁺ b for a symmetric positive semi-definite A (the loops' G M⁻¹ Gᵀ): its eigenvalues below 1e-10 of the largest count as zero; with rank >= 0, at most rank directions where the rest are small (constraints.hpp).
    """
def _make_profile(maker: str, *args) -> typing.Any:
    """
    The profile of the kind `maker` (a row of _profile_kinds) from its arguments, in the row's order.
    """
def _measures_outputs(system: _System, options: IntegratorOptions) -> bool:
    """
    Whether error_on's default for the run is the bodies' displacements (else the state).
    """
def _method_table() -> list:
    """
    The C++ methods, each a dict: name, family, order (of the propagated solution), error_estimate, adaptive (by
    default), measures_outputs (error_on's default: the bodies, else the state), adjoint (rigidfem.gradient), options
    (the names it reads), doc.
    """
def _option_table() -> list:
    """
    The options of the integrators, each a dict: name, type, default, unit, doc, none_allowed.
    """
def _point_positions(system: _System, body: typing.SupportsInt | typing.SupportsIndex, r: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"], frame: typing.SupportsInt | typing.SupportsIndex, t: typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], q: typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]", "flags.c_contiguous"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
    ...
def _point_to_point_laws() -> list[str]:
    """
    The laws of rest_to_rest_profile and ramp_profile, by name.
    """
def _profile_kinds() -> list:
    """
    The kinds of profile, each a dict: maker, arguments (name, type, expected, affine: whether the profile is affine in its numbers) in the maker's order.
    """
def _real(x: typing.Any, name: str, expected: str) -> float:
    """
    x as a float: a real number (int, float, numpy real scalar or 0-d array), else ValueError
    '<name>: expected <expected>, got <repr>'. NaN and inf pass.
    """
def _real_array(x: typing.Any, name: str, expected: str) -> numpy.typing.NDArray[numpy.float64]:
    """
    x as a float64 array of any shape (bindings.hpp's real_array_arg), else the ValueError.
    """
def callback_profile(function: collections.abc.Callable[[float], tuple[typing.SupportsFloat | typing.SupportsIndex, typing.SupportsFloat | typing.SupportsIndex, typing.SupportsFloat | typing.SupportsIndex]]) -> Profile:
    ...
def euler_zyx(phi3: typing.Any, phi2: typing.Any, phi1: typing.Any) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 3]"]:
    """
    R3(phi3) R2(phi2) R1(phi1), book eq. (2.7): yaw, pitch, roll in rad. (3, 3).
    
    Examples
    --------
    >>> import numpy as np, rigidfem as rf
    >>> R = rf.euler_zyx(0.1, 0.2, 0.3)
    >>> bool(np.allclose(R, rf.R3(0.1) @ rf.R2(0.2) @ rf.R1(0.3)))
    True
    """
def homogeneous(R: typing.Any, r: typing.Any) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[4, 4]"]:
    """
    [[R, r], [0, 1]] (4, 4); r in m.
    
    Examples
    --------
    >>> import numpy as np, rigidfem as rf
    >>> rf.homogeneous(np.eye(3), [1.0, 2.0, 3.0])
    array([[1., 0., 0., 1.],
           [0., 1., 0., 2.],
           [0., 0., 1., 3.],
           [0., 0., 0., 1.]])
    """
def inverse(T: typing.Any) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[4, 4]"]:
    """
    Inverse of a homogeneous transform, [[R^T, -R^T r], [0, 1]] (4, 4).
    
    Examples
    --------
    >>> import numpy as np, rigidfem as rf
    >>> T = rf.homogeneous(rf.R3(0.3), [1.0, 0.0, 0.0])
    >>> bool(np.allclose(rf.inverse(T) @ T, np.eye(4)))
    True
    >>> rf.inverse(rf.homogeneous(np.eye(3), [1.0, 2.0, 3.0]))[:3, 3]
    array([-1., -2., -3.])
    """
def joint_transform(coordinates: typing.Any, q: typing.Any) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[4, 4]"]:
    """
    Joint transform Trans(x, y, z) R3(phi3) R2(phi2) R1(phi1) restricted to `coordinates`
    (names from 'x', 'y', 'z', 'rz', 'ry', 'rx', taken in the book's order); q in m and rad. (4, 4).
    
    Examples
    --------
    >>> import rigidfem as rf
    >>> rf.joint_transform(["x", "rz"], [0.5, 0.0])
    array([[1. , 0. , 0. , 0.5],
           [0. , 1. , 0. , 0. ],
           [0. , 0. , 1. , 0. ],
           [0. , 0. , 0. , 1. ]])
    """
def joint_transform_derivative(coordinates: typing.Any, q: typing.Any, i: typing.Any) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[4, 4]"]:
    """
    dT/dq_i of joint_transform (4, 4).
    
    Examples
    --------
    >>> import rigidfem as rf
    >>> rf.joint_transform_derivative(["x", "rz"], [0.5, 0.0], 0)
    array([[0., 0., 0., 1.],
           [0., 0., 0., 0.],
           [0., 0., 0., 0.],
           [0., 0., 0., 0.]])
    """
def joint_transform_second_derivative(coordinates: typing.Any, q: typing.Any, i: typing.Any, j: typing.Any) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[4, 4]"]:
    """
    d2T/dq_i dq_j of joint_transform (4, 4).
    
    Examples
    --------
    >>> import rigidfem as rf
    >>> rf.joint_transform_second_derivative(["x", "rz"], [0.5, 0.0], 1, 1).round(3)
    array([[-1.,  0.,  0.,  0.],
           [ 0., -1.,  0.,  0.],
           [ 0.,  0.,  0.,  0.],
           [ 0.,  0.,  0.,  0.]])
    """
def pseudo_inertia(mass: typing.Any, com: typing.Any, inertia: typing.Any) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[4, 4]"]:
    """
    Pseudo-inertia H = int r r^T dm (4, 4) of a body: mass (kg), centre of mass com (3,) m and
    inertia tensor (3, 3) about the centre of mass (kg m^2), all in the body frame.
    
    Examples
    --------
    >>> import numpy as np, rigidfem as rf
    >>> rf.pseudo_inertia(2.0, [0.5, 0.0, 0.0], np.diag([0.01, 0.02, 0.02])).round(3)
    array([[0.515, 0.   , 0.   , 1.   ],
           [0.   , 0.005, 0.   , 0.   ],
           [0.   , 0.   , 0.005, 0.   ],
           [1.   , 0.   , 0.   , 2.   ]])
    """
def skew(w: typing.Any) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 3]"]:
    """
    Skew-symmetric S(w) with S(w) x = w x x. (3, 3).
    
    Examples
    --------
    >>> import rigidfem as rf
    >>> rf.skew([1.0, 2.0, 3.0])
    array([[ 0., -3.,  2.],
           [ 3.,  0., -1.],
           [-2.,  1.,  0.]])
    >>> rf.skew([1.0, 2.0, 3.0]) @ [4.0, 5.0, 6.0]
    array([-3.,  6., -3.])
    """
build: str  # "baseline" or "x86-64-v3" (rigidfem/_load_core.py)
