"""``rf.sweep``: a study over a grid or a list of cases, on threads, processes or a Dask cluster.

A sweep calls a user function once per case, ``function(**case)``; the function builds a model
(or takes a shared compiled System), runs it and returns what to keep. The results come back as
one table row per case, in the order of the cases, whatever order the workers finish in.

Executors: threads by default (``rf.simulate`` releases the GIL for its C++ loop, and a compiled
System is immutable, so one System may be shared by every thread); "processes" (a process pool of
this machine); any ``concurrent.futures.Executor`` (e.g. mpi4py's ``MPIPoolExecutor``); or a
Dask distributed ``Client``, so that the same call runs on a laptop's ``LocalCluster`` and on a
cluster. Arguments and results travel by pickle to processes and Dask workers: Models, Systems,
Results and Modes pickle (``rigidfem.base.persistence``).
"""

from __future__ import annotations

import concurrent.futures
from concurrent.futures.process import BrokenProcessPool
import inspect
import itertools
import os
import pickle
import threading
import time
import warnings
from collections.abc import Callable, Mapping, Sequence

import numpy as np

from ..base import _checks, _interrupt
from ..base._progress import ProgressBar
from .study import Table

#: Columns a sweep adds to the parameters and the function's values.
ERROR, WALL_TIME, SEED = "error", "wall_time_s", "seed"
#: The error of a case that Ctrl-C stopped or kept from starting.
INTERRUPTED = "KeyboardInterrupt: the sweep was interrupted"
#: How long an interrupted sweep waits for its running cases (their runs stop within about 0.05 s).
GRACE = 0.3


def grid_cases(grid: Mapping[str, Sequence]) -> list[dict]:
    """The Cartesian product of ``grid`` (name -> values) as a list of cases, the last name varying
    fastest: ``grid_cases({"a": [1, 2], "b": [3, 4]})`` gives a=1,b=3; a=1,b=4; a=2,b=3; a=2,b=4."""
    if not isinstance(grid, Mapping) or not grid:
        raise _checks.refuse(f"grid: expected a non-empty dict of parameter names to sequences of values, got {grid!r}")
    names = list(grid)
    values = []
    for name in names:
        v = grid[name]
        if isinstance(v, (str, bytes)) or not isinstance(v, (Sequence, np.ndarray)) or len(v) == 0:
            raise _checks.refuse(f"grid[{name!r}]: expected a non-empty sequence of values, got {v!r}")
        values.append(list(v))
    return [dict(zip(names, combination)) for combination in itertools.product(*values)]


def _cases(cases, grid) -> list[dict]:
    if (cases is None) == (grid is None):
        raise _checks.refuse("cases, grid: expected exactly one of them (a list of dicts, or a dict of sequences)")
    if grid is not None:
        return grid_cases(grid)
    if isinstance(cases, Mapping) or not isinstance(cases, Sequence) or isinstance(cases, (str, bytes)):
        raise _checks.refuse(f"cases: expected a list of dicts of parameters, got {cases!r}")
    for k, case in enumerate(cases):
        if not isinstance(case, Mapping) or not all(isinstance(name, str) for name in case):
            raise _checks.refuse(f"cases[{k}]: expected a dict of parameter names (str) to values, got {case!r}")
    return [dict(case) for case in cases]


def _seeds(seed, n: int) -> list[int]:
    """One independent seed per case from numpy's SeedSequence(seed).spawn(n): the case's stream does
    not depend on the executor nor on the other cases."""
    if seed is not None and (isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0):
        raise _checks.refuse(f"seed: expected None or a non-negative integer, got {seed!r}")
    return [int(child.generate_state(1, np.uint64)[0] >> np.uint64(1))
            for child in np.random.SeedSequence(seed).spawn(n)]


def _takes_seed(function) -> bool:
    try:
        return "seed" in inspect.signature(function).parameters
    except (TypeError, ValueError):  # a builtin without a signature
        return False


