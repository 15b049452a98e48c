"""``rf.simulate``: time integration in C++ (book ch. 5.2) with results as numpy arrays.

Methods (``method=``):

=====================  =========================================================  ===========
name                   scheme                                                     step
=====================  =========================================================  ===========
``"euler"``            explicit Euler, order 1                                    fixed ``dt``
``"symplectic_euler"`` semi-implicit Euler (q̇ first, then q), order 1             fixed ``dt``
``"rk4"``              classical Runge–Kutta, order 4                             fixed ``dt``
``"dopri5"``           Dormand–Prince 5(4), dense output of order 4               ``rtol``/``atol``
``"rkf45"``            Runge–Kutta–Fehlberg 4(5) (the book's), 4th order kept     ``rtol``/``atol``
``"newmark"``          Newmark β, γ (average acceleration ¼, ½), Newton           ``dt`` or adaptive
``"hht"``              Hilber–Hughes–Taylor α ∈ [−⅓, 0], Newton                   ``dt`` or adaptive
``"generalized_alpha"`` Chung–Hulbert generalised-α with ρ∞, Newton                ``dt`` or adaptive
``"implicit_spring"``  generalised-α whose Newton matrix is                       ``dt`` or adaptive
                       M + diag(γ′h b + β′h² c), O(n) per iteration (ABA)
``"scipy:Radau"`` …    SciPy's ``solve_ivp`` (Radau, BDF, LSODA) with the C++      ``rtol``/``atol``
                       ``rhs`` and ``jacobian`` (Python per step: the slow path)
=====================  =========================================================  ===========

The implicit methods solve M(q) q̈ = f(q, q̇, t) at the end of each step by Newton's
method with the iteration matrix M + γ′h ∂r/∂q̇ + β′h² ∂r/∂q of the residual
r = M q̈ − f (∂r/∂q holds K = −∂f/∂q, ∂r/∂q̇ is C = −∂f/∂q̇), reused while it converges:
analytic for the default recursive engine, by central differences for
``compile(algorithm="lagrange")``. ``implicit_spring`` keeps only its diagonal
springs c and dampers b. ``adaptive=True`` controls their step by the local error
estimate h²(β − 1/6)(a_{n+1} − a_n).
"""

from __future__ import annotations

import functools
import warnings
from dataclasses import dataclass, field

import numpy as np

from . import _checks, _core
from ._core import Body, Point

SCIPY_METHODS = ("Radau", "BDF", "LSODA", "RK45", "DOP853")


@dataclass
class Result:
    """A simulation's output at the times ``t`` (s).

    ``q``, ``qd`` are (len(t), nq) in m, rad and per s; the other arrays are computed
    from them on first use: ``qdd`` (len(t), nq), ``driving_forces`` (len(t), np; N or
    N·m), energies (len(t),; J). ``stats`` holds steps, rejected_steps, rhs_evaluations,
    jacobians, factorizations, newton_iterations and wall_time (s).
    """

    system: object = field(repr=False)
    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    stats: dict
    method: str
    interrupted: bool = False

    @functools.cached_property
    def _outputs(self):
        return _core._evaluate_outputs(self.system, self.t, self.q, self.qd)

    @property
    def qdd(self) -> np.ndarray:
        return self._outputs[0]

    @property
    def driving_forces(self) -> np.ndarray:
        """Forces/torques of the drives (len(t), np), in ``system.prescribed_names`` order."""
        return self._outputs[1]

    @property
    def kinetic_energy(self) -> np.ndarray:
        return self._outputs[2]

    @property
    def gravity_energy(self) -> np.ndarray:
        return self._outputs[3]

    @property
    def elastic_energy(self) -> np.ndarray:
        return self._outputs[4]

    @property
    def potential_energy(self) -> np.ndarray:
        return self._outputs[3] + self._outputs[4]

    @property
    def energy(self) -> np.ndarray:
        """Kinetic + gravity + elastic energy (J)."""
        return self._outputs[2] + self._outputs[3] + self._outputs[4]

    def position(self, point, frame: Body | None = None) -> np.ndarray:
        """Positions (len(t), 3) in m of a ``Point`` (or a ``Body``'s origin), in the global
        frame or in the frame of the body ``frame``."""
        if isinstance(point, Body):
            point = point.origin
        if not isinstance(point, Point):
            raise ValueError(f"point: expected a Point or a Body, got {point!r}")
        if frame is not None and not isinstance(frame, Body):
            raise ValueError(f"frame: expected None or a Body, got {frame!r}")
        return _core._point_positions(self.system, point.body, point.r, -1 if frame is None else frame.index,
                                      self.t, self.q)

    def __repr__(self) -> str:
        s = self.stats
        return (f"<rigidfem Result {self.method}: {len(self.t)} outputs to t = {self.t[-1]:g} s, {s['steps']} steps "
                f"({s['rejected_steps']} rejected), {s['rhs_evaluations']} rhs, {s['wall_time']:.3g} s"
                f"{', interrupted' if self.interrupted else ''}>")


