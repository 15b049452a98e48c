"""The site's drawings, made by the build (``conf.py`` calls :func:`write`) rather than pasted.

``rfe_sde.png`` (the method page): two rigid finite elements of a beam, rfe i and rfe i+1, as boxes with
their frames {i} and {i+1} at their left ends (x along the beam, as ``rigidfem.model.beams`` places them),
the spring-damping element sde i+1 that joins them drawn as a spring (stiffness c_k) above a damper
(damping b_k), and the global frame {0} with the poses T_i, T_{i+1} of the two frames in it. The rfes are
drawn apart (an exploded view) so that the sde between them can be seen; in the model frame {i+1} sits
on the sde.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.patches import FancyArrowPatch, Polygon  # noqa: E402

#: Colours: the rfes' faces and edges, the axes x, y, z (red, green, blue as in the 3D viewer), the sde, the poses
FACE, EDGE = "#c9d7ea", "#3d5a80"
AXES = ("#c0392b", "#1e8449", "#2c6fbb")
SDE, POSE = "#222222", "#777777"
#: Cabinet projection: y drawn at 35 degrees, shortened to a half
_OBLIQUE = 0.5 * np.array([np.cos(np.radians(35.0)), np.sin(np.radians(35.0))])


def _p(x, y=0.0, z=0.0):
    """The drawing's point (2,) of the point (x, y, z) (m)."""
    return np.array([x, z]) + y * _OBLIQUE


def _box(ax, x0, x1, half_y, half_z):
    """A box [x0, x1] x [-half_y, half_y] x [-half_z, half_z] (m): its three visible faces, shaded."""
    front = [_p(x0, -half_y, -half_z), _p(x1, -half_y, -half_z), _p(x1, -half_y, half_z), _p(x0, -half_y, half_z)]
    top = [_p(x0, -half_y, half_z), _p(x1, -half_y, half_z), _p(x1, half_y, half_z), _p(x0, half_y, half_z)]
    side = [_p(x1, -half_y, -half_z), _p(x1, half_y, -half_z), _p(x1, half_y, half_z), _p(x1, -half_y, half_z)]
    hidden = [_p(x0, half_y, -half_z), _p(x1, half_y, -half_z)]
    for face, shade in ((front, FACE), (top, "#dde7f3"), (side, "#b3c6df")):
        ax.add_patch(Polygon(face, closed=True, facecolor=shade, edgecolor=EDGE, linewidth=1.2, alpha=0.75, zorder=1))
    ax.plot(*np.transpose([_p(x0, -half_y, -half_z), hidden[0], hidden[1]]), color=EDGE, linewidth=0.8,
            linestyle=(0, (3, 3)), alpha=0.7, zorder=1)
    ax.plot(*np.transpose([hidden[0], _p(x0, half_y, half_z)]), color=EDGE, linewidth=0.8, linestyle=(0, (3, 3)),
            alpha=0.7, zorder=1)


def _arrow(ax, a, b, colour, width=2.0, style="-|>", dashed=False, zorder=3):
    ax.add_patch(FancyArrowPatch(a, b, arrowstyle=style, mutation_scale=16, color=colour, linewidth=width,
                                 linestyle=(0, (5, 3)) if dashed else "-", shrinkA=0, shrinkB=0, zorder=zorder))


def _frame(ax, origin, name, at=(-0.22, 0.72), lengths=(1.0, 1.0, 1.0)):
    """A frame's axes x, y, z as arrows from ``origin`` (x, y, z), each labelled, and its name {name} at ``at``
    from the origin (in the drawing)."""
    o = _p(*origin)
    tips = []
    for k, (axis, colour) in enumerate(zip(("x", "y", "z"), AXES)):
        d = np.zeros(3)
        d[k] = lengths[k]
        tip = _p(*(np.asarray(origin, float) + d))
        tips.append(tip)
        _arrow(ax, o, tip, colour)
        offset = {"x": (0.12, -0.22), "y": (0.16, 0.06), "z": (0.0, 0.16)}[axis]
        ax.text(*(tip + offset), f"${axis}_{{{name}}}$", color=colour, fontsize=13, ha="center", va="center",
                zorder=4, bbox=dict(facecolor="white", edgecolor="none", alpha=0.6, pad=0.3))
    ax.text(*(o + at), rf"$\{{{name}\}}$", fontsize=14, ha="right" if at[0] < 0 else "left", va="center",
            zorder=4)
    ax.plot(*o, "o", color="black", markersize=3.5, zorder=4)


