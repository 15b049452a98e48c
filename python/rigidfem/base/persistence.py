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
"""

from __future__ import annotations

import copy
import dataclasses
import functools

import numpy as np

from .._core import JointSpec

#: Format of the pickled states; bumped when a state's layout changes.
STATE_VERSION = 1


def check_version(state: dict, what: str) -> None:
    """Refuse a state of an unknown (newer) format."""
    version = state.get("rigidfem_state") if isinstance(state, dict) else None
    if version != STATE_VERSION:
        raise ValueError(f"state: expected a pickled rigidfem {what} of state version {STATE_VERSION}, got version "
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
