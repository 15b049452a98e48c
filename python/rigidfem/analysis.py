"""Statics and modal analysis of a compiled System.

Both linearise the book's equations A(q) q̈ = f(q, q̇, t) about a configuration with
the force Jacobians of ``System.force_jacobians`` (in C++: analytic for the default
recursive engine, central differences for ``compile(algorithm="lagrange")``):
K = −∂f/∂q (tangent stiffness: springs, gravity and preload, centrifugal terms of a
prescribed spin) and C = −∂f/∂q̇ (dampers, gyroscopic terms).

Closed chains (``System.nl`` > 0: loop joints and actuators, M q̈ = f + Gᵀλ, g(q, t) = 0):
statics solves f(q) + G(q)ᵀλ = 0, g(q, t) = 0 for (q, λ) by Newton's method on the bordered
system [[K_t, −Gᵀ], [G, 0]], and modal analysis linearises in the null space N of G (the
motions the loops allow), with K_t = K − ∂(Gᵀλ)/∂q: the tree's stiffness plus the loops'
geometric stiffness −λᵀ∂²g/∂q², whose second derivatives are central differences of
G(q)ᵀλ at fixed λ (relative accuracy ~1e-10). Redundant constraint rows (a planar loop closed
by a 3D joint has three) are handled by the rank-revealing SVD of G, rows scaled to unit
length; λ is the least-norm one, as in ``System.loop_multipliers``.

Every answer is a result or an exception: a system without free coordinates (nq = 0)
gets an empty result; bad arguments raise ``ValueError`` naming the argument; a
singular mass matrix (gimbal lock), a mechanism in statics (a coordinate nothing
resists) or non-finite matrices raise one ``SimulationError`` that names the time,
the cause and the coordinates concerned. No LinAlgError or LinAlgWarning escapes.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import warnings

import numpy as np
import scipy.linalg
import scipy.optimize
from scipy.linalg import lapack

from . import _checks, _core, _interrupt, analysis_sensitivities, display, export
from ._core import SimulationError
from .persistence import Versioned

# The dense LAPACK routines of the analyses, answering Ctrl-C while they run (_interrupt).
_eigh = _interrupt.eigh
_eig = _interrupt.responsive(np.linalg.eig)
_getrf = _interrupt.responsive(lapack.dgetrf)
_potrf = _interrupt.cholesky

_EPS = np.finfo(float).eps
#: The tangent stiffness counts as singular when its reciprocal condition number, after symmetric
#: scaling by its row sizes (which removes the mix of units, N/m beside N·m/rad), is below this.
_RCOND_SINGULAR = 1e-13
#: The mass matrix (scaled by its diagonal) only below this: a chain of m rfes in relative
#: coordinates is legitimately conditioned to ~ m⁴ (7e9 at m = 160), a gimbal lock to ~1/ε².
_RCOND_MASS = 16 * _EPS


def _frame(t: float, what: str) -> str:
    return f"at t = {t} s: {what}"


def _require_finite(t: float, what: str, **matrices) -> None:
    for name, a in matrices.items():
        if not np.all(np.isfinite(a)):
            raise SimulationError(f"{_frame(t, what)}: {name} has NaN or inf entries (forces, drives or "
                                  "their derivatives overflow at this time and configuration)")


def _compiled(t: float, what: str, name: str, function, *args):
    """``function(*args)``, a compiled System method whose binding holds its results finite: its overflow (the
    SimulationError whose cause starts "<function>() overflowed") is `what`'s, naming the matrix ``name``."""
    try:
        return function(*args)
    except SimulationError as e:
        if not str(getattr(e, "cause", "")).startswith(f"{function.__name__}() overflowed"):
            raise
        raise SimulationError(f"{_frame(t, what)}: {name} has NaN or inf entries (forces, drives or their derivatives "
                              "overflow at this time and configuration)") from None


def _row_scale(A: np.ndarray) -> np.ndarray:
    """(n,) symmetric scaling s with A_ij / (s_i s_j) of order one: s_i = sqrt(max |row i|, |column i|)."""
    a = np.abs(A)
    s = np.sqrt(np.maximum(a.max(axis=0), a.max(axis=1)))
    s[~(s > 0)] = 1.0  # an all-zero row stays zero: singular
    return s


def _describe_null_space(A: np.ndarray, names, limit: int = 3, basis: np.ndarray | None = None) -> str:
    """The coordinates of A's (near) null space: "payload.rz", "(ball.rz + ball.rx)" for a
    combination, or "6 independent motions of body.x, ..." for a large one. With ``basis``
    (nq, k), A is (k, k) in the coordinates y of q = basis · y (the loops' null space)."""
    s = _row_scale(A)
    _, sv, Vt = np.linalg.svd(A / s[:, None] / s[None, :])
    null = sv <= max(1e-8 * sv[0], sv[-1])
    V = Vt[null].T / s[:, None]  # back to the unscaled coordinates (m and rad)
    if basis is not None:
        V = basis @ V
    V, _ = np.linalg.qr(V)
    n = len(V)
    names = list(names) if names is not None and len(names) == n else [f"q[{i}]" for i in range(n)]
    if V.shape[1] > limit:  # the coordinates that carry a large null space
        weight = np.sum(V**2, axis=1)
        picked = [names[i] for i in range(n) if weight[i] >= 0.1 * weight.max()]
        return f"{V.shape[1]} independent motions of " + ", ".join(picked)
    parts = []
    for v in V.T:
        v = v / v[np.argmax(np.abs(v))]
        big = [i for i in range(len(v)) if abs(v[i]) >= 0.1]
        if len(big) == 1:
            parts.append(names[big[0]])
            continue
        text = ""
        for i in big:
            size = "" if abs(abs(v[i]) - 1) < 1e-3 else f"{abs(v[i]):.2g}·"
            text += ((" − " if text else "−") if v[i] < 0 else " + " if text else "") + size + names[i]
        parts.append(f"({text})")
    return ", ".join(parts)


