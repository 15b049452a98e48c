"""Adjoint gradients: the derivative of one scalar objective of a run by many parameters at once.

``rigidfem.gradient(system, t_end, parameters, outputs=..., running=..., terminal=..., dt=...)`` returns

    J = ∫_{t0}^{t_end} L(t, y(t)) dt + Φ(y(t_end))

and dJ/dp for every parameter p named (``System.parameters``, or initial values ``"q0[<coordinate>]"``,
``"qd0[<coordinate>]"``), where y are the outputs asked for: points' global positions (m) and free
coordinates (m or rad). The integral is the trapezoidal rule on the run's steps, and the gradient is that of
the discrete objective of the discrete solution: the discrete adjoint of the Newmark family or of radau5 at fixed
steps (``cpp/include/rigidfem/adjoint.hpp``). Its cost does not grow with the number of parameters: one forward
run, one backward sweep (a transposed solve per step by GMRES on the RNEA's reverse mode, preconditioned by a
kept factorisation), μᵀ∂r/∂p of every parameter in one O(n) pass, and, when the states do not all fit into
``memory`` bytes, a second forward run of each segment between checkpoints (⌈√N⌉ steps apart).

The objective's functions are Python, called once per run on whole arrays (never per step): ``running(t, y)``
with t (N + 1,) and y a dict {name: (N + 1, 3) or (N + 1,)} returns L at every step (N + 1,);
``terminal(y)`` with y {name: (3,) or float} returns Φ. Their derivatives by y are taken by the complex step
(exact to round-off for functions numpy evaluates in complex arithmetic); a function that does not take
complex input (abs, comparisons, float()) is differentiated by central differences instead
(``Gradient.stats["objective_derivative"]`` says which).

Closed loops with the Newmark family and radau5, a drive's or an actuator's numbers moving them included. Not
yet: Maxwell arms, the Lagrange engine (algorithm='lagrange'), adaptive steps. Links of varying length: a parameter of
their rfes' inertias or of L(t) by differences of μᵀr whole (O(n) per such parameter and step).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..base import _checks
import rigidfem._core as _core  # the compiled core, by its absolute name
from ..simulation import error_control
from ..simulation import options as options_
from ..simulation import integration
from ..simulation import sensitivities as sensitivities_

#: The methods with an adjoint (the method table's), the default first.
METHODS = tuple(sorted((name for name, m in options_.methods().items() if m.adjoint),
                       key=lambda name: name != "generalized_alpha"))


@dataclass
class Gradient:
    """The objective J of a run and its gradient (``rigidfem.gradient``).

    ``value`` is J; ``gradient`` {name: dJ/dp} in units of J per unit of p; ``q0`` and ``qd0`` dJ/dq₀ and
    dJ/dq̇₀ (nq); ``t`` the steps (s); ``outputs`` {name: (len t, 3) or (len t,)}; ``stats`` the run's
    counts and times (s).

    Examples
    --------
    >>> import rigidfem as rf
    >>> model, h = rf.samples.spring_mass()
    >>> system = model.compile()
    >>> g = rf.gradient(system, 1.0, ["q0[block.x]"], outputs={"x": "block.x"},
    ...                terminal=lambda y: y["x"], dt=1e-3, q0=[0.1])
    >>> type(g).__name__, sorted(g.gradient)
    ('Gradient', ['q0[block.x]'])
    """

    value: float
    gradient: dict
    t: np.ndarray = field(repr=False)
    outputs: dict = field(repr=False)
    q0: np.ndarray = field(repr=False)
    qd0: np.ndarray = field(repr=False)
    stats: dict = field(repr=False)

    def __getitem__(self, name: str) -> float:
        if name not in self.gradient:
            raise KeyError(f"name: expected one of the parameters of this gradient {list(self.gradient)}, got {name!r}")
        return self.gradient[name]

    def array(self) -> np.ndarray:
        """dJ/dp in the order of the parameters asked for."""
        return np.array(list(self.gradient.values()))


def gradient(system, t_end: float, parameters=None, *, outputs, running=None, terminal=None,
             method: str = "generalized_alpha", dt: float, t0: float = 0.0, q0=None, qd0=None,
             memory: float = 2.0**28, **options) -> Gradient:
    """J = ∫ L(t, y) dt + Φ(y(t_end)) of a run from ``t0`` to ``t_end`` (s) and dJ/dp by the adjoint.

    Parameters
    ----------
    parameters : list of str, optional
        Names of ``System.parameters`` or initial values ``"q0[<coordinate>]"``, ``"qd0[<coordinate>]"``;
        every parameter of the system by default.
    outputs : dict
        {name: output}: a ``Point`` or ``Body`` (its origin; global position, m) or a free coordinate's name
        or index in q (m or rad).
    running : callable, optional
        L(t, y) -> (N + 1,) array, t (N + 1,) s, y {name: (N + 1, 3) or (N + 1,)}; None: no integral.
    terminal : callable, optional
        Φ(y) -> float, y {name: (3,) or float} at t_end; None: no terminal term.
    method : str
        "generalized_alpha" (default), "newmark", "hht", "implicit_spring" or "radau5", at fixed steps ``dt`` (s).
    memory : float
        Bytes for the states the backward sweep needs (default 256 MiB): all of them if they fit, else
        checkpoints every ⌈√N⌉ steps and each segment run again; the forward run's dense Newton
        factorisations, which precondition the sweep, are kept within an eighth of it besides.
    **options
        The method's options as in ``rigidfem.simulate`` (``rho_inf``, ``alpha``, ``beta``, ``gamma``,
        ``newton_tol``, ``newton_max_iterations``, ``iteration_matrix``: ``rigidfem.integrator_options(method)``);
        the run is at fixed steps ``dt``, so ``adaptive`` and ``error_on`` are refused.

    Returns
    -------
    Gradient
        ``value`` J, ``gradient`` {name: dJ/dp}, ``q0``/``qd0`` dJ/dq₀, dJ/dq̇₀, ``stats``. With loop closures
        ``q0``/``qd0`` are the partial derivatives by each coordinate; an initial value named in ``parameters``
        moves along the loops (as ``System.assemble`` would close them).

    Examples
    --------
    >>> import rigidfem as rf
    >>> model, h = rf.samples.spring_mass()
    >>> system = model.compile()
    >>> g = rf.gradient(system, 1.0, ["q0[block.x]"], outputs={"x": "block.x"},
    ...                terminal=lambda y: y["x"], dt=1e-3, q0=[0.1])
    >>> round(g.value, 4), round(g.gradient["q0[block.x]"], 4)
    (0.0409, 0.4087)
    """
    system = _checks.system(system)

    if not isinstance(method, str) or method not in METHODS:
        raise _checks.refuse(f"method: expected one of {list(METHODS)} (the methods with an adjoint), got {method!r}")
    if dt is None:
        raise _checks.refuse("dt: expected a fixed step (s) > 0: the adjoint runs at fixed steps, got None")
    specs, names = _outputs(system, outputs)
    if running is None and terminal is None:
        raise _checks.refuse("running: expected a function L(t, y) or a terminal Φ(y) (or both), got neither")
    for f, argument in ((running, "running"), (terminal, "terminal")):
        if f is not None and not callable(f):
            raise _checks.refuse(f"{argument}: expected a function or None, got {f!r}")
    t0 = _checks.scalar(t0, "t0")
    t_end = _checks.scalar(t_end, "t_end")
    memory = _checks.scalar(memory, "memory", positive=True, unit="bytes")
    n = system.nq
    q0 = np.zeros(n) if q0 is None else _checks.array(q0, (n,), "q0")
    qd0 = np.zeros(n) if qd0 is None else _checks.array(qd0, (n,), "qd0")
    given = options_.resolve(options) and options  # TypeError naming an unknown option
    for name in ("adaptive", "error_on"):
        if given.get(name) is not None:
            raise _checks.refuse(f"{name}: expected None: the adjoint runs at fixed steps dt, got {given[name]!r}")
    given = {**given, "dt": dt, "adaptive": False}
    opt = options_.compiled(method, given)  # what the method reads; every option given judged:
    _core._check_options(system, t0, t_end, q0, qd0, np.empty(0), options_.compiled(method, given, every=True))
    if parameters is None:
        parameters = list(system.parameters)
    _probe(system, specs, names, running, terminal, t0, q0)  # a bad objective is named before any run
    directions = sensitivities_.directions(system, parameters, opt, t0, t_end, "parameters", one_sided_drives=True)
    integration._check_closed(system, t0, q0, qd0)  # the arguments first, then whether the state closes the loops
    adjoint = _core._Adjoint(system, opt, specs, memory)
    start = time.perf_counter()
    t, Y = adjoint.forward(t0, t_end, q0, qd0)
    y = _split(Y, specs, names)
    value, ybar, how = _objective(t, y, Y, specs, names, running, terminal)
    grad, q0bar, qd0bar, stats = adjoint.backward(ybar)
    stats["objective_derivative"] = how
    stats["wall_time"] = time.perf_counter() - start
    return Gradient(value, dict(zip(directions, map(float, grad))), t, y, q0bar, qd0bar, stats)


def _outputs(system, outputs) -> tuple[list, list]:
    """The C++ specs and names of ``outputs`` (a dict of points, bodies and free coordinates)."""
    if not isinstance(outputs, dict) or not outputs:
        raise _checks.refuse(f"outputs: expected a dict {{name: Point, Body or coordinate}} with at least one output, "
                         f"got {outputs!r}")
    specs = []
    for name, item in outputs.items():
        if not isinstance(name, str):
            raise _checks.refuse(f"outputs: expected names (str) as keys, got {name!r}")
        kind, index, r = error_control._spec(system, item, "outputs")
        if kind not in ("point", "coordinate"):
            raise _checks.refuse(f"outputs: expected points, bodies or free coordinates, got the {kind} {item!r}")
        specs.append((kind, index, r))
    return specs, list(outputs)


def _probe(system, specs, names, running, terminal, t0, q0) -> None:
    """The objective's functions at the initial state: ValueError naming the one that does not return finite
    real numbers of the expected shape."""
    row = []
    for kind, index, r in specs:
        if kind == "point":
            row.extend(_core._point_positions(system, index, r, -1, np.array([t0]), q0[None, :])[0])
        else:
            row.append(q0[index])
    Y = np.array([row], dtype=float)
    if running is not None:
        _values(running(np.array([t0]), _split(Y, specs, names)), (1,), "running", "an array of L at every step")
    if terminal is not None:
        _values(terminal({k: v[0] for k, v in _split(Y, specs, names).items()}), (), "terminal", "a number")


def _split(Y, specs, names) -> dict:
    """{name: (N + 1, 3) or (N + 1,)} of the outputs' columns Y (N + 1, K)."""
    out, k = {}, 0
    for (kind, _, _), name in zip(specs, names):
        width = 3 if kind == "point" else 1
        out[name] = Y[:, k:k + width] if width == 3 else Y[:, k]
        k += width
    return out


