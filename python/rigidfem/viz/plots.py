"""Plots of results, shapes and modes (matplotlib).

Every function draws into the Axes ``ax`` when given (a new figure otherwise), returns what it
drew into and never calls ``plt.show()``. Lengths are in m, angles in rad, times in s, energies
in J, forces in N and torques in N·m.

- time histories of a ``Result``: ``coordinates``, ``position``, ``energies``, ``driving_forces``;
- the shape of a system at a state: ``shape`` (bodies as frames and links, beams as centre lines);
- mode shapes of ``rigidfem.modal_analysis``: ``modes``.

``rigidfem.animation`` animates a Result with the same drawing code as ``shape``.

Examples
--------
>>> import matplotlib
>>> matplotlib.use("Agg")
>>> import matplotlib.pyplot as plt
>>> import rigidfem as rf
>>> model, h = rf.samples.pendulum()
>>> res = rf.simulate(model.compile(), 0.5, q0=[0.5])
>>> ax = rf.plots.coordinates(res)
>>> ax.get_xlabel()
't (s)'
>>> plt.close("all")
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..base import _checks
from .._core import Body, Point
from ..model.beams import Beam

PLANES = {"xy": (0, 1), "xz": (0, 2), "yz": (1, 2)}
ANGULAR = ("rx", "ry", "rz")
QUANTITIES = {"q": ("q", ""), "qd": ("q̇", "/s"), "qdd": ("q̈", "/s²")}  #: symbol, unit per s^k
ENERGIES = {"kinetic": "kinetic_energy", "gravity": "gravity_energy", "elastic": "elastic_energy",
            "total": "energy"}


def _pyplot():
    import matplotlib.pyplot as plt  # imported on first use: importing rigidfem stays free of matplotlib

    return plt


# --- time histories -------------------------------------------------------------------------------

def unit(name: str) -> str:
    """The unit of a joint coordinate called ``name``: "rad" for a rotation (a name ending in
    rx, ry or rz), "m" for a translation."""
    return "rad" if name.endswith(ANGULAR) else "m"


def _select(names: Sequence[str], which, argument: str, what: str, default: int) -> list[int]:
    """Indices into ``names`` of ``which``: None (the first ``default``), a name, an index, or a
    sequence of them."""
    if which is None:
        return list(range(min(len(names), default)))
    items = [which] if isinstance(which, (str, int, np.integer)) else list(which)
    listed = ", ".join(map(repr, names[:20])) + (f", ... ({len(names)} in all)" if len(names) > 20 else "")
    out = []
    for item in items:
        if isinstance(item, str) and item in names:
            out.append(names.index(item))
        elif isinstance(item, (int, np.integer)) and not isinstance(item, bool) and -len(names) <= item < len(names):
            out.append(int(item) % len(names))
        else:
            raise _checks.refuse(f"{argument}: expected {what} from [{listed}] or indices 0..{len(names) - 1}, "
                             f"got {item!r}")
    if not out:
        raise _checks.refuse(f"{argument}: expected at least one of {what}, got {which!r}")
    return out


def _axes(ax, projection: str | None = None):
    """``ax``, or the Axes of a new figure."""
    if ax is not None:
        return ax
    return _pyplot().figure().add_subplot(projection=projection)


def _history(ax, t: np.ndarray, columns: np.ndarray, labels: Sequence[str], ylabel: str):
    """One line per column of ``columns`` (len(t), k) against t, labelled, with a legend."""
    ax = _axes(ax)
    for y, label in zip(columns.T, labels):
        ax.plot(t, y, label=label)
    ax.set_xlabel("t (s)")
    ax.set_ylabel(ylabel)
    ax.legend()
    return ax


def _units(units: Sequence[str]) -> str:
    return ", ".join(dict.fromkeys(units))


def coordinates(result, which=None, *, quantity: str = "q", ax=None):
    """Time histories of joint coordinates of ``result`` (a ``rigidfem.Result``).

    Parameters
    ----------
    which : str, int or sequence of them, optional
        Coordinates by name (``system.coordinate_names``) or index; default the first six.
    quantity : "q", "qd" or "qdd"
        Coordinates (m, rad), their rates (m/s, rad/s) or accelerations (m/s², rad/s²).
    ax : matplotlib Axes, optional

    Returns the Axes: one line per coordinate, labelled "name (unit)", x = ``result.t``; the
    y axis "q (rad)", "q̇ (m/s, rad/s)", ...
    """
    if quantity not in QUANTITIES:
        raise _checks.refuse(f"quantity: expected one of {list(QUANTITIES)}, got {quantity!r}")
    result = _checks.result(result, needs="accelerations" if quantity == "qdd" else None)
    names = result.coordinate_names
    if not names:
        raise _checks.refuse("result: expected a system with free coordinates, got one with nq = 0")
    k = _select(names, which, "which", "coordinate names", 6)
    symbol, per = QUANTITIES[quantity]
    units = [unit(names[i]) + per for i in k]
    values = getattr(result, quantity)[:, k]
    labels = [f"{names[i]} ({u})" for i, u in zip(k, units)]
    return _history(ax, result.t, values, labels, f"{symbol} ({_units(units)})")


def position(result, point, components: str = "xyz", *, frame: Body | None = None, ax=None, label: str = ""):
    """Time histories of the position (m) of ``point`` (a Point, or a Body's origin), in the
    global frame or in the frame of the body ``frame``.

    ``components``: any of "x", "y", "z" (e.g. "xz"). Lines are labelled "{label} x (m)", ...
    Returns the Axes.
    """
    result = _checks.result(result, needs="positions")
    if not isinstance(components, str) or not components or any(c not in "xyz" for c in components) \
            or len(set(components)) != len(components):
        raise _checks.refuse(f"components: expected distinct letters from 'xyz' (e.g. 'xz'), got {components!r}")
    X = result.position(point, frame=frame)
    k = ["xyz".index(c) for c in components]
    prefix = f"{label} " if label else ""
    return _history(ax, result.t, X[:, k], [f"{prefix}{c} (m)" for c in components], "position (m)")


def energies(result, which: Sequence[str] = tuple(ENERGIES), *, ax=None):
    """Kinetic, gravity, elastic and total energy (J) of ``result`` against time; ``which``
    chooses among ``"kinetic", "gravity", "elastic", "total"``. Returns the Axes."""
    result = _checks.result(result, needs="energies")
    k = _select(list(ENERGIES), which, "which", "energies", len(ENERGIES))
    names = [list(ENERGIES)[i] for i in k]
    values = np.column_stack([getattr(result, ENERGIES[n]) for n in names])
    return _history(ax, result.t, values, [f"{n} (J)" for n in names], "energy (J)")


def driving_forces(result, which=None, *, ax=None):
    """Forces (N) and torques (N·m) of the drives of ``result`` against time, by name
    (``system.prescribed_names``) or index; default the first six. Returns the Axes."""
    result = _checks.result(result, needs="driving forces")
    names = result.system.prescribed_names
    if not names:
        raise _checks.refuse("result: expected a system with prescribed coordinates (drives), got none")
    k = _select(names, which, "which", "prescribed coordinate names", 6)
    units = ["N·m" if unit(names[i]) == "rad" else "N" for i in k]
    labels = [f"{names[i]} ({u})" for i, u in zip(k, units)]
    return _history(ax, result.t, result.driving_forces[:, k], labels, f"driving force ({_units(units)})")


# --- the shape of a system ------------------------------------------------------------------------

@dataclass
class Pose:
    """What ``shape`` draws of one state, global coordinates (m); NaN rows separate polylines.

    ``links`` (n, 3): per body, parent origin → joint → origin → centre of mass; ``segments``
    (n, 3): the straight lines between pairs of points; ``triads``: three arrays (n, 3), each
    body's x, y and z axes from its origin, ``frame_size`` (m) long; ``beams``: a centre line
    (m + 2, 3) per beam."""

    links: np.ndarray
    segments: np.ndarray
    triads: list[np.ndarray]
    beams: list[np.ndarray]
    frame_size: float

    def lines(self) -> list[np.ndarray]:
        """The polylines in the order ``ShapeArtists`` draws them."""
        return [self.links, self.segments, *self.triads, *self.beams]

    def points(self) -> np.ndarray:
        """All the finite points drawn, (k, 3)."""
        X = np.vstack(self.lines())
        return X[np.all(np.isfinite(X), axis=1)]


def _is_rfe(name: str) -> bool:
    """Whether a body is a rigid finite element (named "<beam>.rfe<k>" by ``add_beam``)."""
    head, _, tail = name.rpartition(".rfe")
    return bool(head) and tail.isdigit()


class Skeleton:
    """The points that show a system, computed for a state in one positions-only kinematics pass
    (plus one per beam).

    Every body gets a link (parent origin → joint frame → body origin → centre of mass) and,
    unless it is an rfe, a triad of its axes; the rfes of the ``beams`` are drawn by their centre
    lines instead (``Beam.centerline``), other rfes by their links. ``segments``: pairs of points
    (Point or Body; on the ground too) joined by straight lines: ropes, cylinders, springs."""

    def __init__(self, system, beams=(), segments=()):
        self.system = system = _checks.system(system)
        self.beams = _beams(beams, system)
        hidden = {b.index for beam in self.beams for b in beam.rfes[1:]}
        names, model = system.body_names, getattr(system, "_model_id", 0)
        bodies = [Body(i, names[i], model) for i in range(system.nbodies)]
        self.points: list[Point] = []      # on bodies: placed by the kinematics
        self.fixed: dict[int, np.ndarray] = {}  # row -> global position of joints on the ground
        self.links: list[list[int]] = []   # per body, the rows of its polyline
        self.triads: list[tuple[int, int]] = []  # per triad, the rows of the origin and the x axis' unit point
        # each a list of all the bodies' (a call builds it): read once, not per body
        parents, placements, centres = system.parent, system.placements, system.centres_of_mass
        for i, body in enumerate(bodies):
            if i in hidden:
                continue
            joint = self._joint(bodies, i, parents[i], placements[i])
            origin = self._add(body.origin)
            self.links.append(joint + [origin, self._add(body.point(centres[i]))])
            if not _is_rfe(names[i]):
                axes = [self._add(body.point(e)) for e in np.eye(3)]  # unit points along x, y, z
                self.triads.append((origin, axes[0]))
        self.segments = [[self._point(a), self._point(b)] for a, b in _pairs(segments, system)]

    def _joint(self, bodies: list[Body], i: int, p: int, placement) -> list[int]:
        """The rows of body i's parent p's origin and its joint frame at ``placement`` on p (only the joint
        frame on the ground)."""
        r = np.asarray(placement)[:3, 3]
        return [self._fixed(r)] if p < 0 else [self._add(bodies[p].origin), self._add(bodies[p].point(r))]

    @property
    def rows(self) -> int:
        return len(self.points) + len(self.fixed)

    def _point(self, point) -> int:
        """The row of a Point or a Body's origin; fixed on the ground."""
        point = point.origin if isinstance(point, Body) else point
        return self._fixed(np.asarray(point.r, dtype=float)) if point.body < 0 else self._add(point)

    def _add(self, point: Point) -> int:
        self.points.append(point)
        return self.rows - 1

    def _fixed(self, r: np.ndarray) -> int:
        row = self.rows
        self.fixed[row] = r
        return row
    def pose(self, q, *, t: float | None = None, frame_size: float | None = None) -> Pose:
        """The points at the state ``q`` (m, rad) and time ``t`` (s; required with drives).
        ``frame_size``: the triads' length in m; default 8 % of the shape's extent."""
        t = _checks.pose_time(self.system, t)
        if frame_size is not None:
            frame_size = _checks.scalar(frame_size, "frame_size", positive=True, unit="m")
        X = np.empty((self.rows, 3))
        on_bodies = np.setdiff1d(np.arange(self.rows), list(self.fixed))
        if self.points:
            X[on_bodies] = self.system._positions(self.points, t, q)
        for row, r in self.fixed.items():
            X[row] = r
        links, segments = _polylines([X[k] for k in self.links]), _polylines([X[k] for k in self.segments])
        beams = [beam.centerline(self.system, q, t=t) for beam in self.beams]
        if frame_size is None:
            frame_size = 0.08 * _extent(np.vstack([links, segments, *beams]))
        triads = [_polylines([[X[o], X[o] + frame_size * (X[x + a] - X[o])] for o, x in self.triads])
                  for a in range(3)]
        return Pose(links, segments, triads, beams, frame_size)


def _polylines(lines) -> np.ndarray:
    """Polylines joined into one array (n, 3), each followed by a row of NaN."""
    rows = [np.vstack([line, np.full((1, 3), np.nan)]) for line in lines]
    return np.vstack(rows) if rows else np.zeros((0, 3))


def _extent(X: np.ndarray) -> float:
    """The largest side (m) of the bounding box of the finite rows of X (n, 3); 1 m if none."""
    X = X[np.all(np.isfinite(X), axis=1)]
    size = float(np.max(np.ptp(X, axis=0))) if len(X) else 0.0
    return size if size > 0 else 1.0


def _beams(beams, system) -> list[Beam]:
    beams = [beams] if isinstance(beams, Beam) else list(beams)
    for beam in beams:
        if not isinstance(beam, Beam):
            raise _checks.refuse(f"beams: expected Beam handles from Model.add_beam, got {beam!r}")
        _checks.same_model(beam.rfes[0], system, "beams", "beams of the model this system was compiled from")
    return beams


def _pairs(segments, system) -> list[tuple]:
    pairs = list(segments)
    for pair in pairs:
        if not (isinstance(pair, tuple) and len(pair) == 2 and all(isinstance(p, (Point, Body)) for p in pair)):
            raise _checks.refuse(f"segments: expected pairs (a, b) of Point or Body handles, got {pair!r}")
        for p in pair:
            _checks.same_model(p, system, "segments")
    return pairs


def _plane(plane):
    if plane is not None and plane not in PLANES:
        raise _checks.refuse(f"plane: expected None (3D) or one of {list(PLANES)}, got {plane!r}")
    return plane


def _shape_axes(ax, plane):
    """``ax`` checked against ``plane`` (3D axes for plane=None), or new Axes with axis labels."""
    if ax is None:
        ax = _axes(None, "3d" if plane is None else None)
    elif (ax.name == "3d") != (plane is None):
        expected = "3D axes (projection='3d')" if plane is None else "2D axes"
        raise _checks.refuse(f"ax: expected {expected} for plane={plane!r}, got {ax.name} axes")
    for axis, c in zip(("x", "y", "z"), (plane or "xyz")):
        getattr(ax, f"set_{axis}label")(f"{c} (m)")
    return ax


class ShapeArtists:
    """The lines that draw a ``Pose`` in the Axes ``ax`` (3D for plane=None, else the projection
    on ``plane``): links (grey), segments (brown), triads (red x, green y, blue z) and one line per
    beam, labelled with ``beam_names``; ``color`` and ``alpha`` override the style of all."""

    def __init__(self, ax, plane, beam_names, color=None, alpha: float = 1.0):
        self.ax, self.columns = ax, PLANES[plane] if plane else (0, 1, 2)
        line = self.line
        self.links = line(label="_links", color=color or "0.35", lw=1.2, marker="o", ms=2.5, alpha=alpha)
        self.segments = line(label="_segments", color=color or "tab:brown", lw=1.2, alpha=alpha)
        self.triads = [line(label=f"_{c} axes", color=color or k, lw=1.0, alpha=alpha)
                       for c, k in zip("xyz", ("tab:red", "tab:green", "tab:blue"))]
        self.beams = [line(label=name, color=color or "tab:blue", lw=2.0, alpha=alpha) for name in beam_names]
        self.all = [self.links, self.segments, *self.triads, *self.beams]  # in the order of Pose.lines

    def line(self, **style):
        """A new, empty line in the Axes with the matplotlib ``style``."""
        empty = [[]] * len(self.columns)
        return self.ax.plot(*empty, **style)[0]

    def set(self, pose: Pose) -> list:
        """Show ``pose``; returns the changed artists."""
        for artist, X in zip(self.all, pose.lines(), strict=True):
            set_line(artist, X, self.columns)
        return self.all


def set_line(line, X: np.ndarray, columns) -> None:
    """Give the 2D or 3D ``line`` the points X (n, 3) projected on ``columns``."""
    coords = [X[:, c] for c in columns]
    if len(columns) == 3:
        line.set_data_3d(*coords)
    else:
        line.set_data(*coords)


def set_limits(ax, X: np.ndarray) -> None:
    """Equal-aspect limits around the points X (k, 2) of 2D Axes or (k, 3) of 3D ones, with a 5 %
    margin: a square, or a cube in 3D."""
    X = X[np.all(np.isfinite(X), axis=1)]
    lo, hi = (np.min(X, axis=0), np.max(X, axis=0)) if len(X) else (np.zeros(X.shape[1]),) * 2
    half = 0.55 * _extent(X)
    for axis, centre in zip("xyz", 0.5 * (lo + hi)):
        getattr(ax, f"set_{axis}lim")(centre - half, centre + half)
    if X.shape[1] == 2:
        ax.set_aspect("equal", adjustable="box")
    else:
        ax.set_box_aspect((1, 1, 1))


def drawn(ax) -> np.ndarray:
    """The vertices of all the lines in ``ax``, (k, 2) or (k, 3) in 3D, NaN rows included."""
    three = ax.name == "3d"
    rows = [np.column_stack(line.get_data_3d()) if three else line.get_xydata() for line in ax.get_lines()]
    return np.vstack(rows) if rows else np.zeros((0, 3 if three else 2))
def shape(system, q, *, t: float | None = None, ax=None, plane: str | None = None, beams=(), segments=(),
          frame_size: float | None = None):
    """Draw ``system`` at the state ``q`` (m, rad) and time ``t`` (s; required when the system
    has drives, as for ``System.position``).

    Every body is drawn as a triad of its axes (``system.transform``: red x, green y, blue z,
    ``frame_size`` m long, default 8 % of the drawing's extent) and a grey link from its parent's
    origin through its joint frame to its origin and centre of mass. Beams given in ``beams``
    (Beam handles, or one) are drawn as their deformed centre lines (``Beam.centerline``,
    labelled with the beam's name) instead of their rfes; the rfes of other beams as links only.
    ``segments``: pairs (a, b) of Points or Bodies (on the ground too) drawn as straight lines —
    ropes, cylinders, springs, which the System does not place.

    ``plane``: None for 3D axes, or "xy", "xz", "yz" for the projection on that plane. Equal
    aspect around everything drawn into the Axes (several states can share them), axes labelled
    "x (m)", ... Returns the Axes.
    """
    system = _checks.system(system)
    plane = _plane(plane)
    skeleton = Skeleton(system, beams, segments)
    pose = skeleton.pose(q, t=t, frame_size=frame_size)
    ax = _shape_axes(ax, plane)
    ShapeArtists(ax, plane, [b.name for b in skeleton.beams]).set(pose)
    set_limits(ax, drawn(ax))
    return ax


# --- mode shapes ----------------------------------------------------------------------------------

def modes(system, modes, which=(0, 1, 2), *, scale: float | None = None, t: float | None = None,
          plane: str | None = None, beams=(), ax=None):
    """Draw mode shapes of ``modes`` (from ``rigidfem.modal_analysis(system, ...)``): for each
    mode i in ``which`` (indices), the reference shape at ``modes.q`` (grey) and the shape at
    q + scale·φ_i, titled "mode i: f Hz" (``modes.frequencies_hz``).

    ``scale`` (m or rad per unit of the shape, whose largest entry is 1) defaults, per mode, to
    the one that moves the drawn points by at most 10 % of the drawing's extent. ``t`` (s) as
    in ``shape``; ``plane`` and ``beams`` as in ``shape``. ``ax``: a sequence of Axes, one per
    mode (a new figure with one row of them by default). Returns the list of Axes.
    """
    system = _checks.system(system)
    plane = _plane(plane)
    k = _mode_indices(which, len(modes.omega))
    if ax is None:
        fig = _pyplot().figure(figsize=(4 * len(k), 4), layout="constrained")
        ax = [fig.add_subplot(1, len(k), n + 1, projection=None if plane else "3d") for n in range(len(k))]
    elif len(ax) != len(k):
        raise _checks.refuse(f"ax: expected {len(k)} Axes (one per mode in which), got {len(ax)}")
    skeleton = Skeleton(system, beams)
    reference = skeleton.pose(modes.q, t=t)
    names = [b.name for b in skeleton.beams]
    for a, i in zip(ax, k):
        phi = modes.shapes[:, i]
        s = _mode_scale(skeleton, modes.q, reference, phi, t) if scale is None else _checks.scalar(scale, "scale")
        deformed = skeleton.pose(modes.q + s * phi, t=t, frame_size=reference.frame_size)
        _shape_axes(a, plane)
        ShapeArtists(a, plane, [f"_{n} reference" for n in names], color="0.7", alpha=0.8).set(reference)
        ShapeArtists(a, plane, names).set(deformed)
        set_limits(a, drawn(a))
        a.set_title(f"mode {i + 1}: {modes.frequencies_hz[i]:.4g} Hz")
    return ax


def _mode_indices(which, n: int) -> list[int]:
    items = [which] if isinstance(which, (int, np.integer)) else list(which)
    if not items or not all(isinstance(i, (int, np.integer)) and not isinstance(i, bool) and 0 <= i < n
                            for i in items):
        raise _checks.refuse(f"which: expected mode indices in 0..{n - 1} (0 the lowest frequency), got {which!r}")
    return [int(i) for i in items]


def _mode_scale(skeleton: Skeleton, q: np.ndarray, reference: Pose, phi: np.ndarray, t) -> float:
    """The scale s that moves the drawn points of the ``reference`` pose at q by 10 % of its
    extent at q + s φ (from the linearised motion)."""
    eps = 1e-6
    moved = skeleton.pose(q + eps * phi, t=t, frame_size=reference.frame_size)
    a, b = reference.points(), moved.points()
    rate = np.max(np.linalg.norm(b - a, axis=1)) / eps if len(a) else 0.0
    return 0.1 * _extent(a) / rate if rate > 0 else 1.0
