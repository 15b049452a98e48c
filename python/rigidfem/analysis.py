"""Statics and modal analysis of a compiled System.

Both linearise the book's equations A(q) q̈ = f(q, q̇, t) about a configuration with
the force Jacobians of ``System.force_jacobians`` (in C++: analytic for the default
recursive engine, central differences for ``compile(algorithm="lagrange")``):
K = −∂f/∂q (tangent stiffness: springs, gravity and preload, centrifugal terms of a
prescribed spin) and C = −∂f/∂q̇ (dampers, gyroscopic terms).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.linalg

from . import _checks
from ._core import SimulationError


@dataclass
class Equilibrium:
    """Result of ``static_equilibrium``."""

    q: np.ndarray            #: (nq,) equilibrium coordinates, m and rad
    converged: bool          #: always True: a load step that does not converge raises SimulationError
    iterations: int          #: Newton iterations over all load steps
    residual: float          #: max |f(q)| at the end, N or N·m
    load_steps: int
    history: list = field(default_factory=list, repr=False)  #: (load factor, iterations, residual) per step


def static_equilibrium(system, q0=None, t: float = 0.0, load_steps: int = 10, tol: float = 1e-10,
                       max_iterations: int = 50) -> Equilibrium:
    """Solve f(q) = 0 by Newton's method with load stepping.

    Gravity, point forces, torques and applied generalised forces are scaled together
    by λ = 1/n, 2/n, ..., 1 (n = ``load_steps``); each step starts from the previous
    one's solution. Prescribed coordinates are held at their values at time ``t`` (s),
    at rest. A step converges when the Newton correction satisfies
    max |Δq| ≤ tol · max(1, max |q|) (m and rad).

    Raises ``SimulationError`` when Newton does not converge within ``max_iterations``
    in a load step or the tangent stiffness is singular.
    """
    n = system.nq
    q = np.zeros(n) if q0 is None else _checks.array(q0, (n,), "q0").copy()
    steps = int(load_steps)
    if steps < 1:
        raise ValueError(f"load_steps: expected an integer >= 1, got {load_steps}")
    tol = _checks.scalar(tol, "tol", positive=True)
    history, total = [], 0
    for k in range(1, steps + 1):
        lam = k / steps
        f = system.static_forces(t, q, lam)
        for it in range(1, max_iterations + 1):
            K = -system.force_jacobians(t, q, np.zeros(n), lam, True)[0]
            try:
                dq = scipy.linalg.solve(K, f)
            except (scipy.linalg.LinAlgError, ValueError):
                raise SimulationError(f"at t = {t} s: statics: tangent stiffness singular at load factor {lam:.4g} "
                                      "(a mechanism, or a buckling/limit point)") from None
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
            raise SimulationError(f"at t = {t} s: statics: Newton did not converge in {max_iterations} iterations at "
                                  f"load factor {lam:.4g} (residual {np.max(np.abs(f)):.3e}); try more load_steps")
        history.append((lam, it, float(np.max(np.abs(f)))))
    return Equilibrium(q, True, total, float(np.max(np.abs(f))), steps, history)


@dataclass
class Modes:
    """Result of ``modal_analysis``, modes sorted by natural frequency."""

    omega: np.ndarray           #: (k,) natural (undamped) circular frequencies |λ|, rad/s
    frequencies_hz: np.ndarray  #: (k,) omega / 2π, Hz
    damping_ratios: np.ndarray  #: (k,) ζ = −Re λ / |λ| (zero without damping, negative when unstable)
    shapes: np.ndarray          #: (nq, k) mode shapes (real parts), max |entry| = 1
    eigenvalues: np.ndarray     #: (k,) λ = −ζω + iω√(1 − ζ²); Re λ > 0 marks an unstable mode
    q: np.ndarray               #: (nq,) configuration linearised about

    @property
    def stable(self) -> bool:
        """No eigenvalue with a positive real part (to 1e-9 of its modulus)."""
        return bool(np.all(self.eigenvalues.real <= 1e-9 * np.abs(self.eigenvalues)))
    M: np.ndarray = field(repr=False)  #: (nq, nq) mass matrix
    K: np.ndarray = field(repr=False)  #: (nq, nq) tangent stiffness −∂f/∂q
    C: np.ndarray = field(repr=False)  #: (nq, nq) −∂f/∂q̇


def modal_analysis(system, q=None, qd=None, t: float = 0.0) -> Modes:
    """Natural frequencies and mode shapes of the system linearised about (q, q̇) at t.

    M ẍ + C ẋ + K x = 0 with M = A(q), K = −∂f/∂q, C = −∂f/∂q̇. Default q = 0 (the
    undeformed configuration for beams), q̇ = 0; prescribed coordinates follow their
    drives at t, so a steady prescribed spin adds its centrifugal (K) and gyroscopic
    (C) terms; pass an equilibrium q to include the geometric stiffness of a preload.
    Without C the symmetric problem K φ = ω² M φ is solved; otherwise the first-order
    (state-space) one, giving damped eigenvalues.
    """
    n = system.nq
    q = np.zeros(n) if q is None else _checks.array(q, (n,), "q")
    qd = np.zeros(n) if qd is None else _checks.array(qd, (n,), "qd")
    M = system.mass_matrix(q, t)
    dfdq, dfdqd = system.force_jacobians(t, q, qd)
    K, C = -dfdq, -dfdqd
    scale = max(np.max(np.abs(K)), 1e-300)
    # C counts as absent below 1e-9 of its natural unit sqrt(|K| |M|) (the Lagrange engine's central
    # differences leave noise ~1e-12 of it); the symmetric solver is then far more accurate for the
    # low modes of stiff beams.
    if np.max(np.abs(C)) <= 1e-9 * np.sqrt(scale * np.max(np.abs(M))) and \
            np.max(np.abs(K - K.T)) <= 1e-6 * scale:
        w2, X = scipy.linalg.eigh(0.5 * (K + K.T), M)
        # λ = ±iω for ω² > 0; a negative ω² is a divergence, reported by its growing root λ = +sqrt(−ω²).
        lam = np.where(w2 >= 0, 1j * np.sqrt(np.abs(w2)), np.sqrt(np.abs(w2)) + 0j)
        omega = np.abs(lam)
        zeta = -lam.real / np.where(omega > 0, omega, 1.0)
        shapes = X
    else:
        Minv = np.linalg.inv(M)
        S = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ K, -Minv @ C]])
        ev, V = np.linalg.eig(S)
        keep = ev.imag >= -1e-12 * np.abs(ev)  # one of each conjugate pair
        ev, V = ev[keep], V[:n, keep]
        order = np.argsort(np.abs(ev))
        lam, V = ev[order][:n], V[:, order][:, :n]
        omega = np.abs(lam)
        zeta = -lam.real / np.where(omega > 0, omega, 1.0)
        shapes = (V * np.exp(-1j * np.angle(V[np.argmax(np.abs(V), axis=0), range(V.shape[1])]))).real
    order = np.argsort(np.abs(omega))
    shapes = shapes[:, order]
    shapes = shapes / np.max(np.abs(shapes), axis=0)
    return Modes(omega[order], omega[order] / (2 * np.pi), zeta[order], shapes, lam[order], q, M, K, C)
