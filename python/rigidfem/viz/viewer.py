"""A 3D viewer for a teacher's browser: ``rf.view(system, result)`` in a notebook, ``.to_html(path)`` to mail.

The scene is drawn by three.js (r111, MIT, shipped in ``viewer_assets`` and packed into each page: nothing is
fetched from the network): bodies as boxes of their equivalent inertia with their triads (a robot of
``Model.from_urdf``'s by its links' visual geometry: boxes, cylinders, spheres and the meshes found), beams as
tubes through their rigid finite elements' origins and tips, spring-dampers, cylinders, ropes and actuators as
lines, loop joints as a marker and a line between their two frames, and the paths of chosen points; a ground grid
whose square is named (the scale), a legend, and optionally the sdes coloured by a quantity with its
colour bar, ropes coloured by their tension and force arrows. A time slider, play/pause, the playback
speed, the time and a snapshot (PNG) button are below the picture; the mouse turns (left), pans (right)
and zooms (wheel).

What is shown:

- ``rf.view(system, result)`` or ``rf.view(result)``: a run; ``rf.view(system, q=q, t=t)``: one state;
- ``rf.view(system, modes)`` or ``rf.view(modes)``: mode shapes of ``rf.modal_analysis``, animated as
  q₀ + a sin(2π φ) shape over one period (φ the phase), several side by side (``mode=(0, 1, 2)``);
- ``rf.view([result_a, result_b], labels=[...])``: two or more runs (of the same or of different
  systems, e.g. a nonlinear and a linear model) overlaid in the same space or side by side
  (``layout="side"``), at the first run's output times.

The camera is placed from the drawn geometry over the whole result: the scene's box holds every body's
box, every beam's rfes and tip, every force element's points and every trail over all frames; the up
axis is −gravity (or ``up=``; z without gravity); the camera looks at the model's broad side from
above and in front and stands as far as the box needs to fill the picture.

For example::

    import rigidfem as rf
    model, h = rf.samples.kane_beam(omega=6.0, duration=15.0, elements=8)
    system = model.compile()
    result = rf.simulate(system, 20.0, t_eval=[0.05 * k for k in range(401)])
    viewer = rf.view(system, result, trails=[h["beam"].tip])
    path = viewer.to_html("kane.html")          # a self-contained page, about 0.5 MB (10 bodies)

The file holds every frame's pose of every body as float32: 48 bytes × frames × bodies before base64
(4/3), plus 0.25 MB of scripts (three.js, its orbit controls and ``viewer.js``, 0.9 MB as text, packed as one zlib
stream in base64, which the page's ``unpack.js`` inflates as it loads); a 20 s Kane run (m = 20, 401
frames, 22 bodies) is about 0.83 MB. A URDF
robot's meshes add about 24 bytes a triangle, at most ``MAX_TRIANGLES`` = 200,000 of them (about 4.8 MB).
"""

from __future__ import annotations

import base64
import functools
import html
import inspect
import json
import math
import zlib
from pathlib import Path

import numpy as np

from ..base import _checks
from ..model import meshes
import rigidfem._core as _core  # the compiled core, by its absolute name
from .._core import Body, Point, SimulationError

ASSETS = Path(__file__).resolve().parent / "viewer_assets"

#: The most body poses (frames × bodies, all results together) a page holds: 12 float32 each, 96 MB
#: (128 MB as base64).
MAX_POSES = 2_000_000

#: ``color=``: what the sdes of the beams are coloured by, as (label with unit, the deformations it reads).
#: Each value is the sde's own spring and damper law, c (q − q⁰) + b q̇ with the constants of
#: ``System.stiffness``, ``System.rest`` and ``System.damping`` (a viscoelastic law's Maxwell arms are not in it);
#: a curvature is the sde's relative rotation over its length L/m, an axial strain its stretch over L/m.
QUANTITIES = {
    "bending_moment": ("bending moment |M| (N·m)", ("bend_y", "bend_z")),
    "curvature": ("curvature |κ| (1/m)", ("bend_y", "bend_z")),
    "torsion_moment": ("torsion moment |T| (N·m)", ("torsion",)),
    "axial_force": ("axial force N (N)", ("axial",)),
    "axial_strain": ("axial strain ε", ("axial",)),
}

#: The coordinate of an sde's joint that carries each deformation (its rfe's joint: 'beam.rfe3.rz').
_AXIS = {"axial": "x", "shear_y": "y", "shear_z": "z", "torsion": "rx", "bend_y": "ry", "bend_z": "rz"}

#: Frames of a mode shape's period when ``frames`` is not given.
MODE_FRAMES = 48

#: At most this many body poses are sampled for the scene's box (frames thinned evenly beyond it).
_BOX_SAMPLES = 400_000

#: The most triangles of URDF meshes a page holds, all layers together (beyond it the smaller meshes are kept
#: whole and each larger one decimated by vertex clustering to the same number): 12 bytes a vertex and 12 a
#: triangle, about 4.8 MB as base64.
MAX_TRIANGLES = 200_000


class Viewer:
    """A scene and its frames (``rf.view``): shows itself in a notebook (``_repr_html_``: an iframe, no
    network) and writes a self-contained HTML file (``to_html``).

    Examples
    --------
    >>> import rigidfem as rf
    >>> model, h = rf.samples.pendulum()
    >>> system = model.compile()
    >>> viewer = rf.view(system, q=[0.5])
    >>> type(viewer).__name__
    'Viewer'
    >>> "<iframe" in viewer._repr_html_()
    True
    """

    def __init__(self, data: dict, height: int):
        self.data = data
        self.height = height

    @property
    def frames(self) -> int:
        """The number of frames."""
        return len(self.data["t"])

    def html(self) -> str:
        """The page: the frames, and three.js, its orbit controls and the viewer's script packed (``_packed``),
        all inline."""
        data = json.dumps(self.data, separators=(",", ":")).replace("</", "<\\/")
        unpack = (ASSETS / "unpack.js").read_text(encoding="utf-8")
        return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{html.escape(self.data['title'])}</title>
<style>
body {{ margin: 0; font: 13px sans-serif; }}
#rf-view {{ width: 100%; height: {self.height}px; position: relative; overflow: hidden; }}
#rf-legend {{ position: absolute; left: 8px; top: 6px; pointer-events: none; color: #333; line-height: 1.35;
             background: rgba(255, 255, 255, 0.75); padding: 2px 5px; border-radius: 3px; }}
