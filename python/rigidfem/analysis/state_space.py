"""``rf.linearize``: the equations of motion linearised about a state, as a state-space model for control.

About (q₀, q̇₀) at time t₀ the book's equations A(q) q̈ = f(q, q̇, t) + Q(q) u, with inputs u
entering through the generalised forces Q (nq, nu), become

    ẋ = A x + B u,   y = C x + D u,   x = (δq, δq̇) (2 nq),

    A = [[0, I], [∂q̈/∂q, ∂q̈/∂q̇]],   B = [[0], [M⁻¹ Q]],   D = 0,

with ∂q̈/∂q = −M⁻¹ ∂(M q̈ − f)/∂q (``System.acceleration_derivatives``: analytic for the recursive
engine, central differences for ``compile("lagrange")``; exact at any state, the term ∂M/∂q q̈
included). Inputs and outputs are deviations from the operating point: u = 0 is the load the
model already carries, y = 0 the outputs' values there (``ss.y0``).

Closed chains (``System.nl`` > 0) are reduced to the motions the loops allow, as in
``rf.modal_analysis``: δq = N δy with N an orthonormal basis of the null space of G = ∂g/∂q, the
state is x = (δy, δẏ) (2k, k = nq − rank G) and

    A = [[0, I], [−M_r⁻¹ K_r, −M_r⁻¹ C_r]],   B = [[0], [M_r⁻¹ Nᵀ Q]],

M_r = NᵀMN, K_r = NᵀK_tN (K_t = −∂f/∂q − ∂(Gᵀλ)/∂q, the loops' geometric stiffness included),
C_r = −Nᵀ∂f/∂q̇ N: exact about an equilibrium at rest (the rates of G are not linearised).

The module is ``rigidfem.analysis.state_space``; the package exports ``linearize`` and
``NotAnEquilibriumWarning``.

Maxwell arms (``System.nz`` > 0: the Zener and Prony sde laws) add their forces s to the state,
x = (δq, δq̇, s) (2 nq + nz), about relaxed arms (s = 0, the only value at rest):

    ṡ = K_a Eᵀ δq̇ − T⁻¹ s,   δq̈ = ... − M⁻¹ E s,

E (nq, nz) the arms' incidence (E_ij = 1 when arm j acts on q_i), K_a = diag(k), T = diag(τ)
(closed chains: Eᵀ N and Nᵀ E).
"""

from __future__ import annotations

import warnings

import numpy as np
import scipy.signal

from ..base import _checks, _interrupt
import rigidfem._core as _core  # the compiled core, by its absolute name
from .._core import Body, Point
from .operating_point import _EPS, _loop_tangent, _require_finite
from ..base.export import RATE

_solve = _interrupt.responsive(np.linalg.solve)  # Ctrl-C while LAPACK runs (_interrupt)
_inv = _interrupt.responsive(np.linalg.inv)