def simulate(system, t_end: float, method: str = "dopri5", dt: float | None = None, rtol=1e-6,
             atol=1e-9, t_eval=None, q0=None, qd0=None, t0: float = 0.0, progress: bool = False,
             first_step: float | None = None, stiffness_warning: bool = True,
             max_steps: int = 1_000_000, max_step: float = np.inf, adaptive: bool | None = None, beta: float = 0.25,
             gamma: float = 0.5, alpha: float = -0.05, rho_inf: float = 0.8, newton_tol: float = 1e-10,
             newton_max_iterations: int = 10, iteration_matrix: str = "auto") -> Result:
    """Integrate ``system`` from ``t0`` to ``t_end`` (s) in C++ (no Python per step).

    Parameters
    ----------
    method : str
        See the module docstring: "euler", "symplectic_euler", "rk4", "dopri5", "rkf45",
        "newmark", "hht", "generalized_alpha", "implicit_spring", or "scipy:Radau", "scipy:BDF",
        "scipy:LSODA". "implicit_spring" is generalised-α (``rho_inf``) whose Newton matrix
        holds only the coordinates' springs and dampers, M + diag(γ'h b + β'h² c): the
        articulated-body algorithm solves it in O(n), so a stiff beam takes steps far beyond
        the explicit stability limit at O(n) per Newton iteration.
    dt : float
        Step (s) of the fixed-step methods.
    rtol, atol : float or (2 nq,) array
        Error control of adaptive methods, per component of y = [q, q̇] (m, rad; per s).
    first_step : float, optional
        First step (s) of an adaptive run; estimated (Hairer's rule) by default.
    stiffness_warning : bool
        dopri5 runs Hairer's stiffness test (h ρ > 3.25 over 15 accepted steps): its step is
        then bounded by stability, so it costs ~t ω_max/3.3 steps, and at loose tolerances
        the stiff modes keep errors ~rtol ω_max/ω. It warns (RuntimeWarning) and records the
        time in ``stats["stiff_at"]``; ``False`` keeps the record and drops the warning.
    t_eval : array, optional
        Output times (within [t0, t_end]) by dense output; default: every step.
    q0, qd0 : (nq,) arrays
        Initial state (m, rad; per s); zeros by default.
    progress : bool
        Show a progress bar (tqdm when installed).
    max_steps, max_step
        Limits: a run that needs more steps raises SimulationError.
    adaptive : bool, optional
        Step-size control: on by default for dopri5 and rkf45 (``False`` runs them at the
        fixed step ``dt``), off by default for the Newmark family (``True`` switches on its
        local error estimate).
    beta, gamma, alpha, rho_inf
        Newmark's β, γ; HHT's α ∈ [−1/3, 0]; generalised-α's spectral radius ρ∞ ∈ [0, 1].
    newton_tol, newton_max_iterations
        Newton stops when the increments of q and q̇ fall below newton_tol (1 + |q|).
    iteration_matrix : str
        Newton matrix of the Newmark family: "tangent" (the exact tangent
        M + γ'h ∂r/∂q̇ + β'h² ∂r/∂q, analytic for recursive systems, dense LU), "spring" (the
        O(n) matrix of "implicit_spring") or "auto" (spring for implicit_spring, else tangent).

    Returns
    -------
    Result

    Raises
    ------
    SimulationError
        With the time, the step size and the cause (step size underflow, NaN state,
        Newton divergence, singular matrix, max_steps). Ctrl-C returns the partial result
        with a RuntimeWarning instead.
    """
    n = system.nq
    q0 = np.zeros(n) if q0 is None else _checks.array(q0, (n,), "q0")
    qd0 = np.zeros(n) if qd0 is None else _checks.array(qd0, (n,), "qd0")
    t0 = _checks.scalar(t0, "t0")
    t_end = _checks.scalar(t_end, "t_end")
    if not t_end > t0:
        raise ValueError(f"t_end: expected a time after t0 = {t0} s, got {t_end}")
    t_eval = np.zeros(0) if t_eval is None else _checks.vector(t_eval, "t_eval")
    if method.startswith("scipy:"):
        return _simulate_scipy(system, method[6:], t0, t_end, q0, qd0, t_eval, rtol, atol, max_step)
    opt = _core.IntegratorOptions()
    opt.method = method
    opt.dt = 0.0 if dt is None else _checks.scalar(dt, "dt", positive=True)
    if first_step is not None:
        opt.dt = _checks.scalar(first_step, "first_step", positive=True)
    opt.rtol = _tolerance(rtol, "rtol", n)
    opt.atol = _tolerance(atol, "atol", n)
    opt.max_step = float(max_step)
    opt.max_steps = int(max_steps)
    opt.adaptive = -1 if adaptive is None else int(bool(adaptive))
    opt.beta, opt.gamma, opt.alpha, opt.rho_inf = float(beta), float(gamma), float(alpha), float(rho_inf)
    opt.newton_tol = _checks.scalar(newton_tol, "newton_tol", positive=True)
    opt.newton_max_iterations = int(newton_max_iterations)
    opt.iteration_matrix = iteration_matrix
    bar = _ProgressBar(t0, t_end) if progress else None
    try:
        t, q, qd, stats, interrupted = _core._integrate(system, t0, t_end, q0, qd0, t_eval, opt, bar)
    finally:
        if bar is not None:
            bar.close()
    if stiffness_warning and np.isfinite(stats.get("stiff_at", np.nan)):
        warnings.warn(f"{method}: the problem is stiff from t = {stats['stiff_at']:.6g} s on (h rho > 3.25): the step is "
                      "bounded by stability, the cost grows with the highest frequency and loose tolerances leave "
                      "errors in the stiff modes; an implicit method (generalized_alpha, newmark, scipy:Radau) is "
                      "cheaper here", RuntimeWarning, stacklevel=2)
    if interrupted:
        warnings.warn(f"simulation interrupted at t = {t[-1] if len(t) else t0:g} s: returning the partial result",
                      RuntimeWarning, stacklevel=2)
    return Result(system, t, q, qd, stats, method, interrupted)


