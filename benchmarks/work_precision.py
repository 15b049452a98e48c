"""``python -m rigidfem bench`` as the site's pages: the standard scenes (a modified and a classical cantilever's free
vibration, a stiff 3D cantilever, Kane's beam at Ω = 6 rad/s, a whippy strip) under the standard integrators, and
the discretisation error against m. ``rigidfem.studies.study.bench`` runs the scenes (its own CSV files and plot go
to a temporary folder); this module writes the tables the simulation guide reads as pages:
the least wall time to each tip error per method, ``method='auto'`` against the best method, the discretisation
error."""

import csv
import tempfile
from pathlib import Path

from rigidfem.studies import study

from ._common import report


def _read(path: Path) -> study.Table:
    """A table that ``bench`` wrote as CSV, its numbers as floats (an empty cell left out of its row)."""
    with open(path, newline="") as f:
        reader = csv.DictReader(f)
        rows = [{k: float(v) for k, v in r.items() if v != ""} for r in reader]
        return study.Table(rows, tuple(reader.fieldnames))


def run(output_dir="bench", quick: bool = False) -> dict:
    folder = Path(tempfile.mkdtemp(prefix="rigidfem_bench_"))
    table = study.bench(folder, quick=quick)
    disc = _read(folder / "discretisation.csv")  # bench's own, not computed again
    return report({
        "work_precision_summary": ("The bench's scenes, least wall time: the least wall time (s, least of 3 warm runs) "
                                   "to a tip RMS error (m) against the rtol = 1e-10 reference, and the smallest error "
                                   "reached (-: not reached in the sweep)", table.summary()),
        "work_precision_auto": ("The bench's scenes, auto against the best: method='auto' against the best method for "
                                "each error (least wall time, s)", table.auto_against_best()),
        "discretisation": ("The bench's discretisation error: the cantilever's first frequencies against "
                           "Euler–Bernoulli and the elastica's tip against m, modified formulation, with the observed "
                           "order", disc),
    }, output_dir)