def _trapezoid_weights(t: np.ndarray) -> np.ndarray:
    """w with Σ w_n L_n the trapezoidal rule on the steps t."""
    h = np.diff(t)
    w = np.zeros_like(t)
    w[:-1] += h / 2
    w[1:] += h / 2
    return w


def _objective(t, y, Y, specs, names, running, terminal):
    """J and ∂J/∂Y (N + 1, K) and how the functions were differentiated."""
    w = _trapezoid_weights(t)
    value, ybar, how = 0.0, np.zeros_like(Y), "complex step"
    if running is not None:
        L = _values(running(t, y), (len(t),), "running", f"an array of L at the {len(t)} steps")
        value += float(w @ L)
        dL, how_r = _derivatives(lambda Yc: running(t, _split(Yc, specs, names)), Y, (len(t),))
        ybar += w[:, None] * dL
        how = how_r
    if terminal is not None:
        last = lambda Yc: _split(Yc[None, :], specs, names)  # noqa: E731 (one row as the dict of its values)
        first = {k: v[0] for k, v in last(Y[-1]).items()}
        value += float(_values(terminal(first), (), "terminal", "a number"))
        dPhi, how_t = _derivatives(lambda row: terminal({k: v[0] for k, v in last(row).items()}), Y[-1], ())
        ybar[-1] += dPhi
        how = how_t if how_t != "complex step" else how
    return value, ybar, how


