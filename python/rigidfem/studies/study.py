"""Speed against error (book ch. 5.3): work–precision studies of models and integrators,
and the discretisation error against the number of rigid finite elements.

For example (a study of several minutes)::

    scene = study.scenes.kane(omega=6.0, elements=10)
    table = study.work_precision(scene, [("dopri5", "rtol", [1e-4, 1e-6, 1e-8]),
                                         ("generalized_alpha", "dt", [0.01, 0.005])])
    print(table); table.to_csv("wp.csv"); table.plot()

Errors are measured against a reference solved much more tightly (Dormand–Prince at
rtol = 1e-12 by default) at the same output times: the tip position (m) at the final time
and as an RMS over the run, and the same for the joint coordinates. Wall time is the
minimum of several warm runs.

Examples
--------
>>> import rigidfem as rf
>>> scene = rf.study.scenes.cantilever(elements=4)
>>> type(scene).__name__
'Scene'
"""

from __future__ import annotations

import csv
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..model import samples
from .._core import Body, Point
from ..analysis.modes import modal_analysis
from ..analysis.statics import static_equilibrium
from ..base import _checks
from ..base.persistence import Versioned
from ..model.materials import Material, Section
from ..model.model import Model
from ..simulation.integration import simulate
from ..simulation.options import methods as _methods
from ..simulation.result import finished as _finished


@dataclass
class Scene:
    """A simulation to study: a compiled system, its initial state, span and observed point."""

    name: str
    system: object
    t_end: float                       #: s
    tip: Point                         #: the observed point
    frame: Body | None = None          #: observe it in this body's frame (None: global)
    q0: np.ndarray | None = None
    qd0: np.ndarray | None = None
    outputs: int = 51                  #: number of output times (uniform over [0, t_end])

    def __post_init__(self):
        self.system = _checks.system(self.system, "system")
        self.t_end = _checks.scalar(self.t_end, "t_end", positive=True, unit="s")
        if isinstance(self.tip, Body):
            self.tip = self.tip.origin
        if not isinstance(self.tip, Point):
            raise _checks.refuse(f"tip: expected a Point or Body of the system's model, got {_checks._short(self.tip)}")
        _checks.same_model(self.tip, self.system, "tip")
        if self.frame is not None and not isinstance(self.frame, Body):
            raise _checks.refuse(f"frame: expected None or a Body, got {_checks._short(self.frame)}")
        self.outputs = _checks.integer(self.outputs, "outputs", minimum=2, maximum=10**7)

    @property
    def t_eval(self) -> np.ndarray:
        return np.linspace(0.0, self.t_end, self.outputs)


