"""The integrators' methods and options as the C++ core describes them, each once.

The method table (``cpp/include/rigidfem/stepper.hpp``: a row of ``MethodInfo`` per method, in its family's
file) and the option table (``integrator_options`` in ``cpp/src/integrate.cpp``: name, type, default, unit,
doc) are read here through the bindings; ``simulate``'s option handling, its docstring, ``rf.gradient``'s
options and the site's tables are derived from them. The SciPy adapter's methods (``"scipy:<name>"``, Python's
own: ``rigidfem.simulation``) are described here too.

``simulate(system, t_end, method="auto", *, t0, q0, qd0, s0, t_eval, progress, stop, error_estimate, sensitivities,
**options)`` takes the run's arguments by name and the integrator's options as ``**options``: an unknown name is
a TypeError listing the options; an option the chosen method does not read is accepted and left unused (one set
of options can drive a comparison of methods), except ``dt`` given to an adaptive method, which warns (see
``dt``).

>>> import rigidfem as rf
>>> sorted(rf.integrator_options("generalized_alpha"))[:4]
['adaptive', 'atol', 'dt', 'error_on']
>>> rf.integrator_options("generalized_alpha")["rho_inf"].default
0.8
>>> rf.methods()["radau5"].order
5
"""

from __future__ import annotations

import textwrap
from dataclasses import dataclass

import rigidfem._core as _core  # the compiled core, by its absolute name
from ..base import _checks

#: SciPy's solvers behind ``"scipy:<name>"`` (the Python adapter of ``rigidfem.simulation``) and the options it
#: reads.
SCIPY = ("scipy:Radau", "scipy:BDF", "scipy:LSODA", "scipy:RK45", "scipy:DOP853")
SCIPY_OPTIONS = ("rtol", "atol", "first_step", "max_step", "max_steps")


@dataclass(frozen=True)
class Method:
    """One integration method (``rf.methods()``): its ``family``, the ``order`` of its propagated solution, whether
    it has an ``error_estimate`` (so may run adaptive), whether it is ``adaptive`` by default, ``error_on``
    (what its error is measured on by default: "bodies" or "state"; auto: its stiff method's), whether it has an
    ``adjoint`` (``rigidfem.gradient``), the ``options`` it reads and its scheme (``doc``)."""

    name: str
    family: str
    order: int
    error_estimate: bool
    adaptive: bool
    error_on: str
    adjoint: bool
    options: tuple
    doc: str


@dataclass(frozen=True)
class Option:
    """One option of the integrators: ``name``, its ``default``, its ``unit`` and the ``methods`` that
    read it, with what it does (``doc``) and what it takes (``expected``)."""

    name: str
    default: object
    unit: str
    methods: tuple
    doc: str
    expected: str = ""


def _methods() -> dict[str, Method]:
    rows = {r["name"]: Method(r["name"], r["family"], r["order"], r["error_estimate"], r["adaptive"],
                              "bodies" if r["measures_outputs"] else "state", r["adjoint"], tuple(r["options"]), r["doc"])
            for r in _core._method_table()}
    for name in SCIPY:  # adaptive, their own error control on the state
        rows[name] = Method(name, "SciPy", 0, True, True, "state", False, SCIPY_OPTIONS,
                            f"SciPy's {name[6:]} with the C++ rhs and Jacobian, stepped from Python (the slow path); "
                            "closed chains and Maxwell arms refused (ValueError)"
                            + ("; one rtol, the smallest given" if name in ("scipy:Radau", "scipy:BDF") else ""))
    return rows


_METHODS = _methods()
#: Every method's name: "auto" first, then the C++ ones by family, then SciPy's.
METHODS = ("auto",) + tuple(name for name in _METHODS if name != "auto")

OPTIONS = tuple(Option(r["name"], r["default"], r["unit"], tuple(m for m in METHODS if r["name"] in _METHODS[m].options),
                       r["doc"], r["expected"])
                for r in _core._option_table())

_BY_NAME = {o.name: o for o in OPTIONS}


def methods() -> dict[str, Method]:
    """The integration methods (name -> ``Method``): the C++ method table, with SciPy's solvers.

    Examples
    --------
    >>> import rigidfem as rf
    >>> m = rf.methods()
    >>> "dopri5" in m, "radau5" in m
    (True, True)
    """
    return {name: _METHODS[name] for name in METHODS}


def method(name) -> Method:
    """The method called ``name``; ValueError listing the methods otherwise."""
    if not isinstance(name, str) or name not in _METHODS:
        raise _checks.refuse(f"method: expected one of {list(METHODS)}, got {name!r}")
    return _METHODS[name]


