"""The cost of ONE evaluation of each kind, per model: rigidfem against MuJoCo (and Pinocchio on the strip)::

    python -m benchmarks evaluations [--quick] [--output DIR]

The models are the peers pages' own, built by their modules' builders: the slider-crank with a
flexible rod at m = 4 and the Bricard linkage (``loop_peers``), the whippy strip at m = 16, 32, 64
(``strip_peers``; ``quick``: m = 16) and the offshore crane (``crane_peers``). MuJoCo's models are
those modules' (``MujocoLoops``, ``MujocoChain``, ``MujocoCrane``, with their C control callbacks
installed: the crank's and the base's servos, the rope); Pinocchio's is the strip's chain
(``peers.PinocchioChain``: the other models have loops or a prescribed base). Every code is at the
scene's initial state: the loops assembled (``Scene.system_state``), the strip straight at rest, the
crane at its static equilibrium at t = 0. On the strip, MuJoCo's and Pinocchio's accelerations are
first checked equal to rigidfem's (``peers.verify``); the other peers' models are not the same
equations (soft loops, servoed flywheels), the peers pages check their trajectories.

``evaluations_per_call`` (µs per call):

- ``rigidfem_fd_us``: constrained forward dynamics (ABA, then the loops closed), timed in C++
  (``_common.cpp_seconds_per_call``: no Python call);
- ``rigidfem_rk4_step_us``: the CPU time (``time.process_time``) of ``rf.simulate(..., "rk4", dt=h)``
  over N steps (2000; ``quick``: 200) with two outputs, over N; ``rk4_rhs_per_step`` from its stats.
  ``dt_s`` = h = 0.5/ω_max (ω_max: the highest frequency of the springs at the state, the loops
  open; the Bricard has none: its output interval / 100), the same for MuJoCo;
- ``newton_iteration_us`` = ``residual_us`` + ``lu_solve_us``, and ``tangent_us``, ``lu_factor_us``:
  the parts of an implicit (generalised-α) Newton iteration timed in C++ by
  ``implicit_step_parts_seconds`` as ``implicit_step`` does (residual r = M q̈ − f with its
  kinematics; the dense LU). With loops these parts leave out the Gᵀλ term and the loops'
  correction of an iteration: they under-count there;
- ``mujoco_forward_us``, ``mujoco_rk4_step_us``: ``mj_forward`` and ``mj_step`` (integrator RK4,
  step h) per call from Python (``timeit``; the binding's call, ~0.3 µs, included);
- ``pinocchio_aba_us``: ``pinocchio.aba`` with the joint torques computed beforehand (strip only),
  from Python (its binding's call, a few µs with the arrays' conversions, included: compare it
  with rigidfem's ``fd_python_us`` too);
- the ratios rigidfem / peer of each pair of columns.

``evaluations_forward_dynamics`` ("where rigidfem's forward dynamics goes"): the C++ time against
the same call from Python (``python_call_share``), and, with loops, against the same model with
its loops removed (its builder calls replayed without ``add_loop_joint``: ``loops_share``). The
rest — state, kinematics and ABA — is one C++ call that Python cannot split without C++ changes.
``mass_matrix_python_us`` (CRBA) and ``generalized_forces_python_us`` (RNEA at q̈ = 0) are not
stages of the ABA forward dynamics: they are shown for scale (from Python, the call included).

Each time is the least over the rounds (5; ``quick``: 3), a model's measurements interleaved
within a round; a batch of calls lasts at least 0.2 s (``quick``: 0.03 s). Needs MuJoCo
(``pip install mujoco``); Pinocchio (``pip install pin``) is optional.
"""

from __future__ import annotations

import importlib
import math
import time
import timeit
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

import rigidfem as rf
from rigidfem._core._bench import implicit_step_parts_seconds
from rigidfem.base import persistence
from rigidfem.studies.study import Table

from . import crane_peers, loop_peers, strip_peers
from ._common import cpp_seconds_per_call, machine, report
from ._peers_common import peer_guard
from .peers import PinocchioChain, verify

_peer = peer_guard("evaluations", hint="pip install mujoco (and pin, optional)")

STRIPS = (16, 32, 64)
QUICK_STRIPS = (16,)