def _spring(ax, x0, x1, z, turns=6, amplitude=0.13):
    """A zigzag spring from x0 to x1 at the height z (in the plane y = 0), straight leads at its ends."""
    lead = 0.18 * (x1 - x0)
    xs = np.linspace(x0 + lead, x1 - lead, 2 * turns + 1)
    zs = z + amplitude * np.array([0.0] + [(-1) ** k for k in range(2 * turns - 1)] + [0.0])
    pts = [_p(x, 0.0, h) for x, h in zip(np.concatenate([[x0], xs, [x1]]), np.concatenate([[z], zs, [z]]))]
    ax.plot(*np.transpose(pts), color=SDE, linewidth=1.6, zorder=2)


def _damper(ax, x0, x1, z, width=0.15):
    """A dashpot from x0 to x1 at the height z: a cylinder open towards x1 and a piston on a rod from x1."""
    a, b, piston = x0 + 0.3 * (x1 - x0), x0 + 0.72 * (x1 - x0), x0 + 0.56 * (x1 - x0)
    line = dict(color=SDE, linewidth=1.6, zorder=2)
    for xs, zs in (([x0, a], [z, z]), ([b, a, a, b], [z + width, z + width, z - width, z - width]),
                   ([piston, piston], [z - 0.7 * width, z + 0.7 * width]), ([piston, x1], [z, z])):
        ax.plot(*np.transpose([_p(x, 0.0, h) for x, h in zip(xs, zs)]), **line)


def rfe_sde(path: Path) -> None:
    """Two rfes, the sde between them and the frames {0}, {i}, {i+1} into ``path`` (PNG)."""
    fig, ax = plt.subplots(figsize=(9.0, 3.9), dpi=150)
    L, gap, hy, hz = 3.0, 1.9, 0.45, 0.5  # the rfes' length, the exploded sde's length, half width, half height
    a0, a1 = 1.6, 1.6 + L  # rfe i
    b0, b1 = a1 + gap, a1 + gap + L  # rfe i+1
    _box(ax, a0, a1, hy, hz)
    _box(ax, b0, b1, hy, hz)
    ax.text(*_p(0.5 * (a0 + a1) + 0.5, hy, hz + 0.12), "rfe $i$", fontsize=13, ha="center", va="bottom")
    ax.text(*_p(0.5 * (b0 + b1) + 0.5, hy, hz + 0.12), "rfe $i{+}1$", fontsize=13, ha="center", va="bottom")

    # sde i+1 between rfe i's end face and rfe i+1's first face: a spring above a damper
    _spring(ax, a1, b0, 0.24)
    _damper(ax, a1, b0, -0.24)
    mid = 0.5 * (a1 + b0)
    ax.text(*_p(mid, 0.0, 0.46), "$c_k$", fontsize=13, ha="center", va="bottom")
    ax.text(*_p(mid, 0.0, -0.45), "$b_k$", fontsize=13, ha="center", va="top")
    ax.text(*_p(mid, 0.0, -0.9), "sde $i{+}1$", fontsize=13, ha="center", va="top")

    # the frames: {i} and {i+1} at their rfes' first faces on the beam's axis, {0} the global frame
    o0 = (-1.4, 0.0, -1.9)
    _frame(ax, o0, "0", at=(-0.2, 0.45))
    _frame(ax, (a0, 0.0, 0.0), "i")
    _frame(ax, (b0, 0.0, 0.0), "i+1", at=(0.02, -0.47))
    for target, name, t in (((a0, 0.0, 0.0), "T_i", 0.5), ((b0, 0.0, 0.0), "T_{i+1}", 0.62)):
        _arrow(ax, _p(*o0), _p(*target), POSE, width=1.1, style="-|>", dashed=True, zorder=1.5)
        at = (1 - t) * _p(*o0) + t * _p(*target)
        ax.text(at[0] + 0.05, at[1] - 0.13, f"${name}$", color="#444444", fontsize=12, ha="left", va="top")

    ax.set_aspect("equal")
    ax.set_axis_off()
    ax.autoscale_view()
    ax.margins(0.02)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, bbox_inches="tight", pad_inches=0.05)
    plt.close(fig)


def write(folder: Path) -> list[Path]:
    """Every drawing into ``folder``; returns their paths."""
    path = Path(folder) / "rfe_sde.png"
    rfe_sde(path)
    return [path]


if __name__ == "__main__":
    print(write(Path(__file__).resolve().parent / "_generated" / "figures"))