#rf-legend .chip {{ display: inline-block; width: 10px; height: 10px; margin-right: 4px; vertical-align: -1px; }}
#rf-legend .bar {{ display: inline-block; width: 120px; height: 10px; margin: 0 4px; vertical-align: -1px; }}
#rf-bar {{ display: flex; gap: 8px; align-items: center; padding: 4px 8px; }}
#rf-slider {{ flex: 1; }}
</style></head><body>
<div id="rf-view"><div id="rf-legend"></div></div>
<div id="rf-bar"><button id="rf-play">play</button><input id="rf-slider" type="range" min="0" value="0" step="1">
<span id="rf-time"></span><label>speed <select id="rf-speed"><option value="0.25">0.25×</option>
<option value="0.5">0.5×</option><option value="1" selected>1×</option><option value="2">2×</option>
<option value="4">4×</option></select></label><button id="rf-snapshot" title="save the picture as a PNG file">snapshot</button></div>
<script>window.RIGIDFEM = {data};</script>
<script>{unpack}</script>
<script>rigidfemUnpack("{_packed()}");</script>
</body></html>
"""

    def to_html(self, path) -> Path:
        """Writes the page to ``path`` (a str or ``os.PathLike``: a file a browser opens offline); returns it as a
        ``pathlib.Path``."""
        path = Path(_checks.path(path))
        path.write_text(self.html(), encoding="utf-8")
        return path

    def widget(self):
        """The viewer as a Jupyter widget (anywidget: ``pip install anywidget``, in the ``notebooks``
        extra): the same page, with its frame synchronised to the widget's ``frame`` (an int; set it
        from Python to move the slider, read it to know which frame the slider shows). Where no widget
        runs (a notebook rendered as static HTML: nbconvert, the documentation site) it shows as the
        page itself in an iframe, its frames embedded."""
        return _widget_class()(page=self.html(), height=self.height, frames=self.frames)

    def _repr_html_(self) -> str:
        """In a notebook: the page in an iframe (its scripts run apart from the notebook's)."""
        return _iframe(self.html(), self.height)

    def __repr__(self) -> str:
        d = self.data
        layers = 1 + len(d.get("layers", ()))
        return (f"<rigidfem Viewer: {len(d['bodies'])} bodies, {len(d['beams'])} beams, {self.frames} frames"
                f"{f', {layers} layers' if layers > 1 else ''}>")


#: The scripts a page runs, in order, packed into it by ``_packed``.
SCRIPTS = ("three.min.js", "OrbitControls.js", "viewer.js")


def _packed() -> str:
    """SCRIPTS as one zlib stream (RFC 1950: DEFLATE and its Adler-32) in base64, which the page's unpack.js inflates,
    checks and runs: 0.25 MB in the page instead of 0.9 MB of text (more in a notebook, whose iframe escapes the
    text's markup). Packed once per version of the files (their modification times)."""
    return _packed_files(tuple((ASSETS / name).stat().st_mtime_ns for name in SCRIPTS))


@functools.lru_cache(maxsize=1)
def _packed_files(versions: tuple) -> str:
    """_packed's work; ``versions`` (the files' modification times) is only the cache's key."""
    code = "\n;\n".join((ASSETS / name).read_text(encoding="utf-8") for name in SCRIPTS)
    return base64.b64encode(zlib.compress(code.encode("utf-8"), 9)).decode("ascii")


def _iframe(page: str, height: int) -> str:
    """The page in an iframe of the notebook (``srcdoc``: nothing fetched, its scripts apart from the notebook's)."""
    return (f'<iframe srcdoc="{html.escape(page, quote=True)}" style="width: 100%; '
            f'height: {height + 40}px; border: 0;"></iframe>')


def view(system, result=None, *, trails=(), frames: int | None = None, q=None, t: float = 0.0,
         height: int = 420, title: str = "rigidfem", up=None, scale: float = 1.0, color: str | None = None,
         forces: bool = False, mode=0, amplitude: float | None = None, labels=None,
         layout: str | None = None) -> Viewer:
    """The 3D scene of ``system``: the frames of ``result``, one state ``q`` at ``t`` (zeros by default), the
    mode shapes of a ``Modes``, or several results together.

    Parameters
    ----------
    system : System, Result, Modes or a sequence of Results
        The compiled system; or a Result (its system is the result's), a Modes of ``rf.modal_analysis`` (its
        system is the one analysed), or a list of Results (each drawn with its own system).
    result : Result, Modes or a sequence of Results, optional
        What to show of ``system``: a run (a Result of it), its modes, or several runs; None: the state ``q``.
    trails : Point or Body, or a sequence of them
        Points (a Body: its origin) whose paths are drawn from the start up to the frame shown; () (the
        default) draws none.
    frames : int, optional
        At most this many frames, spread evenly over the result's outputs (default: every output, as
        many as ``MAX_POSES`` body poses allow: frames × bodies ≤ 2,000,000, a page of about 130 MB); for
        modes the frames of one period (default 48).
    q, t
        Without a result: the coordinates (m, rad) and the time (s) of the state shown. With modes: ``t``
        is the time (s) the prescribed coordinates are taken at.
    height : int
        Height of the picture in pixels.
    up : sequence of 3 floats, optional
        The scene's up direction (global axes); default −gravity, or z without gravity.
    scale : float
        Deformation scale factor (≥ 1, dimensionless): each beam's deformation, the difference between
        its rfes' poses and the poses they would have if the beam were rigid (carried by its first rfe),
        is magnified by it, positions linearly and rotations by their rotation vectors; bodies carried by
        a beam move with it. 1 (the default) draws the motion as computed; a stiff beam's deflection
        shows at 50 or 100. The legend says the factor. Links of varying length are drawn unscaled.
    color : str, optional
        Colour the beams' sdes by a quantity of ``QUANTITIES`` ("bending_moment" N·m, "curvature" 1/m,
        "torsion_moment" N·m, "axial_force" N, "axial_strain"), from the sdes' spring and damper laws
        at each frame, with a colour bar of its range over all frames.
    forces : bool
        Draw force arrows: the loads of ``add_force`` (N), the ropes' and force elements' pulls on
        their two points and the contacts' forces where they touch; the longest arrow is 15 % of the
        scene, the legend says its force.
    mode : int or sequence of int
        With modes: which mode (0: the lowest) or modes (side by side) to animate.
    amplitude : float, optional
        With modes: the largest displacement (m) of a body's origin or a beam's tip in the animated
        shape (default 10 % of the model's size).
    labels : sequence of str, optional
        The legend's name of each result (default "run 1", "run 2", ...).
    layout : str, optional
        With several results or modes: "overlay" (in the same place, in different colours; the default
        for results) or "side" (side by side along the picture's horizontal; the default for modes).

    Notes
    -----
    Ropes are coloured by their tension (N) whenever a run is shown, with their own colour bar. A model of
    ``Model.from_urdf`` is drawn by its links' visual geometry (boxes, cylinders, spheres and the meshes read,
    in their materials' colours with one result; ``rigidfem.model.urdf``), its flexible links by their tubes.
    Raises ``ValueError`` naming the argument: a result without its system, without outputs or whose
    coordinates are not finite (NaN or inf: it names the first output and coordinate), an unknown
    quantity, a bad scale.

    Examples
    --------
    >>> import rigidfem as rf
    >>> model, h = rf.samples.pendulum()
    >>> system = model.compile()
    >>> viewer = rf.view(system, q=[0.5])
    >>> type(viewer).__name__
    'Viewer'
    >>> "<iframe" in viewer._repr_html_()
    True
    """
    system, layers, kind = _layers(system, result, q, t, mode, frames, amplitude)
    if scale is not None:
        scale = _checks.scalar(scale, "scale", positive=True)
    if kind == "modes" and scale != 1.0:
        raise _checks.refuse(f"scale: expected 1 with modes (amplitude= sets the size of the shape), got {scale!r}")
    if color is not None and color not in QUANTITIES:
        raise _checks.refuse(f"color: expected None or one of {sorted(QUANTITIES)}, got {_checks._short(color)}")
    forces = _checks.boolean(forces, "forces")
    if layout is None:
        layout = "side" if kind == "modes" else "overlay"
    if layout not in ("overlay", "side"):
        raise _checks.refuse(f"layout: expected 'overlay' or 'side', got {_checks._short(layout)}")
    if labels is not None:
        if isinstance(labels, str) or not hasattr(labels, "__len__") or len(labels) != len(layers):
            raise _checks.refuse(f"labels: expected a sequence of {len(layers)} names (one per result), got "
                                 f"{_checks._short(labels)}")
        for layer, label in zip(layers, labels):
            layer["label"] = str(label)
    height = _checks.integer(height, "height", minimum=100, maximum=4000)
    points = _trail_points(trails, system)
    if up is not None:
        up = _checks.vec3(up, "up")
        if not np.linalg.norm(up) > 0:
            raise _checks.refuse("up: expected a non-zero direction, got (0, 0, 0)")
    for layer in layers:
        _check_finite(layer)
    return Viewer(_scene(layers, points, str(title), up, scale, color, forces, layout, kind), height)


def _is_result(x) -> bool:
    return all(hasattr(x, a) for a in ("t", "q", "qd", "system", "stats", "sensitivities"))


def _is_modes(x) -> bool:
    return all(hasattr(x, a) for a in ("omega", "shapes", "frequencies_hz", "q"))


def _layers(system, result, q, t, mode, frames, amplitude):
    """(system, layers, kind): what ``view`` shows as layers {system, t, q, qd, label}, each at the common
    frames; kind "run", "state" or "modes"."""
    if result is None and isinstance(system, (list, tuple)):  # rf.view([r1, r2])
        system, result = None, system
    elif result is None and _is_result(system):  # rf.view(result)
        result = _checks.result(system, needs="the 3D view")
        system = result.system
    elif result is None and _is_modes(system):  # rf.view(modes)
        result, system = system, getattr(system, "_system", None)
        if system is None:
            raise _checks.refuse("system: expected the System the modes are of (rf.view(system, modes)): these modes "
                                 "do not carry it (read back from a file?)")
    if system is not None or not isinstance(result, (list, tuple)):
        system = _checks.system(system)
    if result is None:
        qs = np.zeros(system.nq) if q is None else _checks.reals(q, (system.nq,), "q")
        t = _checks.scalar(t, "t")
        if frames is not None:  # judged as a result's would be, though one state is one frame
            _checks.integer(frames, "frames", minimum=1, maximum=max(MAX_POSES // max(system.nbodies, 1), 1))
        return system, [{"system": system, "t": np.array([t]), "q": qs[None, :], "qd": None, "label": "state",
                         "what": "q"}], "state"
    if q is not None:
        raise _checks.refuse("q: expected None with a result (its frames are shown)")
    if _is_modes(result):
        return system, _mode_layers(system, result, mode, frames, t, amplitude), "modes"
    if isinstance(result, (list, tuple)):
        runs = list(result)
        if not runs:
            raise _checks.refuse("result: expected a Result or a non-empty sequence of Results, got []")
        for k, r in enumerate(runs):
            _checks.result(r, f"result[{k}]", needs="the 3D view")
        if system is not None and runs[0].system is not system:
            raise _checks.refuse(f"result[0]: expected a Result of this system (rf.simulate(system, ...)), got "
                                 f"{_checks._short(runs[0])}")
        system = runs[0].system
    else:
        _checks.result(result, needs="the 3D view")
        if result.system is not system:
            raise _checks.refuse(f"result: expected a Result of this system (rf.simulate(system, ...)), got "
                                 f"{_checks._short(result)}")
        runs = [result]
    for k, r in enumerate(runs):
        if len(r.t) == 0:
            raise _checks.refuse(f"result{'' if len(runs) == 1 else f'[{k}]'}: expected at least one output, got none")
    times = np.asarray(runs[0].t, dtype=float)
    nbodies = sum(r.system.nbodies for r in runs)
    fit = MAX_POSES // max(nbodies, 1)  # the frames whose poses the page holds
    if fit < 1:
        raise _checks.refuse(f"system: expected at most {MAX_POSES:,} bodies to show, got {nbodies:,}")
    if frames is not None:
        frames = _checks.integer(frames, "frames", minimum=1, maximum=fit)
    elif len(times) > fit:
        frames = fit  # bounded before anything is computed: at most MAX_POSES body poses
    keep = np.arange(len(times))
    if frames is not None:
        keep = np.unique(np.round(np.linspace(0, len(times) - 1, min(frames, len(times)))).astype(int))
    times = times[keep]
    layers = []
    for k, r in enumerate(runs):
        rt = np.asarray(r.t, dtype=float)
        # the output nearest each shown time (the first run's own outputs for the first run)
        idx = keep if k == 0 else np.clip(np.searchsorted(rt, times), 0, len(rt) - 1)
        if k:
            before = np.clip(idx - 1, 0, len(rt) - 1)
            idx = np.where(np.abs(rt[before] - times) <= np.abs(rt[idx] - times), before, idx)
        layers.append({"system": r.system, "t": rt[idx], "q": np.asarray(r.q)[idx], "qd": np.asarray(r.qd)[idx],
                       "label": f"run {k + 1}", "what": f"result[{k}]" if len(runs) > 1 else "result",
                       "result": r, "index": idx})
    return system, layers, "run"


def _mode_layers(system, modes, mode, frames, t, amplitude):
    """A layer per chosen mode: q(φ) = q₀ + a sin(2π φ) shape at the phases φ = k/n of one period."""
    shapes = np.asarray(modes.shapes, dtype=float)
    q0 = np.asarray(modes.q, dtype=float)
    if shapes.ndim != 2 or shapes.shape[0] != system.nq or q0.shape != (system.nq,):
        raise _checks.refuse(f"result: expected the Modes of this system (nq = {system.nq}), got shapes of shape "
                             f"{shapes.shape}")
    if shapes.shape[1] == 0:
        raise _checks.refuse("result: expected Modes with at least one mode, got none (nq = 0, or loops leave "
                             "nothing free)")
    chosen = [mode] if not isinstance(mode, (list, tuple, range, np.ndarray)) else list(mode)
    if not chosen:
        raise _checks.refuse("mode: expected a mode index or a non-empty sequence of them, got []")
    chosen = [_checks.integer(m, "mode", minimum=0, maximum=shapes.shape[1] - 1) for m in chosen]
    n = MODE_FRAMES if frames is None else _checks.integer(frames, "frames", minimum=1, maximum=100_000)
    if n * system.nbodies * len(chosen) > MAX_POSES:
        raise _checks.refuse(f"frames: expected at most {MAX_POSES // (system.nbodies * len(chosen)):,} frames of "
                             f"{len(chosen)} mode(s) of {system.nbodies:,} bodies, got {n}")
    t = _checks.scalar(t, "t")
    if amplitude is not None:
        amplitude = _checks.scalar(amplitude, "amplitude", positive=True)
    for name, a in (("result", q0), ("result", shapes)):
        if not np.all(np.isfinite(a)):
            raise _checks.refuse(f"{name}: expected finite mode shapes and q, got NaN or inf")
    phase = np.arange(n) / n
    base = _poses(system, [t], q0[None, :]).astype(float)[0]  # (bodies, 12)
    size = _extent(system, base)
    layers = []
    for m in chosen:
        shape = shapes[:, m]
        # the largest displacement of a body's origin per unit of the shape, by a small step along it
        h = 1e-6
        moved = _poses(system, [t], (q0 + h * shape)[None, :]).astype(float)[0]
        per_unit = float(np.max(np.linalg.norm(moved[:, 9:] - base[:, 9:], axis=1), initial=0.0)) / h
        a = (amplitude if amplitude is not None else 0.1 * size) / per_unit if per_unit > 0 else 1.0
        layers.append({"system": system, "t": np.full(n, t), "q": q0 + a * np.sin(2 * np.pi * phase)[:, None] * shape,
                       "qd": None, "label": f"mode {m + 1}: {modes.frequencies_hz[m]:.4g} Hz", "what": "result",
                       "phase": phase, "amplitude": a})
    return layers


def _extent(system, pose) -> float:
    """The size (m) of a pose (bodies, 12): the diagonal of its origins' box, with the beams' tips."""
    pts = [pose[:, 9:]]
    for beam in getattr(system, "_beams", ()):
        last = pose[beam.rfes[-1].index]
        pts.append((last[:9].reshape(3, 3) @ [beam.length - beam.frames[-1], 0.0, 0.0] + last[9:])[None, :])
    pts = np.concatenate(pts)
    return float(max(np.linalg.norm(pts.max(axis=0) - pts.min(axis=0)), 1e-3))


def _check_finite(layer) -> None:
    """ValueError naming the first output and coordinate that is NaN or inf (a blank page otherwise)."""
    q = layer["q"]
    bad = ~np.isfinite(q)
    if bad.any():
        k, j = np.argwhere(bad)[0]
        names = layer["system"].coordinate_names
        raise _checks.refuse(f"{layer['what']}: expected finite coordinates to show, got {q[k, j]} in "
                             f"{names[j]!r} at t = {layer['t'][k]:g} s (output {int(layer.get('index', np.arange(len(q)))[k])})")


def _trail_points(trails, system) -> list:
    """The points of ``trails`` (``view``'s and ``animate``'s) as a list: a Point or Body, or a sequence (any
    iterable but a string or a mapping) of them, all of the model ``system`` was compiled from; () for none
    (as for ``beams`` and ``segments``; None is refused: a forgotten value, not a choice)."""
    if isinstance(trails, (Point, Body)):
        return [trails]
    items = None
    if trails is not None and not isinstance(trails, (str, bytes, dict)):
        try:
            items = list(trails)
        except TypeError:  # not iterable (a number): refused below
            pass
    if items is None:
        raise _checks.refuse(f"trails: expected a Point or Body, or a sequence of Point or Body handles (() for none), "
                         f"got {_checks._short(trails)}")
    for k, p in enumerate(items):
        if not isinstance(p, (Point, Body)):
            raise _checks.refuse(f"trails: expected a sequence of Point or Body handles, got {_checks._short(p)} at "
                             f"trails[{k}]")
        _checks.same_model(p, system, "trails", "a sequence of Point or Body handles of the model this system was "
                                                f"compiled from (trails[{k}])")
        body = p.body if isinstance(p, Point) else p.index
        if not -1 <= body < system.nbodies:
            raise _checks.refuse(f"trails: expected points on the system's bodies (indices -1 for the ground to "
                                 f"{system.nbodies - 1}), got body {body} at trails[{k}]")
    return items


def _poses(system, times, states) -> np.ndarray:
    """(frames, bodies, 12) float32: each body's rotation row by row, then its origin (one kinematics pass
    per frame in C++, ``_core._body_poses``)."""
    poses = _core._body_poses(system, np.asarray(times, dtype=float), np.ascontiguousarray(states, dtype=float))
    return poses.reshape(len(times), system.nbodies, 12).astype(np.float32)


def _matrices(poses: np.ndarray) -> np.ndarray:
    """(frames, bodies, 4, 4) homogeneous transforms of (frames, bodies, 12) poses."""
    F, B = poses.shape[:2]
    T = np.zeros((F, B, 4, 4))
    T[..., :3, :3] = poses[..., :9].reshape(F, B, 3, 3)
    T[..., :3, 3] = poses[..., 9:]
    T[..., 3, 3] = 1.0
    return T


def _inverse(T: np.ndarray) -> np.ndarray:
    """Inverse of homogeneous transforms (..., 4, 4): (Rᵀ, −Rᵀ p)."""
    out = np.zeros_like(T)
    Rt = np.swapaxes(T[..., :3, :3], -1, -2)
    out[..., :3, :3] = Rt
    out[..., :3, 3] = -np.einsum("...ij,...j->...i", Rt, T[..., :3, 3])
    out[..., 3, 3] = 1.0
    return out


def _magnified(system, times, states, poses: np.ndarray, scale: float) -> np.ndarray:
    """The poses with every beam's deformation magnified by ``scale``: rfe j's pose relative to the pose it
    would have if the beam were rigid, D_j = (T_0 U_j)⁻¹ T_j (T_0 the first rfe's pose, U_j rfe j's pose in
    the first rfe's frame with the beam's sde coordinates at rest), becomes D_j^s (its translation times s,
    its rotation vector times s); a body carried by a beam moves with the rfe it hangs from."""
    from scipy.spatial.transform import Rotation

    beams = [b for b in getattr(system, "_beams", ()) if not b.varying]
    if scale == 1.0 or not beams:
        return poses
    T = _matrices(poses.astype(float))  # (F, B, 4, 4)
    F, B = T.shape[:2]
    names = list(system.coordinate_names)
    rest = np.asarray(system.rest, dtype=float)
    magnified = {}  # rfe index -> (F, 4, 4) magnified pose
    for beam in beams:
        rfes = [b.index for b in beam.rfes]
        sdes = {b.name for b in beam.rfes[1:]}
        own = [i for i, n in enumerate(names) if n.rsplit(".", 1)[0] in sdes]  # the beam's sde coordinates
        q_rest = np.array(states[0], dtype=float)
        q_rest[own] = rest[own]
        T_rest = _matrices(_poses(system, times[:1], q_rest[None, :]).astype(float))[0]
        U = np.einsum("ij,kjl->kil", _inverse(T_rest[rfes[0]]), T_rest[rfes])  # (m+1, 4, 4) rfe j in rfe 0
        rigid = np.einsum("fij,kjl->fkil", T[:, rfes[0]], U)  # (F, m+1, 4, 4)
        D = np.einsum("fkij,fkjl->fkil", _inverse(rigid), T[:, rfes])
        rotvec = Rotation.from_matrix(D[..., :3, :3].reshape(-1, 3, 3)).as_rotvec() * scale
        Ds = np.zeros_like(D)
        Ds[..., :3, :3] = Rotation.from_rotvec(rotvec).as_matrix().reshape(F, len(rfes), 3, 3)
        Ds[..., :3, 3] = scale * D[..., :3, 3]
        Ds[..., 3, 3] = 1.0
        for j, i in enumerate(rfes[1:], start=1):
            magnified[i] = (rfes[0], np.einsum("ij,kjl->kil", U[j], Ds[:, j]))
    # bodies in order (parent[i] < i): C_i = T'_i T_i⁻¹, the correction of body i (identity unless a beam moved it)
    parent = list(system.parent)
    C = np.zeros((F, B, 4, 4))
    out = T.copy()
    eye = np.broadcast_to(np.eye(4), (F, 4, 4))
    for i in range(B):
        Cp = eye if parent[i] < 0 else C[:, parent[i]]
        if i in magnified:
            root, local = magnified[i]
            out[:, i] = np.einsum("fij,fjl->fil", out[:, root], local)  # T'_0 U_j D_j^s
        else:
            out[:, i] = np.einsum("fij,fjl->fil", Cp, T[:, i])
        C[:, i] = np.einsum("fij,fjl->fil", out[:, i], _inverse(T[:, i]))
    poses = np.empty((F, B, 12), dtype=np.float32)
    poses[..., :9] = out[..., :3, :3].reshape(F, B, 9)
    poses[..., 9:] = out[..., :3, 3]
    return poses


def _radius(system, rfes, size: float) -> float:
    """A beam's tube radius (m): sqrt(2 I_x/m) of its rfes (a round section's radius from the inertia about
    the beam's axis, whatever the section, tapered or not; the median over the rfes), kept visible at the
    scene's ``size``."""
    masses, inertias = system.masses, system.inertias  # each a list of all the bodies': read once
    r = [np.sqrt(2.0 * inertias[i][0, 0] / masses[i]) for i in rfes if masses[i] > 0.0]
    return float(np.clip(np.median(r) if r else 0.0, 0.004 * size, 0.02 * size))


def _equivalent_box(mass: float, inertia: np.ndarray) -> list[float] | None:
    """Sides (m) of the uniform box with the body's mass and principal moments, a² = 6 (I_y + I_z − I_x)/m,
    ...; None for a massless body."""
    if not mass > 1e-9:
        return None
    d = np.diag(inertia)
    sides = [np.sqrt(max(6.0 * (d[(i + 1) % 3] + d[(i + 2) % 3] - d[i]) / mass, 0.0)) for i in range(3)]
    return [float(s) for s in sides]


def _calls(system):
    """(name, bound arguments) of the calls that built the system's model (its recipe at compile time)."""
    from ..model.model import Model

    for name, args, kwargs in system._state["model"]["calls"]:
        method = getattr(Model, name, None)
        if method is None:
            continue
        try:
            bound = inspect.signature(method).bind(None, *args, **kwargs)
        except TypeError:
            continue
        bound.apply_defaults()
        yield name, bound.arguments


def _point(p) -> list:
    """[body index, r] of a Point or a Body's origin (−1: the ground)."""
    if isinstance(p, Body):
        return [int(p.index), [0.0, 0.0, 0.0]]
    return [int(p.body), [float(x) for x in p.r]]


def _b64(a: np.ndarray) -> str:
    """A float array as little-endian float32 in base64 (the page decodes it into a Float32Array)."""
    return base64.b64encode(np.ascontiguousarray(a, dtype="<f4").tobytes()).decode("ascii")


def _layer_scene(layer, size_hint: float | None, scale: float) -> dict:
    """The bodies, beams, force elements, shapes and poses of one layer (a result, a state or a mode)."""
    system, times, states = layer["system"], layer["t"], layer["q"]
    names = list(system.body_names)
    index = {n: i for i, n in enumerate(names)}
    poses = _poses(system, times, states)
    if not np.all(np.isfinite(poses)):
        k = int(np.argwhere(~np.isfinite(poses))[0][0])
        if np.all(np.isfinite(states[k])):  # finite coordinates the kinematics overflowed at (a drive at t = 1e300)
            raise SimulationError(f"t = {times[k]:g} s: the body poses to show are NaN or inf at finite coordinates "
                                  "(the drives' or the kinematics' values overflow there)")
        raise _checks.refuse(f"{layer['what']}: expected finite body poses to show, got NaN or inf at t = "
                             f"{times[k]:g} s (the coordinates there)")
    if scale != 1.0:
        poses = _magnified(system, times, states, poses, scale)
    size = size_hint or _extent(system, poses[0].astype(float))
    beams, in_beam, base = [], set(), set()
    for beam in getattr(system, "_beams", ()):  # the model's Beam handles: their rfes, tip and length L(t)
        rfes = [b.index for b in beam.rfes]
        shown = {"name": beam.name, "bodies": rfes, "radius": _radius(system, rfes, size),
                 "tip": [float(beam.length - beam.frames[-1]), 0.0, 0.0]}  # on the last rfe, beyond its frame
        if beam.varying:  # the rfes' frames scale with L(t): the tip at L(t) (1 − s_m/L(0)), frame by frame
            L = beam.length_at(times)
            shown["tips"] = [[float(x), 0.0, 0.0] for x in L * (1.0 - beam.frames[-1] / beam.length)]
        beams.append(shown)
        in_beam.update(rfes)
    for name, a in _calls(system):
        if name == "add_moving_base":
            base.add(index.get(a["name"], -1))
    # the force elements as their laws say, the loops as their kinds do (System._segments)
    segments = [{"kind": kind, "a": [int(ia), [float(x) for x in ra]], "b": [int(ib), [float(x) for x in rb]]}
                for kind, ia, ra, ib, rb in system._segments]
    # the shapes of the contacts, each in its body's frame (System._shapes)
    shapes = [{"kind": kind, "body": int(body), "a": np.asarray(a, float).tolist(), "b": np.asarray(b, float).tolist(),
               "normal": np.asarray(n, float).tolist(), "half_extents": np.asarray(h, float).tolist(),
               "rotation": np.asarray(R, float).ravel().tolist(), "radius": float(r)}
              for kind, body, a, b, n, h, R, r in system._shapes]
    bodies, masses, inertias, centres = [], system.masses, system.inertias, system.centres_of_mass
    visuals = _urdf_visuals(system)
    drawn = {sh["body"] for sh in shapes} | {v["body"] for v in visuals}  # bodies shown by their shapes or visuals
    for i, n in enumerate(names):
        shaped = i in drawn
        box = None if i in in_beam or shaped else _equivalent_box(float(masses[i]), np.asarray(inertias[i]))
        if i in base or (box is not None and max(box) > 2 * size):
            box = [0.08 * size] * 3
        elif box is not None:  # a point mass (a payload of tiny inertia) still shows: sides ≥ 2 % of the scene
            box = [max(a, 0.02 * size) for a in box]
        bodies.append({"name": n, "box": box, "com": [float(x) for x in centres[i]],
                       "triad": 0.0 if i in in_beam else 0.06 * size, "base": i in base})
    return {"label": layer["label"], "bodies": bodies, "beams": beams, "segments": segments, "shapes": shapes,
            "visuals": visuals, "poses": poses}


def _urdf_visuals(system) -> list:
    """The visual geometry of a robot from ``Model.from_urdf`` ([] for another model), each in its body's frame
    (the ground's: global): {body, link, kind, colour, corners (8, 3) of its box} and, for a mesh that was read,
    ``mesh`` (a ``meshes.Mesh``) and ``T`` (4, 4) = T_body_link · origin · diag(scale) taking its vertices into
    the body's frame; for a primitive ``size`` (m) and ``T`` = T_body_link · origin. The visuals of flexible
    links are left out: their beams' tubes are drawn."""
    urdf = next((a["description"] for name, a in _calls(system) if name == "_keep_urdf"), None)
    if urdf is None:
        return []
    out = []
    unit_box = np.array([[x, y, z] for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)])
    for link, visuals in urdf.visuals.items():
        if link in urdf.beams or link not in urdf.bodies:
            continue
        for v in visuals:
            T = urdf.frames[link] @ v.origin
            size = [float(x) for x in v.size]
            if v.kind == "mesh" and v.mesh is not None and v.mesh.size:
                T = T @ np.diag([*(float(x) for x in v.scale), 1.0])
                local = v.mesh.vertices.astype(float) @ T[:3, :3].T + T[:3, 3]
                lo, hi = local.min(axis=0), local.max(axis=0)
                corners = 0.5 * (lo + hi) + unit_box * (hi - lo)
            elif v.kind == "box" and len(size) == 3 and min(size) > 0:
                corners = (unit_box * size) @ T[:3, :3].T + T[:3, 3]
            elif v.kind == "cylinder" and len(size) == 2 and min(size) > 0:
                corners = (unit_box * [2 * size[0], 2 * size[0], size[1]]) @ T[:3, :3].T + T[:3, 3]
            elif v.kind == "sphere" and len(size) == 1 and size[0] > 0:
                corners = (unit_box * 2 * size[0]) @ T[:3, :3].T + T[:3, 3]
            else:  # a mesh not found or not read (model.urdf.notes says which), or no geometry
                continue
            out.append({"body": int(urdf.bodies[link].index), "link": link, "kind": v.kind, "size": size,
                        "colour": v.colour, "mesh": v.mesh if v.kind == "mesh" else None, "T": T,
                        "corners": corners.tolist()})
    return out


def _visuals_json(shown: list, colours: bool) -> None:
    """The visuals of the layers as the page holds them: a mesh's ``vertices`` (float32, body frame, m) and
    ``indices`` (uint32, three a triangle) in base64, decimated so that all the layers' meshes together have at
    most ``MAX_TRIANGLES`` (the smaller meshes whole, each larger one to the same number); a primitive's ``size``
    (m) and ``matrix`` (16, row by row, the visual frame in the body frame). ``colour`` (0xRRGGBB) and ``opacity``
    of the file's material with ``colours`` (one layer), else None: the layer's body colour."""
    sizes = sorted(v["mesh"].size for s in shown for v in s["visuals"] if v["mesh"] is not None)
    cap, left = None, MAX_TRIANGLES  # each mesh's most triangles: the small ones whole, the others alike
    for k, n in enumerate(sizes):
        if n * (len(sizes) - k) > left:
            cap = left // (len(sizes) - k)
            break
        left -= n
    thinned = {}
    for s in shown:
        rows = []
        for v in s["visuals"]:
            rgba = v["colour"] if colours else None
            row = {"body": v["body"], "link": v["link"], "kind": v["kind"],
                   "colour": None if rgba is None else int(sum(round(255 * c) << (16 - 8 * k)
                                                              for k, c in enumerate(rgba[:3]))),
                   "opacity": 1.0 if rgba is None else float(rgba[3])}
            if v["mesh"] is not None:
                mesh = v["mesh"]
                if cap is not None and mesh.size > cap:
                    if id(mesh) not in thinned:
                        thinned[id(mesh)] = meshes.decimated(mesh, cap)
                    mesh = thinned[id(mesh)]
                T = v["T"]
                row["vertices"] = _b64(mesh.vertices.astype(float) @ T[:3, :3].T + T[:3, 3])
                row["indices"] = base64.b64encode(np.ascontiguousarray(mesh.triangles, dtype="<u4").tobytes()
                                                  ).decode("ascii")
                row["triangles"] = int(mesh.size)
            else:
                row["size"] = v["size"]
                row["matrix"] = [float(x) for x in v["T"].ravel()]
            rows.append(row)
        s["visuals"] = rows


def _sde_values(layer, quantity: str, shown_beams: list) -> list:
    """Per beam, (frames, m) values of ``quantity`` at its m sdes (the joints of rfes 1..m), or None for a beam
    without the deformations it reads; from the sdes' laws c (q − q⁰) + b q̇ (System.stiffness, rest, damping)."""
    system, q, qd = layer["system"], layer["q"], layer["qd"]
    names = {n: i for i, n in enumerate(system.coordinate_names)}
    c, rest, b = (np.asarray(x, dtype=float) for x in (system.stiffness, system.rest, system.damping))
    deformations = QUANTITIES[quantity][1]
    out = []
    for beam in getattr(system, "_beams", ()):
        cols = [[names.get(f"{rfe.name}.{_AXIS[d]}") for rfe in beam.rfes[1:]] for d in deformations]
        cols = [col for col in cols if all(i is not None for i in col)]
        if not cols or not beam.rfes[1:]:
            out.append(None)
            continue
        spacing = beam.length / beam.elements  # the sdes' spacing L/m (m)
        parts = []
        for col in cols:
            x = q[:, col] - rest[col]  # (frames, m) the sde's deformation (m or rad)
            if quantity in ("bending_moment", "axial_force", "torsion_moment"):
                v = c[col] * x + (0.0 if qd is None else b[col] * qd[:, col])
            else:  # curvature, axial strain: deformation over the sde's length
                v = x / spacing
            parts.append(v)
        values = np.sqrt(sum(p**2 for p in parts)) if quantity != "axial_force" and quantity != "axial_strain" \
            else parts[0]
        out.append(values)
    return out


def _arrows(layer, poses: np.ndarray, segments: list) -> list:
    """Force arrows of one layer: [{body, r, vectors (frames, 3) in N, kind}] from the loads (add_force), the
    force elements' axial forces (Result.element_forces, on both points) and the contacts' forces
    (System.contact_states at each frame)."""
    system, times, q, qd = layer["system"], layer["t"], layer["q"], layer["qd"]
    F = len(times)
    arrows = []
    T = _matrices(poses.astype(float))

    def world(body, r):  # (F, 3) global position of point r on body (−1: the ground)
        if body < 0:
            return np.broadcast_to(np.asarray(r, float), (F, 3))
        return np.einsum("fij,j->fi", T[:, body, :3, :3], np.asarray(r, float)) + T[:, body, :3, 3]

    for name, a in _calls(system):
        if name != "add_force":
            continue
        point, force, follower = a["point"], a["force"], a.get("follower", False)
        body, r = _point(point)
        if callable(force):
            vec = np.array([np.asarray(force(float(tk)), dtype=float).ravel()[:3] for tk in times])
        else:
            vec = np.broadcast_to(np.asarray(force, dtype=float).ravel()[:3], (F, 3)).copy()
        if follower and body >= 0:
            vec = np.einsum("fij,fj->fi", T[:, body, :3, :3], vec)
        arrows.append({"kind": "load", "body": body, "r": r, "vectors": vec})
    result = layer.get("result")
    if result is not None and len(system.element_names):
        forces = np.asarray(result.element_forces)[layer["index"]]  # (F, nelements) N, + pushing apart
        for e, seg in enumerate(segments[:forces.shape[1]]):
            pa, pb = world(*seg["a"]), world(*seg["b"])
            d = pb - pa
            n = d / np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-12)
            f = forces[:, e:e + 1] * n  # on b; −f on a
            arrows.append({"kind": "element", "body": seg["b"][0], "r": seg["b"][1], "vectors": f})
            arrows.append({"kind": "element", "body": seg["a"][0], "r": seg["a"][1], "vectors": -f})
    if len(system.contact_names):
        rates = np.zeros_like(q) if qd is None else qd
        found = {}
        for k in range(F):
            for c in system.contact_states(float(times[k]), q[k], rates[k]):
                key = (c["contact"], c["a"], c["b"])
                found.setdefault(key, np.full((F, 6), np.nan))[k] = np.r_[c["point"], c["force"]]
        for v in found.values():
            touching = ~np.isnan(v[:, 0])
            pts, vec = np.where(touching[:, None], v[:, :3], 0.0), np.where(touching[:, None], v[:, 3:], 0.0)
            arrows.append({"kind": "contact", "body": -1, "r": [0.0, 0.0, 0.0], "points": pts, "vectors": vec})
    return arrows


def _drawn_points(scene: dict, poses: np.ndarray, trails: list, arrows: list, arrow_scale: float) -> np.ndarray:
    """(n, 3) global points of everything drawn over the frames (thinned to at most _BOX_SAMPLES body poses):
    bodies' origins and boxes' corners, beams' tips, force elements' points, trails, shapes, arrow tips."""
    F, B = poses.shape[:2]
    step = max(1, math.ceil(F * B / _BOX_SAMPLES))
    frames = np.unique(np.r_[np.arange(0, F, step), F - 1])
    P = poses[frames].astype(float)
    R, o = P[..., :9].reshape(len(frames), B, 3, 3), P[..., 9:]
    local = [[] for _ in range(B)]  # points in each body's frame
    corners = np.array([[sx, sy, sz] for sx in (-0.5, 0.5) for sy in (-0.5, 0.5) for sz in (-0.5, 0.5)])
    for i, body in enumerate(scene["bodies"]):
        if body["box"]:
            local[i].extend(np.asarray(body["com"]) + corners * body["box"])
        if body["triad"] > 0:
            local[i].extend(body["triad"] * np.eye(3))
    for v in scene["visuals"]:  # the corners of each visual's box in its body's frame
        if v["body"] >= 0:
            local[v["body"]].extend(v["corners"])
    for beam in scene["beams"]:
        local[beam["bodies"][-1]].extend([beam["tip"]] + beam.get("tips", [])[-1:])
    for seg in scene["segments"]:
        for b, r in (seg["a"], seg["b"]):
            if b >= 0:
                local[b].append(r)
    for tr in trails:
        if tr["body"] >= 0:
            local[tr["body"]].append(tr["r"])
    for sh in scene["shapes"]:
        if sh["kind"] == "half_space" or sh["body"] < 0:
            continue
        for c in (sh["a"], sh["b"]):
            local[sh["body"]].extend(np.asarray(c) + sh["radius"] * np.vstack([np.eye(3), -np.eye(3)]))
    out = [o.reshape(-1, 3)]
    for i, pts in enumerate(local):
        if pts:
            pts = np.asarray(pts, dtype=float)
            out.append((np.einsum("fij,pj->fpi", R[:, i], pts) + o[:, i, None, :]).reshape(-1, 3))
    for seg in scene["segments"]:
        for b, r in (seg["a"], seg["b"]):
            if b < 0:
                out.append(np.asarray(r, float)[None, :])
    for tr in trails:
        if tr["body"] < 0:
            out.append(np.asarray(tr["r"], float)[None, :])
    out += [np.asarray(v["corners"], float) for v in scene["visuals"] if v["body"] < 0]
    for a in arrows:  # the arrows' tips at their drawn length
        if "points" in a:
            base = a["points"][frames]
        elif a["body"] >= 0:
            base = np.einsum("fij,j->fi", R[:, a["body"]], np.asarray(a["r"], float)) + o[:, a["body"]]
        else:
            base = np.broadcast_to(np.asarray(a["r"], float), (len(frames), 3))
        out.append(base + arrow_scale * a["vectors"][frames])
    pts = np.concatenate(out)
    return pts[np.all(np.isfinite(pts), axis=1)]


def _nice(x: float) -> float:
    """The number 1, 2 or 5 × 10^k nearest below x (> 0)."""
    e = 10.0 ** math.floor(math.log10(x))
    return max(m * e for m in (1.0, 2.0, 5.0) if m * e <= x * (1 + 1e-12))


def _framing(points: np.ndarray, up) -> dict:
    """The view of ``points`` (n, 3): the up axis u, the direction d from the target to the camera (unit),
    the screen's right r = u × d and up' = d × r, and the points' extents in (r, up', d) about their centre.
    The camera looks at the points' broad side: d's horizontal part is the horizontal direction along which
    they spread least, its elevation above the horizon grows from 15° (a model standing in a vertical plane)
    to 65° (one spread flat: Kane's beam, seen from above); among the two sides, the one that puts the first
    horizontal global axis to the right."""
    u = np.asarray(up, dtype=float)
    u = u / np.linalg.norm(u)
    lo, hi = points.min(axis=0), points.max(axis=0)
    centre = 0.5 * (lo + hi)
    rel = points - centre
    # an orthonormal horizontal basis (e1, e2) and the points' spread in it
    seed = np.eye(3)[np.argmin(np.abs(u))]
    e1 = seed - u * (seed @ u)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(u, e1)
    h = np.c_[rel @ e1, rel @ e2]
    vertical = float(np.ptp(rel @ u)) if len(rel) else 0.0
    angles = np.radians(np.arange(0.0, 180.0, 3.0))
    widths = [float(np.ptp(h @ [math.cos(a), math.sin(a)])) for a in angles]
    k = int(np.argmin(widths))
    thin, broad = widths[k], max(widths)
    front = math.cos(angles[k]) * e1 + math.sin(angles[k]) * e2  # the horizontal direction of least spread
    right = np.cross(u, front)
    axes = [a for a in np.eye(3) if abs(a @ u) < 0.9]
    lead = max(axes, key=lambda a: abs(a @ right)) if axes else np.eye(3)[0]
    if right @ lead < 0:
        front = -front
    flat = thin / (thin + vertical) if thin + vertical > 0 else 0.0  # 1: spread flat, 0: in a vertical plane
    elevation = math.radians(15.0 + 50.0 * flat)
    azimuth = math.radians(25.0 * min(thin / broad, 1.0)) if broad > 0 else 0.0  # a turn for a 3D model
    front = math.cos(azimuth) * front + math.sin(azimuth) * np.cross(u, front)
    d = math.cos(elevation) * front + math.sin(elevation) * u
    r = np.cross(u, d)
    r /= np.linalg.norm(r)
    v = np.cross(d, r)
    ext = np.c_[rel @ r, rel @ v, rel @ d]
    return {"up": u.tolist(), "dir": d.tolist(), "right": r.tolist(), "centre": centre.tolist(),
            "extent": [ext.min(axis=0).tolist(), ext.max(axis=0).tolist()], "lo": lo.tolist(), "hi": hi.tolist(),
            "front": front.tolist()}


def _grid(points: np.ndarray, framing: dict) -> dict:
    """The ground grid under the points: a plane normal to up at their lowest point (less 2 % of the scene's
    size), squares of a round size (1, 2 or 5 × 10^k m, about 10 across the larger horizontal extent), along
    the picture's right and its front, covering the points' footprint and a square around it."""
    u, r = np.asarray(framing["up"]), np.asarray(framing["right"])
    f = np.cross(r, u)
    centre = np.asarray(framing["centre"])
    rel = points - centre
    a, b, z = rel @ r, rel @ f, rel @ u
    size = float(np.linalg.norm(np.asarray(framing["hi"]) - np.asarray(framing["lo"]))) or 1e-3
    span = max(float(np.ptp(a)), float(np.ptp(b)), 0.2 * size)
    step = _nice(span / 8.0)
    a0, a1 = math.floor((a.min() - step) / step) * step, math.ceil((a.max() + step) / step) * step
    b0, b1 = math.floor((b.min() - step) / step) * step, math.ceil((b.max() + step) / step) * step
    height = float(z.min()) - 0.02 * size
    origin = centre + height * u
    return {"origin": origin.tolist(), "a": r.tolist(), "b": f.tolist(), "step": step,
            "range": [a0, a1, b0, b1]}


#: The colours of the layers (beams, bodies) and the legend's chips: the first is the single result's.
PALETTE = [(0xD08030, 0x4F7FBF), (0x2A9D8F, 0x8E5EA2), (0xC8416B, 0x6B8E23), (0x7A6A58, 0x3F88C5)]


def _scene(layers, trails, title, up, scale, color, forces, layout, kind) -> dict:
    g = np.asarray(layers[0]["system"].gravity, dtype=float)
    if up is None:
        up = -g / np.linalg.norm(g) if np.linalg.norm(g) > 0 else np.array([0.0, 0.0, 1.0])
    shown = [_layer_scene(layer, None, scale) for layer in layers]
    size0 = _extent(layers[0]["system"], shown[0]["poses"][0].astype(float))
    trail_rows = [dict(zip(("body", "r"), _point(p))) for p in trails]
    arrows = [_arrows(layer, s["poses"], s["segments"]) if forces else [] for layer, s in zip(layers, shown)]
    biggest = max([float(np.max(np.linalg.norm(a["vectors"], axis=1), initial=0.0)) for arr in arrows for a in arr],
                  default=0.0)
    arrow_scale = 0.15 * size0 / biggest if biggest > 0 else 0.0  # m per N
    points = [_drawn_points(s, s["poses"], trail_rows, arr, arrow_scale) for s, arr in zip(shown, arrows)]
    framing = _framing(points[0], up)
    offsets = [np.zeros(3) for _ in shown]
    if layout == "side" and len(shown) > 1:  # each layer beside the one before, along the picture's right
        r = np.asarray(framing["right"])
        widths = [float(np.ptp(p @ r)) for p in points]
        gap = 0.15 * max(widths + [1e-3])
        x = 0.0
        for k, p in enumerate(points):
            offsets[k] = r * (x - float((p @ r).min()))
            x += widths[k] + gap
    every = np.concatenate([p + o for p, o in zip(points, offsets)])
    framing = _framing(every, up) if len(shown) > 1 and layout != "side" else framing
    triad = np.vstack([np.zeros((1, 3)), 0.1 * size0 * np.eye(3)])  # the global triad (viewer.js): seen, not aimed at
    every = np.vstack([every, triad])
    framing = _reframed(every, framing)
    grid = _grid(every, framing)
    corners = [np.asarray(grid["origin"]) + x * np.asarray(grid["a"]) + y * np.asarray(grid["b"])
               for x in grid["range"][:2] for y in grid["range"][2:]]
    framing = _reframed(np.vstack([every, corners]), framing)  # the grid in the picture too
    size = float(np.linalg.norm(np.asarray(framing["hi"]) - np.asarray(framing["lo"]))) or 1e-3
    for layer, s in zip(layers, shown):  # tubes visible at the size of the whole scene
        for beam in s["beams"]:
            beam["radius"] = _radius(layer["system"], beam["bodies"], 0.5 * size)
    data = {"title": title, "t": [float(x) for x in (layers[0].get("phase", layers[0]["t"]))],
            "clock": "phase" if kind == "modes" else "t", "loop": kind == "modes",
            "rate": 0.5 if kind == "modes" else 1.0, "size": size, "scene_size": size0,
            "centre": framing["centre"], "up": framing["up"], "camera": framing, "grid": grid,
            "scale": scale, "trails": trail_rows, "legend": []}
    if kind == "modes":
        data["amplitudes"] = [float(layer["amplitude"]) for layer in layers]  # a of each mode (its shape's units)
    colour_bars = []
    if color is not None:
        values = [_sde_values(layer, color, s["beams"]) for layer, s in zip(layers, shown)]
        flat = [v for vs in values for v in vs if v is not None]
        if not flat:
            raise _checks.refuse(f"color: expected beams with the deformations {color!r} reads "
                                 f"({', '.join(QUANTITIES[color][1])}), got none in the model")
        lo, hi = float(min(v.min() for v in flat)), float(max(v.max() for v in flat))
        for s, vs in zip(shown, values):
            for beam, v in zip(s["beams"], vs):
                if v is not None:
                    beam["values"] = _b64(v)
        colour_bars.append({"what": "sdes", "label": QUANTITIES[color][0], "lo": lo, "hi": hi})
    tensions = []
    for layer, s in zip(layers, shown):
        ropes = [e for e, seg in enumerate(s["segments"]) if seg["kind"] == "rope"]
        if layer.get("result") is not None and ropes:
            T = -np.asarray(layer["result"].element_forces)[layer["index"]]  # (F, nelements) a rope's tension
            for e in ropes:
                s["segments"][e]["values"] = _b64(T[:, e])
                tensions.append(T[:, e])
    if tensions:
        colour_bars.append({"what": "ropes", "label": "rope tension T (N)", "lo": float(min(0.0, *[x.min() for x in tensions])),
                            "hi": float(max(x.max() for x in tensions))})
    data["colour_bars"] = colour_bars
    _visuals_json(shown, colours=len(shown) == 1)
    if forces:
        data["arrow_scale"] = {"m_per_N": arrow_scale, "largest": biggest}
    rows = []
    for k, (layer, s, arr, off) in enumerate(zip(layers, shown, arrows, offsets)):
        s["poses"] = _b64(s["poses"])
        s["offset"] = off.tolist()
        s["palette"] = list(PALETTE[k % len(PALETTE)])
        s["arrows"] = [{"kind": a["kind"], "body": a["body"], "r": [float(x) for x in a["r"]],
                        "vectors": _b64(a["vectors"]), **({"points": _b64(a["points"])} if "points" in a else {})}
                       for a in arr]
        rows.append(s)
    data.update(rows[0])
    data["layers"] = rows[1:]
    if len(rows) > 1 or kind == "modes":
        data["legend"] = [{"label": s["label"], "colour": s["palette"][0]} for s in rows]
    return data


def _reframed(points: np.ndarray, framing: dict) -> dict:
    """``framing``'s view (up, direction) with the centre and extents of ``points``."""
    lo, hi = points.min(axis=0), points.max(axis=0)
    centre = 0.5 * (lo + hi)
    rel = points - centre
    r, d = np.asarray(framing["right"]), np.asarray(framing["dir"])
    v = np.cross(d, r)
    ext = np.c_[rel @ r, rel @ v, rel @ d]
    return {**framing, "centre": centre.tolist(), "lo": lo.tolist(), "hi": hi.tolist(),
            "extent": [ext.min(axis=0).tolist(), ext.max(axis=0).tolist()]}


_WIDGET = None


def _widget_class():
    """The anywidget class of the viewer, made on first use (anywidget is optional)."""
    global _WIDGET
    if _WIDGET is None:
        try:
            import anywidget
            import traitlets
        except ImportError as e:
            raise ImportError("Viewer.widget() needs anywidget: pip install anywidget (or pip install "
                              "\"rigidfem[notebooks]\"); the viewer shows without it as an iframe") from e

        class ViewerWidget(anywidget.AnyWidget):
            """rigidfem's 3D viewer in a notebook: ``frame`` follows the slider and moves it. Rendered as
            static HTML (no widget manager), it shows as the page in an iframe."""

            _esm = (ASSETS / "widget.js").read_text(encoding="utf-8")
            page = traitlets.Unicode().tag(sync=True)
            height = traitlets.Int(420).tag(sync=True)
            frames = traitlets.Int(1).tag(sync=True)
            frame = traitlets.Int(0).tag(sync=True)

            @traitlets.validate("frame")
            def _frame_in_range(self, proposal):
                k = proposal["value"]
                if not 0 <= k < self.frames:
                    raise traitlets.TraitError(f"frame: expected an index in [0, {self.frames - 1}], got {k}")
                return k

            def _repr_mimebundle_(self, **kwargs):
                """The widget's view and, for what cannot run widgets (nbconvert, the documentation site,
                GitHub), the page in an iframe and a line of text."""
                bundle = super()._repr_mimebundle_(**kwargs)
                data, meta = bundle if isinstance(bundle, tuple) else (bundle, {})
                data = dict(data or {})
                data["text/html"] = _iframe(self.page, self.height)
                data["text/plain"] = repr(self)
                return (data, meta) if isinstance(bundle, tuple) else data

            def __repr__(self) -> str:
                return f"<rigidfem Viewer widget: {self.frames} frames, frame {self.frame} shown>"

        ViewerWidget.__qualname__ = ViewerWidget.__name__ = "ViewerWidget"
        ViewerWidget.__module__ = __name__
        _WIDGET = ViewerWidget
    return _WIDGET
