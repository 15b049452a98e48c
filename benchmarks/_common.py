"""What the benchmarks share: the C++ timing call and the report (CSV files, markdown)."""

from __future__ import annotations

import ctypes
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


def report(tables: dict, output_dir) -> dict:
    """Write each ``rigidfem.study.Table`` of ``tables`` (name -> (title, table)) as
    ``<output_dir>/<name>.csv`` and print its title and markdown. Returns name -> Table."""
    out = Path(output_dir)
    for name, (title, table) in tables.items():
        path = table.to_csv(out / f"{name}.csv")
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
