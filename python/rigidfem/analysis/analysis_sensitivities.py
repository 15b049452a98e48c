"""Derivatives of static equilibria and of natural frequencies and damping ratios by named parameters
(``static_equilibrium(..., sensitivities=[...])``, ``modal_analysis(..., sensitivities=[...])``).

Every matrix involved — the static forces f, the mass matrix M, the stiffness K = −∂f/∂q, the damping C =
−∂f/∂q̇, and with loops the geometric stiffness −∂(Gᵀλ)/∂q at the multipliers λ (linear in f) — is linear in
the constants a parameter sets (``rigidfem.parameters``), so their derivatives are the differences
(X(p + h) − X(p))/h of the system at p + h, exact to round-off.

Statics: at an equilibrium f(q*; p) = 0 (with loops f + Gᵀλ = 0, g(q*) = 0),

    K_t dq*/dp = ∂f/∂p        (loops: dq*/dp = N (NᵀK_tN)⁻¹ Nᵀ ∂f/∂p, N the null space of G).

Modes, for the symmetric problem K φ = ω² M φ (φᵀMφ = 1; loops: in the null space N) at the given (q, q̇)
held fixed:

    dω²_i/dp = φ_iᵀ (dK − ω_i² dM) φ_i,
    ζ_i = φ_iᵀ D φ_i / (2 ω_i):  dζ_i/dp = (φ_iᵀ dD φ_i + 2 φ_iᵀ D dφ_i)/(2 ω_i) − ζ_i (dω_i/dp)/ω_i,
    dφ_i = Σ_{j: ω_j ≠ ω_i} φ_jᵀ(dK − ω_i² dM)φ_i / (ω_i² − ω_j²) φ_j − ½ (φ_iᵀ dM φ_i) φ_i.

Within a group of equal frequencies (a symmetric section's two bending planes) the derivatives are those of
the eigenvalues of Φ_cᵀ(dK − ω² dM)Φ_c, ascending: for an increasing parameter the group splits in that
order (one-sided derivatives: a repeated frequency is not differentiable). Modes with gyroscopic or
circulatory terms (a spinning base) are not covered (ValueError). The modes of a preloaded structure are
differentiated at its q held fixed; where q is an equilibrium that moves with p, its own change adds
(dK/dq)(dq*/dp).
"""

from __future__ import annotations

import numpy as np

from ..model import parameters as parameters_
from ..base import _checks


def _changed(system, name: str, argument: str):
    """(system at p + h, h) of a named parameter; ValueError naming ``argument`` for an unknown one or one of a
    profile (a motion in time: statics and modes hold the drives at t)."""
    params = system._parameters
    if not params.parameter(name, argument).linear:
        raise _checks.refuse(f"{argument}: expected a parameter the equations are linear in (statics and modes at one "
                             f"t difference it one-sidedly), got {name!r}, a profile's number or a contact's "
                             "restitution")
    h = params.step(name)
    return params.shifted(system, name, h), h


def check_names(system, names, argument: str = "sensitivities") -> list[str]:
    """The parameters' names of a ``sensitivities`` argument; ValueError naming it for anything else."""
    names = parameters_.names_argument(names, argument)
    for name in names:
        system._parameters.parameter(name, argument)
    return names


def static(system, names: list[str], Kt: np.ndarray, N, forces) -> dict[str, np.ndarray]:
    """{name: dq*/dp (nq,)} at an equilibrium with the tangent stiffness K_t (nq, nq), the loops' null space N
    (None without loops) and ``forces(system)``, the static forces f (nq,) of a system there."""
    f = forces(system)
    out = {}
    for name in names:
        plus, h = _changed(system, name, "sensitivities")
        df = (forces(plus) - f) / h
        if N is None:
            out[name] = np.linalg.solve(Kt, df)
        else:  # the loops carry ∂f/∂p along G: only its part in the allowed motions moves q
            out[name] = N @ np.linalg.solve(N.T @ Kt @ N, N.T @ df)
    return out


def modal(system, names: list[str], matrices, undamped) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """{name: (dω/dp, dζ/dp), each (k,)} of the modes of ``matrices(system)`` = (M, K, C) as modal_analysis forms
    them (reduced to the loops' null space), ``undamped(K, M)`` its undamped solver (ω² ascending, Φ)."""
    M, K, C = matrices(system)
    Ks, D, G = 0.5 * (K + K.T), 0.5 * (C + C.T), 0.5 * (C - C.T)
    scale = np.sqrt(max(np.max(np.abs(K)), 1e-300) * np.max(np.abs(M)))
    if np.max(np.abs(G)) > 1e-9 * scale or np.max(np.abs(K - K.T)) > 1e-6 * np.max(np.abs(K)):
        raise _checks.refuse("sensitivities: expected modes without gyroscopic or circulatory terms (the derivatives of "
                         "a spinning or non-conservative system's modes are not implemented), got a skew part in C "
                         "or K")
    w2, Phi = undamped(Ks, 0.5 * (M + M.T))
    omega = np.sqrt(np.abs(w2))
    order = np.argsort(omega, kind="stable")
    w2, Phi, omega = w2[order], Phi[:, order], omega[order]
    groups = _groups(w2)
    out = {}
    for name in names:
        plus, h = _changed(system, name, "sensitivities")
        M1, K1, C1 = matrices(plus)
        dM, dK, dD = (M1 - M) / h, (0.5 * (K1 + K1.T) - Ks) / h, (0.5 * (C1 + C1.T) - D) / h
        dw2, P = np.zeros(len(w2)), Phi.copy()
        for g in groups:  # within a group of equal ω²: the eigenvalues of Φ_cᵀ(dK − ω² dM)Φ_c, ascending
            Pc = Phi[:, g]
            A = Pc.T @ (dK - w2[g[0]] * dM) @ Pc
            vals, vecs = np.linalg.eigh(0.5 * (A + A.T))
            dw2[g], P[:, g] = vals, Pc @ vecs
        with np.errstate(divide="ignore", invalid="ignore"):  # ω = √|ω²|: a divergence's grows as −ω² does
            domega = np.where(omega > 0, np.sign(w2) * dw2 / (2 * omega), 0.0)
        dzeta = np.where(w2 > 0, 0.0, np.nan)  # ζ of a divergence or a zero mode: not differentiated
        group_of = {i: k for k, g in enumerate(groups) for i in g}
        for i in range(len(w2)):
            if not w2[i] > 0:
                continue
            phi = P[:, i]
            others = np.array([j for j in range(len(w2)) if group_of[j] != group_of[i]], dtype=int)
            coefficient = np.zeros(len(w2))
            coefficient[others] = (P[:, others].T @ ((dK - w2[i] * dM) @ phi)) / (w2[i] - w2[others])
            dphi = P @ coefficient - 0.5 * (phi @ dM @ phi) * phi
            zeta = phi @ D @ phi / (2 * omega[i])
            dzeta[i] = (phi @ dD @ phi + 2 * phi @ D @ dphi) / (2 * omega[i]) - zeta * domega[i] / omega[i]
        out[name] = (domega, dzeta)
    return out


def _groups(w2: np.ndarray, rtol: float = 1e-8) -> list[list[int]]:
    """Indices of equal ω² (to rtol of their size), in order."""
    groups = [[0]] if len(w2) else []
    for i in range(1, len(w2)):
        if abs(w2[i] - w2[groups[-1][0]]) <= rtol * max(abs(w2[i]), abs(w2[groups[-1][0]])):
            groups[-1].append(i)
        else:
            groups.append([i])
    return groups