class scenes:
    """The standard scenes of ``python -m rigidfem bench``."""

    @staticmethod
    def cantilever(formulation: str = "modified", elements: int = 10, periods: float = 2.0) -> Scene:
        """Free vibration of a steel cantilever (1 m, 20 × 5 mm, bending in x–y) released from
        rest at its static deflection under a 20 N tip load; classical adds axial and shear."""
        deform = ("bend_z",) if formulation == "modified" else ("axial", "shear_y", "bend_z")
        loaded, hl = samples.cantilever(elements=elements, formulation=formulation, deform=deform)
        loaded.add_force("load0", hl["beam"].tip, (0.0, 20.0, 0.0))
        q0 = static_equilibrium(loaded.compile(), load_steps=2).q
        model, h = samples.cantilever(elements=elements, formulation=formulation, deform=deform)
        T1 = 2 * np.pi / 105.0  # first period of this cantilever (s)
        return Scene(f"cantilever {formulation} m={elements}", model.compile(), periods * T1, h["beam"].tip, q0=q0)

    @staticmethod
    def stiff_cantilever(elements: int = 10, periods: float = 2.0) -> Scene:
        """The steel cantilever in 3D (both bendings and torsion, modified formulation) released
        from rest at its static deflection under a skew tip load (0, 20, 10) N and a 1 N·m
        torque: bending in the stiff plane and torsion put ω_max at 2.8·10⁴ rad/s (rf.modal_analysis),
        270 times the first frequency (105 rad/s), and the torque excites the torsion modes."""
        deform = ("torsion", "bend_y", "bend_z")
        loaded, hl = samples.cantilever(elements=elements, deform=deform)
        loaded.add_force("load0", hl["beam"].tip, (0.0, 20.0, 10.0))
        loaded.add_torque("load1", hl["beam"].tip, (1.0, 0.0, 0.0))
        q0 = static_equilibrium(loaded.compile(), load_steps=2).q
        model, h = samples.cantilever(elements=elements, deform=deform)
        T1 = 2 * np.pi / 105.0
        return Scene(f"stiff 3D cantilever m={elements}", model.compile(), periods * T1, h["beam"].tip, q0=q0)

    @staticmethod
    def kane(omega: float = 6.0, elements: int = 10, t_end: float = 20.0, linear: bool = False) -> Scene:
        """Kane's spin-up beam, tip observed in the hub frame."""
        model, h = samples.kane_beam(omega=omega, elements=elements, linear=linear)
        kind = "linear" if linear else "nonlinear"
        return Scene(f"kane {kind} Omega={omega:g} m={elements}", model.compile(), t_end, h["beam"].tip,
                     frame=h["hub"])

    @staticmethod
    def whippy(elements: int = 10, t_end: float = 1.0) -> Scene:
        """A whippy aluminium strip (1 m, 20 × 1 mm) clamped horizontally under gravity, held bent
        far upwards by a tip force (tip rotation ~60°) and released: it whips through large
        deflections under gravity."""
        def build(force):
            model = Model(gravity=(0.0, -9.81, 0.0))
            beam = model.add_beam("beam", model.ground, 1.0, Material(E=7e10, rho=2700.0),
                                  Section.rectangle(0.001, 0.02), elements, deform=("bend_z",))
            if force:
                model.add_force("load0", beam.tip, (0.0, 1.0, 0.0), follower=False)
            return model, beam

        loaded, _ = build(True)
        q0 = static_equilibrium(loaded.compile(), load_steps=10).q
        model, beam = build(False)
        return Scene(f"whippy m={elements}", model.compile(), t_end, beam.tip, q0=q0)


