"""What the peer benchmark drivers (``kane_peers``, ``loop_peers``, ``strip_peers``, ``sweep_peers``,
and those built on them) share: importing a peer code, the versions line, a sweep's first
timed run of a setting, the interleaved timing of the settings worth timing, the cheapest
setting per code and threshold, the summary table of the cheapest settings, Exudyn's
fixed-step simulation settings and solve, and MuJoCo's stepping between outputs.

The rows these functions read and write are dicts, one per run of a code at a setting, with at
least ``code``, ``method``, ``setting`` (the name of the swept setting, e.g. ``"dt"`` or
``"rtol"``), ``value``, an error column (its name is the caller's: ``key``), ``first_cpu_s``
(the first run's CPU time, s), ``cpu_s`` (the least CPU time, s) and ``note``. CPU time is
``time.process_time``.
"""

from __future__ import annotations

import itertools
import time
import warnings
from typing import Callable, Iterable, Mapping

import numpy as np

import rigidfem
from rigidfem import SimulationError
from rigidfem.studies.study import Table

from ._common import machine
from .peers import _require

#: How to install the peer codes, said by ``require_peer``'s ImportError.
INSTALL_HINT = 'pip install ".[benchmarks]" (or: pip install exudyn mujoco)'
#: The codes of a driver comparing rigidfem against its two peers; the first is the baseline of the ratios.
CODES = ("rigidfem", "Exudyn", "MuJoCo")


# ---------------------------------------------------------------------------------------------
# The peer codes
# ---------------------------------------------------------------------------------------------

def require_peer(driver: str, module: str, package: str, hint: str = INSTALL_HINT):
    """Import the peer code ``module`` (e.g. ``"exudyn"``) for the benchmark driver ``driver``
    (e.g. ``"kane_peers"``), or raise an ImportError "benchmarks.<driver> needs '<package>':
    <hint>" (``python -m benchmarks`` prints it and exits)."""
    try:
        return _require(module, package)
    except ImportError as e:
        raise ImportError(f"benchmarks.{driver} needs '{package}': {hint}") from e


def peer_guard(driver: str, hint: str = INSTALL_HINT) -> Callable:
    """``require_peer`` for one driver: a function ``(module, package) -> module``, e.g.
    ``_peer = peer_guard("kane_peers")`` then ``exu = _peer("exudyn", "exudyn")``."""
    def peer(module: str, package: str):
        return require_peer(driver, module, package, hint)
    peer.__doc__ = f"Import a peer code for benchmarks.{driver}, or raise an ImportError saying how to install it."
    return peer


def versions(peer: Callable | None = None) -> dict:
    """{"rigidfem", "exudyn", "mujoco", "numpy"} -> version, the peers imported by ``peer``
    (a ``peer_guard`` function; default: ``peer_guard("peers")``)."""
    peer = peer or peer_guard("peers")
    exu, mujoco = peer("exudyn", "exudyn"), peer("mujoco", "mujoco")
    return {"rigidfem": rigidfem.__version__, "exudyn": exu.__version__, "mujoco": mujoco.__version__,
            "numpy": np.__version__}


def versions_line(info: Mapping) -> str:
    """The line a driver prints first: "rigidfem V, Exudyn V, MuJoCo V, numpy V[, <other> V ...];
    machine: ..." from ``versions()`` (other keys of ``info`` follow numpy, in their order)."""
    names = {"rigidfem": "rigidfem", "exudyn": "Exudyn", "mujoco": "MuJoCo", "numpy": "numpy"}
    parts = [f"{names[k]} {info[k]}" for k in names] + [f"{k} {v}" for k, v in info.items() if k not in names]
    return f"{', '.join(parts)}; {machine()}"