# --------------------------------------------------------------------------- loops

#: Constraint rows of each loop kind (``rigidfem.loops``), in the order of ``System.loop_kinds``.
_LOOP_ROWS = _core._Model._loop_kinds()
#: A row of G counts as zero below this fraction of the largest row (round-off of a row that is
#: zero in exact arithmetic, e.g. the out-of-plane rows of a planar loop).
_ROW_ZERO = 1e-10
#: G's rank for the analyses: singular values of G (rows scaled to unit length) above this fraction of
#: the largest. (The dynamics' least-norm solves decide on G M⁻¹ Gᵀ, 1e-10 of its largest singular
#: value, i.e. rows below about 1e-5 of G's largest: constraints.cpp.)
_RANK_TOL = 1e-10


def _loop_of_rows(system) -> list:
    """The name of the loop of every constraint row (nl)."""
    rows = []
    for name, kind in zip(system.loop_names, system.loop_kinds):
        rows += [name] * _LOOP_ROWS[kind]
    return rows


def _worst_loop(system, g: np.ndarray) -> str:
    names = _loop_of_rows(system)
    i = int(np.argmax(np.abs(g)))
    return f"loop '{names[i]}'" if len(names) == len(g) else f"row {i}"


@dataclass
class _Constraints:
    """The loops' Jacobian G (nl, nq) at one configuration, split by its SVD (rows scaled to unit
    length: the rank does not depend on the units, m beside cosines)."""

    G: np.ndarray
    rank: int
    R: np.ndarray     #: (nq, r) orthonormal basis of G's row space
    N: np.ndarray     #: (nq, nq − r) orthonormal basis of its null space: the motions the loops allow
    live: np.ndarray  #: (nl,) rows that are not zero
    U: np.ndarray     #: (live rows, r) left singular vectors of the scaled live rows
    sv: np.ndarray    #: (r,) their singular values
    norms: np.ndarray  #: (nl,) row lengths

    @classmethod
    def of(cls, G: np.ndarray) -> "_Constraints":
        nl, n = G.shape
        norms = np.linalg.norm(G, axis=1)
        live = norms > _ROW_ZERO * max(norms.max(initial=0.0), 1e-300)
        if not live.any() or n == 0:
            return cls(G, 0, np.zeros((n, 0)), np.eye(n), live, np.zeros((int(live.sum()), 0)), np.zeros(0), norms)
        U, sv, Vt = np.linalg.svd(G[live] / norms[live, None])
        r = int(np.sum(sv > _RANK_TOL * sv[0]))
        return cls(G, r, Vt[:r].T, Vt[r:].T, live, U[:, :r], sv[:r], norms)

    def correction(self, g: np.ndarray) -> np.ndarray:
        """Least-norm Δq (nq,) with G Δq = −g (least squares over the rows the rank keeps)."""
        gs = g[self.live] / self.norms[self.live]
        return -self.R @ ((self.U.T @ gs) / self.sv)

    def multipliers(self, h: np.ndarray) -> np.ndarray:
        """Least-norm λ (nl,) minimising |Gᵀλ − h| (h (nq,))."""
        lam = np.zeros(len(self.G))
        if self.rank == 0:
            return lam
        # Scaled rows: Gᵀλ = Gsᵀ μ with μ = D λ on the live rows; one μ, then the least-norm λ is its
        # projection onto range(G) = D·range(U) (the λ that Gᵀ maps to zero are left out).
        mu = self.U @ ((self.R.T @ h) / self.sv)
        lam[self.live] = mu / self.norms[self.live]
        B, _ = np.linalg.qr(self.U * self.norms[self.live, None])
        lam[self.live] = B @ (B.T @ lam[self.live])
        return lam


def _loop_jacobian(system, t: float, q: np.ndarray):
    g, _, G = system.loop_constraints(t, q, np.zeros(len(q)))
    return g, G


def _constraint_stiffness(system, t: float, q: np.ndarray, lam: np.ndarray) -> np.ndarray:
    """The loops' geometric stiffness −∂(G(q)ᵀλ)/∂q = −Σ λ_i ∂²g_i/∂q² (nq, nq) at fixed λ:
    central differences of G with steps h_j = ε^⅓ max(1, |q_j|) (relative error ~1e-10),
    symmetrised (it is a sum of Hessians)."""
    n = len(q)
    Kg = np.zeros((n, n))
    if not np.any(lam):
        return Kg
    for j in range(n):
        h = _EPS ** (1 / 3) * max(1.0, abs(q[j]))
        qp, qm = q.copy(), q.copy()
        qp[j] += h
        qm[j] -= h
        Gp, Gm = _loop_jacobian(system, t, qp)[1], _loop_jacobian(system, t, qm)[1]
        Kg[:, j] = -(Gp.T @ lam - Gm.T @ lam) / (qp[j] - qm[j])
    return 0.5 * (Kg + Kg.T)


def _close_loops(system, q: np.ndarray, t: float, what: str) -> np.ndarray:
    """q assembled onto the loops (``System.assemble``), or the SimulationError naming the loop."""
    try:
        return system.assemble(q, None, t=t)[0]
    except SimulationError as err:
        raise SimulationError(f"{err} ({what} starts from the coordinates closed onto the loops "
                              f"{system.loop_names})") from err


# --------------------------------------------------------------------------- statics

