"""What the analyses about an operating point share: the checks that name a matrix with NaN or inf, the
description of a singular tangent, and the loop closures' constraints (their Jacobian, least-norm multipliers,
geometric stiffness and the basis N of the motions they allow) at a state."""

from __future__ import annotations

from dataclasses import dataclass


import numpy as np
from scipy.linalg import lapack

from ..base import _interrupt
import rigidfem._core as _core  # the compiled core, by its absolute name
from .._core import SimulationError
from ..base import _checks

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


def _require_finite(t: float, what: str, cause: str = "forces, drives or their derivatives overflow at this time "
                                                    "and configuration", **matrices) -> None:
    for name, a in matrices.items():
        if not np.all(np.isfinite(a)):
            raise SimulationError(f"{_frame(t, what)}: {name} has NaN or inf entries ({cause})")


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


def _loop_tangent(system, q: np.ndarray, qd: np.ndarray, t: float, K: np.ndarray, what: str, tol: float = 1e-8):
    """(constraints G split by its SVD, K_t = K − ∂(Gᵀλ)/∂q (nq, nq), λ (nl,)) of a closed chain at
    (q, q̇): λ the least squares of f + Gᵀλ = 0. ValueError naming q or qd when they do not close the
    loops (to ``tol``: m, or cosines)."""
    g, gd, G = system.loop_constraints(t, q, qd)
    _require_finite(t, what, **{"loop Jacobian G": G, "g(q)": g, "ġ": gd})
    for name, v in (("q", g), ("qd", gd)):
        if np.max(np.abs(v)) > tol:
            raise _checks.refuse(
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
