"""Animations of simulation results (matplotlib ``FuncAnimation``).

``animate(result)`` draws the system frame by frame with the drawing code of
``rigidfem.plots.shape``, the time as text and trails of chosen points. In a notebook show it
with ``IPython.display.HTML(anim.to_jshtml())``; write a movie with ``save(anim, "movie.gif")``
(pillow, installed with matplotlib) or ``.mp4`` (needs ffmpeg).

Examples
--------
>>> import rigidfem as rf
>>> sorted(rf.animation.WRITERS)[:2]
['.avi', '.gif']
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.animation import FuncAnimation, writers

from ..base import _checks
from . import plots
from .viewer import _trail_points

#: File extension -> matplotlib movie writer.
WRITERS = {".gif": "pillow", ".mp4": "ffmpeg", ".mov": "ffmpeg", ".avi": "ffmpeg", ".mkv": "ffmpeg",
           ".webm": "ffmpeg", ".html": "html"}
DEFAULT_FRAMES = 100
#: The most frames an animation draws, and the most points' poses (frames × bodies) it computes.
MAX_FRAMES, MAX_POSES = 100_000, 2_000_000


class Animation(FuncAnimation):
    """A ``FuncAnimation`` of a Result: frame k shows the state at ``times[k]`` (s), the output
    ``indices[k]`` of the result; ``update(k)`` draws it and returns the changed artists."""

    def __init__(self, fig, update, indices: np.ndarray, times: np.ndarray, interval: float):
        self.indices, self.times, self.update = indices, times, update
        super().__init__(fig, update, frames=len(indices), interval=interval, blit=False, cache_frame_data=False)


def frame_indices(t: np.ndarray, frames: int | None = None, fps: float | None = None, bodies: int = 1) -> np.ndarray:
    """Indices into the output times ``t`` (s) of the frames: ``frames`` evenly spread over the
    outputs (at most len(t); default min(len(t), 100)), or the outputs nearest to the times
    t0 + k/``fps`` (frames per second of simulated time). At most ``MAX_FRAMES`` frames and
    ``MAX_POSES`` poses (frames × ``bodies``), bounded before any is computed."""
    if frames is not None and fps is not None:
        raise _checks.refuse(f"fps: expected None when frames is given, got fps={fps!r} and frames={frames!r}")
    n, most = len(t), max(1, min(MAX_FRAMES, MAX_POSES // max(bodies, 1)))
    if fps is None:
        count = min(n, DEFAULT_FRAMES) if frames is None else min(n, _checks.integer(frames, "frames", minimum=1))
        if count > most:
            raise _checks.refuse(f"frames: expected at most {most:,} frames (MAX_FRAMES = {MAX_FRAMES:,}, frames × "
                             f"{bodies:,} bodies ≤ MAX_POSES = {MAX_POSES:,}), got {count:,}")
        return np.unique(np.round(np.linspace(0, n - 1, count)).astype(int))
    fps = _checks.scalar(fps, "fps", positive=True, unit="frames per s")
    count = np.floor((t[-1] - t[0]) * fps + 1e-9) + 1  # a float: checked before anything is allocated
    if not count <= most:
        raise _checks.refuse(f"fps: expected at most {most:,} frames over the {t[-1] - t[0]:g} s of the result "
                         f"(MAX_FRAMES = {MAX_FRAMES:,}, frames × bodies ≤ MAX_POSES = {MAX_POSES:,}), got fps = "
                         f"{fps:g}: {count:g} frames")
    wanted = t[0] + np.arange(int(count)) / fps
    right = np.clip(np.searchsorted(t, wanted), 1, n - 1) if n > 1 else np.zeros(len(wanted), int)
    left = np.maximum(right - 1, 0)
    return np.where(np.abs(t[left] - wanted) <= np.abs(t[right] - wanted), left, right)


def animate(result, *, plane: str | None = None, beams=(), segments=(), trails=(), frames: int | None = None,
            fps: float | None = None, interval: float | None = None, frame_size: float | None = None,
            ax=None) -> Animation:
    """Animate ``result`` (a ``rigidfem.Result``).

    Parameters
    ----------
    plane : None, "xy", "xz" or "yz"
        3D axes (None) or the projection on a plane, as in ``rigidfem.plots.shape``.
    beams : Beam or sequence of Beam
        Drawn as their deformed centre lines (``plots.shape``).
    segments : sequence of (a, b) pairs of Point or Body
        Straight lines between points: ropes, cylinders, springs (``plots.shape``).
    trails : Point or Body, or a sequence of them
        Points (a Body: its origin) whose paths are drawn from the start up to the current frame (e.g.
        ``[beam.tip]``); () (the default) draws none.
    frames : int, optional
        Number of frames, spread evenly over the outputs (at most len(result.t); default up to 100).
    fps : float, optional
        Instead of ``frames``: frames per second of simulated time, each the nearest output.
    interval : float, optional
        Delay between frames in ms; default real time (the simulated time between frames).
    frame_size : float, optional
        Length of the bodies' triads, m (default 8 % of the first frame's extent).
    ax : matplotlib Axes, optional
        3D for plane=None.

    Returns
    -------
    matplotlib.animation.FuncAnimation
        ``anim.to_jshtml()`` shows it in a notebook, ``save(anim, "movie.gif")`` writes it to a file.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import matplotlib.pyplot as plt
    >>> import rigidfem as rf
    >>> model, h = rf.samples.pendulum()
    >>> res = rf.simulate(model.compile(), 0.5, q0=[0.5], t_eval=[0.0, 0.25, 0.5])
    >>> anim = rf.animate(res, plane="xz", frames=2)
    >>> "<script" in anim.to_jshtml()
    True
    >>> plt.close("all")
    """
    result = _checks.result(result, needs="an animation")
    plane = plots._plane(plane)
    t = np.asarray(result.t)
    indices = frame_indices(t, frames, fps, result.system.nbodies)
    interval = _real_time(t[indices]) if interval is None else _checks.scalar(interval, "interval", positive=True,
                                                                             unit="ms")
    points = _trail_points(trails, result.system)
    skeleton = plots.Skeleton(result.system, beams, segments)
    first = skeleton.pose(result.q[indices[0]], t=t[indices[0]], frame_size=frame_size)
    poses = [skeleton.pose(result.q[i], t=t[i], frame_size=first.frame_size) for i in indices]
    paths = [result.position(p) for p in points]

    ax = plots._shape_axes(ax, plane)
    shape = plots.ShapeArtists(ax, plane, [b.name for b in skeleton.beams])
    lines = [shape.line(color=f"C{k + 1}", lw=1.0, label=f"trail {k}") for k in range(len(paths))]
    clock = (ax.text2D if plane is None else ax.text)(0.02, 0.95, "", transform=ax.transAxes)
    plots.set_limits(ax, np.vstack([p.points() for p in poses] + paths)[:, list(shape.columns)])

    def update(k: int) -> list:
        for line, path in zip(lines, paths):
            plots.set_line(line, path[: indices[k] + 1], shape.columns)
        clock.set_text(f"t = {t[indices[k]]:.3f} s")
        return shape.set(poses[k]) + lines + [clock]

    return Animation(ax.figure, update, indices, t[indices], interval)


def _real_time(times: np.ndarray) -> float:
    """The delay between frames (ms) that plays ``times`` (s) in real time; 40 ms for one frame."""
    step = (times[-1] - times[0]) / (len(times) - 1) if len(times) > 1 else 0.0
    return 1000.0 * step if step > 0 else 40.0


def save(anim, path, *, fps: float | None = None, dpi: float | None = None) -> Path:
    """Write the animation ``anim`` to ``path``; the extension chooses the writer (``WRITERS``:
    .gif by pillow, .mp4 and others by ffmpeg, .html). ``fps``: frames per second of the file
    (default from the animation's interval); ``dpi``: resolution. Raises ValueError when the
    extension is unknown or its writer is not installed. Returns the path (a ``pathlib.Path``)."""
    path = Path(_checks.path(path))
    ext = path.suffix.lower()
    if ext not in WRITERS:
        raise _checks.refuse(f"path: expected a file name ending in one of {list(WRITERS)}, got {str(path)!r}")
    writer = WRITERS[ext]
    if not writers.is_available(writer):
        raise _checks.refuse(f"path: expected a format whose movie writer is available, got {ext!r}, whose writer "
                             f"{writer!r} is not installed; install it or save as .gif (pillow)")
    anim.save(path, writer=writer, fps=fps, dpi=dpi)
    return path
