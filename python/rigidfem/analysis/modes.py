"""``rf.modal_analysis``: the modes of the linearised equations of motion at an operating point (book ch. 5.3):
M δq̈ + C δq̇ + K δq = 0 with K = −∂f/∂q and C = −∂f/∂q̇ (the tangent of ``System.force_jacobians``); closed loops
reduce them to the basis N of the motions the loops allow (with the loops' geometric stiffness)."""

from __future__ import annotations

from dataclasses import dataclass, field

import warnings

import numpy as np
import scipy.linalg
import scipy.optimize
from scipy.linalg import lapack

from ..base import _checks, _interrupt, display, export
import rigidfem._core as _core  # the compiled core, by its absolute name
from . import analysis_sensitivities
from .._core import SimulationError
from ..base.persistence import Versioned

# The dense LAPACK routines of the analyses, answering Ctrl-C while they run (_interrupt).
_eigh = _interrupt.eigh
_eig = _interrupt.responsive(np.linalg.eig)
_getrf = _interrupt.responsive(lapack.dgetrf)
from .operating_point import (_compiled, _describe_null_space, _EPS, _frame, _loop_tangent, _potrf, _RCOND_MASS,
                              _require_finite)

@dataclass
class Modes(Versioned):
    """Result of ``modal_analysis``: one entry per mode (k = nq, or nq − rank G with loops), sorted
    by natural frequency.

    Examples
    --------
    >>> import rigidfem as rf
    >>> model, h = rf.samples.cantilever(elements=4)
    >>> modes = rf.modal_analysis(model.compile())
    >>> len(modes.omega), round(float(modes.frequencies_hz[0]), 2)
    (4, 16.95)
    """

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
            raise _checks.refuse(f"name: expected one of the sensitivities asked for {list(self.sensitivities)}, got {name!r}")
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
    circulatory terms; ``rigidfem.analysis.analysis_sensitivities``).

    Examples
    --------
    >>> import rigidfem as rf
    >>> model, h = rf.samples.spring_mass()
    >>> modes = rf.modal_analysis(model.compile())
    >>> modes.omega.round(3)
    array([20.])
    """
    system = _checks.system(system)
    names = analysis_sensitivities.check_names(system, sensitivities)
    modes = _modal_analysis(system, q, qd, t)
    if names:
        n = system.nq
        qd = np.zeros(n) if qd is None else _checks.array(qd, (n,), "qd")
        modes.sensitivities = analysis_sensitivities.modal(
            system, names, lambda s: _modal_matrices(s, modes.q, qd, _checks.scalar(t, "t"), modes.basis), _undamped)
    modes._system = system  # for rf.view(modes) (not a field: not pickled)
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