PER_CALL_COLUMNS = ("model", "nq", "nl", "rigidfem_fd_us", "rigidfem_rk4_step_us", "rk4_rhs_per_step",
                    "newton_iteration_us", "residual_us", "lu_solve_us", "tangent_us", "lu_factor_us", "mujoco_nv",
                    "mujoco_forward_us", "mujoco_rk4_step_us", "pinocchio_aba_us", "fd/mujoco_forward",
                    "rk4_step/mujoco_rk4_step", "fd/pinocchio_aba", "dt_s", "note")
FORWARD_COLUMNS = ("model", "nq", "nl", "fd_cpp_us", "fd_python_us", "python_call_share", "tree_fd_cpp_us",
                   "tree_share", "loops_share", "mass_matrix_python_us", "generalized_forces_python_us", "note")


@dataclass
class Case:
    """A model at its initial state in rigidfem (``system``, q, q̇) and MuJoCo (``model``, ``data``;
    ``reset()`` puts data at that state at t = 0 and installs the model's control callback), the
    step h of both steppers, and Pinocchio's chain (strip only)."""

    name: str
    system: object
    q: np.ndarray
    qd: np.ndarray
    h: float
    model: object
    data: object
    reset: Callable
    pinocchio: PinocchioChain | None = None
    notes: list = field(default_factory=list)


def _pinocchio():
    try:
        return importlib.import_module("pinocchio")
    except ImportError:
        return None


def _step(omega_max: float, interval: float) -> float:
    return 0.5 / omega_max if omega_max > 0 else interval / 100


def _loop_case(mujoco, scene: loop_peers.Scene) -> Case:
    q, qd = scene.system_state()
    peer = loop_peers.MujocoLoops(scene)

    def reset():
        peer.install()
        mujoco.mj_resetData(peer.model, peer.data)
        peer.data.qpos[peer.address] = scene.q0

    case = Case(scene.name, scene.system, q, qd, _step(scene.omega_max, scene.interval), peer.model, peer.data, reset)
    if not peer.native:
        case.notes.append("MuJoCo's crank drive a Python callback (no C compiler)")
    return case


def _strip_case(mujoco, m: int) -> Case:
    s = strip_peers.whippy_strip(m)
    system = s.system
    q, qd = np.zeros(system.nq), np.zeros(system.nq)
    peer = strip_peers.MujocoChain(s)

    def reset():
        mujoco.set_mjcb_control(None)
        mujoco.mj_resetData(peer.model, peer.data)
        peer.data.qpos[peer.address] = q
        peer.data.qvel[peer.address] = qd

    reset()
    mujoco.mj_forward(peer.model, peer.data)
    verify(system, q, qd, peer.data.qacc[peer.address].copy(), 1e-8, "MuJoCo")
    pin = None
    if _pinocchio() is not None:
        pin = PinocchioChain(s.chain)
        verify(system, q, qd, pin.forward_dynamics(q, qd), 1e-9, "Pinocchio")
    case = Case(f"strip m={m}", system, q, qd, _step(s.omega_max, s.interval), peer.model, peer.data, reset, pin)
    if pin is None:
        case.notes.append("Pinocchio not installed")
    return case


def _crane_case(mujoco) -> Case:
    scene = crane_peers.crane()
    peer = crane_peers.MujocoCrane(scene)

    def reset():
        peer.install()
        mujoco.mj_resetData(peer.model, peer.data)
        peer.data.qpos[peer.address] = peer.q0

    case = Case(scene.name, scene.system, scene.q0, np.zeros(scene.system.nq),
                _step(crane_peers.omega_max(scene), scene.interval), peer.model, peer.data, reset)
    if not peer.native:
        case.notes.append("MuJoCo's callback in Python (no C compiler)")
    return case


def cases(mujoco, quick: bool = False) -> list:
    """The models, each a function building its ``Case`` (built one at a time, as it is timed)."""
    return ([lambda: _loop_case(mujoco, loop_peers.slider_crank(4)), lambda: _loop_case(mujoco, loop_peers.bricard())]
            + [lambda m=m: _strip_case(mujoco, m) for m in (QUICK_STRIPS if quick else STRIPS)]
            + [lambda: _crane_case(mujoco)])


