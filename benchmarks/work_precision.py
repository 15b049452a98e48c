"""``python -m rigidfem bench`` as the site's pages: the standard scenes (a modified and a classical cantilever's free
vibration, a stiff 3D cantilever, Kane's beam at Ω = 6 rad/s, a whippy strip) under the standard integrators, and
the discretisation error against m. ``rigidfem.studies.study.bench`` runs the scenes (its own CSV files and plot go
to a temporary folder); this module writes the tables the simulation guide reads as pages:
the least wall time to each tip error per method, ``method='auto'`` against the best method, the discretisation
error."""

import tempfile

from rigidfem.studies import study

from ._common import report


def run(output_dir="bench", quick: bool = False) -> dict:
    table = study.bench(tempfile.mkdtemp(prefix="rigidfem_bench_"), quick=quick)
    disc = study.discretisation_error(elements=(5, 10, 20) if quick else (5, 10, 20, 40, 80))
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
