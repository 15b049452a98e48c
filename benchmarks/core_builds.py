"""The two builds of the C++ core side by side on this machine::

    python -m benchmarks core_builds [--quick] [--output DIR]

rigidfem/_load_core.py loads the build made for x86-64-v3 (AVX2) where the processor has it, the portable build
elsewhere. Each build runs in a process of its own (``RIGIDFEM_CORE=baseline`` or ``x86-64-v3``), the two
alternated for three rounds (one with ``--quick``), and the least time of each is kept:

- the C++ time of one forward dynamics (``_bench.forward_dynamics_seconds``, best of 3 in a process) on the
  models of the evaluations page (the slider-crank, the Bricard linkage, the strip at m = 16, 32, 64, the crane)
  and on the peers page's 3-rotation cantilever at m = 10 and 100, at their states;
- the CPU time of the README's quick start's run: the steel strip of 20 rfes, 2 s from rest by
  ``method="auto"`` (radau5), best of 2 in a process.

Needs an x86-64-v3 processor, an install with both builds (x86-64 Linux) and MuJoCo (``pip install mujoco``),
which builds the evaluations page's models.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from rigidfem import _load_core
from rigidfem.studies.study import Table

from ._common import report

COLUMNS = ("model", "nq", "what", "baseline_us", "x86_64_v3_us", "v3/baseline")

# One process's measurements, as JSON: {name: [nq, what, µs]}.
CHILD = r"""
import json, sys, time
import mujoco
import numpy as np
import rigidfem as rf
from benchmarks import evaluations, peers
from benchmarks._common import cpp_seconds_per_call
quick = sys.argv[1] == "1"
out = {"build": rf._core.build}
def forward(name, system, q, qd):
    out[name] = [system.nq, "forward dynamics (C++)", 1e6 * min(cpp_seconds_per_call(system, q, qd) for _ in range(3))]
for make in evaluations.cases(mujoco, quick):
    case = make()
    forward(case.name, case.system, case.q, case.qd)
for m in (10,) if quick else (10, 100):
    model, _ = peers.cantilever(m)
    system = model.compile()
    forward(f"3-rotation cantilever m={m}", system, *peers._random_state(system))
E, rho, b, h = 2.1e11, 7850.0, 0.02, 0.005
model = rf.Model(gravity=(0.0, -9.81, 0.0))
model.add_beam("strip", model.ground, 1.0, rf.Material(E=E, rho=rho), rf.Section.rectangle(h, b), 20, deform="bend_z")
system = model.compile()
times = []
for _ in range(2):
    start = time.process_time()
    result = rf.simulate(system, 2.0)
    times.append(time.process_time() - start)
out["README's strip, 2 s"] = [system.nq, f"run (CPU): {result.stats['method'].split()[0]}", 1e6 * min(times)]
print(json.dumps(out))
"""


def measure(build: str, quick: bool) -> dict:
    """One process of the build: {name: [nq, what, µs]}."""
    root = Path(__file__).resolve().parents[1]
    run = subprocess.run([sys.executable, "-c", CHILD, "1" if quick else "0"], capture_output=True, text=True,
                         cwd=root, env={**os.environ, "RIGIDFEM_CORE": build}, check=True)
    out = json.loads(run.stdout.splitlines()[-1])
    assert out.pop("build") == build
    return out


def run(output_dir="bench", quick: bool = False) -> dict:
    """``python -m benchmarks core_builds``: the table of the module's docstring, as core_builds.csv."""
    if not _load_core.X86_64_V3_FLAGS <= _load_core.cpu_flags():
        raise ImportError("this processor lacks x86-64-v3's features: there is no second build to compare")
    best: dict = {}
    for round_ in range(1 if quick else 3):
        for build in _load_core.CHOICES:
            for name, (nq, what, us) in measure(build, quick).items():
                entry = best.setdefault(name, {"nq": nq, "what": what})
                entry[build] = min(entry.get(build, float("inf")), us)
            print(f"round {round_ + 1}: {build} measured", flush=True)
    rows = [{"model": name, "nq": e["nq"], "what": e["what"], "baseline_us": e["baseline"],
             "x86_64_v3_us": e["x86-64-v3"], "v3/baseline": e["x86-64-v3"] / e["baseline"]} for name, e in best.items()]
    tables = report({"core_builds": ("The two builds of the C++ core: least time (µs) of the portable build and of "
                                     "the x86-64-v3 build, each in its own process, alternated",
                                     Table(rows, COLUMNS))}, output_dir)
    return tables