def without_loops(system):
    """The same model with its loops removed: its builder calls (the System's recipe) replayed
    without ``add_loop_joint``, compiled with the same algorithm."""
    state = system._state["model"]
    calls = [c for c in state["calls"] if c[0] != "add_loop_joint"]
    model = persistence.replay(rf.Model(gravity=state["gravity"]), {**state, "calls": calls})
    tree = model.compile(system._state["algorithm"])
    if tree.nl or list(tree.coordinate_names) != list(system.coordinate_names):
        raise RuntimeError(f"{system}: the model without loops has other coordinates")
    return tree


def _batch(function, target: float, reset: Callable | None = None) -> Callable:
    """A callable timing a batch of calls of ``function`` lasting at least ``target`` s (after
    ``reset()``, if given) and returning seconds per call."""
    timer = timeit.Timer(function)
    if reset:
        reset()
    first = timer.timeit(100) / 100
    number = max(100, math.ceil(target / max(first, 1e-9)))

    def batch():
        if reset:
            reset()
        return timer.timeit(number) / number
    return batch


def _least(batches: dict, rounds: int) -> dict:
    """Least result of each batch (seconds, or a dict of them) over ``rounds`` rounds, the batches
    taking turns within a round."""
    best = {}
    for _ in range(rounds):
        for name, batch in batches.items():
            out = batch()
            for key, value in (out if isinstance(out, dict) else {name: out}).items():
                best[key] = min(best.get(key, np.inf), value)
    return best


def _batches(case: Case, mujoco, tree, rk4: Callable, parts: Callable, calls: int, target: float) -> dict:
    """The timed batches of one model: name -> callable returning seconds per call (or a dict of them)."""
    system, q, qd, model, data = case.system, case.q, case.qd, case.model, case.data
    batches = {
        "fd_cpp": lambda: cpp_seconds_per_call(system, q, qd, calls),
        "parts": parts,
        "rk4": rk4,
        "fd_python": _batch(lambda: system.forward_dynamics(0.0, q, qd), target),
        "mass_matrix_python": _batch(lambda: system.mass_matrix(0.0, q), target),
        "generalized_forces_python": _batch(lambda: system.generalized_forces(0.0, q, qd), target),
        "mj_forward": _batch(lambda: mujoco.mj_forward(model, data), target, case.reset),
    }
    model.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
    model.opt.timestep = case.h
    batches["mj_step"] = _batch(lambda: mujoco.mj_step(model, data), target, case.reset)
    if tree is not None:
        batches["tree_fd_cpp"] = lambda: cpp_seconds_per_call(tree, q, qd, calls)
    if case.pinocchio is not None:
        chain = case.pinocchio
        tau = chain.chain.joint_forces(q, qd)
        batches["pin_aba"] = _batch(lambda: chain.pin.aba(chain.model, chain.data, q, qd, tau), target)
    return batches