@dataclass
class Equilibrium(Versioned):
    """Result of ``static_equilibrium``."""

    q: np.ndarray            #: (nq,) equilibrium coordinates, m and rad
    converged: bool          #: always True: a load step that does not converge raises SimulationError
    iterations: int          #: Newton iterations over all load steps
    residual: float          #: max |f(q)| at the end (with loops max |f + Gᵀλ|), N or N·m
    load_steps: int
    history: list = field(default_factory=list, repr=False)  #: (load factor, iterations, residual) per step
    #: (nl,) the loops' multipliers λ of f + Gᵀλ = 0 (least-norm where rows are redundant), in the
    #: units of ``System.loop_multipliers``; empty without loops. ``System.loop_reactions(t, q, 0)``
    #: gives the reactions (force and torque) when the drives are at rest at t.
    multipliers: np.ndarray = field(default_factory=lambda: np.zeros(0))
    constraint_residual: float = 0.0  #: max |g(q, t)| at the end (m, or cosines), 0 without loops
    #: {name: dq/dp (nq,)} of ``static_equilibrium(sensitivities=...)`` (m or rad per unit of the parameter)
    sensitivities: dict = field(default_factory=dict, repr=False)

    def sensitivity(self, name: str) -> np.ndarray:
        """dq/dp (nq,) of the equilibrium by the parameter ``name`` (``static_equilibrium(sensitivities=...)``)."""
        if name not in self.sensitivities:
            raise ValueError(f"name: expected one of the sensitivities asked for {list(self.sensitivities)}, got {name!r}")
        return self.sensitivities[name]


def _solve_tangent(K: np.ndarray, f: np.ndarray):
    """Δq (nq,) with K Δq = f, or None when K is singular to working precision."""
    s = _row_scale(K)
    Ks = K / s[:, None] / s[None, :]
    lu, piv, info = _getrf(Ks)
    if info != 0:
        return None
    rcond, info = lapack.dgecon(lu, np.linalg.norm(Ks, 1))
    if info != 0 or not rcond > _RCOND_SINGULAR:  # NaN fails too
        return None
    x, info = lapack.dgetrs(lu, piv, f / s)
    return x / s if info == 0 else None


#: The most load steps static_equilibrium takes (each is a Newton solve: more is a typo, not a study).
MAX_LOAD_STEPS = 100_000


def _integer_at_least_one(x, name: str) -> int:
    v = _checks.integer(x, name)
    if v < 1:
        raise ValueError(f"{name}: expected an integer >= 1, got {v}")
    return v
def static_equilibrium(system, q0=None, *, t: float = 0.0, load_steps: int = 10, tol: float = 1e-10,
                       max_iterations: int = 50, sensitivities=None) -> Equilibrium:
    """Solve f(q) = 0 by Newton's method with load stepping.

    Gravity, point forces, torques and applied generalised forces are scaled together
    by λ = 1/n, 2/n, ..., 1 (n = ``load_steps``, 1 to 100,000); each step starts from the previous
    one's solution (``q0``, m and rad, default 0, for the first). Prescribed coordinates
    are held at their values at time ``t`` (s), at rest. A step converges when the
    Newton correction satisfies max |Δq| ≤ tol · max(1, max |q|) (m and rad).

    A system without free coordinates (nq = 0) returns at once with ``q`` of shape (0,).

    Closed chains (loop joints, actuators): ``q0`` is first closed onto the loops
    (``System.assemble``), then each step solves f(q) + G(q)ᵀλ = 0, g(q, t) = 0 by Newton
    on the bordered system [[K_t, −Gᵀ], [G, 0]] (Δq, Δλ), K_t = −∂f/∂q − ∂(Gᵀλ)/∂q, in the
    null space of G (redundant rows allowed); ``residual`` is then max |f + Gᵀλ| and the
    result carries λ (``multipliers``) and max |g| (``constraint_residual``).

    Raises ``ValueError`` for a bad argument, and ``SimulationError`` (naming t) when
    Newton does not converge within ``max_iterations`` in a load step, when forces or
    their Jacobian are not finite, when ``q0`` cannot be closed onto the loops (naming the
    loop), or when the tangent stiffness K = −∂f/∂q (with loops: K_t in the motions the loops
    allow) is singular: the message then names the coordinates nothing resists (a mechanism,
    e.g. the yaw of a hanging payload, or a buckling/limit point).

    ``sensitivities``: named parameters (``System.parameters``) whose derivatives dq/dp of the
    equilibrium come with it, K_t dq/dp = ∂f/∂p (``Equilibrium.sensitivity(name)``;
    ``rigidfem.analysis_sensitivities``).
    """
    names = analysis_sensitivities.check_names(system, sensitivities)
    eq = _static_equilibrium(system, q0, t, load_steps, tol, max_iterations)
    if names:
        t, q = _checks.scalar(t, "t"), eq.q
        Kt = -_core._System.force_jacobians(system, t, q, np.zeros(system.nq), 1.0, True)[0]
        N = None
        if system.nl:
            Kt = Kt + _constraint_stiffness(system, t, q, eq.multipliers)
            N = _Constraints.of(_loop_jacobian(system, t, q)[1]).N
        eq.sensitivities = analysis_sensitivities.static(system, names, Kt, N,
                                                         lambda s: _core._System.static_forces(s, t, q, 1.0))
    return eq