_KINDS = ("force", "torque", "position", "velocity")  # the first entry of a spec tuple
_AXES = {"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "z": (0.0, 0.0, 1.0)}
#: The state counts as an equilibrium when max |M q̈| <= this fraction of the largest generalised
#: force acting (N or N·m): the loads, or the springs, dampers and velocity terms.
EQUILIBRIUM_TOL = 1e-6


class NotAnEquilibriumWarning(UserWarning):
    """``rf.linearize`` about a state that is not an equilibrium (q̈ ≠ 0): the linear model holds
    for small deviations along the trajectory through that state only.

    Examples
    --------
    >>> import warnings
    >>> import rigidfem as rf
    >>> model, h = rf.samples.pendulum()
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     ss = rf.linearize(model.compile(), [0.5])
    >>> [w.category.__name__ for w in caught]
    ['NotAnEquilibriumWarning']
    """
def linearize(system, q, qd=None, *, t: float = 0.0, inputs=(), outputs=None, dt: float | None = None):
    """The system linearised about (q, q̇) at t: a ``scipy.signal.StateSpace`` (A, B, C, D).

    Parameters
    ----------
    system : System
    q, qd : (nq,) arrays
        The operating point, m and rad; m/s and rad/s (zero by default). With loops they must
        close them (``rf.static_equilibrium`` or ``System.assemble`` find such q).
    t : float
        Time (s) of the operating point (prescribed coordinates follow their drives).
    inputs : sequence or dict of name -> spec
        Each input u_j (a deviation from the loads already applied) is one of

        - ``"link.rz"``: a generalised force (N or N·m) on that coordinate of q;
        - ``("force", point, direction)``: a force (N) u d at a ``Point`` (or a ``Body``'s origin)
          along the global ``direction`` d (3,) — a unit vector makes u the force in N;
        - ``("torque", body, axis)``: a torque (N·m) u a on a ``Body`` about the global ``axis`` a (3,).

        A dict names them; a sequence gets names such as ``"force tip(0.1, 0, 0)·(0, 1, 0)"``.
    outputs : sequence or dict of name -> spec, optional
        Each output is one of ``"link.rz"`` (δq, m or rad), ``"link.rz.dot"`` (δq̇, m/s or rad/s),
        ``("position", point, axis)`` (m) or ``("velocity", point, axis)`` (m/s), with ``axis``
        "x", "y", "z" or a global direction (3,). Default: every coordinate of q.
        Position rows are J δq with the point's translational Jacobian J = ∂v/∂q̇; velocity rows
        J δq̇ + ∂v/∂q δq, whose ∂v/∂q (zero at rest without drives) is central differences of
        ``System.velocity`` (relative accuracy ~1e-10).
    dt : float, optional
        Sample time (s): the discrete model by zero-order hold (exact for inputs held over each
        sample, ``scipy.signal.cont2discrete``). Default: the continuous model.

    Returns
    -------
    scipy.signal.StateSpace
        With the attributes ``state_names`` (coordinate names, then ``<name>.dot``; with loops
        ``y[k]``, ``y[k].dot``; then ``<name>.arm<j>`` for the Maxwell arms' forces), ``input_names``, ``output_names``, ``y0`` (the outputs at the
        operating point), ``basis`` (N (nq, k) for closed chains, else None) and ``q``, ``qd``, ``t``.
        ``ss.to_discrete(dt)`` discretises it again (the names stay valid but are not carried).

    Warns ``NotAnEquilibriumWarning`` when M q̈ is not ≈ 0 (relative to the forces acting): the
    model then holds along the trajectory through the state only. Raises ``ValueError`` naming the
    argument for bad input (unknown coordinate names list the valid ones; points of another model;
    dt <= 0; shapes).

    Examples
    --------
    >>> import numpy as np, rigidfem as rf
    >>> model, h = rf.samples.pendulum()
    >>> ss = rf.linearize(model.compile(), [0.0])
    >>> ss.A.shape, np.sort(np.linalg.eigvals(ss.A).imag).round(3)
    ((2, 2), array([-3.836,  3.836]))
    """
    system = _checks.system(system)
    n = system.nq
    t = _checks.scalar(t, "t")
    q = _checks.array(q, (n,), "q")
    qd = np.zeros(n) if qd is None else _checks.array(qd, (n,), "qd")
    dt = None if dt is None else _checks.scalar(dt, "dt", positive=True, unit="s")
    in_names, Q = _inputs(system, q, t, inputs)
    out_names, Cq, Cv, y0 = _outputs(system, q, qd, t, outputs)
    M = _core._System.mass_matrix(system, t, q)
    if system.nl:
        A, B, N, C = _reduced(system, q, qd, t, M, Q, Cq, Cv)
        states = [f"y[{k}]" for k in range(N.shape[1])]
    else:
        dqdd_dq, dqdd_dqd = system.acceleration_derivatives(t, q, qd)
        # A = [[0, I], [∂q̈/∂q, ∂q̈/∂q̇]],  B = [[0], [M⁻¹ Q]],  C = [C_q, C_v]
        A = np.block([[np.zeros((n, n)), np.eye(n)], [dqdd_dq, dqdd_dqd]])
        B = np.vstack([np.zeros((n, Q.shape[1])), _solve(M, Q)])
        N, C, states = None, np.hstack([Cq, Cv]), list(system.coordinate_names)
    states = states + [s + RATE for s in states]
    if system.nz:
        A, B, C, states = _with_arms(system, M, N, A, B, C, states)
    _require_finite(t, "linearize", A=A, B=B, C=C)
    _warn_unless_equilibrium(system, q, qd, t, M)  # after the loops' check: q closes them
    D = np.zeros((C.shape[0], B.shape[1]))
    if dt is None:
        ss = scipy.signal.StateSpace(A, B, C, D)
    else:
        with np.errstate(over="ignore", invalid="ignore"):  # e^{A dt} overflowing is said below, by name
            Ad, Bd, Cd, Dd = scipy.signal.cont2discrete((A, B, C, D), dt, method="zoh")[:4]
        _require_finite(t, f"linearize (zero-order hold at dt = {dt:g} s)", "e^(A dt) overflows: dt is too long "
                        "for the model's growing or fastest modes", A=Ad, B=Bd)
        ss = scipy.signal.StateSpace(Ad, Bd, Cd, Dd, dt=dt)
    ss.state_names, ss.input_names, ss.output_names = states, in_names, out_names
    ss.y0, ss.basis, ss.q, ss.qd, ss.t = y0, N, q, qd, t
    return ss


def _with_arms(system, M, N, A, B, C, states):
    """(A, B, C, state names) with the Maxwell arms' forces s appended to the state (module docstring)."""
    arms = system.arms
    n, nz, k = system.nq, len(arms), A.shape[0] // 2
    coordinate, stiffness, tau = arms[:, 0].astype(int), arms[:, 1], arms[:, 2]
    E = np.zeros((n, nz))
    E[coordinate, np.arange(nz)] = 1.0
    if N is None:
        force, rate = _solve(M, E), E.T  # δq̈ −= M⁻¹ E s,  ṡ = K_a Eᵀ δq̇ − s/τ
    else:
        Mr = N.T @ M @ N
        force, rate = _solve(0.5 * (Mr + Mr.T), N.T @ E), E.T @ N
    A = np.block([[A, np.vstack([np.zeros((k, nz)), -force])],
                  [np.hstack([np.zeros((nz, k)), stiffness[:, None] * rate]), -np.diag(1.0 / tau)]])
    names = system.coordinate_names
    arm_names = [f"{names[i]}.arm{j}" for j, i in enumerate(coordinate)]
    return (A, np.vstack([B, np.zeros((nz, B.shape[1]))]), np.hstack([C, np.zeros((C.shape[0], nz))]),
            states + arm_names)


def _reduced(system, q, qd, t, M, Q, Cq, Cv):
    """(A, B, N, C) of a closed chain in the loops' null space: δq = N δy (see the module docstring)."""
    dfdq, dfdqd = _core._System.force_jacobians(system, t, q, qd)
    c, Kt, _ = _loop_tangent(system, q, qd, t, -dfdq, "linearize")
    N = c.N
    k = N.shape[1]
    Mr = N.T @ M @ N
    # ÿ = −M_r⁻¹ (K_r y + C_r ẏ) + M_r⁻¹ Nᵀ Q u
    Minv = _inv(0.5 * (Mr + Mr.T))
    A = np.block([[np.zeros((k, k)), np.eye(k)], [-Minv @ N.T @ Kt @ N, Minv @ N.T @ dfdqd @ N]])
    B = np.vstack([np.zeros((k, Q.shape[1])), Minv @ N.T @ Q])
    return A, B, N, np.hstack([Cq @ N, Cv @ N])


def _warn_unless_equilibrium(system, q, qd, t, M):
    """NotAnEquilibriumWarning unless max |M q̈| <= EQUILIBRIUM_TOL · (the largest force acting)."""
    qdd = system.forward_dynamics(t, q, qd)
    f_all = system.generalized_forces(t, q, qd)
    f_inner = system.generalized_forces(t, q, qd, 0.0)  # springs, dampers, velocity terms; no loads
    scale = max(np.max(np.abs(f_inner), initial=0.0), np.max(np.abs(f_all - f_inner), initial=0.0))
    residual = np.max(np.abs(M @ qdd), initial=0.0)
    if residual > EQUILIBRIUM_TOL * scale + 1e3 * _EPS:
        i = int(np.argmax(np.abs(qdd)))
        warnings.warn(f"rigidfem.linearize: the state at t = {t:g} s is not an equilibrium (max |M q̈| = "
                      f"{residual:.3g} against forces of {scale:.3g}; q̈ = {qdd[i]:.3g} for "
                      f"{system.coordinate_names[i]}): the linear model holds along the trajectory through this "
                      "state only; rigidfem.static_equilibrium finds an equilibrium", NotAnEquilibriumWarning,
                      stacklevel=3)


def _named(specs, what: str) -> list:
    """[(name or None, spec)] of a dict of specs, a sequence of them, or one spec."""
    if isinstance(specs, dict):
        if not all(isinstance(k, str) for k in specs):
            raise _checks.refuse(f"{what}: expected names (str) as the keys of the dict, got {list(specs)!r}")
        return list(specs.items())
    if isinstance(specs, str) or (isinstance(specs, tuple) and specs and specs[0] in _KINDS):
        return [(None, specs)]  # one spec
    if not isinstance(specs, (list, tuple)):
        raise _checks.refuse(f"{what}: expected a list or dict of specs, got {specs!r}")
    return [(None, s) for s in specs]


def _coordinate(system, name: str, what: str) -> int:
    names = system.coordinate_names
    if name not in names:
        raise _checks.refuse(f"{what}: expected a coordinate name, one of {names}, got {name!r}")
    return names.index(name)


def _point(system, point, what: str) -> Point:
    if isinstance(point, Body):
        point = point.origin
    if not isinstance(point, Point):
        raise _checks.refuse(f"{what}: expected a Point or Body of this system's model, got {point!r}")
    _checks.same_model(point, system, what)
    if not 0 <= point.body < system.nbodies:
        raise _checks.refuse(f"{what}: expected a Point or Body of this system's model, got {point!r}")
    return point


def _label(system, point: Point) -> str:
    r = ", ".join(f"{x:g}" for x in point.r)
    return f"{system.body_names[point.body]}({r})"


def _direction(x, what: str) -> tuple[np.ndarray, str]:
    """(d (3,), label) of an axis "x", "y", "z" or a global direction (3,), not zero."""
    if isinstance(x, str):
        if x not in _AXES:
            raise _checks.refuse(f"{what}: expected 'x', 'y', 'z' or a direction (3,), got {x!r}")
        return np.array(_AXES[x]), x
    d = _checks.vec3(x, what)
    if not np.any(d):
        raise _checks.refuse(f"{what}: expected a non-zero direction (3,), got {x!r}")
    return d, "(" + ", ".join(f"{v:g}" for v in d) + ")"


def _point_jacobian(system, point: Point, q, t) -> np.ndarray:
    """J (3, nq) = ∂v/∂q̇ of a point: v = J(q) q̇ + ∂p/∂t is linear in q̇, so column j is
    v(q, e_j) − v(q, 0) (exact)."""
    n = len(q)
    v0 = system.velocity(point, t, q, np.zeros(n))
    return np.column_stack([system.velocity(point, t, q, e) - v0 for e in np.eye(n)]).reshape(3, n)


def _rotation_jacobian(system, body: Body, q, t) -> np.ndarray:
    """J_ω (3, nq) with ω = J_ω q̇ (+ drives) the body's angular velocity, global: from the points
    at the body's unit axes a_k = R e_k, whose velocities differ from the origin's by ω × a_k, so
    ω = ½ Σ_k a_k × (v_k − v_0) (Σ_k a_k × (ω × a_k) = 3ω − ω)."""
    R = system.transform(body, t, q)[:3, :3]
    J0 = _point_jacobian(system, body.origin, q, t)
    Jk = [_point_jacobian(system, body.point(e), q, t) - J0 for e in np.eye(3)]
    return 0.5 * sum(np.cross(R[:, k][:, None], Jk[k], axis=0) for k in range(3))


def _inputs(system, q, t, inputs) -> tuple[list[str], np.ndarray]:
    """(names, Q (nq, nu)): the generalised forces of unit inputs."""
    names, columns = [], []
    for j, (name, spec) in enumerate(_named(inputs, "inputs")):
        what = f"inputs[{name!r}]" if name is not None else f"inputs[{j}]"
        if isinstance(spec, str):  # Q = e_i
            col, auto = np.eye(system.nq)[_coordinate(system, spec, what)], spec
        elif isinstance(spec, tuple) and len(spec) == 3 and spec[0] == "force":  # Q = Jᵀ d
            p = _point(system, spec[1], what)
            d, label = _direction(spec[2], what)
            col, auto = _point_jacobian(system, p, q, t).T @ d, f"force {_label(system, p)}·{label}"
        elif isinstance(spec, tuple) and len(spec) == 3 and spec[0] == "torque":  # Q = J_ωᵀ a
            if not isinstance(spec[1], Body) or spec[1].index < 0:
                raise _checks.refuse(f"{what}: expected ('torque', body, axis) with a Body of this model, got {spec!r}")
            _point(system, spec[1], what)
            a, label = _direction(spec[2], what)
            col, auto = _rotation_jacobian(system, spec[1], q, t).T @ a, f"torque {spec[1].name}·{label}"
        else:
            raise _checks.refuse(f"{what}: expected a coordinate name, ('force', point, direction) or "
                             f"('torque', body, axis), got {spec!r}")
        names.append(auto if name is None else name)
        columns.append(col)
    return names, np.array(columns, dtype=float).reshape(len(columns), system.nq).T


def _outputs(system, q, qd, t, outputs):
    """(names, C_q (ny, nq), C_v (ny, nq), y0 (ny,)): y = C_q δq + C_v δq̇ about y0."""
    n = system.nq
    if outputs is None:
        outputs = list(system.coordinate_names)
    names, Cq, Cv, y0 = [], [], [], []
    for j, (name, spec) in enumerate(_named(outputs, "outputs")):
        what = f"outputs[{name!r}]" if name is not None else f"outputs[{j}]"
        row_q, row_v = np.zeros(n), np.zeros(n)
        if isinstance(spec, str) and spec.endswith(RATE) and spec not in system.coordinate_names:
            i = _coordinate(system, spec[:-len(RATE)], what)
            row_v[i], value, auto = 1.0, qd[i], spec
        elif isinstance(spec, str):
            i = _coordinate(system, spec, what)
            row_q[i], value, auto = 1.0, q[i], spec
        elif isinstance(spec, tuple) and len(spec) == 3 and spec[0] in ("position", "velocity"):
            p = _point(system, spec[1], what)
            d, label = _direction(spec[2], what)
            J = _point_jacobian(system, p, q, t)
            if spec[0] == "position":  # δp = J δq
                row_q, value, auto = d @ J, d @ system.position(p, t, q), f"{_label(system, p)}.{label}"
            else:  # δv = ∂v/∂q δq + J δq̇
                row_q, row_v = d @ _velocity_derivative(system, p, q, qd, t), d @ J
                value, auto = d @ system.velocity(p, t, q, qd), f"{_label(system, p)}.{label}{RATE}"
        else:
            raise _checks.refuse(f"{what}: expected a coordinate name, '<name>{RATE}', ('position', point, axis) or "
                             f"('velocity', point, axis), got {spec!r}")
        names.append(auto if name is None else name)
        Cq.append(row_q)
        Cv.append(row_v)
        y0.append(value)
    shape = (len(names), n)
    return names, np.array(Cq).reshape(shape), np.array(Cv).reshape(shape), np.array(y0, dtype=float)


def _velocity_derivative(system, point, q, qd, t) -> np.ndarray:
    """∂v/∂q (3, nq) of a point's velocity at (q, q̇): zero at rest without drives, else central
    differences with steps h_j = ε^⅓ max(1, |q_j|)."""
    n = len(q)
    if not np.any(qd) and not system.np:
        return np.zeros((3, n))
    cols = []
    for j in range(n):
        h = _EPS ** (1 / 3) * max(1.0, abs(q[j]))
        qp, qm = q.copy(), q.copy()
        qp[j] += h
        qm[j] -= h
        cols.append((system.velocity(point, t, qp, qd) - system.velocity(point, t, qm, qd)) / (qp[j] - qm[j]))
    return np.column_stack(cols).reshape(3, n)

