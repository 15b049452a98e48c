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


import numpy as np
from scipy.linalg import lapack

from ..base import _checks, _interrupt
import rigidfem._core as _core  # the compiled core, by its absolute name
from . import analysis_sensitivities
from .._core import SimulationError
from ..base.persistence import Versioned

# The dense LAPACK routines of the analyses, answering Ctrl-C while they run (_interrupt).
_eigh = _interrupt.eigh
_eig = _interrupt.responsive(np.linalg.eig)
_getrf = _interrupt.responsive(lapack.dgetrf)
from .operating_point import (_close_loops, _compiled, _constraint_stiffness, _Constraints, _describe_null_space,
                              _frame, _loop_jacobian, _RCOND_SINGULAR, _require_finite,
                              _row_scale, _worst_loop)

@dataclass
class Equilibrium(Versioned):
    """Result of ``static_equilibrium``.

    Examples
    --------
    >>> import rigidfem as rf
    >>> model, h = rf.samples.spring_mass()
    >>> eq = rf.static_equilibrium(model.compile())
    >>> eq.converged, eq.q.round(6)
    (True, array([0.]))
    """

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
            raise _checks.refuse(f"name: expected one of the sensitivities asked for {list(self.sensitivities)}, got {name!r}")
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
        raise _checks.refuse(f"{name}: expected an integer >= 1, got {v}")
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
    ``rigidfem.analysis.analysis_sensitivities``).

    Examples
    --------
    >>> import rigidfem as rf
    >>> model, h = rf.samples.cantilever(elements=4)
    >>> eq = rf.static_equilibrium(model.compile())
    >>> eq.converged, eq.q.shape
    (True, (4,))
    """
    system = _checks.system(system)
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