def _tolerance(x, name, n) -> np.ndarray:
    tol = np.atleast_1d(np.asarray(x, dtype=float))
    if tol.ndim != 1 or tol.size not in (1, 2 * n) or not np.all(np.isfinite(tol)) or np.any(tol < 0):
        raise ValueError(f"{name}: expected a non-negative number or {2 * n} (2 nq) of them, got {x!r}")
    return tol


def _simulate_scipy(system, name, t0, t_end, q0, qd0, t_eval, rtol, atol, max_step) -> Result:
    """SciPy's solve_ivp with the C++ rhs and Jacobian (analytic for recursive systems; slow path)."""
    import time

    from scipy.integrate import solve_ivp

    if name not in SCIPY_METHODS:
        raise ValueError(f"method: expected one of {['scipy:' + m for m in SCIPY_METHODS]}, got 'scipy:{name}'")
    start = time.perf_counter()
    jac = system.jacobian if name in ("Radau", "BDF", "LSODA") else None
    sol = solve_ivp(system.rhs, (t0, t_end), np.concatenate([q0, qd0]), method=name, rtol=rtol, atol=atol,
                    t_eval=t_eval if len(t_eval) else None, jac=jac, max_step=max_step, dense_output=False)
    wall = time.perf_counter() - start
    if not sol.success:
        raise _core.SimulationError(f"at t = {sol.t[-1]} s: scipy {name} failed: {sol.message}")
    n = system.nq
    stats = {"steps": len(sol.t) - 1 if not len(t_eval) else -1, "rejected_steps": -1, "rhs_evaluations": int(sol.nfev),
             "jacobians": int(sol.njev), "factorizations": int(sol.nlu), "newton_iterations": -1, "wall_time": wall,
             "stiff_at": float("nan")}
    return Result(system, sol.t, sol.y[:n].T.copy(), sol.y[n:].T.copy(), stats, "scipy:" + name)


class _ProgressBar:
    """tqdm when installed, otherwise a line on stderr; updated from the C++ loop's monitor."""

    def __init__(self, t0, t_end):
        self.t0, self.t_end = t0, t_end
        try:
            from tqdm.auto import tqdm

            self.bar = tqdm(total=t_end - t0, unit="s", desc="simulate")
        except ImportError:
            self.bar = None

    def __call__(self, t):
        if self.bar is not None:
            self.bar.update(t - self.t0 - self.bar.n)
        else:
            import sys

            print(f"\rsimulate: t = {t:.4g} of {self.t_end:g} s", end="", file=sys.stderr, flush=True)

    def close(self):
        if self.bar is not None:
            self.bar.close()
        else:
            import sys

            print(file=sys.stderr)