def _check_parameters(function, cases, seed) -> None:
    """ValueError naming a case's parameter that ``function`` does not take (every case would just record
    the same TypeError), or a ``seed`` given to a function without a ``seed`` parameter (it would be
    ignored). Functions with ``**kwargs``, or without a signature, take anything."""
    try:
        parameters = inspect.signature(function).parameters
    except (TypeError, ValueError):  # a builtin without a signature
        return
    if any(p.kind is inspect.Parameter.VAR_KEYWORD for p in parameters.values()):
        return
    unknown = sorted({name for case in cases for name in case} - set(parameters))
    if unknown:
        raise _checks.refuse(f"cases: expected parameters of {getattr(function, '__name__', 'the function')}"
                         f"({', '.join(parameters)}), got {unknown}")
    if seed is not None and SEED not in parameters:
        raise _checks.refuse(f"seed: expected None for a function without a 'seed' parameter "
                         f"({getattr(function, '__name__', 'the function')}({', '.join(parameters)})), got {seed!r}")


def run_case(function, case: dict, seed: int | None, record_errors: bool):
    """One case in a worker: (value, error, wall time in s). ``error`` is "Type: message" when the
    function raised and errors are recorded, else None."""
    start = time.perf_counter()
    try:
        value = function(**case) if seed is None else function(**case, seed=seed)
        error = None
    except Exception as e:  # noqa: BLE001 (a failing case is reported in its row)
        if not record_errors:
            raise
        value, error = None, f"{type(e).__name__}: {e}"
    return value, error, time.perf_counter() - start


def _check_pickles(function) -> None:
    """A process pool sends the function by pickle: say so before the pool fails on it."""
    try:
        pickle.dumps(function)
    except (pickle.PicklingError, AttributeError, TypeError) as e:
        raise _checks.refuse(f"function: expected a function that pickles for executor='processes' (defined at module "
                         f"level; lambdas and closures do not), got {function!r} ({e}); threads or a Dask Client "
                         f"(cloudpickle) take it") from None


def _is_dask_client(executor) -> bool:
    return type(executor).__module__.split(".")[0] == "distributed" and hasattr(executor, "gather")


def _resolve_executor(executor, workers):
    """(executor, whether this call owns it and must shut it down)."""
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, (int, np.integer))
                                or workers < 1):
        raise _checks.refuse(f"workers: expected None or a positive integer, got {workers!r}")
    if executor == "serial":
        return None, False
    if executor == "threads":
        return concurrent.futures.ThreadPoolExecutor(workers or os.cpu_count() or 1), True
    if executor == "processes":
        return concurrent.futures.ProcessPoolExecutor(workers or os.cpu_count() or 1), True
    if isinstance(executor, concurrent.futures.Executor) or _is_dask_client(executor):
        if workers is not None:
            raise _checks.refuse("workers: expected None with an executor or a Dask Client (they have their own workers)")
        return executor, False
    raise _checks.refuse(f"executor: expected 'threads', 'processes', 'serial', a concurrent.futures.Executor or a "
                     f"dask.distributed.Client, got {executor!r}")


def _case_in_thread(stop, function, case, seed, record_errors):
    """run_case in a worker thread, whose runs stop with the sweep (``_interrupt.sweep_stop``): a
    batch of one case."""
    with _interrupt.sweep_stop(stop):
        return [run_case(function, case, seed, record_errors)]


def run_cases(function, cases: list, seeds: list, record_errors: bool, packed: bool = False):
    """A batch of cases in one worker task: run_case's (value, error, wall time) for each. ``packed`` (a
    process's task): the outcomes pickled here, where a value that does not pickle is its case's error
    (recorded) instead of the whole batch's."""
    outcomes = [run_case(function, case, seed, record_errors) for case, seed in zip(cases, seeds)]
    if not packed:
        return outcomes
    try:
        return pickle.dumps(outcomes)
    except Exception:  # noqa: BLE001, S110 (which value does not pickle: each case's own error, below)
        pass
    kept = []
    for case, (value, error, wall) in zip(cases, outcomes):
        try:
            pickle.dumps(value)
        except Exception as e:  # noqa: BLE001
            if not record_errors:
                raise _checks.refuse(f"function: expected return values that pickle with executor='processes' (a "
                                 f"process sends them back by pickle), got {type(value).__name__} for the case "
                                 f"{case!r}: {type(e).__name__}: {e}") from None
            value, error = None, (f"{type(e).__name__}: the function's return value does not pickle (a process "
                                  f"sends it back by pickle): {e}")
        kept.append((value, error, wall))
    return pickle.dumps(kept)