def integrator_options(method: str | None = None) -> dict[str, Option]:
    """The options (name -> ``Option``) that ``method`` reads, or every option for None. ValueError for
    an unknown method.

    Examples
    --------
    >>> import rigidfem as rf
    >>> sorted(rf.integrator_options("rk4"))
    ['dt', 'max_steps']
    """
    if method is None:
        return dict(_BY_NAME)
    readers = globals()["method"](method).options
    return {o.name: o for o in OPTIONS if o.name in readers}


def resolve(options: dict) -> dict:
    """Every option's value: those given in ``options``, the defaults for the rest. TypeError naming an
    unknown option (as Python does for an unexpected keyword), with the list of options."""
    unknown = sorted(set(options) - set(_BY_NAME))
    if unknown:
        raise TypeError(f"simulate() got unexpected options {unknown}; the integrators' options are "
                        f"{list(_BY_NAME)} (rigidfem.integrator_options(method) lists those a method reads), "
                        "and the run's arguments t0, q0, qd0, s0, t_eval, progress, stop, error_estimate, sensitivities")
    return {name: options.get(name, o.default) for name, o in _BY_NAME.items()}


def compiled(method: str, options: dict, every: bool = False) -> _core.IntegratorOptions:
    """The C++ options of ``method`` with ``options`` ({name: value}) set, each converted by the bindings' rule
    (ValueError naming it); error_on, rtol and atol are left to the caller (they depend on the system). An option
    the method does not read (the method table's) is converted and left at its default: rk4 given ``first_step``
    or ``max_step`` steps at dt as without them. ``every``: all of them set, for ``check_options`` to judge their
    values (a bad one is named whatever the method). ``adaptive`` is a request, always passed on: a method
    without an error estimate refuses True (``check_options``). An option at its default (the table's own object,
    as ``resolve`` fills it in) is not set again: a fresh ``IntegratorOptions`` holds the table's defaults."""
    opt = _core.IntegratorOptions()
    opt.method = method
    reads = _METHODS[method].options if method in _METHODS else ()
    for name, value in given(options).items():
        (opt if every or name in reads or name == "adaptive" else _core.IntegratorOptions()).set(name, value)
    return opt


def given(options: dict) -> dict:
    """The options of ``options`` that ``compiled`` sets: those not at their default (the table's own object),
    except error_on, rtol and atol (the caller's)."""
    return {name: value for name, value in options.items()
            if name not in ("error_on", "rtol", "atol") and value is not _BY_NAME[name].default}


def read_by(method: str, options: dict) -> bool:
    """Whether ``method`` reads every option that ``compiled`` sets (adaptive counts as read): then the options
    with every one set are the method's own."""
    reads = _METHODS[method].options if method in _METHODS else ()
    return all(name in reads or name == "adaptive" for name in given(options))


def _readers(o: Option) -> str:
    return "every method" if set(o.methods) >= set(METHODS) else ", ".join(o.methods)


def table() -> str:
    """The options as a markdown table: name, default, unit, the methods that read them."""
    lines = ["| option | default | unit | read by |", "|---|---|---|---|"]
    for o in OPTIONS:
        lines.append(f"| `{o.name}` | {o.default!r} | {o.unit} | {_readers(o)} |")
    return "\n".join(lines)


def method_table() -> str:
    """The methods as a markdown table: name, family, order, adaptive by default, error measured on, scheme."""
    lines = ["| method | family | order | step | error on | scheme |", "|---|---|---|---|---|---|"]
    for m in methods().values():
        step = "rtol/atol" if m.adaptive else ("dt or adaptive" if m.error_estimate else "fixed dt")
        lines.append(f"| `{m.name}` | {m.family} | {m.order or ''} | {step} | {m.error_on} | {m.doc} |")
    return "\n".join(lines)


def docstring(indent: int = 8) -> str:
    """The options as a numpydoc parameter list, wrapped to 100 columns and indented by ``indent``
    (for ``simulate.__doc__``)."""
    parts = []
    pad = " " * indent
    for o in OPTIONS:
        unit = f", {o.unit}" if o.unit and o.unit != "1" else ""
        parts.append(f"{pad}{o.name} : default {o.default!r}{unit}")
        parts.append(textwrap.fill(f"{o.doc} Read by: {_readers(o)}.", 100, initial_indent=pad + "    ",
                                   subsequent_indent=pad + "    "))
    return "\n".join(parts)
