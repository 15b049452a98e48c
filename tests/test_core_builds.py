"""The two builds of the C++ core (rigidfem/_load_core.py): the choice by processor and RIGIDFEM_CORE, and the same
answers, names and pickles from both."""

import importlib.util
import os
import pickle
import subprocess
import sys

import numpy as np
import pytest

import rigidfem as rf
from rigidfem import _load_core

ALL = _load_core.X86_64_V3_FLAGS | {"sse2", "ssse3"}
V3_HERE = (_load_core.X86_64_V3_FLAGS <= _load_core.cpu_flags()
           and importlib.util.find_spec("rigidfem._core_v3") is not None)


def test_the_processor_chooses_unless_the_environment_does():
    assert _load_core.choose("", ALL, True) == "x86-64-v3"
    assert _load_core.choose("", ALL, False) == "baseline"  # not built (not x86-64 Linux)
    assert _load_core.choose("", ALL - {"fma"}, True) == "baseline"
    assert _load_core.choose("", frozenset(), True) == "baseline"  # no /proc/cpuinfo
    assert _load_core.choose("baseline", ALL, True) == "baseline"
    assert _load_core.choose("x86-64-v3", ALL, True) == "x86-64-v3"


def test_a_build_this_processor_cannot_run_is_refused_by_name():
    with pytest.raises(ImportError, match="lacks avx2, movbe"):
        _load_core.choose("x86-64-v3", ALL - {"avx2", "movbe"}, True)
    with pytest.raises(ImportError, match="no x86-64-v3 build"):
        _load_core.choose("x86-64-v3", ALL, False)
    with pytest.raises(ImportError, match="RIGIDFEM_CORE: expected one of 'baseline', 'x86-64-v3' or unset, got 'avx'"):
        _load_core.choose("avx", ALL, True)


def test_cpu_flags_reads_the_first_processor(tmp_path):
    cpuinfo = tmp_path / "cpuinfo"
    cpuinfo.write_text("processor\t: 0\nflags\t\t: fpu sse2 avx2 fma\n\nprocessor\t: 1\nflags\t\t: fpu\n")
    assert _load_core.cpu_flags(str(cpuinfo)) == {"fpu", "sse2", "avx2", "fma"}
    assert _load_core.cpu_flags(str(tmp_path / "none")) == frozenset()


def test_the_loaded_build_is_rigidfem_core():
    assert rf._core.__name__ == "rigidfem._core" and sys.modules["rigidfem._core"] is rf._core
    assert rf._core.build == ("x86-64-v3" if V3_HERE and not os.environ.get("RIGIDFEM_CORE") else
                              os.environ.get("RIGIDFEM_CORE") or "baseline")
    assert rf.Data.__module__ == "rigidfem._core" and rf._core.stages.__name__ == "rigidfem._core.stages"


# Run under each build: its name, a steel cantilever's forward dynamics and 500 steps of rk4, and a pickled System.
CHILD = r"""
import pickle, sys
import numpy as np
import rigidfem as rf
model = rf.Model()
model.add_beam("link", "ground", 0.5, rf.Material(E=2.1e11, rho=7850.0), rf.Section.circle(0.01), 8,
               deform=("torsion", "bend_y", "bend_z"))
system = model.compile()
rng = np.random.default_rng(5)
q, qd = 0.1 * rng.standard_normal(system.nq), rng.standard_normal(system.nq)
qdd = system.forward_dynamics(0.0, q, qd)
result = rf.simulate(system, 0.01, "rk4", q0=q, dt=2e-5)
np.save(sys.argv[1] + "_qdd.npy", qdd)
np.save(sys.argv[1] + "_q.npy", result.q[-1])
with open(sys.argv[1] + ".pickle", "wb") as f:
    pickle.dump(system, f)
print(rf._core.build)
"""


def run_with(build, tmp_path):
    out = subprocess.run([sys.executable, "-c", CHILD, str(tmp_path / build)], capture_output=True, text=True,
                         env={**os.environ, "RIGIDFEM_CORE": build}, timeout=300)
    assert out.returncode == 0, out.stderr
    return out.stdout.strip()


@pytest.mark.skipif(not V3_HERE, reason="the x86-64-v3 build needs an x86-64-v3 processor and x86-64 Linux")
def test_both_builds_give_the_same_answers_and_read_each_others_pickles(tmp_path):
    assert run_with("baseline", tmp_path) == "baseline"
    assert run_with("x86-64-v3", tmp_path) == "x86-64-v3"
    for part in ("qdd", "q"):
        a, b = (np.load(tmp_path / f"{build}_{part}.npy") for build in ("baseline", "x86-64-v3"))
        # the builds round differently (Eigen's kernels: four lanes, fused multiply-adds): measured 1.2e-12
        # (relative) for both the accelerations (up to 9e8 rad/s²) and the state after 500 steps of rk4
        assert np.abs(a - b).max() <= 1e-10 * np.abs(a).max(), part
        assert not np.array_equal(a, np.zeros_like(a))
    for build in ("baseline", "x86-64-v3"):
        with open(tmp_path / f"{build}.pickle", "rb") as f:
            system = pickle.load(f)  # read by this process's build (x86-64-v3 unless RIGIDFEM_CORE says otherwise)
        assert system.nq == 24
    # and the x86-64-v3 build's pickle read by the portable build
    read = f"import pickle; print(pickle.load(open({str(tmp_path / 'x86-64-v3.pickle')!r}, 'rb')).nq)"
    out = subprocess.run([sys.executable, "-c", read], capture_output=True, text=True, timeout=300,
                         env={**os.environ, "RIGIDFEM_CORE": "baseline"})
    assert out.returncode == 0 and out.stdout.strip() == "24", out.stderr