def _static_equilibrium(system, q0, t, load_steps, tol, max_iterations) -> Equilibrium:
    t = _checks.scalar(t, "t")
    n = system.nq
    q = np.zeros(n) if q0 is None else _checks.array(q0, (n,), "q0").copy()
    steps = _checks.integer(load_steps, "load_steps", minimum=1, maximum=MAX_LOAD_STEPS)
    tol = _checks.scalar(tol, "tol", positive=True)
    max_iterations = _integer_at_least_one(max_iterations, "max_iterations")
    if system.nl:
        q = _close_loops(system, q, t, "static_equilibrium")
    if n == 0:
        return Equilibrium(q, True, 0, 0.0, steps, [(k / steps, 0, 0.0) for k in range(1, steps + 1)],
                           np.zeros(system.nl))
    if system.nl:
        return _constrained_statics(system, q, t, steps, tol, max_iterations)
    history, total = [], 0
    for k in range(1, steps + 1):
        lam = k / steps
        what = f"statics at load factor {lam:.4g}"
        f = system.static_forces(t, q, lam)
        for it in range(1, max_iterations + 1):
            K = -_compiled(t, what, "tangent stiffness K", _core._System.force_jacobians, system, t, q, np.zeros(n), lam,
                           True)[0]
            _require_finite(t, what, **{"f(q)": f, "tangent stiffness K": K})
            dq = _solve_tangent(K, f)
            if dq is None:
                raise _mechanism(t, what, K, system.coordinate_names)
            # Backtracking line search on |f| keeps large-rotation steps from overshooting.
            alpha, norm0 = 1.0, np.max(np.abs(f))
            while True:
                q_new = q + alpha * dq
                f_new = system.static_forces(t, q_new, lam)
                if np.max(np.abs(f_new)) <= norm0 or alpha < 1e-3:
                    break
                alpha *= 0.5
            q, f = q_new, f_new
            total += 1
            if np.max(np.abs(alpha * dq)) <= tol * max(1.0, np.max(np.abs(q))):
                break
        else:
            raise SimulationError(f"{_frame(t, 'statics')}: Newton did not converge in {max_iterations} iterations at "
                                  f"load factor {lam:.4g} (residual {np.max(np.abs(f)):.3e}); try more load_steps")
        history.append((lam, it, float(np.max(np.abs(f)))))
    return Equilibrium(q, True, total, float(np.max(np.abs(f))), steps, history)


def _mechanism(t: float, what: str, K: np.ndarray, names, basis=None) -> SimulationError:
    within = "" if basis is None else " within the motions the loops allow"
    return SimulationError(
        f"{_frame(t, what)}: the tangent stiffness K = −∂f/∂q{'' if basis is None else ' − ∂(Gᵀλ)/∂q'} is "
        f"singular to working precision{within}: nothing resists {_describe_null_space(K, names, basis=basis)}. A mechanism "
        "(give these coordinates stiffness, prescribe or lock them), or a buckling/limit point")


def _constrained_statics(system, q: np.ndarray, t: float, steps: int, tol: float, max_iterations: int) -> Equilibrium:
    """``static_equilibrium`` of a closed chain, from q on the loops: Newton on the bordered system

        [K_t  −Gᵀ] [Δq]   [f + Gᵀλ]
        [G     0 ] [Δλ] = [  −g   ],   K_t = −∂f/∂q − ∂(Gᵀλ)/∂q,

    solved in the null space N of G: Δq = −G⁺g + N y with (NᵀK_tN) y = Nᵀ(f + K_t G⁺g), then the
    least-norm λ + Δλ of Gᵀ(λ + Δλ) = K_tΔq − f. A backtracking line search keeps |Nᵀ f| (the
    load the loops do not carry) from growing."""
    n, names = system.nq, system.coordinate_names
    zero = np.zeros(n)

    def state(q, lam_factor):
        f = system.static_forces(t, q, lam_factor)
        g, G = _loop_jacobian(system, t, q)
        c = _Constraints.of(G)
        return f, g, c

    def unbalance(f, c):  # max |f + Gᵀλ| with the least-squares λ: the part of f the loops do not carry
        return float(np.max(np.abs(c.N @ (c.N.T @ f)))) if c.N.shape[1] else 0.0

    history, total = [], 0
    for k in range(1, steps + 1):
        lf = k / steps
        what = f"statics at load factor {lf:.4g}"
        f, g, c = state(q, lf)
        lam = c.multipliers(-f)
        for it in range(1, max_iterations + 1):
            K = -_compiled(t, what, "tangent stiffness K", _core._System.force_jacobians, system, t, q, zero, lf, True)[0]
            _require_finite(t, what, **{"f(q)": f, "tangent stiffness K": K, "loop Jacobian G": c.G, "g(q)": g})
            Kt = K + _constraint_stiffness(system, t, q, lam)
            _require_finite(t, what, **{"geometric stiffness of the loops": Kt})
            dq = c.correction(g)
            N = c.N
            if N.shape[1]:
                y = _solve_tangent(N.T @ Kt @ N, N.T @ (f - Kt @ dq))
                if y is None:
                    raise _mechanism(t, what, N.T @ Kt @ N, names, N)
                dq = dq + N @ y
            # Backtracking line search on the unbalanced load keeps large-rotation steps from overshooting.
            alpha, norm0 = 1.0, unbalance(f, c)
            while True:
                q_new = q + alpha * dq
                f_new, g_new, c_new = state(q_new, lf)
                if unbalance(f_new, c_new) <= norm0 or alpha < 1e-3:
                    break
                alpha *= 0.5
            lam_newton = c.multipliers(Kt @ dq - f)
            q, f, g, c = q_new, f_new, g_new, c_new
            lam = lam_newton if alpha == 1.0 else c.multipliers(-f)
            total += 1
            if np.max(np.abs(alpha * dq)) <= tol * max(1.0, np.max(np.abs(q))):
                break
        else:
            lam = c.multipliers(-f)
            raise SimulationError(
                f"{_frame(t, 'statics')}: Newton did not converge in {max_iterations} iterations at load factor "
                f"{lf:.4g} (residual max |f + Gᵀλ| = {np.max(np.abs(f + c.G.T @ lam)):.3e}, loops' residual "
                f"max |g| = {np.max(np.abs(g)):.3e} in {_worst_loop(system, g)}); try more load_steps or a q0 nearer "
                "the equilibrium")
        lam = c.multipliers(-f)
        history.append((lf, it, float(np.max(np.abs(f + c.G.T @ lam)))))
    lam = c.multipliers(-f)
    return Equilibrium(q, True, total, float(np.max(np.abs(f + c.G.T @ lam))), steps, history, lam,
                       float(np.max(np.abs(g))))