def measure(case: Case, mujoco, quick: bool) -> tuple:
    """(per-call row, forward-dynamics row) of one model (module docstring)."""
    system, q, qd, h = case.system, case.q, case.qd, case.h
    target, rounds, steps = (0.03, 3, 200) if quick else (0.2, 5, 2000)
    calls = max(3, int((2e4 if quick else 2e5) / system.nq))
    qdd = system.forward_dynamics(0.0, q, qd)
    tree = None
    notes = list(case.notes)
    if system.nl:
        try:
            tree = without_loops(system)
        except Exception as e:  # noqa: BLE001 - a recipe that cannot be replayed: said in the table
            notes.append(f"no model without loops ({type(e).__name__})")
    stats = {}

    def rk4():
        start = time.process_time()
        r = rf.simulate(system, steps * h, "rk4", dt=h, q0=q, qd0=qd, t_eval=[0.0, steps * h],
                        stiffness_warning=False)
        cpu = time.process_time() - start
        stats.update(r.stats)
        return cpu / r.stats["steps"]

    def parts():
        p = implicit_step_parts_seconds(system, 0.0, q, qd, qdd, calls)
        return {f"part_{k}": v for k, v in p.items()}

    model, data = case.model, case.data
    printer = mujoco.get_mju_user_warning()
    mujoco.set_mju_user_warning(lambda message: None)
    try:
        t = _least(_batches(case, mujoco, tree, rk4, parts, calls, target), rounds)
    finally:
        mujoco.set_mju_user_warning(printer)
        mujoco.set_mjcb_control(None)  # MuJoCo's callback is process-wide: leave none behind
    if data.warning[mujoco.mjtWarning.mjWARN_BADQACC].number or not np.all(np.isfinite(data.qpos)):
        notes.append(f"MuJoCo RK4 unstable at dt = {h:.3g} s")
    if stats["steps"] != steps:
        raise RuntimeError(f"{case.name}: rk4 made {stats['steps']} steps, expected {steps}")
    us = {k: 1e6 * v for k, v in t.items()}
    fd = us["fd_cpp"]
    residual, solve = us["part_residual"], us["part_lu_solve"]
    row = {"model": case.name, "nq": system.nq, "nl": system.nl, "rigidfem_fd_us": fd,
           "rigidfem_rk4_step_us": us["rk4"], "rk4_rhs_per_step": stats["rhs_evaluations"] / stats["steps"],
           "newton_iteration_us": residual + solve, "residual_us": residual, "lu_solve_us": solve,
           "tangent_us": us["part_tangent"], "lu_factor_us": us["part_lu_factor"], "mujoco_nv": model.nv,
           "mujoco_forward_us": us["mj_forward"], "mujoco_rk4_step_us": us["mj_step"],
           "pinocchio_aba_us": us.get("pin_aba", "-"), "fd/mujoco_forward": fd / us["mj_forward"],
           "rk4_step/mujoco_rk4_step": us["rk4"] / us["mj_step"],
           "fd/pinocchio_aba": fd / us["pin_aba"] if "pin_aba" in us else "-", "dt_s": h,
           "note": "; ".join(notes)}
    tree_fd = us.get("tree_fd_cpp")
    split = {"tree_fd_cpp_us": "-", "tree_share": 1.0, "loops_share": 0.0} if not system.nl else (
        {"tree_fd_cpp_us": tree_fd, "tree_share": tree_fd / fd, "loops_share": (fd - tree_fd) / fd} if tree_fd
        else {"tree_fd_cpp_us": "-", "tree_share": "-", "loops_share": "-"})
    forward = {"model": case.name, "nq": system.nq, "nl": system.nl, "fd_cpp_us": fd,
               "fd_python_us": us["fd_python"], "python_call_share": (us["fd_python"] - fd) / us["fd_python"],
               **split, "mass_matrix_python_us": us["mass_matrix_python"],
               "generalized_forces_python_us": us["generalized_forces_python"], "note": "; ".join(notes)}
    return row, forward


def versions(mujoco) -> str:
    pin = _pinocchio()
    return (f"rigidfem {rf.__version__}, MuJoCo {mujoco.__version__}, "
            f"Pinocchio {pin.__version__ if pin else 'not installed'}, numpy {np.__version__}; {machine()}")


def run(output_dir="bench", quick: bool = False) -> dict:
    """``python -m benchmarks evaluations``: per model (module docstring), one evaluation of each
    kind in rigidfem, MuJoCo and Pinocchio, and where rigidfem's forward dynamics goes. Writes
    evaluations_{per_call,forward_dynamics}.csv into ``output_dir``."""
    mujoco = _peer("mujoco", "mujoco")
    print(versions(mujoco), flush=True)
    start = time.perf_counter()
    rows, forward = [], []
    for make in cases(mujoco, quick):
        case = make()
        row, split = measure(case, mujoco, quick)
        rows.append(row)
        forward.append(split)
        print(f"[{time.perf_counter() - start:6.1f} s] {case.name}: timed", flush=True)
    tables = report({
        "evaluations_per_call": ("One evaluation of each kind (µs per call): rigidfem's forward dynamics (C++ timer), "
                                 "rk4 step (simulate's CPU time / steps) and implicit Newton iteration's parts (C++ "
                                 "timer; with loops without the loops' terms) against MuJoCo's mj_forward and RK4 "
                                 "mj_step at the same step, Pinocchio's ABA; ratios rigidfem / peer",
                                 Table(rows, PER_CALL_COLUMNS)),
        "evaluations_forward_dynamics": ("Where rigidfem's forward dynamics goes (µs): the Python call's share, the "
                                         "loops' share (against the same model without its loops); state, kinematics "
                                         "and ABA are one C++ call, not separable from Python; mass_matrix (CRBA) and "
                                         "generalized_forces (RNEA) are not stages of it: for scale, from Python",
                                         Table(forward, FORWARD_COLUMNS)),
    }, output_dir)
    return {name[len("evaluations_"):]: table for name, table in tables.items()}