def exudyn_settings(exu, t_end: float, h: float, interval: float, end_accelerations: bool | None = False):
    """Exudyn's ``SimulationSettings`` for a fixed-step run to ``t_end`` at the step ``h``: no
    automatic step size, silent, no solution file, sensors written every ``interval`` (in
    memory, for ``SensorNode(storeInternal=True)``), no timers or statistics.
    ``end_accelerations``: the explicit solvers' ``computeEndOfStepAccelerations`` (False saves
    a forward evaluation per step; None leaves Exudyn's default)."""
    ss = exu.SimulationSettings()
    ti = ss.timeIntegration
    ti.endTime = t_end
    ti.numberOfSteps = int(round(t_end / h))
    ti.automaticStepSize = False
    ti.verboseMode = 0
    if end_accelerations is not None:
        ti.explicit.computeEndOfStepAccelerations = end_accelerations
    ss.solution.file.write = False
    ss.solution.sensors.writePeriod = interval
    ss.show.computationTime = False
    ss.show.statistics = False
    ss.show.globalTimers = False
    return ss


def exudyn_solve(exu, mbs, ss, sensor, method: str, dt: float, t_eval, *, text: Callable = str,
                 quiet: bool = False, bound: float | None = None) -> np.ndarray:
    """``mbs.SolveDynamic(ss)`` by Exudyn's solver ``method`` (a ``DynamicSolverType`` name) at
    the step ``dt``, Python warnings ignored (``quiet``: Exudyn's console printing off for the
    run too), and the stored data of ``sensor`` (a ``SensorNode`` with ``storeInternal``):
    (len(t_eval), 1 + coordinates), time first. Raises ``SimulationError`` "Exudyn <method>
    dt=<dt>: <text(e)>" when the solver throws, "...: failed or unstable" when it fails or the
    data are not one finite row per output (or, with ``bound``, a coordinate exceeds it), and
    ``RuntimeError`` when the sensor's times are off ``t_eval``."""
    console = exu.config.printToConsole
    if quiet:
        exu.config.printToConsole = False  # its "DYNAMIC SOLVER FAILED" banners: the tables say it
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            ok = mbs.SolveDynamic(ss, solverType=getattr(exu.DynamicSolverType, method))
        except Exception as e:  # noqa: BLE001 - Exudyn's solver errors
            raise SimulationError(f"Exudyn {method} dt={dt:g}: {text(e)}") from e
        finally:
            if quiet:
                exu.config.printToConsole = console
    data = np.asarray(mbs.GetSensorStoredData(sensor))
    if ok is False or len(data) != len(t_eval) or not np.all(np.isfinite(data)) \
            or (bound is not None and np.max(np.abs(data[:, 1:])) > bound):
        raise SimulationError(f"Exudyn {method} dt={dt:g}: failed or unstable")
    if np.max(np.abs(data[:, 0] - t_eval)) > 1e-6:
        raise RuntimeError(f"Exudyn {method}: sensor times off the output grid")
    return data


def mujoco_fixed_step(mujoco, model, data, method: str, dt: float, interval: float) -> int:
    """Sets ``model`` to MuJoCo's integrator ``method`` (``mjtIntegrator``'s name without
    ``mjINT_``, any case: "Euler", "implicitfast", "RK4", ...) at the fixed step ``dt``, which
    must divide the output ``interval`` (ValueError otherwise), and resets ``data``
    (``mj_resetData``); returns the number of steps per output interval."""
    n = int(round(interval / dt))
    if abs(n * dt - interval) > 1e-9 * interval:
        raise ValueError(f"dt: expected a step dividing {interval} s, got {dt}")
    model.opt.timestep = dt
    model.opt.integrator = getattr(mujoco.mjtIntegrator, f"mjINT_{method.upper()}")
    mujoco.mj_resetData(model, data)
    return n


def mujoco_outputs(mujoco, model, data, steps: int, outputs: int, read: Callable, label: str, *,
                   bound: float | None = None) -> np.ndarray:
    """From ``data``'s state as it is: ``read(data)`` (a 1-D array) now and after each
    ``mj_step(model, data, nstep=steps)``, ``outputs`` rows in all (no Python per step; MuJoCo's
    user warnings silenced for the run). Raises ``SimulationError`` "MuJoCo <label>: unstable"
    when MuJoCo flagged a bad qacc or a row is not finite (or, with ``bound``, a value exceeds it)."""
    first = read(data)
    out = np.empty((outputs, len(first)))
    out[0] = first
    printer = mujoco.get_mju_user_warning()
    mujoco.set_mju_user_warning(lambda message: None)
    try:
        for k in range(1, outputs):
            mujoco.mj_step(model, data, nstep=steps)
            out[k] = read(data)
    finally:
        mujoco.set_mju_user_warning(printer)
    if data.warning[mujoco.mjtWarning.mjWARN_BADQACC].number or not np.all(np.isfinite(out)) \
            or (bound is not None and np.max(np.abs(out)) > bound):
        raise SimulationError(f"MuJoCo {label}: unstable")
    return out


