"""What the benchmarks share: the C++ timing call and the report (CSV files, markdown)."""

from __future__ import annotations

import os
import platform
from pathlib import Path

from rigidfem._core._bench import forward_dynamics_seconds


def cpp_seconds_per_call(system, q, qd, calls: int | None = None) -> float:
    """Seconds per ``system.forward_dynamics(0, q, qd)`` call timed in C++ (one workspace, no
    Python call), averaged over ``calls`` calls (default max(3, 2e5/nq): about as much work
    whatever the size)."""
    calls = max(3, int(2e5 / system.nq)) if calls is None else calls
    return forward_dynamics_seconds(system, 0.0, q, qd, calls)


def machine() -> str:
    """One line naming the machine and Python."""
    return (f"machine: {platform.machine()} {platform.processor() or ''}, {platform.python_implementation()} "
            f"{platform.python_version()}, {os.cpu_count()} cores")


def report(tables: dict, output_dir) -> dict:
    """Write each ``rigidfem.study.Table`` of ``tables`` (name -> (title, table)) as
    ``<output_dir>/<name>.csv`` and print its title and markdown. Returns name -> Table."""
    out = Path(output_dir)
    for name, (title, table) in tables.items():
        path = table.to_csv(out / f"{name}.csv")
        print(f"\n{title} ({path}):\n")
        print(table.to_markdown(), flush=True)
    return {name: table for name, (_, table) in tables.items()}
