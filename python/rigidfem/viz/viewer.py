"""A 3D viewer for a teacher's browser: ``rf.view(system, result)`` in a notebook, ``.to_html(path)`` to mail.

The scene is drawn by three.js (r111, MIT, shipped in ``viewer_assets``: nothing is fetched from the
network): bodies as boxes of their equivalent inertia with their triads, beams as tubes through their
rigid finite elements' origins and tips, spring-dampers, cylinders, ropes and actuators as lines, loop
joints as a marker and a line between their two frames, and the paths of chosen points. A time slider,
play/pause, the playback speed and the time are below the picture; the mouse turns (left), pans
(right) and zooms (wheel).

For example::

    import rigidfem as rf
    model, h = rf.samples.kane_beam(omega=6.0, duration=15.0, elements=8)
    system = model.compile()
    result = rf.simulate(system, 20.0, t_eval=[0.05 * k for k in range(401)])
    viewer = rf.view(system, result, trails=[h["beam"].tip])
    path = viewer.to_html("kane.html")          # a self-contained page, 1.15 MB (10 bodies)

The file holds every frame's pose of every body as float32: 48 bytes × frames × bodies before base64
(4/3), plus 0.9 MB of three.js; a 20 s Kane run (m = 20, 401 frames, 22 bodies) is about 1.5 MB.
"""

from __future__ import annotations

import base64
import html
import inspect
import json
from pathlib import Path

import numpy as np

from ..base import _checks
import rigidfem._core as _core  # the compiled core, by its absolute name
from .._core import Body, Point

ASSETS = Path(__file__).resolve().parent / "viewer_assets"

class Viewer:
    """A scene and its frames (``rf.view``): shows itself in a notebook (``_repr_html_``: an iframe, no
    network) and writes a self-contained HTML file (``to_html``)."""

    def __init__(self, data: dict, height: int):
        self.data = data
        self.height = height

    @property
    def frames(self) -> int:
        """The number of frames."""
        return len(self.data["t"])

    def html(self) -> str:
        """The page: three.js, its orbit controls, the frames and the viewer's script, all inline."""
        scripts = "\n".join(f"<script>{(ASSETS / name).read_text(encoding='utf-8')}</script>"
                            for name in ("three.min.js", "OrbitControls.js"))
        data = json.dumps(self.data, separators=(",", ":")).replace("</", "<\\/")
        app = (ASSETS / "viewer.js").read_text(encoding="utf-8")
        return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{html.escape(self.data['title'])}</title>
