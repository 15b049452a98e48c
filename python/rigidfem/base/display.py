"""Notebook displays: the HTML of ``_repr_html_`` for Model, System, Result and Modes.

Every name is escaped with ``html.escape``; long tables show their first ``MAX_ROWS`` rows and
a last row "… n more". The functions only read their object (a Model is compiled into a
System to list its coordinates; a Model that does not compile shows its bodies and the error).

Examples
--------
>>> import rigidfem as rf
>>> model, h = rf.samples.pendulum()
>>> system = model.compile()
>>> html = rf.display.system_html(system)
>>> "link.ry" in html
True
"""

from __future__ import annotations

import html
import re

import numpy as np

from . import _checks

#: Rows shown of a long table (bodies, modes) before "… n more".
MAX_ROWS = 20

#: A joint's kind from its coordinates (free and prescribed, in the book's order x, y, z, rz, ry, rx).
_KINDS = {(): "fixed", ("rz", "ry", "rx"): "spherical", ("x", "y", "z", "rz", "ry", "rx"): "free",
          ("x", "y", "rz"): "planar xy", ("y", "z", "rx"): "planar yz", ("x", "z", "ry"): "planar zx"}
_ORDER = ("x", "y", "z", "rz", "ry", "rx")
_RFE = re.compile(r"^(.*)\.rfe(\d+)$")  # the rfes of a beam are named <beam>.rfe<k> (Model.add_beam)


def _e(x) -> str:
    return html.escape(str(x))


def _joint_kind(coordinates: tuple[str, ...]) -> str:
    """'revolute z', 'prismatic x', 'cylindrical z', 'universal (rz, ry)', ... from the coordinates."""
    if coordinates in _KINDS:
        return _KINDS[coordinates]
    if len(coordinates) == 1:
        c = coordinates[0]
        return f"revolute {c[1]}" if c.startswith("r") else f"prismatic {c}"
    if len(coordinates) == 2 and coordinates[1] == "r" + coordinates[0]:
        return f"cylindrical {coordinates[0]}"
    if len(coordinates) == 2 and all(c.startswith("r") for c in coordinates):
        return f"universal ({', '.join(coordinates)})"
    return f"custom ({', '.join(coordinates)})"


def _by_body(names) -> dict[str, list[str]]:
    """Coordinate names 'body.axis' grouped by body: {body: [axis, ...]}."""
    out: dict[str, list[str]] = {}
    for name in names:
        body, axis = name.rsplit(".", 1)
        out.setdefault(body, []).append(axis)
    return out


def _table(header, rows, more: str = "rows") -> str:
    """An HTML table of the first MAX_ROWS ``rows`` (already escaped cells) and a "… n more" row."""
    head = "".join(f"<th>{h}</th>" for h in header)
    body = "".join("<tr>" + "".join(f"<td>{c}</td>" for c in row) + "</tr>" for row in rows[:MAX_ROWS])
    if len(rows) > MAX_ROWS:
        body += f'<tr><td colspan="{len(header)}">… {len(rows) - MAX_ROWS} more {more}</td></tr>'
    return f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


def _facts(title: str, facts: dict) -> str:
    """A title line and a list 'key: value' (values escaped here)."""
    items = "".join(f"<li>{_e(k)}: {_e(v)}</li>" for k, v in facts.items())
    return f"<strong>{_e(title)}</strong><ul>{items}</ul>"


def _beams(body_names) -> list[tuple[str, int]]:
    """The beams of a model, (name, number of rfes), recognised by their rfes' names <beam>.rfe<k>."""
    beams: dict[str, int] = {}
    for name in body_names:
        m = _RFE.match(name)
        if m:
            beams[m.group(1)] = beams.get(m.group(1), 0) + 1
    return list(beams.items())


