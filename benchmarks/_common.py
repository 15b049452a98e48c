"""What the benchmarks share: the C++ timing call and the report (CSV files, markdown)."""

from __future__ import annotations

import ctypes
import datetime
import os
import platform
import shutil
import subprocess
import tempfile
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


#: When and under what load the run started (set by ``python -m benchmarks``: :func:`start`)
_STARTED: dict = {}


def start(command: str) -> None:
    """Note the run's command, date and load average at its start, for the pages :func:`report` writes."""
    _STARTED.update(command=command, date=datetime.datetime.now(datetime.timezone.utc), load=_load())


def _load() -> str:
    return ", ".join(f"{x:.2f}" for x in os.getloadavg()) if hasattr(os, "getloadavg") else "unknown"


def _cpu() -> str:
    """The processor's model name (from /proc/cpuinfo on Linux), else platform's answer."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def provenance() -> str:
    """One paragraph: the command, the date, the machine, the versions and the load at the start and at the end."""
    import numpy as np

    import rigidfem as rf

    started = _STARTED.get("date")
    when = f"{started:%Y-%m-%d %H:%M} UTC" if started else "an unrecorded date"
    return (f"Written by `{_STARTED.get('command', 'python -m benchmarks')}` on {when}: {_cpu()}, "
            f"{os.cpu_count()} cores, {platform.system()}; Python {platform.python_version()}, rigidfem "
            f"{rf.__version__} (core build {rf._core.build}), numpy {np.__version__}; load average (1, 5, 15 min) {_STARTED.get('load', 'unknown')} "
            f"at the start, {_load()} at the end.")


def report(tables: dict, output_dir) -> dict:
    """Write each ``rigidfem.study.Table`` of ``tables`` (name -> (title, table)) as ``<output_dir>/<name>.csv``
    and as a page ``<output_dir>/<name>.md`` (its title, :func:`provenance` and the table in markdown), and print
    its title and markdown. Run with ``--output docs/benchmarks``, the pages become pages of the site. Returns
    name -> Table."""
    out = Path(output_dir)
    for name, (title, table) in tables.items():
        path = table.to_csv(out / f"{name}.csv")
        heading, _, rest = title.partition(": ")
        parts = [f"# {heading}", f"{rest}." if rest else "",
                 f"The table as CSV: [{name}.csv]({name}.csv).", provenance(), table.to_markdown()]
        (out / f"{name}.md").write_text("\n\n".join(p for p in parts if p) + "\n", encoding="utf-8")
        print(f"\n{title} ({path}):\n")
        print(table.to_markdown(), flush=True)
    return {name: table for name, (_, table) in tables.items()}


def compile_mujoco_callback(mujoco, source: str, prefix: str):
    """A MuJoCo callback's C ``source`` compiled against MuJoCo's headers (cc -O2 -shared) and loaded by
    ctypes, or None without a C compiler or the headers (the caller then falls back to Python)."""
    compiler = shutil.which(os.environ.get("CC", "cc")) or shutil.which("gcc")
    include = Path(mujoco.__file__).parent / "include"
    if compiler is None or not (include / "mujoco" / "mujoco.h").exists():
        return None
    folder = Path(tempfile.mkdtemp(prefix=prefix))
    (folder / "drive.c").write_text(source)
    try:
        subprocess.run([compiler, "-O2", "-shared", "-fPIC", f"-I{include}", str(folder / "drive.c"), "-o",
                        str(folder / "drive.so"), "-lm"], check=True, capture_output=True)
        return ctypes.CDLL(str(folder / "drive.so"))
    except (OSError, subprocess.CalledProcessError):
        return None