@dataclass
class Table(Versioned):
    """Rows of a study (dicts), printable, savable as CSV and plottable."""

    rows: list = field(default_factory=list)
    columns: tuple = ()

    def __str__(self) -> str:
        widths = [max(len(c), *(len(_fmt(r.get(c))) for r in self.rows)) for c in self.columns]
        lines = ["  ".join(c.rjust(w) for c, w in zip(self.columns, widths))]
        lines += ["  ".join(_fmt(r.get(c)).rjust(w) for c, w in zip(self.columns, widths)) for r in self.rows]
        return "\n".join(lines)

    def to_csv(self, path) -> Path:
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        with open(path, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(self.columns))
            w.writeheader()
            w.writerows({c: r.get(c) for c in self.columns} for r in self.rows)
        return path

    def column(self, name) -> np.ndarray:
        """The column as an array (NaN where a row has no value)."""
        return np.array([r.get(name, np.nan) for r in self.rows], dtype=float)

    def summary(self, thresholds=(1e-4, 1e-6), error: str = "tip_error_rms_m") -> Table:
        """Per scene and method (and setting kind): the method's order (``rf.methods()``; auto's: its stiff
        method's), the least wall time among the runs whose ``error`` is at most each threshold ("-" when none
        reaches it), and the smallest error reached."""
        groups = {}
        for r in self.rows:
            groups.setdefault((r["scene"], r["method"], r["setting"]), []).append(r)
        rows = []
        for (scene, method, setting), runs in groups.items():
            known = _methods().get(method.split(" ")[0])  # "esdirk43 (spring)": esdirk43
            row = {"scene": scene, "method": f"{method} ({setting})", "order": known.order if known else "-"}
            for tol in thresholds:
                best = cheapest(runs, error, "wall_time_s", tol)
                row[f"time_s_to_{tol:g}"] = best["wall_time_s"] if best else "-"
            row["smallest_error"] = min(r[error] for r in runs)
            rows.append(row)
        return Table(rows, ("scene", "method", "order", *(f"time_s_to_{t:g}" for t in thresholds), "smallest_error"))

    def auto_against_best(self, thresholds=(1e-4, 1e-6), error: str = "tip_error_rms_m") -> Table:
        """Per scene and threshold: the cheapest run of ``method="auto"`` reaching it against the
        cheapest run of any other method (the best, with its name), their ratio, and the error
        ``auto`` delivered at rtol = threshold (``delivered_at_rtol``, "-" if not run)."""
        rows = []
        for scene in dict.fromkeys(r["scene"] for r in self.rows):
            runs = [r for r in self.rows if r["scene"] == scene]
            auto = [r for r in runs if r["method"] == "auto"]
            others = [r for r in runs if r["method"] != "auto"]
            for tol in thresholds:
                a, b = cheapest(auto, error, "wall_time_s", tol), cheapest(others, error, "wall_time_s", tol)
                at = [r[error] for r in auto if r["setting"] == "rtol" and r["value"] == tol]
                rows.append({"scene": scene, "error_at_most": tol,
                             "best": f"{b['method']} ({b['setting']} {b['value']:g})" if b else "-",
                             "best_time_s": b["wall_time_s"] if b else "-",
                             "auto_time_s": a["wall_time_s"] if a else "-",
                             "auto_over_best": a["wall_time_s"] / b["wall_time_s"] if a and b else "-",
                             "delivered_at_rtol": at[0] if at else "-"})
        return Table(rows, ("scene", "error_at_most", "best", "best_time_s", "auto_time_s", "auto_over_best",
                            "delivered_at_rtol"))

    def to_markdown(self) -> str:
        lines = ["| " + " | ".join(self.columns) + " |", "|" + "---|" * len(self.columns)]
        lines += ["| " + " | ".join(_fmt(r.get(c)) for c in self.columns) + " |" for r in self.rows]
        return "\n".join(lines)

    def plot(self, ax=None, x: str = "wall_time_s", y: str = "tip_error_final_m", by=("scene", "method")):
        """Log–log plot of ``y`` against ``x``, one line per group of ``by``."""
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots(figsize=(6, 4.5))
        groups = {}
        for r in self.rows:
            groups.setdefault(tuple(r[b] for b in by), []).append(r)
        for key, rows in groups.items():
            rows = sorted(rows, key=lambda r: r[x])
            ax.loglog([r[x] for r in rows], [max(r[y], 1e-16) for r in rows], "o-", label=" / ".join(map(str, key)))
        ax.set(xlabel=x.replace("_", " "), ylabel=y.replace("_", " "))
        ax.legend(fontsize=7)
        ax.grid(True, which="both", alpha=0.3)
        return ax


def cheapest(runs, error: str, cost: str, tol: float):
    """The run (a row) of least ``cost`` among those whose ``error`` is at most ``tol``, or None."""
    ok = [r for r in runs if r[error] <= tol]
    return min(ok, key=lambda r: r[cost]) if ok else None


def _fmt(v) -> str:
    if isinstance(v, float):
        return f"{v:.3g}"
    return "" if v is None else str(v)


def _observe(scene: Scene, result):
    return result.position(scene.tip, frame=scene.frame)


def _scene(scene) -> None:
    if not isinstance(scene, Scene):
        raise _checks.refuse(f"scene: expected a rigidfem.study.Scene (e.g. rigidfem.study.scenes.cantilever()), got "
                         f"{_checks._short(scene)}")


def reference(scene: Scene, rtol: float = 1e-10):
    """The scene solved tightly by Dormand–Prince; returns the Result."""
    _scene(scene)
    return _finished(simulate(scene.system, scene.t_end, method="dopri5", rtol=rtol, atol=rtol * 1e-2,
                             t_eval=scene.t_eval, q0=scene.q0, qd0=scene.qd0, max_steps=10**8, stiffness_warning=False),
                    "reference")


