"""Ctrl-C in every long phase.

- The C++ core's long loops (a tangent's columns, Newton's and GMRES's iterations, the ω_max
  estimate, the loops' Gauss–Newton) look at Python's signals about every 0.05 s themselves
  (``InterruptScope`` in errors.hpp): a System method raises KeyboardInterrupt, ``rf.simulate``
  returns its partial result.
- LAPACK (SciPy's and NumPy's dense eigensolvers and factorisations) releases the GIL but never
  looks at signals: :func:`responsive` runs such a call in a worker thread while the calling
  thread waits in 0.05 s slices, so Ctrl-C raises KeyboardInterrupt at once; the worker finishes
  in the background and its result is dropped.
- A sweep's worker threads never see Ctrl-C (Python delivers signals to the main thread):
  :func:`sweep_stop` gives the runs of a sweep's case the sweep's stop event, which ``rf.simulate``
  checks like its own ``stop``.
"""

from __future__ import annotations

import contextlib
import functools
import threading

#: Matrices of fewer entries take less than a few ms in LAPACK: called directly.
RESPONSIVE_FROM = 200 * 200

_local = threading.local()


def responsive(function):
    """``function`` (a NumPy/SciPy dense routine) made interruptible: for arrays of at least
    ``RESPONSIVE_FROM`` entries, called in a worker thread while the main thread waits (see the module)."""

    @functools.wraps(function)
    def call(*args, **kwargs):
        big = any(getattr(a, "size", 0) >= RESPONSIVE_FROM for a in args)
        if not big or threading.current_thread() is not threading.main_thread():
            return function(*args, **kwargs)
        box = {}

        def work():
            try:
                box["value"] = function(*args, **kwargs)
            except BaseException as e:  # noqa: BLE001 (re-raised in the caller's thread)
                box["error"] = e

        worker = threading.Thread(target=work, name=f"rigidfem-{function.__name__}", daemon=True)
        worker.start()
        while worker.is_alive():
            worker.join(0.05)  # Ctrl-C raises KeyboardInterrupt here
        if "error" in box:
            raise box["error"]
        return box["value"]

    return call


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
