"""What an adaptive run measures its error on (``rf.simulate(..., error_on=...)``).

The C++ measure (``cpp/include/rigidfem/error_measure.hpp``) maps a step's error estimate
e = (e_q, e_q̇) through the Jacobians of the outputs: a point moves by δp = J_p e_q and its velocity
by J_p e_q̇, held as the displacement h·J_p e_q̇ it makes over the step h. Each output's error is
held to atol + rtol · scale: the model's size L (m, ``Result.stats["model_size"]``) for points and
bodies (or the farthest a centre of mass has moved, if larger), the largest magnitude the output has
reached so far for coordinates, element forces and loop reactions.

``error_on`` takes

- ``None`` or ``"bodies"`` (the default): every body with mass, by the RMS displacement of its
  material √(|δc|² + δθᵀ I_C δθ / m) (m): the displacements of the whole model, whatever
  coordinates describe them;
- ``"state"``: every component of y = [q, q̇] to its own atol_i + rtol_i |y_i| (the measure of
  earlier versions: on a beam it resolves every mode, seen by an output or not);
- a list of outputs: ``Point`` (m), ``Body`` (its origin, m), a coordinate's name or index in q
  (m or rad), a force element's name (its axial force, N) or a loop's name (its multipliers, N or
  N·m).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

import rigidfem._core as _core  # the compiled core, by its absolute name
from ..base._checks import same_model
from .._core import Body, Point
from ..base.persistence import Versioned
from ..base import _checks

#: The kinds of error_on besides lists of outputs.
MEASURES = ("bodies", "state")


def specs(system, error_on) -> list:
    """The C++ outputs of ``error_on`` as (kind, index, r) tuples; [] for "state". ValueError naming
    ``error_on`` for an output the system does not have."""
    if error_on is None or (isinstance(error_on, str) and error_on == "bodies"):
        return [("bodies", -1, np.zeros(3))]
    if isinstance(error_on, str) and error_on == "state":
        return []
    items = [error_on] if isinstance(error_on, (str, Point, Body, int, np.integer)) else error_on
    try:
        items = list(items)
    except TypeError:
        raise _checks.refuse(f"error_on: expected None, 'bodies', 'state' or a list of outputs (points, bodies, "
                         f"coordinate, element or loop names), got {error_on!r}") from None
    if not items:
        raise _checks.refuse("error_on: expected at least one output, got an empty list")
    return [_spec(system, item) for item in items]


def _spec(system, item, argument: str = "error_on"):
    """(kind, index, r) of one output; ValueError naming ``argument``."""
    if isinstance(item, Body):
        item = item.origin
    if isinstance(item, Point):
        same_model(item, system, argument, "points and bodies of the model this system was compiled from")
        if item.body < 0:
            raise _checks.refuse(f"{argument}: expected points on moving bodies (the ground's do not move), got {item!r}")
        return ("point", int(item.body), np.asarray(item.r, dtype=float))
    if isinstance(item, (int, np.integer)) and not isinstance(item, bool):
        if not 0 <= item < system.nq:
            raise _checks.refuse(f"{argument}: expected coordinate indices 0 ... {system.nq - 1} (nq - 1), got {item}")
        return ("coordinate", int(item), np.zeros(3))
    if isinstance(item, str):
        found = [(kind, names.index(item)) for kind, names in
                 (("coordinate", list(system.coordinate_names)), ("element", list(system.element_names)),
                  ("loop", list(system.loop_names))) if item in names]
        if len(found) == 1:
            return (found[0][0], found[0][1], np.zeros(3))
        if len(found) > 1:
            raise _checks.refuse(f"{argument}: expected a name that is one thing, got {item!r}, the name of a "
                                 f"{' and of a '.join(k for k, _ in found)}: ambiguous")
        raise _checks.refuse(f"{argument}: expected a coordinate ({_few(system.coordinate_names)}), force element "
                         f"({_few(system.element_names)}) or loop ({_few(system.loop_names)}) name, got {item!r}")
    raise _checks.refuse(f"{argument}: expected points, bodies, coordinate indices or names of coordinates, force "
                     f"elements or loops, got {item!r}")


def _few(names) -> str:
    names = list(names)
    if not names:
        return "none"
    shown = ", ".join(repr(n) for n in names[:4])
    return shown + (f", ... {len(names)} in all" if len(names) > 4 else "")


# ---------------------------------------------------------------------------------------------------
# The error bar: the global time-integration error of a Result's outputs (Result.error_estimate)

#: The tolerances of the second run of an adaptive method, over those of the first.
TIGHTER = 10.0


@dataclass
class ErrorEstimate(Versioned):
    """The estimated global time-integration error of a Result's outputs (``Result.error_estimate``).

    Obtained from a second run of the same method on the same outputs: at tolerances ``TIGHTER``
    (10) times smaller for an adaptive method, at half the step for a fixed-step one. The difference
    of the two runs at the output times is the estimate: for an adaptive run as it stands (the second
    run's own error is 0.1-0.25 of the first's where the error falls with the tolerance at the rates
    measured, 0.6-1 per decade, so the difference is within 0.75-1.1 of the first run's error); for a
    fixed step of order p, Richardson's 2^p/(2^p − 1) times it. The model's own error (the number of
    elements, the deformations kept) is not in it: ``rigidfem.resolve`` estimates that one.

    ``history`` (len(t), n) holds each output's estimated error at the output times ``t``, ``max``
    its largest over time, ``names`` and ``units`` say what each column is: a point's or body's
    displacement (m), a coordinate (m or rad), an element's axial force (N), a loop's multipliers
    (N or N·m); "bodies" is the largest displacement of any body's origin or centre of mass (m).
    ``of(quantity)`` gives the estimate of any other quantity of the run.

    Examples
    --------
    >>> import rigidfem as rf
    >>> model, h = rf.samples.pendulum()
    >>> system = model.compile()
    >>> res = rf.simulate(system, 1.0, q0=[0.5], rtol=1e-6, error_estimate=True)
    >>> est = res.error_estimate
    >>> type(est).__name__, est.names
    ('ErrorEstimate', ['bodies'])
    >>> bool(est.max[0] < 1e-4)
    True
    """

    t: np.ndarray
    names: list
    units: list
    history: np.ndarray
    factor: float
    how: str
    reference: object = field(repr=False, default=None)  #: the second run (a Result)
    result: object = field(repr=False, default=None)     #: the run it estimates (a Result)

    @property
    def max(self) -> np.ndarray:
        """(n,) the largest estimated error of each output over the output times."""
        return self.history.max(axis=0) if len(self.t) else np.zeros(len(self.names))

    def of(self, quantity) -> np.ndarray:
        """The estimated error of ``quantity(result)`` (a function of a Result returning an array, e.g.
        ``lambda r: r.position(beam.tip)``): factor × |quantity(result) − quantity(second run)|, elementwise."""
        if not callable(quantity):
            raise _checks.refuse(f"quantity: expected a function of a Result (e.g. lambda r: r.position(tip)), got "
                             f"{quantity!r}")
        a, b = np.asarray(quantity(self.result), dtype=float), np.asarray(quantity(self.reference), dtype=float)
        if a.shape != b.shape:
            raise _checks.refuse(f"quantity: expected the same shape from both runs, got {a.shape} and {b.shape}")
        return self.factor * np.abs(a - b)

    def table(self) -> list:
        """Rows (output, unit, largest estimated error)."""
        return [(n, u, float(m)) for n, u, m in zip(self.names, self.units, self.max)]

    def __repr__(self) -> str:
        rows = ", ".join(f"{n}: {m:.2g} {u}" for n, u, m in self.table())
        return f"<rigidfem ErrorEstimate ({self.how}): {rows}>"


def output_names(system, error_on) -> tuple[list, list]:
    """The names and units of the outputs of ``error_on`` (as ``specs`` reads it)."""
    names, units = [], []
    for kind, index, r in specs(system, error_on) or [("state", -1, None)]:
        if kind in ("bodies", "state"):
            names.append("bodies"), units.append("m")
        elif kind == "point":
            names.append(f"{system.body_names[index]} ({', '.join(f'{x:g}' for x in r)})"), units.append("m")
        elif kind == "coordinate":
            name = system.coordinate_names[index]
            names.append(name), units.append("rad" if name.split(".")[-1].startswith("r") else "m")
        elif kind == "element":
            names.append(f"{system.element_names[index]} force"), units.append("N")
        else:
            names.append(f"{system.loop_names[index]} reaction"), units.append("N or N·m")
    return names, units


def output_histories(result, error_on) -> list:
    """Each output of ``error_on`` (the state: "bodies") along a Result: arrays (len(t), k)."""
    system = result.system
    out = []
    for kind, index, r in specs(system, error_on) or [("bodies", -1, None)]:
        if kind == "bodies":
            out.append(_bodies(system, result.t, result.q))
        elif kind == "point":
            out.append(_core._point_positions(system, index, r, -1, result.t, result.q))
        elif kind == "coordinate":
            out.append(result.q[:, index:index + 1])
        elif kind == "element":
            out.append(result.element_forces[:, index:index + 1])
        else:
            out.append(result.loop_reactions[:, index, :])
    return out


def _bodies(system, t, q) -> np.ndarray:
    """(len(t), 6 nbodies): each body's origin and centre of mass, x_i = T_i [c_i; 1] (m, global), from one
    kinematics pass per output (``_core._body_poses``)."""
    n, N = system.nbodies, len(t)
    P = _core._body_poses(system, np.asarray(t, dtype=float), np.ascontiguousarray(q, dtype=float)).reshape(N, n, 12)
    R, origin = P[:, :, :9].reshape(N, n, 3, 3), P[:, :, 9:]
    com = np.einsum("knij,nj->kni", R, np.asarray(system.centres_of_mass, dtype=float).reshape(n, 3)) + origin
    return np.concatenate([origin, com], axis=2).reshape(N, 6 * n)


def estimate(result, rerun, fixed_order: int | None) -> ErrorEstimate:
    """The ErrorEstimate of ``result`` from ``rerun`` (the second run's Result at the same output
    times); ``fixed_order`` the order p of a fixed-step method (None: adaptive)."""
    error_on = result.run.get("error_on") if result.run else None
    if result.run and not result.run.get("outputs"):
        error_on = "state"
    factor = 1.0 if fixed_order is None else 2.0**fixed_order / (2.0**fixed_order - 1.0)
    names, units = output_names(result.system, error_on)
    first, second = output_histories(result, error_on), output_histories(rerun, error_on)
    history = np.column_stack([factor * _largest(a, b) for a, b in zip(first, second)]) if names else np.zeros((len(result.t), 0))
    how = (f"a second run at rtol/{TIGHTER:g}, atol/{TIGHTER:g}" if fixed_order is None
           else f"a second run at dt/2, Richardson's factor {factor:.3g} for order {fixed_order}")
    return ErrorEstimate(result.t.copy(), names, units, history, factor, how, rerun, result)


def _largest(a, b) -> np.ndarray:
    """The largest difference per output time: over the coordinates of points (Euclidean, per point of
    3) and over the rest."""
    d = np.abs(np.asarray(a) - np.asarray(b))
    if d.shape[1] % 3 == 0 and d.shape[1] >= 3 and a.shape[1] != 1:
        return np.linalg.norm(d.reshape(len(d), -1, 3), axis=2).max(axis=1)
    return d.max(axis=1) if d.shape[1] else np.zeros(len(d))