def work_precision(scene: Scene, methods, repeats: int = 3, ref=None, max_steps: int = 10**7) -> Table:
    """Run ``scene`` with each method over a sweep of tolerances or steps.

    Parameters
    ----------
    methods : list of (method, "rtol" or "dt", values[, extra keyword arguments])
        e.g. ``[("dopri5", "rtol", [1e-4, 1e-8]), ("newmark", "dt", [1e-3], {"adaptive": False})]``.
    repeats : int
        Wall time is the minimum over this many runs (after a first, warm-up run).
    ref : Result, optional
        The reference; by default ``reference(scene)``.

    Returns
    -------
    Table
        One row per run: scene, method, setting, value, tip_error_final_m, tip_error_rms_m,
        q_error_final, q_error_rms (max over coordinates), wall_time_s, steps, rejected_steps,
        rhs_evaluations, jacobians, factorizations; failures have error = inf and the
        SimulationError's message in ``note``.
    """
    from .._core import SimulationError

    _scene(scene)
    ref = reference(scene) if ref is None else _checks.result(ref, "ref", needs="the reference's tip")
    repeats = _checks.integer(repeats, "repeats", minimum=0)
    tip_ref = _observe(scene, ref)
    rows = []
    for entry in methods:
        method, key, values = entry[:3]
        extra = entry[3] if len(entry) > 3 else {}
        for value in values:
            kw = dict(extra, **{key: value})
            kw.setdefault("max_steps", max_steps)
            kw.setdefault("stiffness_warning", False)  # recorded in the table's stiff_at column instead
            if key == "rtol":
                kw.setdefault("atol", value * 1e-2)
            row = {"scene": scene.name, "method": method, "setting": key, "value": value, "note": ""}
            try:
                times = []
                for k in range(repeats + 1):
                    r = _finished(simulate(scene.system, scene.t_end, method=method, t_eval=scene.t_eval,
                                          q0=scene.q0, qd0=scene.qd0, **kw), f"work_precision ({method})")
                    if k > 0 or repeats == 0:
                        times.append(r.stats["wall_time"])
                tip_err = np.linalg.norm(_observe(scene, r) - tip_ref, axis=1)
                q_err = np.abs(r.q - ref.q).max(axis=1)
                row.update(tip_error_final_m=float(tip_err[-1]), tip_error_rms_m=float(np.sqrt(np.mean(tip_err**2))),
                           q_error_final=float(q_err[-1]), q_error_rms=float(np.sqrt(np.mean(q_err**2))),
                           wall_time_s=float(min(times)), **{k: r.stats[k] for k in _STATS})
            except SimulationError as e:
                row.update(tip_error_final_m=np.inf, tip_error_rms_m=np.inf, q_error_final=np.inf,
                           q_error_rms=np.inf, wall_time_s=np.nan, note=str(e)[:120], **{k: -1 for k in _STATS})
            rows.append(row)
    return Table(rows, _COLUMNS)


_STATS = ("steps", "rejected_steps", "rhs_evaluations", "jacobians", "factorizations", "stiff_at")
_COLUMNS = ("scene", "method", "setting", "value", "tip_error_final_m", "tip_error_rms_m", "q_error_final",
            "q_error_rms", "wall_time_s", *_STATS, "note")


