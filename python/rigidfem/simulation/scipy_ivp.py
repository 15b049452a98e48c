"""SciPy's step-by-step solvers (the OdeSolver classes behind solve_ivp) as ``simulate``'s methods ``"scipy:<name>"``,
with the C++ right-hand side and Jacobian: Python per step, the slow path."""

from __future__ import annotations

import numpy as np

from . import options as options_
from ..base import _checks

#: SciPy's solvers by name (``"scipy:Radau"`` runs ``Radau``): the adapter's methods, ``rigidfem.options.SCIPY``.
SCIPY_METHODS = tuple(m[len("scipy:"):] for m in options_.SCIPY)


class _NonFinite(Exception):
    """The state or its derivative became NaN or inf in a scipy: run (at ``t``)."""

    def __init__(self, t, cause):
        super().__init__(cause)
        self.t, self.cause = float(t), cause


def _run_scipy(system, name, t0, t_end, q0, qd0, t_eval, rtol, atol, max_step, max_steps, keep_going,
               first_step=None):
    """SciPy's step-by-step solvers (the OdeSolver classes behind solve_ivp) with the C++ rhs and
    Jacobian (analytic for recursive systems), stepped here so that max_steps, Ctrl-C and ``stop``
    hold as in the C++ loop (Python per step: the slow path). A state, rate or Jacobian that becomes
    NaN or inf ends the run with a SimulationError at its time, as in the C++ loop. Returns what
    _core._integrate does."""
    import time

    import scipy.integrate

    if name not in SCIPY_METHODS:
        raise _checks.refuse(f"method: expected one of {['scipy:' + m for m in SCIPY_METHODS]}, got 'scipy:{name}'")
    if np.max(rtol) == 0.0 and np.min(atol) == 0.0:
        raise _checks.refuse("atol: expected positive values when rtol is zero")
    n = system.nq
    start = time.perf_counter()
    solver_class = getattr(scipy.integrate, name)

    def finite(evaluate, what):
        """``evaluate`` of the C++ system, raising _NonFinite at t when its state or value is not finite."""
        def checked(t, y):
            if not np.all(np.isfinite(y)):
                raise _NonFinite(t, f"the state became NaN or inf (scipy {name})")
            value = evaluate(t, y)
            if not np.all(np.isfinite(value)):
                raise _NonFinite(t, f"the {what} became NaN or inf (scipy {name})")
            return value
        return checked

    rhs = finite(system.rhs, "accelerations")
    jacobian = finite(system.jacobian, "Jacobian of the rhs")

    options = {"jac": jacobian} if name in ("Radau", "BDF", "LSODA") else {}
    if first_step is not None:
        options["first_step"] = min(first_step, t_end - t0)
    rtol = np.maximum(rtol, 100 * np.finfo(float).eps)  # SciPy's floor, without its warning
    if name in ("Radau", "BDF"):  # one rtol only (their Newton tolerance is a scalar): the strictest
        rtol = np.min(rtol, keepdims=True)
    y0 = np.concatenate([q0, qd0])
    steps, last_check, interrupted, failure, solver = 0, start, False, None, None
    ts, ys = ([t0], [y0]) if not len(t_eval) else ([], [])
    try:
        # overflows are reported as the SimulationError below, not as numpy's RuntimeWarnings
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            solver = solver_class(rhs, t0, y0, t_end, rtol=rtol if rtol.size > 1 else rtol[0],
                                  atol=atol if atol.size > 1 else atol[0], max_step=max_step, **options)
            ts, ys = ([t0], [solver.y.copy()]) if not len(t_eval) else ([], [])
            ts, ys = _scipy_outputs(t_eval, t0, t0, None, solver.y, ts, ys)
            while solver.status == "running":
                if steps >= max_steps:
                    failure = _failure(solver.t, f"max_steps = {max_steps} reached (scipy {name})")
                    break
                if min(max_step, t_end - solver.t) < _smallest_step(solver.t):  # the C++ methods' floor
                    failure = _failure(solver.t, f"the step size fell below the minimum (max_step = {max_step:g} s "
                                                 f"against {_smallest_step(solver.t):g} s at this time; scipy {name})")
                    break
                t_before = solver.t
                message = solver.step()
                if solver.status == "failed":
                    failure = _failure(solver.t, f"scipy {name} failed: {message}")
                    break
                if solver.status == "running" and solver.t - t_before < _smallest_step(t_before):
                    failure = _failure(solver.t, f"the step size fell below the minimum: the problem is too stiff or "
                                                 f"singular for this method (step size {solver.t - t_before:g} s; "
                                                 f"scipy {name})")
                    break
                steps += 1
                dense = solver.dense_output() if len(t_eval) else None
                ts, ys = _scipy_outputs(t_eval, t_before, solver.t, dense, solver.y, ts, ys)
                if keep_going is not None and time.perf_counter() - last_check > 0.05:
                    last_check = time.perf_counter()
                    if not keep_going(solver.t):
                        interrupted = True
                        break
    except KeyboardInterrupt:
        interrupted = True
    except (_NonFinite, ValueError) as e:
        # the state or SciPy's own numbers (its LU refuses the iteration matrix) overflowed: the inputs
        # were checked, so this is a numerical failure, at the last accepted time
        if isinstance(e, ValueError) and "infs or NaNs" not in str(e):
            raise
        last = solver.t if solver is not None else t0
        if isinstance(e, _NonFinite) and np.isfinite(e.t):
            failure = _failure(e.t, e.cause)
        elif isinstance(e, _NonFinite) or not np.isfinite(getattr(solver, "h_abs", np.nan)):
            failure = _failure(last, f"the step size became NaN or inf (scipy {name})" +
                               (" (atol = 0 leaves it no error scale for a component at zero: give atol > 0)"
                                if np.min(atol) == 0.0 else ""))
        else:
            failure = _failure(last, f"the iteration matrix overflowed (scipy {name}: {e})")
    y = np.array(ys).reshape(len(ys), 2 * n)
    count = (lambda key: int(getattr(solver, key))) if solver is not None else (lambda key: 0)
    stats = {"steps": steps, "rejected_steps": -1, "rhs_evaluations": count("nfev"), "jacobians": count("njev"),
             "factorizations": count("nlu"), "newton_iterations": -1, "wall_time": time.perf_counter() - start,
             "stiff_at": float("nan")}
    return np.array(ts, dtype=float), y[:, :n].copy(), y[:, n:].copy(), stats, interrupted, failure


def _scipy_outputs(t_eval, t_before, t_after, dense, y_after, ts, ys):
    """Append the outputs of a step (t_before, t_after]: each requested time it covers by the
    solver's dense output (t_eval given), or the step's end."""
    if not len(t_eval):
        if t_after > t_before:
            ts.append(t_after)
            ys.append(y_after.copy())
        return ts, ys
    lo = np.searchsorted(t_eval, t_before, side="right" if ts else "left")
    hi = np.searchsorted(t_eval, t_after, side="right")
    for tk in t_eval[lo:hi]:
        ts.append(float(tk))
        ys.append(y_after.copy() if tk == t_after or dense is None else dense(tk))
    return ts, ys


def _failure(t, cause):
    """(message, time, cause) of a failed run, as _core._integrate reports it."""
    return f"at t = {t:.10g} s: {cause}", float(t), cause


def _smallest_step(t: float) -> float:
    """The smallest step (s) a run takes at time t, as the C++ methods: 16 ε max(1, |t|), below which t + h
    no longer resolves the step (a step of 1e-300 s, or of less than 3.5 s at t = 1e15 s)."""
    return 16.0 * np.finfo(float).eps * max(1.0, abs(t))