# --------------------------------------------------------------------------- modes

@dataclass
class Modes(Versioned):
    """Result of ``modal_analysis``: one entry per mode (k = nq, or nq − rank G with loops), sorted
    by natural frequency."""

    omega: np.ndarray           #: (k,) undamped natural circular frequencies, rad/s (a divergence: √(−ω²))
    frequencies_hz: np.ndarray  #: (k,) omega / 2π, Hz
    damping_ratios: np.ndarray  #: (k,) modal ζ = φᴴCφ / (2ω φᴴMφ): > 1 overdamped, inf damped ω = 0, < 0 unstable
    shapes: np.ndarray          #: (nq, k) undamped mode shapes (real parts), max |entry| = 1
    eigenvalues: np.ndarray     #: (k,) per mode the root of det(λ²M + λC + K) with the largest Re, Im ≥ 0; 1/s
    q: np.ndarray               #: (nq,) configuration linearised about

    @property
    def stable(self) -> bool:
        """No eigenvalue with a positive real part (to 1e-9 of its modulus)."""
        return bool(np.all(self.eigenvalues.real <= 1e-9 * np.abs(self.eigenvalues)))
    M: np.ndarray = field(repr=False)  #: (nq, nq) mass matrix
    K: np.ndarray = field(repr=False)  #: (nq, nq) tangent stiffness −∂f/∂q (loops: −∂f/∂q − ∂(Gᵀλ)/∂q)
    C: np.ndarray = field(repr=False)  #: (nq, nq) −∂f/∂q̇
    #: (nq, k) orthonormal basis N of the motions the loops allow (null space of G); the modes are
    #: those of NᵀMN, NᵀKN, NᵀCN, shapes = N φ. None without loops.
    basis: np.ndarray | None = field(default=None, repr=False)
    #: (nl,) the loops' multipliers λ (least squares of f + Gᵀλ = 0) in the geometric stiffness; empty without loops
    multipliers: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False)
    #: {name: (dω/dp, dζ/dp)} of ``modal_analysis(sensitivities=...)``, each (k,): rad/s and 1 per unit of the parameter
    sensitivities: dict = field(default_factory=dict, repr=False)

    def sensitivity(self, name: str) -> tuple[np.ndarray, np.ndarray]:
        """(dω/dp, dζ/dp), each (k,), by the parameter ``name`` (``modal_analysis(sensitivities=...)``)."""
        if name not in self.sensitivities:
            raise ValueError(f"name: expected one of the sensitivities asked for {list(self.sensitivities)}, got {name!r}")
        return self.sensitivities[name]

    def _repr_html_(self) -> str:
        """Notebook display: the frequency table (``rigidfem.display``)."""
        return display.modes_html(self)

    def table(self) -> list[dict]:
        """The frequency table, one dict per mode: ``mode`` (1, 2, ...), ``omega (rad/s)``,
        ``f (Hz)``, ``zeta`` (no pandas needed)."""
        return export.modes_table(self)

    def to_dataframe(self):
        """``table()`` as a pandas DataFrame indexed by mode (ImportError without pandas)."""
        return export.modes_dataframe(self)


def _check_mass_matrix(M: np.ndarray, names, t: float, basis: np.ndarray | None = None) -> None:
    """SimulationError naming the coordinates without inertia unless M is positive definite
    (``basis``: M is NᵀAN in the loops' null space N)."""
    s = np.sqrt(np.abs(np.diag(M)))
    singular = not np.all(s > 0)
    if not singular:
        Ms = M / s[:, None] / s[None, :]
        L, info = _potrf(Ms)
        singular = info != 0
        if not singular:
            rcond, info = lapack.dpocon(L, np.linalg.norm(Ms, 1))
            singular = info != 0 or not rcond > _RCOND_MASS
    if singular:
        raise SimulationError(f"{_frame(t, 'modal analysis')}: the mass matrix A(q) is singular to working "
                              f"precision: no inertia along {_describe_null_space(M, names, basis=basis)} (Euler angles in "
                              "gimbal lock at pitch ±π/2, or massless bodies)")


def _undamped(K: np.ndarray, M: np.ndarray):
    """ω² (n,) ascending and mode shapes Φ (n, n) with ΦᵀMΦ = I of K φ = ω² M φ (K symmetric).

    The stiffness form eigh(K, M) is accurate to ε ω_max² in ω², which for a stiff beam
    (ω_max²/ω₁² ~ 1e11) spoils the low modes. When K is positive definite the flexibility
    form M φ = μ K φ, μ = 1/ω², gives the low modes to ε ω_i²/ω₁² instead; with a wide
    spectrum both are solved and each mode taken from the better one, split at a gap near
    the geometric mean of ω₁² and ω_max² where the two errors are equal.
    """
    n = len(K)
    try:
        mu, X = _eigh(M, K)  # raises when K is not positive definite
    except np.linalg.LinAlgError:
        mu = None
    if mu is None or not mu[0] > 0:  # a zero mode, a divergence (spin softening, buckling): stiffness form
        w2, Phi = _eigh(K, M)
        w2[np.abs(w2) <= 64 * n * _EPS * np.max(np.abs(w2))] = 0.0  # rigid-body modes: zero, not ±round-off
        return w2, Phi
    w2, Phi = 1.0 / mu[::-1], X[:, ::-1] / np.sqrt(mu[::-1])
    if w2[-1] <= 1e6 * w2[0]:
        return w2, Phi
    w2s, Phis = _eigh(K, M)
    gm = np.sqrt(w2[0] * w2[-1])
    near = np.flatnonzero((w2[1:] >= gm / 10) & (w2[:-1] <= gm * 10)) + 1  # splits k: flexibility below k
    if near.size == 0:
        return w2, Phi
    k = near[np.argmax(w2[near] / w2[near - 1])]
    return np.concatenate([w2[:k], w2s[k:]]), np.hstack([Phi[:, :k], Phis[:, k:]])