def system_html(system, title: str = "rigidfem System") -> str:
    """Bodies (parent, joint kind, free and prescribed coordinates), counts of coordinates, beams,
    loops and force elements of a compiled System."""
    system = _checks.system(system)
    names, parents = system.body_names, system.parent
    free, driven = _by_body(system.coordinate_names), _by_body(system.prescribed_names)
    rows = []
    for name, parent in zip(names, parents):
        coords = tuple(c for c in _ORDER if c in free.get(name, []) + driven.get(name, []))
        rows.append([_e(name), _e("ground" if parent < 0 else names[parent]), _e(_joint_kind(coords)),
                     _e(", ".join(free.get(name, []))), _e(", ".join(driven.get(name, [])))])
    beams = _beams(names)
    facts = {"bodies": system.nbodies, "free coordinates (nq)": system.nq, "prescribed coordinates": system.np,
             "beams": ", ".join(f"{b} ({n} rfes)" for b, n in beams) if beams else "none",
             "loops": f"{len(system.loop_names)} ({system.nl} constraint rows)",
             "force elements": len(system.element_names), "algorithm": system.algorithm}
    return (_facts(title, facts) +
            _table(["body", "parent", "joint", "coordinates", "prescribed"], rows, "bodies") +
            _coordinate_list(system.coordinate_names))


def _coordinate_list(names) -> str:
    """The coordinate names in the order of q (the first MAX_ROWS·5 of a long list)."""
    shown = names[:5 * MAX_ROWS]
    rest = f" … {len(names) - len(shown)} more" if len(names) > len(shown) else ""
    return f"<p>q = ({_e(', '.join(shown))}{rest})</p>"


def model_html(model) -> str:
    """The Model as the System it compiles to; a Model that does not compile (yet) lists its bodies
    and the reason."""
    try:
        return system_html(model.compile(), title="rigidfem Model")
    except Exception as err:  # noqa: BLE001 (a display never raises: it says why it cannot compile)
        rows = [[_e(n)] for n in model.body_names]
        return (_facts("rigidfem Model", {"bodies": model.nbodies, "does not compile": err}) +
                _table(["body"], rows, "bodies"))


def _stat(stats: dict, key: str):
    """A counter of ``Result.stats``; '—' where the method does not count it (-1)."""
    v = stats.get(key, -1)
    return "—" if v is None or (np.isscalar(v) and v < 0) else v


def result_html(result) -> str:
    """Method, outputs, steps, rejected steps, rhs evaluations, Newton iterations, wall time."""
    result = _checks.result(result)
    s, t = result.stats, result.t
    chosen = result.stats.get("method", result.method)
    facts = {"method": result.method + (f" ({chosen})" if chosen != result.method else ""), "outputs": len(t),
             "t": f"{t[0]:g} … {t[-1]:g} s" if len(t) else "—", "nq": result.q.shape[1],
             "steps": _stat(s, "steps"), "rejected steps": _stat(s, "rejected_steps"),
             "rhs evaluations": _stat(s, "rhs_evaluations"), "Newton iterations": _stat(s, "newton_iterations"),
             "wall time": f"{s.get('wall_time', float('nan')):.3g} s", "interrupted": result.interrupted}
    estimate = getattr(result, "estimate", None)
    if estimate is not None:
        facts["estimated error"] = "; ".join(f"{n}: {m:.2g} {u}" for n, u, m in estimate.table())
    return _facts("rigidfem Result", facts)


def modes_html(modes) -> str:
    """The frequency table: mode k (from 1), ω (rad/s), f (Hz), ζ, each to 6 significant digits."""
    rows = [[str(k + 1), f"{w:.6g}", f"{f:.6g}", f"{z:.6g}"]
            for k, (w, f, z) in enumerate(zip(modes.omega, modes.frequencies_hz, modes.damping_ratios))]
    title = _facts("rigidfem Modes", {"modes": len(rows), "stable": modes.stable})
    return title + _table(["mode", "ω (rad/s)", "f (Hz)", "ζ"], rows, "modes")