class OutputTimes:
    """For a scene (a dataclass) with its output times ``t_eval``, uniformly spaced from 0: the run's
    end and the output interval (s)."""

    @property
    def t_end(self) -> float:
        return float(self.t_eval[-1])

    @property
    def interval(self) -> float:
        return float(self.t_eval[1] - self.t_eval[0])


# ---------------------------------------------------------------------------------------------
# The models checked equal
# ---------------------------------------------------------------------------------------------

def peer_self_checks(runners: Mapping, tight_newton) -> dict:
    """code -> (how its converged solution was run, its run at twice that step) for the peers whose
    runners have ``reference_step()`` and ``reference(h)``: Exudyn's generalised-α with Newton's
    tolerances ``tight_newton``, MuJoCo's RK4."""
    checks = {}
    for code, method in (("Exudyn", "GeneralizedAlpha"), ("MuJoCo", "RK4")):
        h = runners[code].reference_step()
        how = f"{method} dt={h:.3g}" + (f" newton={tight_newton}" if code == "Exudyn" else "")
        checks[code] = (f"{how} (self-check: dt={2 * h:.3g})", runners[code].reference(2 * h))
    return checks


def check_agreement(scene: str, code: str, difference: float, tolerance: float, what: str = "point") -> None:
    """AssertionError when a code's converged ``what`` differs from rigidfem's by more than
    ``tolerance`` of its amplitude: the models are not equal."""
    if difference > tolerance:
        raise AssertionError(f"{scene}: {code}'s converged {what} differs from rigidfem's by {difference:.3g} of its "
                             f"amplitude (allowed {tolerance:g}): the models are not equal")


# ---------------------------------------------------------------------------------------------
# Sweeps and timing
# ---------------------------------------------------------------------------------------------

def first_run(row: dict, run: Callable, measure: Callable, key: str, note: Callable | None = None,
              diverged: float = 1.0):
    """A sweep's first run of a setting: calls ``run()`` and sets ``row["first_cpu_s"]`` (its CPU
    time), then the columns of ``measure(result)`` (a dict, the error ``key`` among them; not
    timed). A ``SimulationError`` or ``RuntimeError`` sets ``row[key]`` = inf and ``row["note"]``
    = ``note(e)`` (default: the first 80 characters of the message). A non-finite error or one
    above ``diverged`` is noted "unstable or diverged" unless noted already. Returns the result,
    or None after an error."""
    start = time.process_time()
    result = None
    try:
        result = run()
        row["first_cpu_s"] = time.process_time() - start
        row.update(measure(result))
    except (SimulationError, RuntimeError) as e:
        row.update({"first_cpu_s": time.process_time() - start, key: np.inf,
                    "note": note(e) if note else str(e)[:80]})
        result = None
    if not np.isfinite(row[key]) or row[key] > diverged:
        row["note"] = row.get("note") or "unstable or diverged"
    return result


def interleaved(groups: Mapping[str, list]) -> list:
    """The rows of ``groups`` (code -> rows) in one order, the codes alternating row by row
    (the first of each code, then the second of each, ...)."""
    return [r for group in itertools.zip_longest(*groups.values()) for r in group if r is not None]


def least_cpu_times(groups: Mapping[str, list], run: Callable, rounds: int, long: float | None = None) -> None:
    """Times the rows of ``groups`` (code -> rows) in ``rounds`` rounds, the codes alternating
    run by run within a round (``interleaved``: a change of machine load hits them alike):
    ``run(row)`` runs a row's setting, and ``row["cpu_s"]`` becomes the least of its CPU time
    (``time.process_time``) and the row's ``cpu_s`` so far (set it to ``first_cpu_s`` before).
    A row whose first run took over ``long`` s (None: no limit) is not run again: it keeps its
    time (its noise is small against it)."""
    for _ in range(rounds):
        for r in interleaved(groups):
            if long is not None and r["first_cpu_s"] > long:
                continue
            start = time.process_time()
            run(r)
            r["cpu_s"] = min(r.get("cpu_s", np.inf), time.process_time() - start)


