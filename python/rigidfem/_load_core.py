"""Loads the build of the C++ core made for this processor, before anything imports ``rigidfem._core``.

On x86-64 Linux two builds of the same core ship: ``_core`` for any x86-64 processor and ``_core_v3`` compiled
for x86-64-v3 (AVX, AVX2, FMA, BMI1, BMI2, F16C, LZCNT, MOVBE: Intel since Haswell, 2013, AMD since
Excavator, 2015), whose forward dynamics run 3-21 % faster (python -m benchmarks core_builds). The second is
loaded where /proc/cpuinfo lists those features; elsewhere, and on other systems, the first. Both name themselves
``rigidfem._core``, and ``rigidfem._core.build`` says which one runs ("x86-64-v3" or "baseline").

The environment variable ``RIGIDFEM_CORE`` overrides the choice: "baseline" loads the portable build,
"x86-64-v3" the other. ``import rigidfem`` raises an ImportError naming the variable for any other value, and
for "x86-64-v3" where the processor lacks a feature it needs or the build is not installed.
"""

import importlib
import importlib.util
import os
import sys

#: /proc/cpuinfo's names of the features that x86-64-v3 adds to x86-64 (abm: LZCNT; xsave: the OS saves AVX state).
X86_64_V3_FLAGS = frozenset({"avx", "avx2", "bmi1", "bmi2", "f16c", "fma", "abm", "movbe", "xsave"})
CHOICES = ("baseline", "x86-64-v3")


def cpu_flags(path: str = "/proc/cpuinfo") -> frozenset:
    """The first processor's feature flags in /proc/cpuinfo, empty where there is no such file."""
    try:
        with open(path, encoding="ascii", errors="replace") as f:
            for line in f:
                if line.startswith("flags"):
                    return frozenset(line.partition(":")[2].split())
    except OSError:
        pass
    return frozenset()


def choose(requested: str, flags: frozenset, v3_installed: bool) -> str:
    """The build to load ("baseline" or "x86-64-v3") for RIGIDFEM_CORE = `requested` ("" for none)."""
    if requested not in ("", *CHOICES):
        raise ImportError(f"RIGIDFEM_CORE: expected one of {', '.join(map(repr, CHOICES))} or unset, got {requested!r}")
    missing = sorted(X86_64_V3_FLAGS - flags)
    if requested == "x86-64-v3":
        if missing:
            raise ImportError(f"RIGIDFEM_CORE='x86-64-v3', but this processor lacks {', '.join(missing)}")
        if not v3_installed:
            raise ImportError("RIGIDFEM_CORE='x86-64-v3', but this installation has no x86-64-v3 build of the core "
                              "(it is built on x86-64 Linux only)")
        return "x86-64-v3"
    return "x86-64-v3" if requested == "" and not missing and v3_installed else "baseline"


def load(package: str):
    """Imports the chosen build and registers it as ``<package>._core``; returns the module."""
    v3_installed = importlib.util.find_spec(f"{package}._core_v3") is not None
    build = choose(os.environ.get("RIGIDFEM_CORE", ""), cpu_flags(), v3_installed)
    module = importlib.import_module(f"{package}._core_v3" if build == "x86-64-v3" else f"{package}._core")
    sys.modules[f"{package}._core"] = module
    sys.modules[package]._core = module
    return module
