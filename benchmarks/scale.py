"""The hidden costs at scale: a call from Python against the same work timed in C++, a result's
point positions, a beam's centre line, and building and compiling a long beam::

    python -m benchmarks scale [--quick] [--output DIR]

Times in s, the least of several repeats.
"""

from __future__ import annotations

import time

import numpy as np

import rigidfem as rf
from rigidfem import samples
from rigidfem.studies.study import Table

from ._common import cpp_seconds_per_call, machine, report

DEFORM = ("bend_z", "bend_y", "torsion")


def _least(function, repeats: int = 5, calls: int = 1) -> float:
    """Least wall time (s) per call of ``function()`` over ``repeats`` batches of ``calls`` calls."""
    best = np.inf
    for _ in range(repeats):
        start = time.perf_counter()
        for _ in range(calls):
            function()
        best = min(best, (time.perf_counter() - start) / calls)
    return best


def call_cost(elements=(10, 100, 300, 800, 1000)) -> Table:
    """``system.forward_dynamics`` from Python (a per-thread workspace reused) against the C++
    time of the same call, and what a fresh workspace (``make_data``) would cost."""
    rows = []
    for m in elements:
        system = samples.cantilever(elements=m, deform=DEFORM)[0].compile()
        rng = np.random.default_rng(0)
        q, qd = rng.uniform(-1e-3, 1e-3, system.nq), rng.uniform(-1e-2, 1e-2, system.nq)
        calls = max(3, int(2e5 / system.nq))
        python = _least(lambda: system.forward_dynamics(0.0, q, qd), calls=calls)
        cpp = min(cpp_seconds_per_call(system, q, qd, calls) for _ in range(5))
        rows.append({"m": m, "nq": system.nq, "python_call_s": python, "cpp_s": cpp, "python_over_cpp": python / cpp,
                     "make_data_s": _least(system.make_data, calls=max(3, calls // 10))})
    return Table(rows, ("m", "nq", "python_call_s", "cpp_s", "python_over_cpp", "make_data_s"))


def output_cost(elements=(10, 100, 1000), samples_per_run: int = 200) -> Table:
    """Per output sample: ``Result.position`` of the tip and ``Beam.centerline`` (all m + 2
    points at one state), against one forward-dynamics call timed in C++."""
    rows = []
    for m in elements:
        model, h = samples.cantilever(elements=m, deform=DEFORM)
        system = model.compile()
        q = np.random.default_rng(0).uniform(-1e-3, 1e-3, system.nq)
        Q = np.tile(q, (samples_per_run, 1))
        result = rf.Result(system, np.zeros(samples_per_run), Q, np.zeros_like(Q), {}, "none")
        tip = h["beam"].tip
        rows.append({"m": m, "nq": system.nq,
                     "position_s_per_sample": _least(lambda: result.position(tip), repeats=3) / samples_per_run,
                     "centerline_s": _least(lambda: h["beam"].centerline(system, q, t=0.0), repeats=3),
                     "forward_dynamics_cpp_s": cpp_seconds_per_call(system, q, q)})
    return Table(rows, ("m", "nq", "position_s_per_sample", "centerline_s", "forward_dynamics_cpp_s"))


def build_cost(elements=(1_000, 10_000, 100_000)) -> Table:
    """Building a planar beam of m elements (``add_beam``) and compiling it."""
    rows = []
    for m in elements:
        model = rf.Model(gravity=None)
        start = time.perf_counter()
        model.add_beam("beam", model.ground, 1.0, rf.Material(E=2.1e11, rho=7850.0), rf.Section.rectangle(0.02, 0.005),
                       m, deform=("bend_z",))
        built = time.perf_counter()
        system = model.compile()
        compiled = time.perf_counter()
        rows.append({"m": m, "nq": system.nq, "add_beam_s": built - start, "compile_s": compiled - built,
                     "total_s": compiled - start})
    return Table(rows, ("m", "nq", "add_beam_s", "compile_s", "total_s"))


def run(output_dir="bench", quick: bool = False) -> dict:
    """``python -m benchmarks scale``: the three tables, written to ``output_dir`` and printed."""
    print(machine(), flush=True)
    return report({
        "call_cost": ("forward_dynamics from Python against C++ (s per call)",
                      call_cost((10, 100) if quick else (10, 100, 300, 800, 1000))),
        "output_cost": ("Result.position per sample and Beam.centerline (s)",
                        output_cost((10, 100) if quick else (10, 100, 1000))),
        "build_cost": ("add_beam and compile (s)", build_cost((1_000,) if quick else (1_000, 10_000, 100_000))),
    }, output_dir)
