"""The options of ``rigidfem.simulate``'s integrators, each written once: its default, its unit and the
methods that read it.

``simulate(system, t_end, method="auto", *, t0, q0, qd0, s0, t_eval, progress, stop, error_estimate, sensitivities,
**options)`` takes the run's arguments by name and the integrator's options as ``**options``, checked
against this table: an unknown name is a TypeError listing the options; an option the chosen method
does not read is accepted and left unused (one set of options can drive a comparison of methods),
except ``dt`` given to an adaptive method, which warns (see ``dt``).

>>> import rigidfem as rf
>>> sorted(rf.integrator_options("generalized_alpha"))[:4]
['atol', 'dt', 'error_on', 'first_step']
>>> rf.integrator_options("generalized_alpha")["rho_inf"].default
0.8
"""

from __future__ import annotations

import textwrap
from dataclasses import dataclass

import numpy as np

#: The C++ methods by family, and SciPy's solvers behind ``"scipy:<name>"``.
EXPLICIT_FIXED = ("euler", "symplectic_euler", "rk4")
EXPLICIT_ADAPTIVE = ("dopri5", "rkf45")
NEWMARK = ("newmark", "hht", "generalized_alpha", "implicit_spring")
IMPLICIT_RK = ("esdirk43", "radau5")
SCIPY = ("scipy:Radau", "scipy:BDF", "scipy:LSODA", "scipy:RK45", "scipy:DOP853")
METHODS = ("auto",) + EXPLICIT_FIXED + EXPLICIT_ADAPTIVE + NEWMARK + IMPLICIT_RK + SCIPY

_ADAPTIVE_CPP = ("auto",) + EXPLICIT_ADAPTIVE + IMPLICIT_RK + NEWMARK  # the Newmark family with adaptive=True
_IMPLICIT = ("auto",) + NEWMARK + IMPLICIT_RK


@dataclass(frozen=True)
class Option:
    """One option of the integrators: ``name``, its ``default``, its ``unit`` and the ``methods`` that
    read it, with what it does (``doc``)."""

    name: str
    default: object
    unit: str
    methods: tuple
    doc: str


OPTIONS = (
    Option("dt", None, "s", EXPLICIT_FIXED + NEWMARK + IMPLICIT_RK + EXPLICIT_ADAPTIVE + ("auto",),
           "Step of the fixed-step methods: steps end on t0 + k·dt exactly, the last on t_end. Given to an "
           "adaptive method (dopri5, rkf45, esdirk43, radau5, auto) it sets only the first step, with a "
           "UserWarning saying so (``adaptive=False`` runs those at fixed steps of dt)."),
    Option("rtol", 1e-6, "1", _ADAPTIVE_CPP + SCIPY,
           "Relative tolerance of adaptive runs (float, or (2 nq,) per component of y = [q, q̇] with "
           "``error_on='state'``). On outputs each output's local error is held to atol + rtol × scale: for "
           "points and bodies the model's size L (m, ``stats['model_size']``) or the farthest a centre of mass "
           "has moved if larger; the largest magnitude reached so far for coordinates, element forces and loop "
           "reactions. On the state: atol_i + rtol_i |y_i| (atol = 0: purely relative; an exactly zero "
           "component counts as exact). SciPy's methods raise rtol to their floor 100 ε; scipy:Radau and "
           "scipy:BDF take one rtol, the smallest given."),
    Option("atol", 1e-9, "m, rad (per s for rates)", _ADAPTIVE_CPP + SCIPY,
           "Absolute tolerance of adaptive runs, as rtol."),
    Option("error_on", None, "", _ADAPTIVE_CPP,
           "What the adaptive C++ methods measure their local error on (``rigidfem.error_control``): a list "
           "of points and bodies (their positions, m), coordinate names or indices (m or rad), force element "
           "names (their axial force, N) and loop names (their multipliers, N or N·m), each error mapped from "
           "the state's through the output's Jacobian, a velocity's held as the displacement it makes over the "
           "step. None (the default): 'bodies' — every body's displacement, the RMS over its material "
           "√(|δc|² + δθᵀ I_C δθ/m) — for radau5, the adaptive Newmark family and auto's radau5; 'state' for "
           "dopri5, rkf45, esdirk43 and auto's dopri5 phase. A mode that no output sees is not resolved: the "
           "L-stable radau5 damps it (the released strip of 1 m, m = 32: 2,800 steps to 1e-6 m instead of "
           "177,000)."),
    Option("first_step", None, "s", _ADAPTIVE_CPP + SCIPY,
           "First step of an adaptive run; estimated (Hairer's rule) by default."),
    Option("max_step", np.inf, "s", _ADAPTIVE_CPP + SCIPY, "Largest step of an adaptive run."),
    Option("max_steps", 1_000_000, "", METHODS,
           "A run that needs more steps (accepted and rejected) raises SimulationError carrying the partial "
           "result."),
    Option("adaptive", None, "", ("auto",) + EXPLICIT_ADAPTIVE + IMPLICIT_RK + NEWMARK,
           "Step-size control: on by default for dopri5, rkf45, esdirk43 and radau5 (False runs them at the "
           "fixed step dt), off by default for the Newmark family (True switches on its local error "
           "estimate); auto takes None or True."),
    Option("stiffness_warning", True, "", EXPLICIT_ADAPTIVE,
           "dopri5 and rkf45 run Hairer's stiffness test (h ρ > 3.25, rkf45 2.95, over 15 accepted steps): "
           "the step is then bounded by stability, so it costs ~t ω_max/3.3 steps, and at loose tolerances "
           "the stiff modes keep errors ~rtol ω_max/ω, or grow. It warns (RuntimeWarning) and records the "
           "time in ``stats['stiff_at']``; False keeps the record and drops the warning."),
    Option("beta", 0.25, "1", ("newmark",), "Newmark's β."),
    Option("gamma", 0.5, "1", ("newmark",), "Newmark's γ."),
    Option("alpha", -0.05, "1", ("hht",), "HHT's α ∈ [−1/3, 0]."),
    Option("rho_inf", 0.8, "1", ("generalized_alpha", "implicit_spring"),
           "Generalised-α's spectral radius at infinite frequency ρ∞ ∈ [0, 1]."),
    Option("newton_tol", 1e-10, "1", _IMPLICIT,
           "Newton stops when the increments of q and q̇ fall below newton_tol (1 + |q|); the Newmark family "
           "also holds them to 0.03 of the step's local error estimate e_q (q̇'s to 0.03 e_q/√(h T), T the run's "
           "length), down to 1e-3 newton_tol (1 + |q|) and at least 500 ε (1 + |q|), so that small steps keep "
           "the method's order; adaptive esdirk43 "
           "and radau5 runs stop it at 0.03 of the error weights instead."),
    Option("newton_max_iterations", 10, "", _IMPLICIT, "Newton iterations per step (or stage) at most."),
    Option("iteration_matrix", "auto", "", _IMPLICIT,
           "Newton matrix of the implicit methods: 'tangent' (the exact tangent M + γ'h ∂r/∂q̇ + β'h² ∂r/∂q, "
           "analytic for recursive systems, dense LU: O(n³)), 'krylov' (the same tangent, never formed: its "
           "products are directional derivatives of the inverse dynamics and its solves GMRES preconditioned "
           "by the spring matrix, O(n) per iteration; recursive systems), 'spring' (the O(n) matrix of "
           "implicit_spring: M + diag(γ'h b + β'h² c)) or 'auto' (spring for implicit_spring, else krylov for "
           "a recursive system of more than 200 coordinates and tangent below). radau5 takes the tangent, "
           "dense or krylov. ``stats['linear_iterations']`` counts the GMRES iterations."),
)