def discretisation_error(elements=(5, 10, 20, 40, 80), modes: int = 3) -> Table:
    """The other error source: the cantilever's first natural frequencies against
    Euler–Bernoulli (slender section) and the elastica's tip (PL²/EI = 3, by solve_bvp)
    against m, for the modified formulation; with the observed order between successive m."""
    from scipy.integrate import solve_bvp

    E, rho, L = 2.1e11, 7850.0, 1.0
    sec = Section(A=1e-4, Iy=2e-12, Iz=1e-12, J=3e-12)
    beta_l = np.array([1.8751040687, 4.6940911330, 7.8547574382, 10.9955407349, 14.1371683910])[:modes]
    w_ref = beta_l**2 * np.sqrt(E * sec.Iz / (rho * sec.A * L**4))
    k = 3.0  # PL²/EI
    s = np.linspace(0, 1, 201)

    def bvp(x, y):  # θ'' = −k cos θ, x' = cos θ, y' = sin θ
        return np.vstack([y[1], -k * np.cos(y[0]), np.cos(y[0]), np.sin(y[0])])

    sol = solve_bvp(bvp, lambda a, b: np.array([a[0], b[1], a[2], a[3]]), s, np.zeros((4, s.size)), tol=1e-10,
                    max_nodes=100000)
    tip_ref = sol.sol(1.0)[2:] * L
    rows, previous, previous_m = [], None, None
    for m in elements:
        model = Model(gravity=None)
        beam = model.add_beam("b", model.ground, L, Material(E, rho), sec, m, deform=("bend_z",))
        w = modal_analysis(model.compile()).omega[:modes]
        model.add_force("load0", beam.tip, (0.0, k * E * sec.Iz / L**2, 0.0))
        system = model.compile()
        tip = system.position(beam.tip, 0.0, static_equilibrium(system, load_steps=5).q)[:2]
        errors = np.r_[np.abs(w / w_ref - 1), np.linalg.norm(tip - tip_ref) / L]
        row = {"m": m, **{f"mode{j + 1}_rel_error": errors[j] for j in range(modes)}, "elastica_tip_error_L": errors[-1]}
        if previous is not None:
            row["order_mode1"] = float(np.log(previous[0] / errors[0]) / np.log(m / previous_m))
            row["order_elastica"] = float(np.log(previous[-1] / errors[-1]) / np.log(m / previous_m))
        rows.append(row)
        previous, previous_m = errors, m
    columns = ("m", *(f"mode{j + 1}_rel_error" for j in range(modes)), "elastica_tip_error_L", "order_mode1",
               "order_elastica")
    return Table(rows, columns)


def standard_methods(quick: bool = False):
    """The integrators and settings of the benchmark."""
    quick = _checks.boolean(quick, "quick")
    r = [1e-4, 1e-6, 1e-8] if quick else [1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9]
    loose = [1e-1, 1e-2] if quick else [1e-1, 3e-2, 1e-2]
    return [("auto", "rtol", loose + r), ("esdirk43", "rtol", loose + r[:-2]), ("radau5", "rtol", loose + r[:-2]),
            ("dopri5", "rtol", r), ("rkf45", "rtol", r[:-1]),
            ("generalized_alpha", "rtol", r[:3], {"adaptive": True})]


