"""The portable Linux wheel, installed in a fresh virtual environment with no compiler on the PATH: the demo runs
and the fast subset of the tests (tests/fast_subset.txt, as cibuildwheel runs it on every wheel) passes.

Which wheel: the file that RIGIDFEM_WHEEL names, otherwise the newest ``dist/rigidfem-*-cpXY-cpXY-manylinux*``
wheel for this Python and machine (``python scripts/build_wheel.py`` puts it there). Without either the test is
a slow one (``pytest -m slow tests/test_wheel.py``) and builds the wheel itself, which takes minutes.
Dependencies (NumPy, SciPy, Matplotlib; pytest and Hypothesis for the subset) come from the package index or
pip's cache, as binary wheels only, by a current pip (``venv --upgrade-deps``). The times of the install and of
the demo are printed (``-s`` shows them).
"""

import os
import platform
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest

from rigidfem import _load_core

ROOT = Path(__file__).resolve().parents[1]
TAG = f"cp{sys.version_info.major}{sys.version_info.minor}"
COMPILERS = ("cc", "c++", "gcc", "g++", "clang", "clang++", "zig")


def built_wheel():
    """The wheel to test: RIGIDFEM_WHEEL, or the newest of dist/ for this Python and machine, or None."""
    if os.environ.get("RIGIDFEM_WHEEL"):
        return Path(os.environ["RIGIDFEM_WHEEL"]).resolve()
    found = sorted((ROOT / "dist").glob(f"rigidfem-*-{TAG}-{TAG}-manylinux*_{platform.machine()}.whl"),
                   key=lambda p: p.stat().st_mtime)
    return found[-1] if found else None


WHEEL = built_wheel()
pytestmark = [pytest.mark.skipif(sys.platform != "linux", reason="a manylinux wheel (Linux only)")]
if WHEEL is None:
    pytestmark.append(pytest.mark.slow)  # no wheel yet: the test builds one (minutes)


def run(cmd, env, cwd, timeout=900):
    out = subprocess.run([str(c) for c in cmd], check=False, env=env, cwd=cwd, capture_output=True, text=True,
                         timeout=timeout)
    assert out.returncode == 0, f"{' '.join(map(str, cmd))} failed ({out.returncode}):\n{out.stdout}\n{out.stderr}"
    return out.stdout


@pytest.fixture(scope="module")
def wheel(tmp_path_factory):
    if WHEEL is not None:
        assert WHEEL.is_file(), f"RIGIDFEM_WHEEL: no file {WHEEL}"
        return WHEEL
    out = tmp_path_factory.mktemp("dist")
    subprocess.run([sys.executable, ROOT / "scripts" / "build_wheel.py", "--out", out], check=True, timeout=3600)
    (built,) = out.glob("rigidfem-*.whl")
    return built


@pytest.fixture(scope="module")
def installed(wheel, tmp_path_factory):
    """A fresh virtual environment with the wheel installed, and an environment for running it whose PATH is the
    venv's bin alone (no compiler) and whose CC and CXX are /bin/false: (venv python, env, run folder, times)."""
    home = tmp_path_factory.mktemp("wheel")
    venv, cwd = home / "venv", home / "run"
    cwd.mkdir()
    env = {k: v for k, v in os.environ.items() if k not in ("VIRTUAL_ENV", "PYTHONPATH", "PYTHONHOME")}
    env.update(PATH=str(venv / "bin"), CC="/bin/false", CXX="/bin/false", MPLBACKEND="Agg",
               PIP_DISABLE_PIP_VERSION_CHECK="1")
    python = venv / "bin" / "python"
    start = time.perf_counter()
    subprocess.run([sys.executable, "-m", "venv", "--upgrade-deps", venv], check=True)  # a current pip
    made = time.perf_counter()
    run([python, "-m", "pip", "install", "-q", "--only-binary=:all:", wheel], env, cwd)
    times = {"venv": made - start, "pip install": time.perf_counter() - made}
    return python, env, cwd, times


def test_no_compiler_and_the_module_comes_from_the_wheel(installed):
    python, env, cwd, _ = installed
    code = (f"import shutil, rigidfem._core as c; print([n for n in {COMPILERS!r} if shutil.which(n)]); "
            "print(c.__file__); print(c.build)")
    where = run([python, "-c", code], env, cwd).split("\n")
    assert where[0] == "[]", f"compilers on the test's PATH: {where[0]}"
    assert Path(where[1]).is_relative_to(python.parent.parent), where[1]
    # an x86-64 wheel holds both builds of the core, and loads the x86-64-v3 one where the processor has it
    v3_here = platform.machine() == "x86_64" and _load_core.X86_64_V3_FLAGS <= _load_core.cpu_flags()
    assert where[2] == ("x86-64-v3" if v3_here else "baseline"), where[2]


def test_demo(installed):
    python, env, cwd, times = installed
    start = time.perf_counter()
    out = run([python, "-m", "rigidfem", "demo"], env, cwd)
    times["demo"] = time.perf_counter() - start
    assert "nonlinear model" in out and (cwd / "rigidfem_demo.png").stat().st_size > 0
    print(f"\n{WHEEL.name if WHEEL else '(built)'}: " + ", ".join(f"{k} {v:.1f} s" for k, v in times.items())
          + f"; pip install + demo {times['pip install'] + times['demo']:.1f} s")


def test_fast_subset(installed):
    """The fast subset from a copy of tests/ and pyproject.toml in the run folder, as cibuildwheel's test-sources
    lays them out: `import rigidfem` can only find the wheel's package."""
    python, env, cwd, _ = installed
    run([python, "-m", "pip", "install", "-q", "--only-binary=:all:", "pytest>=8.2", "pytest-xdist>=3", "hypothesis>=6"], env, cwd)
    shutil.copytree(ROOT / "tests", cwd / "tests", ignore=shutil.ignore_patterns("__pycache__", "fuzz_corpus"))
    shutil.copy(ROOT / "pyproject.toml", cwd)
    start = time.perf_counter()
    out = run([python, "-m", "pytest", "-q", "-p", "no:cacheprovider", "@tests/fast_subset.txt"], env, cwd)
    print(f"\nfast subset: {out.strip().splitlines()[-1]} ({time.perf_counter() - start:.1f} s)")
