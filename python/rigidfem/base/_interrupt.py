"""Ctrl-C in every long phase.

- The C++ core's long loops (a tangent's columns, Newton's and GMRES's iterations, the ω_max
  estimate, the loops' Gauss–Newton) look at Python's signals about every 0.05 s themselves
  (``InterruptScope`` in errors.hpp): a System method raises KeyboardInterrupt, ``rf.simulate``
  returns its partial result.
- LAPACK never looks at signals: :func:`responsive` runs a dense routine that releases the GIL
  in a worker thread while the calling thread waits in 0.05 s slices, so Ctrl-C raises
  KeyboardInterrupt at once; the worker finishes in the background and its result is dropped, and
  the interpreter's exit waits for it (OpenBLAS's shutdown at exit hangs, or with one BLAS thread
  crashes, while a call is still in flight: measured 2 hangs in 50 runs of tests/test_interrupt.py).
  Not every wrapper releases the GIL (measured with SciPy 1.17: ``scipy.linalg.eigh`` and
  ``lapack.dpotrf`` hold it, NumPy's ``linalg`` routines and ``lapack.dgetrf`` do not): for large
  matrices :func:`eigh` and :func:`cholesky` take NumPy's routines.
- A sweep's worker threads never see Ctrl-C (Python delivers signals to the main thread):
  :func:`sweep_stop` gives the runs of a sweep's case the sweep's stop event, which ``rf.simulate``
  checks like its own ``stop``.
"""

from __future__ import annotations

import atexit
import contextlib
import functools
import threading

import numpy as np
import scipy.linalg

#: Matrices of fewer entries take less than a few ms in LAPACK: called directly.
RESPONSIVE_FROM = 200 * 200

_local = threading.local()

#: The workers of ``responsive`` still inside their routine, each by the event it sets when done.
_unfinished: set = set()
_unfinished_lock = threading.Lock()


@atexit.register
def _wait_for_workers() -> None:
    """At exit, the workers a Ctrl-C left inside LAPACK finish first (a second Ctrl-C stops waiting)."""
    with _unfinished_lock:
        pending = list(_unfinished)
    try:
        for done in pending:
            done.wait()
    except KeyboardInterrupt:
        pass


def responsive(function):
    """``function`` (a NumPy/SciPy dense routine) made interruptible: for arrays of at least
    ``RESPONSIVE_FROM`` entries, called in a worker thread while the main thread waits (see the module)."""

    @functools.wraps(function)
    def call(*args, **kwargs):
        big = any(getattr(a, "size", 0) >= RESPONSIVE_FROM for a in args)
        if not big or threading.current_thread() is not threading.main_thread():
            return function(*args, **kwargs)
        box = {}
        done = threading.Event()

        def work():
            try:
                box["value"] = function(*args, **kwargs)
            except BaseException as e:  # noqa: BLE001 (re-raised in the caller's thread)
                box["error"] = e
            finally:
                with _unfinished_lock:
                    _unfinished.discard(done)
                done.set()

        with _unfinished_lock:
            _unfinished.add(done)
        worker = threading.Thread(target=work, name=f"rigidfem-{function.__name__}", daemon=True)
        worker.start()
        # Ctrl-C raises KeyboardInterrupt here. The worker's own event says when it is done: a join(0.05)
        # that Ctrl-C interrupts marks the thread finished while it still runs (CPython gh-90882, <= 3.12).
        while not done.wait(0.05):
            pass
        if "error" in box:
            raise box["error"]
        return box["value"]

    return call


def _reduced_eigh(A, B):
    """A x = λ B x (A symmetric, B positive definite) as LAPACK's sygv computes it, by NumPy: B = L Lᵀ,
    C = L⁻¹ A L⁻ᵀ, C y = λ y, x = L⁻ᵀ y (so Xᵀ B X = I). LinAlgError when B is not positive definite."""
    L = np.linalg.cholesky(B)
    C = np.linalg.solve(L, np.linalg.solve(L, A).T)  # L⁻¹ (L⁻¹ A)ᵀ = L⁻¹ A L⁻ᵀ (A symmetric)
    w, Y = np.linalg.eigh(0.5 * (C + C.T))
    return w, np.linalg.solve(L.T, Y)


def eigh(A, B):
    """scipy.linalg.eigh(A, B) for small matrices; for large ones the same reduction by NumPy's routines,
    which release the GIL, in a worker thread (responsive)."""
    if A.size < RESPONSIVE_FROM:
        return scipy.linalg.eigh(A, B)
    return _responsive_reduced_eigh(A, B)


def cholesky(A):
    """(U, info) of lapack.dpotrf(A) (upper: A = UᵀU) for small matrices; NumPy's (which releases the GIL)
    in a worker thread for large ones, info = 1 when A is not positive definite."""
    if A.size < RESPONSIVE_FROM:
        return scipy.linalg.lapack.dpotrf(A)
    try:
        return _responsive_cholesky(A).T.copy(), 0
    except np.linalg.LinAlgError:
        return A, 1


@contextlib.contextmanager
def sweep_stop(event: threading.Event):
    """Within it, this thread's runs also stop when ``event`` is set (a sweep interrupted)."""
    previous = getattr(_local, "stop", None)
    _local.stop = event
    try:
        yield
    finally:
        _local.stop = previous


def current_sweep_stop():
    """The stop event of the sweep whose case this thread runs, or None."""
    return getattr(_local, "stop", None)


_responsive_reduced_eigh = responsive(_reduced_eigh)
_responsive_cholesky = responsive(np.linalg.cholesky)