def _roots(W: np.ndarray, Kt: np.ndarray, Ct: np.ndarray, basis: np.ndarray):
    """One root per mode of ÿ + Ct ẏ + Kt y = 0 (modal coordinates y, (n,)).

    First-order form in z = (W y, ẏ), W = diag(W) ≈ diag(ω), so that the matrix is of
    size ω_max, not ω_max² (the low roots keep their accuracy). Each root λ with Im λ ≥ 0
    goes to the column of ``basis`` (n, n) that carries most of its y; a mode takes, of its
    roots, the one with the largest real part (the slower of an overdamped pair, the
    growing one of a divergence). Returns λ (n,) and the y of each (n, n), |z| = 1.
    """
    n = len(W)
    A = np.block([[np.zeros((n, n)), np.diag(W)], [-Kt / W[None, :], -Ct]])
    ev, Z = _eig(A)
    ev = np.where(np.abs(ev) <= 64 * n * _EPS * np.max(np.abs(A)), 0.0, ev)  # zero roots: exactly zero
    keep = ev.imag >= 0
    ev, Y = ev[keep], Z[:n, keep] / W[:, None]
    P = np.abs(np.linalg.lstsq(basis, Y, rcond=None)[0]) ** 2  # (n modes, candidates)
    owner = np.argmax(P, axis=0)
    pick = -np.ones(n, dtype=int)
    for k in range(n):
        mine = np.flatnonzero(owner == k)
        if mine.size:
            pick[k] = mine[np.lexsort((ev[mine].imag, ev[mine].real))[-1]]
    empty, unused = np.flatnonzero(pick < 0), np.setdiff1d(np.arange(ev.size), pick)
    if empty.size:  # strongly coupled modes (e.g. a degenerate pair split by gyroscopic terms)
        rows, cols = scipy.optimize.linear_sum_assignment(-P[np.ix_(empty, unused)])
        pick[empty[rows]] = unused[cols]
    return ev[pick], Y[:, pick]
def modal_analysis(system, q=None, qd=None, *, t: float = 0.0, sensitivities=None) -> Modes:
    """Natural frequencies, damping ratios and mode shapes of the system linearised about (q, q̇) at t.

    M ẍ + C ẋ + K x = 0 with M = A(q), K = −∂f/∂q, C = −∂f/∂q̇ (``q`` in m and rad, default
    0: the undeformed configuration for beams; ``qd`` in m/s and rad/s, default 0; ``t`` in s).
    Prescribed coordinates follow their drives at t, so a steady prescribed spin adds its
    centrifugal (K) and gyroscopic (C) terms; pass an equilibrium q to include the geometric
    stiffness of a preload.

    - ``omega`` (rad/s) and ``shapes`` come from the undamped problem K φ = ω² M φ, solved
      once (in its flexibility form μ = 1/ω² when K is positive definite, which keeps the
      lowest frequency of a stiff beam accurate). With gyroscopic terms (skew part of C) or
      circulatory ones (skew part of K) the undamped problem is M ẍ + G ẋ + K x = 0 with the
      skew part G of C, ω = |λ| and the shapes are the real parts of its complex modes. A
      negative ω² (divergence) is reported as its growth rate √(−ω²).
    - ``damping_ratios``: ζ = φᴴ D φ / (2 ω φᴴ M φ) from the symmetric part D of C (exactly
      c/(2√(km)) for one spring–mass, μω/2 for Kelvin–Voigt damping), > 1 for an overdamped
      mode (whose ω stays the undamped one); 0 for an undamped ω = 0 mode, inf for a damped
      one; −Re λ/|λ| < 0 for a mode whose undamped root grows (−1 for a divergence).
    - ``eigenvalues`` (1/s): per mode, the root of the full quadratic problem det(λ²M + λC + K)
      = 0 with the largest real part (Im ≥ 0): −ζω + iω√(1 − ζ²) for light proportional
      damping, the slower real root of an overdamped mode, iω without damping.

    Closed chains (loop joints, actuators): (q, q̇) must close the loops (``static_equilibrium``
    or ``System.assemble`` find such q). The equations are linearised in the motions the loops
    allow, q = q₀ + N y with N an orthonormal basis of the null space of G = ∂g/∂q (SVD; redundant
    rows allowed): NᵀMN ÿ + NᵀCN ẏ + NᵀK_tN y = 0 with K_t = K − ∂(Gᵀλ)/∂q, the loops' geometric
    stiffness at the multipliers λ of f + Gᵀλ = 0 (least squares: exact at an equilibrium). There
    are nq − rank G modes; ``shapes`` are N φ in the full coordinates, ``basis`` is N and
    ``multipliers`` λ. (About a moving state the rates of G are not linearised.)

    A system without free coordinates (nq = 0) gives empty arrays. Raises ``ValueError`` for
    a bad argument (q or qd that do not close the loops, naming them) and ``SimulationError``
    (naming t) when the mass matrix is singular (it names the coordinates, e.g. Euler angles in
    gimbal lock) or the matrices are not finite.

    ``sensitivities``: named parameters (``System.parameters``) whose derivatives (dω/dp, dζ/dp) at
    this (q, q̇) come with the modes (``Modes.sensitivity(name)``; symmetric problems: no gyroscopic or
    circulatory terms; ``rigidfem.analysis_sensitivities``).
    """
    names = analysis_sensitivities.check_names(system, sensitivities)
    modes = _modal_analysis(system, q, qd, t)
    if names:
        n = system.nq
        qd = np.zeros(n) if qd is None else _checks.array(qd, (n,), "qd")
        modes.sensitivities = analysis_sensitivities.modal(
            system, names, lambda s: _modal_matrices(s, modes.q, qd, _checks.scalar(t, "t"), modes.basis), _undamped)
    return modes