<style>
body {{ margin: 0; font: 13px sans-serif; }}
#rf-view {{ width: 100%; height: {self.height}px; }}
#rf-bar {{ display: flex; gap: 8px; align-items: center; padding: 4px 8px; }}
#rf-slider {{ flex: 1; }}
</style></head><body>
<div id="rf-view"></div>
<div id="rf-bar"><button id="rf-play">play</button><input id="rf-slider" type="range" min="0" value="0" step="1">
<span id="rf-time"></span><label>speed <select id="rf-speed"><option value="0.25">0.25×</option>
<option value="0.5">0.5×</option><option value="1" selected>1×</option><option value="2">2×</option>
<option value="4">4×</option></select></label></div>
{scripts}
<script>window.RIGIDFEM = {data};</script>
<script>{app}</script>
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
        from Python to move the slider, read it to know which frame the slider shows)."""
        return _widget_class()(page=self.html(), height=self.height, frames=self.frames)

    def _repr_html_(self) -> str:
        """In a notebook: the page in an iframe (its scripts run apart from the notebook's)."""
        return (f'<iframe srcdoc="{html.escape(self.html(), quote=True)}" style="width: 100%; '
                f'height: {self.height + 40}px; border: 0;"></iframe>')

    def __repr__(self) -> str:
        return (f"<rigidfem Viewer: {len(self.data['bodies'])} bodies, {len(self.data['beams'])} beams, "
                f"{self.frames} frames>")


#: The most body poses (frames × bodies) a page holds: 12 float32 each, 96 MB (128 MB as base64).
MAX_POSES = 2_000_000


def view(system, result=None, *, trails=(), frames: int | None = None, q=None, t: float = 0.0,
         height: int = 420, title: str = "rigidfem") -> Viewer:
    """The 3D scene of ``system``: the frames of ``result`` (a ``Result`` of it), or the one state ``q``
    at ``t`` (zeros by default).

    Parameters
    ----------
    trails : Point or Body, or a sequence of them
        Points (a Body: its origin) whose paths are drawn from the start up to the frame shown; () (the
        default) draws none.
    frames : int, optional
        At most this many frames, spread evenly over the result's outputs (default: every output, as
        many as ``MAX_POSES`` body poses allow: frames × bodies ≤ 2,000,000, a page of about 130 MB).
    q, t
        Without a result: the coordinates (m, rad) and the time (s) of the state shown.
    height : int
        Height of the picture in pixels.
    """

    system = _checks.system(system)
    if result is not None:
        if _checks.result(result).system is not system:
            raise _checks.refuse(f"result: expected a Result of this system (rf.simulate(system, ...)), got "
                             f"{_checks._short(result)}")
        if q is not None:
            raise _checks.refuse("q: expected None with a result (its frames are shown)")
        times, states = np.asarray(result.t), np.asarray(result.q)
        if len(times) == 0:
            raise _checks.refuse("result: expected at least one output")
    else:
        q = np.zeros(system.nq) if q is None else _checks.array(q, (system.nq,), "q")
        times, states = np.array([_checks.scalar(t, "t")]), q[None, :]
    fit = MAX_POSES // max(system.nbodies, 1)  # the frames whose poses the page holds
    if fit < 1:
        raise _checks.refuse(f"system: expected at most {MAX_POSES:,} bodies to show, got {system.nbodies:,}")
    if frames is not None:
        frames = _checks.integer(frames, "frames", minimum=1, maximum=fit)
    elif len(times) > fit:
        frames = fit  # bounded before anything is computed: at most MAX_POSES body poses
    if frames is not None:
        keep = np.unique(np.round(np.linspace(0, len(times) - 1, min(frames, len(times)))).astype(int))
        times, states = times[keep], states[keep]
    height = _checks.integer(height, "height", minimum=100, maximum=4000)
    points = _trail_points(trails, system)
    return Viewer(_scene(system, times, states, points, str(title)), height)


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
    return items


def _poses(system, times, states) -> np.ndarray:
    """(frames, bodies, 12) float32: each body's rotation row by row, then its origin (one kinematics pass
    per frame in C++, ``_core._body_poses``)."""
    poses = _core._body_poses(system, np.asarray(times, dtype=float), np.ascontiguousarray(states, dtype=float))
    return poses.reshape(len(times), system.nbodies, 12).astype(np.float32)


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


def _scene(system, times, states, trails, title) -> dict:
    names = list(system.body_names)
    index = {n: i for i, n in enumerate(names)}
    poses = _poses(system, times, states)
    origins = poses[:, :, 9:].reshape(-1, 3).astype(float)
    lo, hi = (origins.min(axis=0), origins.max(axis=0)) if len(origins) else (np.zeros(3), np.zeros(3))
    size = float(max(np.linalg.norm(hi - lo), 1e-3))
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
    for i, n in enumerate(names):
        shaped = any(sh["body"] == i for sh in shapes)  # a body with shapes is shown by them
        box = None if i in in_beam or shaped else _equivalent_box(float(masses[i]), np.asarray(inertias[i]))
        if i in base or (box is not None and max(box) > 2 * size):
            box = [0.08 * size] * 3
        bodies.append({"name": n, "box": box, "com": [float(x) for x in centres[i]],
                       "triad": 0.0 if i in in_beam else 0.06 * size, "base": i in base})
    g = np.asarray(system.gravity, dtype=float)
    up = (-g / np.linalg.norm(g)).tolist() if np.linalg.norm(g) > 0 else [0.0, 0.0, 1.0]
    return {"title": title, "t": [float(x) for x in times], "size": size,
            "centre": ((lo + hi) / 2).tolist(), "up": up, "bodies": bodies, "beams": beams, "segments": segments, "shapes": shapes,
            "trails": [dict(zip(("body", "r"), _point(p))) for p in trails],
            "poses": base64.b64encode(poses.astype("<f4").tobytes()).decode("ascii")}


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
            """rigidfem's 3D viewer in a notebook: ``frame`` follows the slider and moves it."""

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

        _WIDGET = ViewerWidget
    return _WIDGET