# ---------------------------------------------------------------------------------------------
# The cheapest settings
# ---------------------------------------------------------------------------------------------

def _codes(code) -> tuple:
    return (code,) if isinstance(code, str) else tuple(code)


def cheapest(rows: list, code, key: str, threshold: float, admit: Callable | None = None):
    """The run of least ``cpu_s`` among ``rows`` of ``code`` (a code, or several: any of them)
    whose error ``row[key]`` is at most ``threshold`` and, with ``admit``, for which
    ``admit(row)`` holds; None if there is none."""
    codes = _codes(code)
    ok = [r for r in rows if r["code"] in codes and r[key] <= threshold and (admit is None or admit(r))]
    return min(ok, key=lambda r: r["cpu_s"]) if ok else None


def setting_text(r: dict) -> str:
    """A run's setting as the tables show it: "<method> <setting>=<value>"."""
    return f"{r['method']} {r['setting']}={r['value']:.3g}"


def _groups(groups) -> dict:
    return dict(groups) if isinstance(groups, Mapping) else {code: (code,) for code in groups}


def summary_columns(leading: Iterable[str], error_column: str, groups=CODES, extra: Iterable[str] = ()) -> tuple:
    """The columns of ``summary_table``: ``leading``, ``error_column``, per group
    <group>_cpu_s, <group>_setting and <group>_<extra>, then <peer>/<baseline> per other group."""
    names = list(_groups(groups))
    return (*leading, error_column, *(f"{g}_{k}" for g in names for k in ("cpu_s", "setting", *extra)),
            *(f"{p}/{names[0]}" for p in names[1:]))


def summary_table(rows: list, leading: Mapping, error_column: str, key: str, thresholds: Iterable[float],
                  groups=CODES, *, extra: Mapping[str, Callable] | None = None, admit: Callable | None = None,
                  setting: Callable | None = None, missing: Callable | None = None) -> Table:
    """Per threshold, one row: the cheapest run (``cheapest``) of each group and the groups'
    CPU time over the first group's (rigidfem's).

    - ``leading``: the row's first columns and their values (e.g. {"m": 20});
    - ``error_column``: the column holding the threshold; ``key``: the rows' error column;
    - ``groups``: codes (each its own group; default ``CODES``) or {group: codes} (a group's
      cheapest is that of any of its codes);
    - ``extra``: {name: function(run) -> value}: more columns per group, <group>_<name>;
    - ``admit(run, threshold)``: whether a run may count at that threshold (default: all);
    - ``setting(group, run)``: the <group>_setting text (default ``setting_text(run)``);
    - ``missing(group, codes, threshold)``: the <group>_setting text without a run (default "-").

    Columns: ``summary_columns``; "-" where there is no run (or no ratio)."""
    groups, extra = _groups(groups), dict(extra or {})
    names = list(groups)
    out = []
    for tol in thresholds:
        row = {**leading, error_column: tol}
        test = (lambda r, t=tol: admit(r, t)) if admit else None
        best = {g: cheapest(rows, codes, key, tol, test) for g, codes in groups.items()}
        for g, r in best.items():
            row[f"{g}_cpu_s"] = r["cpu_s"] if r else "-"
            if r:
                row[f"{g}_setting"] = setting(g, r) if setting else setting_text(r)
            else:
                row[f"{g}_setting"] = missing(g, groups[g], tol) if missing else "-"
            for name, value in extra.items():
                row[f"{g}_{name}"] = value(r) if r else "-"
        base = best[names[0]]
        for peer in names[1:]:
            row[f"{peer}/{names[0]}"] = best[peer]["cpu_s"] / base["cpu_s"] if best[peer] and base else "-"
        out.append(row)
    return Table(out, summary_columns(leading, error_column, groups, extra))