def _modal_matrices(system, q, qd, t, basis):
    """(M, K, C) as modal_analysis forms them (loops: K_t, all in the basis N of the allowed motions)."""
    M = _core._System.mass_matrix(system, t, q)
    dfdq, dfdqd = _core._System.force_jacobians(system, t, q, qd)
    K, C = -dfdq, -dfdqd
    if basis is None:
        return M, K, C
    Kt = _loop_tangent(system, q, qd, t, K, "modal analysis")[1]
    return basis.T @ M @ basis, basis.T @ Kt @ basis, basis.T @ C @ basis


def _modal_analysis(system, q, qd, t) -> Modes:
    t = _checks.scalar(t, "t")
    n = system.nq
    q = np.zeros(n) if q is None else _checks.array(q, (n,), "q")
    qd = np.zeros(n) if qd is None else _checks.array(qd, (n,), "qd")
    if n == 0:
        e = np.zeros((0, 0))
        return Modes(np.zeros(0), np.zeros(0), np.zeros(0), e, np.zeros(0, complex), q, e, e.copy(), e.copy())
    if system.nz:
        warnings.warn(f"rigidfem.modal_analysis: the system's {system.nz} Maxwell arms (Zener/Prony sde laws) are left "
                      "out: K and C are those of the relaxed structure (E = E_inf); rigidfem.linearize keeps the arms' "
                      "forces as states (the eigenvalues of its A are the viscoelastic modes')", UserWarning,
                      stacklevel=3)
    M = _compiled(t, "modal analysis", "mass matrix", _core._System.mass_matrix, system, t, q)
    dfdq, dfdqd = _compiled(t, "modal analysis", "stiffness K = −∂f/∂q or damping/gyroscopic matrix C = −∂f/∂q̇",
                            _core._System.force_jacobians, system, t, q, qd)
    K, C = -dfdq, -dfdqd
    _require_finite(t, "modal analysis", **{"mass matrix": M, "stiffness K = −∂f/∂q": K,
                                            "damping/gyroscopic matrix C = −∂f/∂q̇": C})
    names = system.coordinate_names
    if system.nl:
        return _constrained_modes(system, q, qd, t, M, K, C)
    _check_mass_matrix(M, names, t)
    omega, zeta, shapes, lam = _solved_modes(M, K, C, t)
    order = np.argsort(omega, kind="stable")
    shapes = shapes[:, order] / np.max(np.abs(shapes[:, order]), axis=0)
    return Modes(omega[order], omega[order] / (2 * np.pi), zeta[order], shapes, lam[order], q, M, K, C)


def _loop_tangent(system, q: np.ndarray, qd: np.ndarray, t: float, K: np.ndarray, what: str, tol: float = 1e-8):
    """(constraints G split by its SVD, K_t = K − ∂(Gᵀλ)/∂q (nq, nq), λ (nl,)) of a closed chain at
    (q, q̇): λ the least squares of f + Gᵀλ = 0. ValueError naming q or qd when they do not close the
    loops (to ``tol``: m, or cosines)."""
    g, gd, G = system.loop_constraints(t, q, qd)
    _require_finite(t, what, **{"loop Jacobian G": G, "g(q)": g, "ġ": gd})
    for name, v in (("q", g), ("qd", gd)):
        if np.max(np.abs(v)) > tol:
            raise ValueError(
                f"{name}: expected {'coordinates' if name == 'q' else 'rates'} that close every loop of "
                f"{system.loop_names} (max |g{'' if name == 'q' else 'd'}| = {np.max(np.abs(v)):.3g} > {tol:g} in "
                f"{_worst_loop(system, v)}); rigidfem.static_equilibrium or system.assemble(q, qd, t=t) finds them")
    c = _Constraints.of(G)
    f = system.generalized_forces(t, q, qd)
    _require_finite(t, what, **{"f(q, q̇)": f})
    lam = c.multipliers(-f)
    with np.errstate(over="ignore", invalid="ignore"):  # an overflow is reported by _require_finite
        Kt = K + _constraint_stiffness(system, t, q, lam)
    _require_finite(t, what, **{"geometric stiffness of the loops": Kt})
    return c, Kt, lam