_BY_NAME = {o.name: o for o in OPTIONS}


def integrator_options(method: str | None = None) -> dict[str, Option]:
    """The options (name -> ``Option``) that ``method`` reads, or every option for None. ValueError for
    an unknown method."""
    if method is None:
        return dict(_BY_NAME)
    if not isinstance(method, str) or method not in METHODS:
        raise ValueError(f"method: expected one of {list(METHODS)}, got {method!r}")
    return {o.name: o for o in OPTIONS if method in o.methods}


def resolve(options: dict) -> dict:
    """Every option's value: those given in ``options``, the defaults for the rest. TypeError naming an
    unknown option (as Python does for an unexpected keyword), with the list of options."""
    unknown = sorted(set(options) - set(_BY_NAME))
    if unknown:
        raise TypeError(f"simulate() got unexpected options {unknown}; the integrators' options are "
                        f"{list(_BY_NAME)} (rigidfem.integrator_options(method) lists those a method reads), "
                        "and the run's arguments t0, q0, qd0, s0, t_eval, progress, stop, error_estimate, sensitivities")
    return {name: options.get(name, o.default) for name, o in _BY_NAME.items()}


def table() -> str:
    """The options as a markdown table: name, default, unit, the methods that read them."""
    lines = ["| option | default | unit | read by |", "|---|---|---|---|"]
    for o in OPTIONS:
        readers = "every method" if set(o.methods) >= set(METHODS) else ", ".join(o.methods)
        lines.append(f"| `{o.name}` | {o.default!r} | {o.unit} | {readers} |")
    return "\n".join(lines)


def docstring(indent: int = 8) -> str:
    """The options as a numpydoc parameter list, wrapped to 100 columns and indented by ``indent``
    (for ``simulate.__doc__``)."""
    parts = []
    pad = " " * indent
    for o in OPTIONS:
        unit = f", {o.unit}" if o.unit and o.unit != "1" else ""
        readers = "every method" if set(o.methods) >= set(METHODS) else ", ".join(o.methods)
        parts.append(f"{pad}{o.name} : default {o.default!r}{unit}")
        parts.append(textwrap.fill(f"{o.doc} Read by: {readers}.", 100, initial_indent=pad + "    ",
                                   subsequent_indent=pad + "    "))
    return "\n".join(parts)
