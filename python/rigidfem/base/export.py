"""Export of results: tables (pandas DataFrame, CSV), NumPy archives, the modes' frequency table.

Column names of a Result's table (``Result.to_dataframe``, ``Result.to_csv``):

- ``t``: time, s (the DataFrame's index; the first CSV column);
- one column per coordinate, named as in ``System.coordinate_names`` (``"link.rz"``): q, m or rad;
- ``<name>.dot`` per coordinate: q̇, m/s or rad/s;
- for ``points={"tip": beam.tip}``: ``tip.x``, ``tip.y``, ``tip.z``, the global position in m;
- once ``Result.error_estimate`` has been computed: ``<output>.error`` per output it estimates
  (``bodies.error`` by default), the estimated time-integration error in the output's unit.

The modes' table (``Modes.table``, ``Modes.to_dataframe``) has the columns ``mode`` (1, 2, ...),
``omega (rad/s)``, ``f (Hz)`` and ``zeta`` (the modal damping ratio, dimensionless).

Examples
--------
>>> import rigidfem as rf
>>> model, h = rf.samples.pendulum()
>>> system = model.compile()
>>> res = rf.simulate(system, 0.5, q0=[0.5], t_eval=[0.0, 0.5])
>>> names, table = rf.export.result_columns(res, points={"tip": h["tip"]})
>>> names, table.shape
(['link.ry', 'link.ry.dot', 'tip.x', 'tip.y', 'tip.z'], (2, 5))
"""

from __future__ import annotations

import json
from collections.abc import Mapping

import numpy as np

from . import _checks

#: Suffix of the velocity columns: "<coordinate name>.dot" holds q̇ (m/s or rad/s).
RATE = ".dot"
#: Suffix of the error columns: "<output>.error" holds Result.error_estimate's history, once computed.
ERROR = ".error"
MODE_COLUMNS = ("mode", "omega (rad/s)", "f (Hz)", "zeta")


def _pandas(what: str):
    try:
        import pandas
    except ImportError:
        raise ImportError(f"{what} needs pandas: pip install pandas (or use to_csv / table(), which do not)") from None
    return pandas


def result_columns(result, points=None) -> tuple[list[str], np.ndarray]:
    """(names, values (len(t), ncolumns)) of a Result's table without the time column: q, q̇ and
    the positions (m) of ``points`` (a dict name -> Point or Body)."""
    result = _checks.result(result)
    if points is None:
        points = {}
    if not isinstance(points, Mapping) or not all(isinstance(k, str) for k in points):
        raise _checks.refuse(f"points: expected None or a dict of column names (str) to Points or Bodies, e.g. "
                         f"{{'tip': beam.tip}}, got {points!r}")
    names = list(_names(result))
    columns = names + [n + RATE for n in names]
    blocks = [result.q, result.qd]
    for key, point in points.items():
        columns += [f"{key}.{axis}" for axis in "xyz"]
        blocks.append(result.position(point))  # checks the point (ValueError naming it)
    estimate = getattr(result, "estimate", None)
    if estimate is not None:  # the error bar, once computed: "<output>.error" in its unit
        columns += [f"{name}{ERROR}" for name in estimate.names]
        blocks.append(estimate.history)
    return columns, np.hstack(blocks).reshape(len(result.t), len(columns))


def to_dataframe(result, points=None):
    """pandas DataFrame indexed by t (s); columns as in this module's docstring."""
    pandas = _pandas("Result.to_dataframe")
    columns, values = result_columns(result, points)
    return pandas.DataFrame(values, index=pandas.Index(result.t, name="t"), columns=columns)


def to_csv(result, path, points=None):
    """CSV with a header line "t,<columns>" and one row per output time, 17 significant digits
    (floats read back exactly); no pandas needed. Returns the path."""
    columns, values = result_columns(result, points)
    for name in columns:
        if "," in name or '"' in name:
            raise _checks.refuse(f"points: expected column names without ',' or '\"' for CSV, got {name!r}")
    np.savetxt(path, np.column_stack([result.t, values]), delimiter=",", fmt="%.17g",
               header=",".join(["t", *columns]), comments="")
    return path


def _names(result) -> list:
    """The names of a result's coordinates: its own (a loaded result's saved ones) or its system's."""
    names = getattr(result, "coordinate_names", None)
    return _checks.result(result, needs="its coordinates' names").system.coordinate_names if names is None else names


def to_npz(result, path):
    """NumPy archive with t (s), q, qd (m, rad; per s), arm_forces (N or N·m), the method's own loop
    multipliers (if any), the forward sensitivities (if any: their names and a (P, len t, 2 nq) array),
    coordinate_names, method and stats (JSON)."""
    result = _checks.result(result)
    own = {} if result.multipliers is None else {"multipliers": result.multipliers}
    if result.sensitivities:
        own["sensitivity_names"] = np.array(list(result.sensitivities), dtype=str)
        own["sensitivities"] = np.stack(list(result.sensitivities.values()))
    np.savez(path, t=result.t, q=result.q, qd=result.qd, arm_forces=result.arm_forces, coordinate_names=np.array(_names(result),
             dtype=str), method=np.array(result.method), stats=np.array(json.dumps(result.stats)),
             interrupted=np.array(result.interrupted), **own)
    return path


def read_npz(file) -> dict:
    """The fields of the Result saved by ``to_npz`` in ``file`` (a path or an open binary file), unchecked:
    ``rigidfem.base.persistence.read_result`` checks the file and the system for ``rigidfem.load_npz``."""
    with np.load(file, allow_pickle=False) as f:
        names = [str(n) for n in f["coordinate_names"]]
        return {"t": f["t"], "q": f["q"], "qd": f["qd"], "coordinate_names": names, "stats": json.loads(str(f["stats"])),
                "method": str(f["method"]), "interrupted": bool(f["interrupted"]),
                "arm_forces": f["arm_forces"] if "arm_forces" in f.files else None,
                "multipliers": f["multipliers"] if "multipliers" in f.files else None,
                "sensitivities": dict(zip((str(n) for n in f["sensitivity_names"]), f["sensitivities"]))
                if "sensitivities" in f.files else {}}


def modes_table(modes) -> list[dict]:
    """One dict per mode with the keys ``MODE_COLUMNS``: k (from 1), ω (rad/s), f (Hz), ζ."""
    return [dict(zip(MODE_COLUMNS, (k + 1, float(w), float(f), float(z))))
            for k, (w, f, z) in enumerate(zip(modes.omega, modes.frequencies_hz, modes.damping_ratios))]


def modes_dataframe(modes):
    """``modes_table`` as a pandas DataFrame indexed by mode."""
    pandas = _pandas("Modes.to_dataframe")
    return pandas.DataFrame(modes_table(modes), columns=list(MODE_COLUMNS)).set_index("mode")