def _values(x, shape, argument, expected) -> np.ndarray:
    """x as finite reals of ``shape``; ValueError naming ``argument`` otherwise."""
    try:
        a = np.asarray(x, dtype=float)
    except (TypeError, ValueError):
        raise _checks.refuse(f"{argument}: expected {expected} (finite real numbers), got {_checks._short(x)}") from None
    if a.shape != shape or not np.isfinite(a).all():
        raise _checks.refuse(f"{argument}: expected {expected} (finite real numbers, shape {shape}), got "
                         f"{_checks._short(x)}")
    return a


def _derivatives(f, X, shape) -> tuple[np.ndarray, str]:
    """∂f/∂X column by column (f vectorised over the rows of X: shape (N,) per column of X (N, K), or a scalar of
    a row X (K,)): by the complex step where it agrees with central differences (to 1e-5: a function that drops
    the imaginary part, as abs or float() do, would give a wrong one), else by the central differences."""
    central = np.zeros_like(X)
    for c in range(X.shape[-1]):
        step = 1e-6 * np.maximum(1.0, np.abs(X[..., c]))
        Xp, Xm = X.copy(), X.copy()
        Xp[..., c] += step
        Xm[..., c] -= step
        central[..., c] = (np.asarray(f(Xp), dtype=float) - np.asarray(f(Xm), dtype=float)).reshape(shape) / (2 * step)
    h = 1e-30
    exact = np.zeros_like(X)
    try:
        for c in range(X.shape[-1]):
            Xc = X.astype(complex)
            Xc[..., c] += 1j * h
            v = np.asarray(f(Xc))
            if not np.iscomplexobj(v):
                raise TypeError("not complex")
            exact[..., c] = (v.imag / h).reshape(shape)
    except (TypeError, ValueError, AttributeError):
        return central, "central differences"
    if np.allclose(exact, central, rtol=1e-5, atol=1e-8 * max(np.abs(central).max(), 1e-300)):
        return exact, "complex step"
    return central, "central differences"