def bench(output_dir="bench", quick: bool = False) -> Table:
    """``python -m rigidfem bench``: the standard scenes under the standard integrators, plus
    fixed-step sweeps; writes ``work_precision.csv``/``.png`` and ``discretisation.csv`` into
    ``output_dir`` and prints the tables. (The maintainers' scaling and peer benchmarks are in
    the checkout's ``benchmarks/``: ``python -m benchmarks scaling``.)"""
    import platform

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(output_dir)
    quick = _checks.boolean(quick, "quick")
    m = 6 if quick else 10
    todo = [
        (scenes.cantilever("modified", m), standard_methods(quick) + [
            ("rk4", "dt", [2e-5, 1e-5] if quick else [4e-5, 2e-5, 1e-5]),
            ("newmark", "dt", [1e-3, 5e-4] if quick else [1e-3, 5e-4, 2.5e-4, 1.25e-4]),
            ("generalized_alpha", "dt", [1e-3, 5e-4] if quick else [1e-3, 5e-4, 2.5e-4, 1.25e-4]),
            ("implicit_spring", "dt", [1e-3, 5e-4] if quick else [1e-3, 5e-4, 2.5e-4, 1.25e-4])]),
        (scenes.stiff_cantilever(4 if quick else m), [
            ("auto", "rtol", [1e-1, 1e-2, 1e-4, 1e-6] if quick else [1e-1, 3e-2, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8]),
            ("esdirk43", "rtol", [1e-1, 1e-2, 1e-4] if quick else [1e-1, 3e-2, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6]),
            ("radau5", "rtol", [1e-1, 1e-2, 1e-4] if quick else [1e-1, 3e-2, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6]),
            ("dopri5", "rtol", [1e-4, 1e-6] if quick else [1e-4, 1e-6, 1e-8]),
            ("rk4", "dt", [1e-6] if quick else [2e-6, 1e-6, 5e-7]),
            ("generalized_alpha", "dt", [1e-3, 5e-4] if quick else [2e-3, 1e-3, 5e-4, 2.5e-4, 1.25e-4]),
            ("implicit_spring", "dt", [1e-3, 5e-4] if quick else [2e-3, 1e-3, 5e-4, 2.5e-4, 1.25e-4])]),
        (scenes.cantilever("classical", m), [
            ("auto", "rtol", [1e-1, 1e-2, 1e-4, 1e-6] if quick else [1e-1, 3e-2, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8]),
            ("esdirk43", "rtol", [1e-1, 1e-2, 1e-4] if quick else [1e-1, 3e-2, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6]),
            ("radau5", "rtol", [1e-1, 1e-2, 1e-4] if quick else [1e-1, 3e-2, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6]),
            ("dopri5", "rtol", [1e-4, 1e-6] if quick else [1e-4, 1e-6, 1e-8]),
            ("newmark", "dt", [1e-3, 5e-4] if quick else [1e-3, 5e-4, 2.5e-4, 1.25e-4]),
            ("generalized_alpha", "dt", [1e-3, 5e-4] if quick else [1e-3, 5e-4, 2.5e-4, 1.25e-4])]),
        (scenes.kane(6.0, m, t_end=10.0 if quick else 20.0), standard_methods(quick) + [
            ("generalized_alpha", "dt", [0.01, 0.005] if quick else [0.02, 0.01, 0.005, 0.0025]),
            ("implicit_spring", "dt", [0.01, 0.005] if quick else [0.02, 0.01, 0.005, 0.0025])]),
        (scenes.whippy(m, t_end=0.5 if quick else 1.0), standard_methods(quick) + [
            ("generalized_alpha", "dt", [2e-3, 1e-3] if quick else [2e-3, 1e-3, 5e-4, 2.5e-4]),
            ("implicit_spring", "dt", [2e-3, 1e-3] if quick else [2e-3, 1e-3, 5e-4, 2.5e-4])]),
    ]
    rows = []
    for scene, methods in todo:
        t = time.perf_counter()
        rows += work_precision(scene, methods, repeats=1 if quick else 3).rows
        print(f"[{time.perf_counter() - t:6.1f} s] {scene.name}", flush=True)
    table = Table(rows, _COLUMNS)
    table.to_csv(out / "work_precision.csv")
    fig, axes = plt.subplots(1, len(todo), figsize=(5 * len(todo), 4.5))
    for ax, (scene, _) in zip(axes, todo):
        Table([r for r in rows if r["scene"] == scene.name], _COLUMNS).plot(ax=ax, by=("method", "setting"))
        ax.set_title(scene.name, fontsize=9)
    fig.tight_layout()
    fig.savefig(out / "work_precision.png", dpi=100)
    plt.close(fig)
    disc = discretisation_error(elements=(5, 10, 20) if quick else (5, 10, 20, 40, 80))
    disc.to_csv(out / "discretisation.csv")
    print(f"machine: {platform.machine()} {platform.processor() or ''}, {platform.python_implementation()} "
          f"{platform.python_version()}, {__import__('os').cpu_count()} cores")
    print(table)
    print("\nLeast wall time (s) to reach a tip RMS error (m):")
    print(table.summary().to_markdown())
    print("\nmethod='auto' against the best method for each error (least wall time, s):")
    print(table.auto_against_best().to_markdown())
    print(disc.to_markdown())
    return table