def _unpacked(outcomes):
    """A task's outcomes: pickled by a process (``run_cases(packed=True)``), or as they are."""
    return pickle.loads(outcomes) if isinstance(outcomes, bytes) else outcomes


#: Tasks per worker a process pool or a Dask cluster gets (each a batch of cases): a task costs
#: ~3 ms of Dask's scheduling and pickling (a 5 ms run of Kane's beam took 8 ms a case on a
#: 2-worker LocalCluster sent one case a task), and a few batches per worker still even out
#: cases of unequal length.
BATCHES_PER_WORKER = 4


def _worker_count(executor) -> int:
    """How many cases the executor runs at once: a Dask cluster's threads, a pool's workers."""
    if _is_dask_client(executor):
        return max(1, sum(executor.nthreads().values()))
    return max(1, getattr(executor, "_max_workers", None) or os.cpu_count() or 1)


def _batches(executor, n: int) -> list[range]:
    """The cases' indices in batches, one task each: one case a task on threads (a task costs
    nothing there, and Ctrl-C stops each case's run), else BATCHES_PER_WORKER tasks per worker."""
    if isinstance(executor, concurrent.futures.ThreadPoolExecutor):
        return [range(k, k + 1) for k in range(n)]
    size = max(1, -(-n // (BATCHES_PER_WORKER * _worker_count(executor))))  # ceil
    return [range(k, min(k + size, n)) for k in range(0, n, size)]


def _submit_all(executor, function, cases, seeds, record_errors, stop, batches) -> list:
    """A future per batch of cases, in the order of the cases: each returns its cases' outcomes."""
    if isinstance(executor, concurrent.futures.ThreadPoolExecutor):
        return [executor.submit(_case_in_thread, stop, function, cases[b[0]], seeds[b[0]], record_errors)
                for b in batches]
    options = {"pure": False} if _is_dask_client(executor) else {}
    packed = isinstance(executor, concurrent.futures.ProcessPoolExecutor)
    futures = []
    for b in batches:
        try:
            futures.append(executor.submit(run_cases, function, [cases[k] for k in b], [seeds[k] for k in b],
                                           record_errors, packed, **options))
        except BrokenProcessPool as e:  # a worker died before every batch was in: the rest fail as its batch did
            failed = concurrent.futures.Future()
            failed.set_exception(e)
            futures.append(failed)
    return futures


def _as_completed(executor, futures):
    if _is_dask_client(executor):
        from distributed import as_completed

        return as_completed(futures)
    return concurrent.futures.as_completed(futures)


def _outcomes(function, cases, seeds, executor, record_errors, bar, stop) -> list:
    """(value, error, wall time) per case, in the order of the cases. Ctrl-C sets ``stop``: the running
    cases' runs return their partial results, the cases not started are not (INTERRUPTED)."""
    if executor is None:
        out = []
        with _interrupt.sweep_stop(stop):  # a run's Ctrl-C (it returns its partial result) stops the sweep
            for case, seed in zip(cases, seeds):
                if stop.is_set():
                    break
                out.append(run_case(function, case, seed, record_errors))
                if bar is not None:
                    bar.update(len(out))
        return out + [(None, INTERRUPTED, float("nan"))] * (len(cases) - len(out))
    batches = _batches(executor, len(cases))
    futures = _submit_all(executor, function, cases, seeds, record_errors, stop, batches)
    size = {f: len(b) for f, b in zip(futures, batches)}  # Dask's futures hash by their key
    try:
        done = 0
        for future in _as_completed(executor, futures):
            done += size[future]
            if bar is not None:
                bar.update(done)
    except KeyboardInterrupt:
        stop.set()
        for f in futures:
            f.cancel()
        concurrent.futures.wait([f for f in futures if not _is_dask_client(executor)], timeout=GRACE)
    outcomes, lost = {}, []
    for f, b in zip(futures, batches):
        if f.done() and not f.cancelled() and f.exception() is None:
            outcomes.update(zip(b, _unpacked(f.result())))
        elif stop.is_set():
            outcomes.update((k, (None, INTERRUPTED, float("nan"))) for k in b)
        elif not record_errors and isinstance(f.exception(), BrokenProcessPool):
            raise _checks.refuse(f"function: expected a function that returns, got one whose worker process died "
                             f"running the cases {[cases[k] for k in b]!r}: {f.exception()}") from None
        elif not record_errors:
            raise f.exception()  # errors="raise": the case's own exception
        elif isinstance(executor, concurrent.futures.ProcessPoolExecutor):
            lost += b  # a worker died (BrokenProcessPool): which case killed it, each run alone tells
        else:
            error = f"{type(f.exception()).__name__}: {f.exception()}"
            outcomes.update((k, (None, error, float("nan"))) for k in b)
    outcomes.update(_alone(function, cases, seeds, lost, stop))
    return [outcomes[k] for k in range(len(cases))]


def _alone(function, cases, seeds, indices, stop) -> dict:
    """The cases of batches whose process died, each run again alone in a fresh process: the case that
    kills its process gets that as its error, the others their results (errors="record")."""
    out = {}
    for k in indices:
        if stop.is_set():
            out[k] = (None, INTERRUPTED, float("nan"))
            continue
        with concurrent.futures.ProcessPoolExecutor(1) as pool:
            start = time.perf_counter()
            try:
                out[k] = _unpacked(pool.submit(run_cases, function, [cases[k]], [seeds[k]], True, True).result())[0]
            except KeyboardInterrupt:
                stop.set()
                out[k] = (None, INTERRUPTED, float("nan"))
            except Exception as e:  # noqa: BLE001 (the process died: this case's failure, timed until then)
                out[k] = (None, f"{type(e).__name__}: {e} (the case's worker process died)",
                          time.perf_counter() - start)
    return out


def _row(case: dict, seed, value, error, wall_time) -> dict:
    row = dict(case)
    if seed is not None:
        row[SEED] = seed
    if isinstance(value, Mapping):
        row.update(value)
    elif error is None:
        row["result"] = value
    row[ERROR], row[WALL_TIME] = error, wall_time
    return row


def _columns(rows: list[dict]) -> list[str]:
    """Columns in order of first appearance, the error and wall time last."""
    names = dict.fromkeys(name for row in rows for name in row if name not in (ERROR, WALL_TIME))
    return [*names, ERROR, WALL_TIME]


def _table(rows: list[dict], as_frame):
    columns = _columns(rows)
    if as_frame is None:
        try:
            import pandas  # noqa: F401
        except ImportError:
            as_frame = False
        else:
            as_frame = True
    if not as_frame:
        return Table([{c: row.get(c) for c in columns} for row in rows], tuple(columns))
    try:
        import pandas as pd
    except ImportError:
        raise _checks.refuse("as_frame: expected None or False without pandas installed (pip install pandas), "
                         "got True") from None
    frame = pd.DataFrame.from_records(rows, columns=columns)
    frame[ERROR] = pd.Series([row[ERROR] for row in rows], index=frame.index, dtype=object)  # None where it ran
    return frame


def sweep(function: Callable, cases: Sequence[Mapping] | None = None, *, grid: Mapping[str, Sequence] | None = None,
          executor="threads", workers: int | None = None, seed: int | None = None, progress: bool = False,
          errors: str = "record", as_frame: bool | None = None):
    """Run ``function(**case)`` for every case and gather what it returns in a table.

    Parameters
    ----------
    function : callable
        ``function(**parameters)`` builds a model (or uses a compiled System it shares), runs it
        and returns what to keep: a dict of named values (a column each; numbers, arrays or any
        object) or a single value (column ``"result"``). If it has a parameter ``seed``, each case
        gets its own integer seed (for ``np.random.default_rng(seed)``), drawn from ``seed`` below.
    cases : list of dicts, optional
        The parameters of each case, e.g. ``[{"omega": 4.0}, {"omega": 6.0}]``.
    grid : dict of sequences, optional
        Instead of ``cases``: every combination (``grid_cases``), the last name varying fastest.
    executor : str, Executor or dask.distributed.Client
        ``"threads"`` (default: a thread pool; the C++ integrators run without the GIL),
        ``"processes"`` (a process pool; the function and its arguments must pickle),
        ``"serial"``, any ``concurrent.futures.Executor`` (e.g. ``mpi4py.futures.MPIPoolExecutor``),
        or a Dask ``Client`` (``pip install ".[dask]"``; Dask pickles with cloudpickle, so
        functions defined in a notebook travel too). Processes, executors and Dask get the cases
        in batches, ``BATCHES_PER_WORKER`` (4) tasks per worker, so that short runs do not pay a
        task's cost each (~3 ms on Dask); threads one case a task.
    workers : int, optional
        Threads or processes of a pool made here (default: the number of cores).
    seed : int, optional
        Root of the per-case seeds (numpy ``SeedSequence(seed).spawn``): the same seed gives every
        case the same stream on any executor. None: fresh entropy, still one stream per case.
    progress : bool
        A progress bar (tqdm when installed, else a line on stderr) counting finished cases.
    errors : "record" or "raise"
        "record" (default): a case whose function raises gets its row with ``error`` = "Type:
        message" and no values, the others go on; "raise": the first failure propagates.
    as_frame : bool, optional
        None (default): a pandas DataFrame when pandas is installed, else a ``rigidfem.study.Table``
        of records; True/False force one.

    Returns
    -------
    pandas.DataFrame or rigidfem.study.Table
        One row per case in the order of the cases: the parameters, ``seed`` (when the function
        takes one), the returned values, ``error`` (None when it ran) and ``wall_time_s`` (s,
        the case's own time in its worker).

    Examples
    --------
    >>> import rigidfem as rf
    >>> def run(length):
    ...     model, h = rf.samples.pendulum(length=length)
    ...     return {"omega": float(rf.modal_analysis(model.compile()).omega[0])}
    >>> table = rf.sweep(run, grid={"length": [1.0, 4.0]}, executor="serial")
    >>> [round(w, 3) for w in table["omega"]]
    [3.836, 1.918]
    """
    if not callable(function):
        raise _checks.refuse(f"function: expected a callable function(**parameters), got {function!r}")
    if errors not in ("record", "raise"):
        raise _checks.refuse(f"errors: expected 'record' or 'raise', got {errors!r}")
    if as_frame is not None and not isinstance(as_frame, (bool, np.bool_)):
        raise _checks.refuse(f"as_frame: expected None, True or False, got {as_frame!r}")
    cases = _cases(cases, grid)
    if executor == "processes":
        _check_pickles(function)
    _check_parameters(function, cases, seed)
    draw = _takes_seed(function) and not any(SEED in case for case in cases)  # else cases give their own
    seeds = _seeds(seed, len(cases)) if draw else [None] * len(cases)
    pool, owned = _resolve_executor(executor, workers)
    bar = ProgressBar(len(cases), "cases", "sweep") if _checks.boolean(progress, "progress") else None
    stop = threading.Event()
    try:
        outcomes = _outcomes(function, cases, seeds, pool, errors == "record", bar, stop)
    finally:
        if bar is not None:
            bar.close()
        if owned:
            pool.shutdown(wait=not stop.is_set(), cancel_futures=True)
    rows = [_row(case, s, *outcome) for case, s, outcome in zip(cases, seeds, outcomes)]
    if stop.is_set():
        kept = sum(outcome[1] != INTERRUPTED for outcome in outcomes)
        warnings.warn(f"sweep interrupted: returning the {kept} of {len(cases)} cases that ran (a run stopped part-way "
                      f"keeps its partial result; the others' error is {INTERRUPTED!r})", RuntimeWarning, stacklevel=2)
    return _table(rows, as_frame)
