"""Pickling: models, systems, results and tables as a versioned state.

A ``Model`` is kept as its recipe: the gravity it was made with and every public builder call
that succeeded (``add_body``, ``add_beam``, ``prescribe``, ...), with copies of the arguments.
Unpickling replays the calls on a new Model that adopts the original's id, so the ``Body`` and
``Point`` handles made by the original (inside a user's closure, a ``Beam``) name the same bodies
of the copy. A ``System`` pickles as the recipe of its model at compile time and the algorithm,
and compiles again when unpickled: the same description compiled by the same code, hence
bitwise identical results in any process. Results, modes and tables pickle their fields.

Every state carries ``STATE_VERSION``; a state written by a newer rigidfem is refused with a clear
error rather than misread. What a recipe cannot hold is a Python function that does not pickle
(a lambda or a closure given as a force law or drive): pickle raises then and names it. Dask
pickles with cloudpickle, which also takes those.

A Result saved as a NumPy archive (``Result.to_npz``) is read back by ``read_result``
(``rigidfem.load_npz``): a file that is not such an archive is a ValueError naming ``path``, a missing
one stays a FileNotFoundError.
"""

from __future__ import annotations

import copy
import dataclasses
import functools
import os
import zipfile
import zlib
from typing import NoReturn

import numpy as np

from . import _checks, export
from .._core import JointSpec

#: Format of the pickled states; bumped when a state's layout changes.
STATE_VERSION = 1


def check_version(state: dict, what: str) -> None:
    """Refuse a state of an unknown (newer) format."""
    version = state.get("rigidfem_state") if isinstance(state, dict) else None
    if version != STATE_VERSION:
        raise _checks.refuse(f"state: expected a pickled rigidfem {what} of state version {STATE_VERSION}, got version "
                         f"{version!r} (pickled by another rigidfem release?)")


def _copied(x):
    """A copy of a builder's argument that later changes by the caller cannot reach: arrays and
    containers copied, joint specs (mutable) duplicated; handles, profiles and functions kept."""
    if isinstance(x, np.ndarray):
        return x.copy()
    if isinstance(x, (list, tuple)):
        return type(x)(_copied(v) for v in x) if type(x) in (list, tuple) else x
    if isinstance(x, dict):
        return {k: _copied(v) for k, v in x.items()}
    if isinstance(x, JointSpec):
        return copy.copy(x)
    return x


def recorded(method):
    """Decorator of a Model builder: appends (name, args, kwargs) to the model's recipe when the
    call succeeds. Builders calling builders (``add_beam`` adds bodies) record the outer call only."""

    @functools.wraps(method)
    def builder(self, *args, **kwargs):
        if self._building:
            return method(self, *args, **kwargs)
        call = (method.__name__, _copied(args), _copied(kwargs))
        self._building = True
        try:
            out = method(self, *args, **kwargs)
        finally:
            self._building = False
        self._calls.append(call)
        return out

    return builder


def model_state(model) -> dict:
    """The versioned recipe of a Model as built so far."""
    return {"rigidfem_state": STATE_VERSION, "id": model.id, "gravity": model._gravity0.copy(),
            "calls": list(model._calls)}


def replay(model, state: dict):
    """The Model ``model`` (new, of the state's gravity) made the copy of ``state``: the original's
    id adopted, the recorded calls replayed."""
    model._adopt_id(state["id"])
    for name, args, kwargs in state["calls"]:
        getattr(model, name)(*args, **kwargs)
    return model


class Versioned:
    """Mixin of the dataclasses of results (Result, Modes, Equilibrium, Table): pickles the fields
    (not the cached outputs) with the state version."""

    def __getstate__(self) -> dict:
        fields = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        return {"rigidfem_state": STATE_VERSION, "fields": fields}

    def __setstate__(self, state: dict) -> None:
        check_version(state, type(self).__name__)
        self.__dict__.update(state["fields"])


#: The first bytes of a zip file, hence of a NumPy .npz archive (np.savez writes zip files).
ZIP_MAGIC = (b"PK\x03\x04", b"PK\x05\x06")


def read_result(path, system=None) -> dict:
    """The fields of the Result that ``Result.to_npz`` saved at ``path`` (a str or ``os.PathLike``), for
    ``rigidfem.load_npz``; ``system`` (None: without it) must have the coordinate names saved.

    ValueError naming ``system`` (checked first) or ``path``: not a file path (None, 3), or a file that is
    not such an archive (another file, another archive, one without the arrays of a Result, or with
    arrays of inconsistent shapes), the cause in parentheses. A file that does not exist stays a
    FileNotFoundError, one that cannot be read an OSError (Python's convention for files)."""
    if system is not None:
        system = _checks.system(system)
    path = _checks.path(path)
    # FileNotFoundError, IsADirectoryError, PermissionError: as they are. The file is read through this handle,
    # which closes whatever happens (np.load leaves its own open when the zip is corrupt)
    with open(path, "rb") as file:
        head = file.read(4)
        if head not in ZIP_MAGIC:
            _not_a_result(path, f"not a NumPy .npz archive: it begins with {head!r}")
        file.seek(0)
        try:
            fields = export.read_npz(file)
        except KeyError as e:  # np.load's "x is not a file in the archive"
            _not_a_result(path, f"an archive without the arrays of a Result: {e.args[0] if e.args else e}", e)
        except (ValueError, TypeError, EOFError, zipfile.BadZipFile, zlib.error) as e:
            _not_a_result(path, f"{type(e).__name__}: {e}", e)
    names, t, q, qd = fields["coordinate_names"], fields["t"], fields["q"], fields["qd"]
    for name, a in (("t", t), ("q", q), ("qd", qd)):
        if not np.issubdtype(a.dtype, np.number):
            _not_a_result(path, f"its {name} holds {a.dtype}, not numbers")
    if t.ndim != 1:
        _not_a_result(path, f"its t has shape {t.shape}, expected one dimension")
    for name, a in (("q", q), ("qd", qd)):
        if a.shape != (len(t), len(names)):
            _not_a_result(path, f"its {name} has shape {a.shape}, expected (len(t), len(coordinate_names)) = "
                                f"{(len(t), len(names))}")
    if system is not None and list(system.coordinate_names) != names:
        raise _checks.refuse(f"system: expected a System with the coordinates {names} saved in {path}, got "
                         f"{list(system.coordinate_names)}")
    return fields


def _not_a_result(path, cause: str, error: BaseException | None = None) -> NoReturn:
    cause = cause if len(cause) <= 200 else cause[:197] + "..."
    raise _checks.refuse(f"path: expected a file written by Result.to_npz, got {os.fspath(path)!r} ({cause})") from error