def _constrained_modes(system, q: np.ndarray, qd: np.ndarray, t: float, M: np.ndarray, K: np.ndarray,
                       C: np.ndarray, tol: float = 1e-8) -> Modes:
    """``modal_analysis`` of a closed chain: the modes of NᵀMN, NᵀK_tN, NᵀCN (N: null space of G)."""
    what = "modal analysis"
    c, Kt, lam = _loop_tangent(system, q, qd, t, K, what, tol)
    N = c.N
    k = N.shape[1]
    if k == 0:  # the loops leave nothing free
        e = np.zeros(0)
        return Modes(e, e.copy(), e.copy(), np.zeros((system.nq, 0)), np.zeros(0, complex), q, M, Kt, C, N, lam)
    with np.errstate(over="ignore", invalid="ignore"):  # an overflow is reported by _require_finite
        Mr, Kr, Cr = N.T @ M @ N, N.T @ Kt @ N, N.T @ C @ N
    _require_finite(t, what, **{"reduced stiffness NᵀK_tN": Kr, "reduced damping/gyroscopic matrix NᵀCN": Cr})
    Mr = 0.5 * (Mr + Mr.T)
    _check_mass_matrix(Mr, system.coordinate_names, t, basis=N)
    omega, zeta, phi, ev = _solved_modes(Mr, Kr, Cr, t)
    order = np.argsort(omega, kind="stable")
    shapes = N @ phi[:, order]
    shapes = shapes / np.max(np.abs(shapes), axis=0)
    return Modes(omega[order], omega[order] / (2 * np.pi), zeta[order], shapes, ev[order], q, M, Kt, C, N, lam)


def _solved_modes(M: np.ndarray, K: np.ndarray, C: np.ndarray, t: float):
    """``_modes`` with its failures as SimulationErrors: the eigensolvers' own, and eigenvalues beyond the
    range of doubles (K/M or C²/M² overflowing)."""
    what = "modal analysis"
    try:
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):  # an overflow is reported below
            omega, zeta, shapes, lam = _modes(M, K, C)
    except np.linalg.LinAlgError as err:  # the eigensolvers' own failures, rare after the checks before
        raise SimulationError(f"{_frame(t, what)}: eigensolver failed ({err})") from err
    except ValueError as err:  # SciPy's "array must not contain infs or NaNs": an overflow inside _modes
        raise SimulationError(f"{_frame(t, what)}: the eigenproblem overflowed (largest |K| = "
                              f"{np.max(np.abs(K)):.3g}, |C| = {np.max(np.abs(C)):.3g}: {err})") from err
    if not (np.all(np.isfinite(omega)) and np.all(np.isfinite(lam)) and np.all(np.isfinite(shapes))):
        raise SimulationError(f"{_frame(t, what)}: the eigenvalues overflowed (K/M beyond the range of "
                              f"doubles: largest |K| = {np.max(np.abs(K)):.3g}, smallest mass-matrix diagonal "
                              f"{np.min(np.abs(np.diag(M))):.3g})")
    return omega, zeta, shapes, lam


def _modes(M: np.ndarray, K: np.ndarray, C: np.ndarray):
    """(ω, ζ, shapes, λ) in solver order; see ``modal_analysis``."""
    n = len(M)
    Ks, Ka = 0.5 * (K + K.T), 0.5 * (K - K.T)
    D, G = 0.5 * (C + C.T), 0.5 * (C - C.T)
    k_scale = max(np.max(np.abs(K)), 1e-300)
    # C (its parts) count as absent below 1e-9 of their natural unit sqrt(|K| |M|): the Lagrange
    # engine's central differences leave noise ~1e-12 of it, and round-off in K's symmetry likewise.
    c_small = 1e-9 * np.sqrt(k_scale * np.max(np.abs(M)))
    damped = np.max(np.abs(D)) > c_small
    conservative = np.max(np.abs(G)) <= c_small and np.max(np.abs(Ka)) <= 1e-6 * k_scale
    w2, Phi = _undamped(Ks, M)
    W = np.sqrt(np.abs(w2))
    W = np.where(W > 0, W, max(1e-8 * W.max(), 1e-300) if W.max() > 0 else 1.0)  # scaling only
    if conservative:
        lam0 = np.where(w2 > 0, 1j * np.sqrt(np.abs(w2)), np.sqrt(np.abs(w2)) + 0j)
        Yc = np.eye(n)
        shapes = Phi
    else:  # gyroscopic or circulatory: the undamped problem is not symmetric; solve it in the basis Φ
        lam0, Yc = _roots(W, Phi.T @ K @ Phi, Phi.T @ G @ Phi, np.diag(1 / (np.sqrt(2) * W)))
        lam0 = np.where(np.abs(lam0.imag) <= 1e-12 * np.abs(lam0), lam0.real + 0j, lam0)
        psi = Phi @ Yc
        pivot = psi[np.argmax(np.abs(psi), axis=0), range(n)]
        shapes = (psi * np.exp(-1j * np.angle(pivot))).real
    omega = np.abs(lam0)
    growing = lam0.real > 1e-9 * omega
    zeta = np.where(growing, -lam0.real / np.where(omega > 0, omega, 1.0), 0.0)
    if not damped:
        return omega, zeta, shapes, lam0
    Dm = np.real(np.einsum("ik,ij,jk->k", Yc.conj(), Phi.T @ D @ Phi, Yc))  # φᴴDφ
    Mm = np.real(np.einsum("ik,ik->k", Yc.conj(), Yc))                      # φᴴMφ (ΦᵀMΦ = I)
    with np.errstate(divide="ignore", invalid="ignore"):
        modal = np.where(omega > 0, Dm / (2 * omega * Mm), np.where(Dm > 1e-12 * np.max(np.abs(Dm)), np.inf, 0.0))
    zeta = np.where(growing, zeta, modal)
    # The damped roots go to the undamped modes they are made of (Yc: each of unit energy |z| = 1).
    basis = np.diag(1 / (np.sqrt(2) * W)) if conservative else Yc
    lam, _ = _roots(W, Phi.T @ K @ Phi, Phi.T @ C @ Phi, basis)
    return omega, zeta, shapes, lam
