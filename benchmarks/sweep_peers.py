"""Sweeps side by side: 64 runs of Kane's spin-up beam on 2 cores in rigidfem, Exudyn and MuJoCo
(issue 29, row 5).

The study: Kane's spin-up beam of ``benchmarks.kane_peers`` (m = 20 elements, 20 s, the tip in the
hub frame at 201 outputs) at 64 spin rates Ω evenly spaced over 4–11 rad/s (the spin-up time
T = 15 s as there). Each code runs every case at its cheapest setting reaching a tip RMS error
of 1e-4 m (kane_peers' table at Ω = 6 rad/s: rigidfem radau5 rtol 1e-4, Exudyn
TrapezoidalIndex2 h = 12.5 ms, MuJoCo implicitfast dt = 1.06 ms); ``choose`` re-checks that
error at the lowest and the highest Ω against each code's own converged solution (kane_peers'
references, checked to agree within 1e-5 m) and moves to the next finer setting where one misses
it (at 11 rad/s all three do: rigidfem radau5 rtol 3e-5, Exudyn h = 9.09 ms, MuJoCo dt = 0.71 ms).

Each code's sweep machinery, on 2 workers, and serial for scale:

- rigidfem: ``rigidfem.sweep`` of ``rigidfem_case`` (build the beam at Ω, compile, radau5, the tip
  in the hub frame at the outputs) with threads (2), processes (2) and a Dask ``LocalCluster`` (2
  worker processes × 1 thread; its start-up and the workers' first import timed apart); plus
  serial and threads sharing one compiled System (``System.with_parameters`` sets the drive's Ω;
  no build per case);
- Exudyn: ``exudyn.processing.ParameterVariation`` (a ``multiprocessing.Pool`` of 2 processes,
  ``useMultiProcessing=True, numberOfThreads=2``) of ``exudyn_case``, which builds and solves one
  case (``ObjectKinematicTree``, the hub's rotation exact by a coordinate constraint with symbolic
  θ(t), θ̇(t), as kane_peers does for Exudyn's implicit solvers; the joint angles at the outputs
  by a ``SensorNode``);
- MuJoCo: ``mujoco.rollout.Rollout(nthread=2)`` over one model compiled once (the MJCF of
  kane_peers), 64 rollouts at once. The hub is kane_peers' flywheel (rotor inertia J = 1e10 kg·m²
  and a motor, here of gear 100: J θ̈ reaches 1.5e10 N·m at 11 rad/s, past the largest control
  MuJoCo admits, 1e10). Its torque J θ̈(t) cannot come from the ``mjcb_control`` callback as in
  kane_peers: that callback is one per process, shared by the rollout's threads, and sees only
  (model, data) — nothing tells it which Ω the rollout on that data has. So each case's control
  sequence J θ̈(t_k) is precomputed per step (numpy, inside the timed sweep) and given to the
  rollout as its open-loop control array. With implicitfast this is the same drive as the
  callback (evaluated once per step at the step's start time; checked equal). The rollout
  records the state at every step; the sweep rolls out one output interval at a time (200 calls
  of 141 steps at dt = 0.709 ms, from the previous states) instead of holding 64 × 28,200 states
  (0.6 GB).

Wall-clock time (``time.perf_counter``) of the whole sweep per executor, the executors in
interleaved rounds, the least of the rounds kept; runs per second; the ratio to rigidfem's best.
The results are checked (``AssertionError`` otherwise): a code's executors give the same tips
to 1e-12 m, and every code's tip history per Ω agrees with rigidfem's within the sum of their
errors, 2e-4 m + 1e-5 m (``agreement``).

    python -m benchmarks sweep_peers [--quick] [--output DIR]

Needs the peer codes and Dask: ``pip install exudyn mujoco "dask[distributed]"``.
"""

from __future__ import annotations

import ctypes
import importlib
import math
import time
import warnings
from dataclasses import dataclass

import numpy as np

import rigidfem as rf
from rigidfem import SimulationError, samples
from rigidfem.studies.study import Table

from . import _peers_common as common
from . import kane_peers as kp
from ._common import report
from ._peers_common import exudyn_settings

ELEMENTS = 20
RUNS = 64
OMEGAS = tuple(float(w) for w in np.linspace(4.0, 11.0, RUNS))  #: Ω, rad/s
WORKERS = 2
TARGET = 1e-4                 #: m, the tip RMS error each code is held to
AGREEMENT = 1e-5              #: m, largest tip distance allowed between the codes' references (TARGET / 10)
#: MuJoCo's hub motor gear: the torque J θ̈ reaches 1.5e10 N·m at Ω = 11 rad/s, past MuJoCo's
#: largest admissible control (1e10, mjMAXVAL: larger values are taken as a divergence and the
#: state is reset), so the control is J θ̈ / GEAR through a motor of that gear.
GEAR = 100.0
T_EVAL = np.linspace(0.0, kp.T_END, kp.OUTPUTS)
#: Each code's settings, coarse to fine, from its cheapest at 1e-4 m in kane_peers (m = 20, Ω = 6).
RTOLS = (1e-4, 3e-5, 1e-5, 3e-6, 1e-6)                              #: rigidfem radau5, atol = rtol / 100
EXUDYN_DIVISIONS = (8, 11, 16, 23, 32, 45, 64, 91, 128)            #: TrapezoidalIndex2, h = 0.1 s / k
MUJOCO_FACTORS = (1.0, 1.25, 1.5, 2.0, 3.0, 4.0, 6.0, 8.0, 12.0, 16.0, 24.0, 32.0, 48.0, 64.0)
#: (MuJoCo implicitfast: dt = 2 / (ω_max f), from its stability limit f = 1)


def spin_up_acceleration(omega, t):
    """θ̈(t) of Kane's spin-up to ``omega`` (rad/s²), vectorised over numpy arrays."""
    t = np.asarray(t, dtype=float)
    return np.where(t < kp.SPIN_UP, omega / kp.SPIN_UP * (1.0 - np.cos(2.0 * np.pi * t / kp.SPIN_UP)), 0.0)


# ---------------------------------------------------------------------------------------------
# rigidfem: one case, for rf.sweep
# ---------------------------------------------------------------------------------------------

def rigidfem_case(omega: float, elements: int, rtol: float) -> dict:
    """Build Kane's beam spun up to ``omega``, compile it, run radau5 (rtol, atol = rtol/100) over
    20 s and return the tip in the hub frame at the 201 outputs (m)."""
    model, h = samples.kane_beam(omega=omega, duration=kp.SPIN_UP, elements=elements)
    r = rf.simulate(model.compile(), kp.T_END, method="radau5", rtol=rtol, atol=rtol * 1e-2, t_eval=T_EVAL,
                    max_steps=10**8, stiffness_warning=False)
    return {"tip": r.position(h["beam"].tip, frame=h["hub"])}


_SHARED = {}


def rigidfem_shared_case(omega: float, elements: int, rtol: float) -> dict:
    """As ``rigidfem_case`` on one compiled System shared by the threads: the drive's Ω set by
    ``System.with_parameters`` (no build per case)."""
    if elements not in _SHARED:
        model, h = samples.kane_beam(omega=kp.OMEGA, duration=kp.SPIN_UP, elements=elements)
        _SHARED[elements] = (model.compile(), h)
    system, h = _SHARED[elements]
    r = rf.simulate(system.with_parameters({"hub.rz.drive.omega": omega}), kp.T_END, method="radau5", rtol=rtol,
                    atol=rtol * 1e-2, t_eval=T_EVAL, max_steps=10**8, stiffness_warning=False)
    return {"tip": r.position(h["beam"].tip, frame=h["hub"])}


# ---------------------------------------------------------------------------------------------
# Exudyn: one case, for ParameterVariation
# ---------------------------------------------------------------------------------------------

def kinematic_tree(chain) -> dict:
    """The chain as the numbers of an Exudyn ``ObjectKinematicTree`` (plain arrays, pickled to the
    worker processes): link 0 the hub with rfe 0 welded on, links 1..m the rfes on RevoluteZ."""
    hub, welded = chain.links[0], chain.links[1]
    if hub.coordinates != ("rz",) or welded.coordinates or welded.parent != 0:
        raise ValueError("chain: expected a hub on rz carrying rfe 0 rigidly")
    B0 = welded.placement
    links = chain.links[2:]
    tree = {"transforms": [np.eye(4)], "masses": [welded.mass],
            "coms": [B0[:3, :3] @ welded.com + B0[:3, 3]],
            "inertias": [B0[:3, :3] @ welded.inertia @ B0[:3, :3].T],
            "parents": [-1], "stiffness": [0.0], "damping": [0.0], "rest": [0.0]}
    for link in links:
        if link.coordinates != ("rz",) or link.parent < 1:
            raise ValueError(f"chain: expected rfes on rz joints, got {link.coordinates} on {link.name}")
        tree["transforms"].append((B0 if link.parent == 1 else np.eye(4)) @ link.placement)
        tree["masses"].append(link.mass)
        tree["coms"].append(link.com)
        tree["inertias"].append(link.inertia)
        tree["parents"].append(link.parent - 1)
        tree["stiffness"].append(float(link.stiffness[0]))
        tree["damping"].append(float(link.damping[0]))
        tree["rest"].append(float(link.rest[0]))
    return tree


def exudyn_run(tree: dict, omega: float, method: str, dt: float) -> np.ndarray:
    """Build Kane's beam spun up to ``omega`` in Exudyn and solve it at the fixed step ``dt``:
    the beam's joint angles at the 201 outputs (OUTPUTS, m). Implicit solvers get the exact hub
    (a coordinate constraint with symbolic θ(t), θ̇(t)); RK44 the flywheel hub (rotor inertia J,
    symbolic torque J θ̈(t)), as kane_peers."""
    import exudyn as exu
    from exudyn.advancedUtilities import CreateSymbolicUserFunction
    from exudyn.itemInterface import (LoadCoordinate, MarkerNodeCoordinate, NodeGenericODE2, NodePointGround,
                                      ObjectConnectorCoordinate, ObjectKinematicTree, SensorNode)

    implicit = method in kp.ExudynKane.IMPLICIT
    n = len(tree["masses"])
    inertias = [np.array(I, dtype=float) for I in tree["inertias"]]
    if not implicit:
        inertias[0] = inertias[0] + np.diag([0.0, 0.0, kp.HUB_INERTIA])
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    node = mbs.AddNode(NodeGenericODE2(referenceCoordinates=[0.0] * n, initialCoordinates=[0.0] * n,
                                       initialCoordinates_t=[0.0] * n, numberOfODE2Coordinates=n))
    mbs.AddObject(ObjectKinematicTree(
        nodeNumber=node, jointTypes=[exu.JointType.RevoluteZ] * n, linkParents=list(tree["parents"]),
        jointTransformations=exu.Matrix3DList([H[:3, :3] for H in tree["transforms"]]),
        jointOffsets=exu.Vector3DList([H[:3, 3] for H in tree["transforms"]]),
        linkInertiasCOM=exu.Matrix3DList(inertias), linkCOMs=exu.Vector3DList(tree["coms"]),
        linkMasses=list(tree["masses"]), jointPControlVector=list(tree["stiffness"]),
        jointDControlVector=list(tree["damping"]), jointPositionOffsetVector=list(tree["rest"]),
        jointVelocityOffsetVector=[0.0] * n))
    marker = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=node, coordinate=0))
    esym = exu.symbolic
    Om, Ts, w, J = float(omega), kp.SPIN_UP, 2.0 * math.pi / kp.SPIN_UP, kp.HUB_INERTIA
    if implicit:
        def angle(mbs, t, itemNumber, lOffset):
            return esym.IfThenElse(t < Ts, Om / Ts * (0.5 * t * t + (esym.cos(w * t) - 1.0) / w**2),
                                   Om * (t - 0.5 * Ts))

        def rate(mbs, t, itemNumber, lOffset):
            return esym.IfThenElse(t < Ts, Om / Ts * (t - esym.sin(w * t) / w), esym.Real(Om))

        keep = [CreateSymbolicUserFunction(mbs, angle, "offsetUserFunction", itemTypeName="ObjectConnectorCoordinate"),
                CreateSymbolicUserFunction(mbs, rate, "offsetUserFunction_t", itemTypeName="ObjectConnectorCoordinate")]
        ground = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=mbs.AddNode(NodePointGround()), coordinate=0))
        mbs.AddObject(ObjectConnectorCoordinate(markerNumbers=[ground, marker], offsetUserFunction=keep[0],
                                                offsetUserFunction_t=keep[1]))
    else:
        def torque(mbs, t, load):
            return esym.IfThenElse(t < Ts, J * Om / Ts * (1.0 - esym.cos(w * t)), esym.Real(0.0))

        keep = [CreateSymbolicUserFunction(mbs, torque, "loadUserFunction", itemTypeName="LoadCoordinate")]
        mbs.AddLoad(LoadCoordinate(markerNumber=marker, load=0.0, loadUserFunction=keep[0]))
    sensor = mbs.AddSensor(SensorNode(nodeNumber=node, storeInternal=True,
                                      outputVariableType=exu.OutputVariableType.Coordinates))
    mbs.Assemble()
    ss = exudyn_settings(exu, kp.T_END, dt, kp.INTERVAL)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ok = mbs.SolveDynamic(ss, solverType=getattr(exu.DynamicSolverType, method))
    data = np.asarray(mbs.GetSensorStoredData(sensor))
    if ok is False or len(data) != kp.OUTPUTS or not np.all(np.isfinite(data)):
        raise SimulationError(f"Exudyn {method} dt={dt:g} at Ω = {omega:g}: failed or unstable")
    if np.max(np.abs(data[:, 0] - T_EVAL)) > 1e-6:
        raise RuntimeError(f"Exudyn {method}: sensor times off the output grid")
    del keep
    return data[:, 2:]  # time, hub angle, then the beam's joint angles (rigidfem's q)


def exudyn_case(parameters: dict) -> np.ndarray:
    """ParameterVariation's parameterFunction: one case, ``parameters`` = {"omega": Ω,
    "functionData": {"tree", "method", "dt"}} -> the beam's joint angles at the outputs."""
    data = parameters["functionData"]
    return exudyn_run(data["tree"], parameters["omega"], data["method"], data["dt"])


def exudyn_sweep(tree: dict, omegas, method: str, dt: float, processes: int | None) -> list:
    """``ParameterVariation`` over ``omegas`` (``processes`` None: serial)."""
    from exudyn.processing import ParameterVariation

    _, values = ParameterVariation(exudyn_case, {"omega": [float(w) for w in omegas]},
                                   useMultiProcessing=processes is not None, numberOfThreads=processes or 1,
                                   showProgress=False, parameterFunctionData={"tree": tree, "method": method, "dt": dt})
    return values


# ---------------------------------------------------------------------------------------------
# MuJoCo: every case at once by rollout
# ---------------------------------------------------------------------------------------------

def mujoco_sweep(xml: str, address, omegas, dt: float, nthread: int) -> np.ndarray:
    """Kane's beam at every Ω of ``omegas`` by ``mujoco.rollout`` on ``nthread`` threads (0: the
    calling thread), implicitfast at the step ``dt`` (dividing the output interval): compile the
    model, precompute each case's control J θ̈(t_k) per step, roll out one output interval at a
    time. Returns the beam's joint angles (len(omegas), OUTPUTS, m)."""
    import mujoco
    from mujoco import rollout

    n = int(round(kp.INTERVAL / dt))
    if abs(n * dt - kp.INTERVAL) > 1e-9 * kp.INTERVAL:
        raise ValueError(f"dt: expected a step dividing {kp.INTERVAL} s, got {dt}")
    mujoco.set_mjcb_control(None)  # the open-loop control array drives the hub, not a callback
    model = mujoco.MjModel.from_xml_string(xml)
    model.opt.timestep = dt
    model.opt.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    omegas = np.asarray(omegas, dtype=float)
    t = dt * np.arange(n * (kp.OUTPUTS - 1))
    control = (kp.HUB_INERTIA / GEAR * spin_up_acceleration(omegas[:, None], t[None, :]))[:, :, None]
    datas = [mujoco.MjData(model) for _ in range(max(nthread, 1))]
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    state0 = np.empty(mujoco.mj_stateSize(model, spec))
    mujoco.mj_getState(model, datas[0], state0, spec)
    state = np.tile(state0, (len(omegas), 1))
    chunk = np.empty((len(omegas), n, len(state0)))
    out = np.empty((len(omegas), kp.OUTPUTS, len(address)))
    qpos = 1 + np.asarray(address)  # the full physics state: time, qpos, qvel
    out[:, 0] = state[:, qpos]
    printer = mujoco.get_mju_user_warning()
    mujoco.set_mju_user_warning(lambda message: None)  # a diverging candidate: said below, not printed
    try:
        with rollout.Rollout(nthread=nthread) as pool:
            for k in range(1, kp.OUTPUTS):
                pool.rollout(model, datas, state, np.ascontiguousarray(control[:, (k - 1) * n:k * n]), nstep=n,
                             state=chunk)
                state = np.ascontiguousarray(chunk[:, -1])
                out[:, k] = state[:, qpos]
                if np.max(np.abs(state[:, 0] - k * kp.INTERVAL)) > 1e-9:  # MuJoCo resets a diverging state
                    raise SimulationError(f"MuJoCo implicitfast dt={dt:g}: unstable (state reset before t = "
                                          f"{k * kp.INTERVAL:.3g} s)")
    finally:
        mujoco.set_mju_user_warning(printer)
    if not np.all(np.isfinite(out)):
        raise SimulationError(f"MuJoCo implicitfast dt={dt:g}: unstable (not finite)")
    return out


def geared(xml: str) -> str:
    """kane_peers' MJCF with the hub motor's gear GEAR."""
    old = '<motor name="hub" joint="hub.rz" gear="1"/>'
    if old not in xml:
        raise RuntimeError("MJCF: hub motor not found")
    return xml.replace(old, f'<motor name="hub" joint="hub.rz" gear="{GEAR:g}"/>')


class MujocoAt(kp.MujocoKane):
    """kane_peers' MuJoCo runner (the ``mjcb_control`` callback, one Ω at a time) at spin rate
    ``omega``: the references (RK4) and the check that the rollout's control array drives the
    hub as the callback does."""

    def __init__(self, scene, omega: float):
        super().__init__(scene)
        self.omega = float(omega)
        self.xml = geared(self.xml)
        self.model = self.mujoco.MjModel.from_xml_string(self.xml)
        self.data = self.mujoco.MjData(self.model)

    def install(self) -> None:
        lib = self._callback()
        if lib is not None:
            super().install()
            ctypes.c_double.in_dll(lib, "kp_omega").value = self.omega
            ctypes.c_double.in_dll(lib, "kp_J").value = self.hub_inertia / GEAR
        else:
            J, w = self.hub_inertia / GEAR, self.omega

            def drive(model, data):
                data.ctrl[0] = J * float(spin_up_acceleration(w, data.time))
            self.mujoco.set_mjcb_control(drive)


# ---------------------------------------------------------------------------------------------
# The study
# ---------------------------------------------------------------------------------------------

@dataclass
class Study:
    """The scene (kane_peers' Kane at m elements) and what each code's sweep needs."""

    scene: kp.Kane
    tree: dict
    xml: str
    address: np.ndarray

    @property
    def elements(self) -> int:
        return self.scene.elements

    def tips(self, q) -> np.ndarray:
        """Tip in the hub frame (OUTPUTS, 3) from the beam's joint angles (kane_peers' kinematics)."""
        return kp.tip_in_hub(self.scene, q)


def study(elements: int = ELEMENTS) -> Study:
    scene = kp.kane(elements)
    mk = kp.MujocoKane(scene)
    return Study(scene, kinematic_tree(scene.chain), geared(mk.xml), mk.address)


def scene_at(s: Study, omega: float) -> kp.Kane:
    """kane_peers' scene spun up to ``omega`` (the chain does not depend on Ω; the drive does)."""
    model, h = samples.kane_beam(omega=omega, duration=kp.SPIN_UP, elements=s.elements)
    return kp.Kane(s.elements, model.compile(), h["beam"].tip, s.scene.chain, s.scene.omega_max, h["hub"])


def references(s: Study, omega: float) -> dict:
    """Each code's converged tip history at ``omega`` (kane_peers' references: rigidfem dopri5 rtol
    1e-12; Exudyn RK44 and MuJoCo RK4 at half their stability limit, flywheel hub)."""
    scene = scene_at(s, omega)
    h = kp._divide(kp.REFERENCE_STEP * 2.785 / s.scene.omega_max)
    return {"rigidfem": kp.tip_in_hub(scene, kp.RigidfemKane(scene).reference()),
            "Exudyn": s.tips(exudyn_run(s.tree, omega, "RK44", h)),
            "MuJoCo": s.tips(MujocoAt(s.scene, omega).run("RK4", "dt", h))}


def candidates(s: Study) -> dict:
    """code -> [(label, setting value)], coarse to fine."""
    mujoco_steps = sorted({kp._divide(2.0 / s.scene.omega_max / f) for f in MUJOCO_FACTORS}, reverse=True)
    return {"rigidfem": [(f"radau5 rtol={r:g}", r) for r in RTOLS],
            "Exudyn": [(f"TrapezoidalIndex2 h={kp.INTERVAL / k * 1e3:.3g} ms", kp.INTERVAL / k)
                       for k in EXUDYN_DIVISIONS],
            "MuJoCo": [(f"implicitfast dt={dt * 1e3:.3g} ms", dt) for dt in mujoco_steps]}


def tips_of(s: Study, code: str, value: float, omegas) -> np.ndarray:
    """(len(omegas), OUTPUTS, 3): one code's tip histories at ``omegas`` at setting ``value``, run
    serially by the same functions the sweeps call."""
    if code == "rigidfem":
        return np.array([rigidfem_case(w, s.elements, value)["tip"] for w in omegas])
    if code == "Exudyn":
        return np.array([s.tips(q) for q in exudyn_sweep(s.tree, omegas, "TrapezoidalIndex2", value, None)])
    return np.array([s.tips(q) for q in mujoco_sweep(s.xml, s.address, omegas, value, 0)])


def choose(s: Study, omegas, target: float = TARGET) -> tuple[dict, Table]:
    """Each code's coarsest setting whose tip RMS error is ≤ ``target`` at the lowest and the highest Ω,
    against the code's own reference; the references checked against each other (within
    ``AGREEMENT`` m) and MuJoCo's control array against kane_peers' callback."""
    ends = (min(omegas), max(omegas))
    refs = {w: references(s, w) for w in ends}
    rows = []
    for w in ends:
        for code in ("Exudyn", "MuJoCo"):
            d = float(np.max(np.linalg.norm(refs[w][code] - refs[w]["rigidfem"], axis=1)))
            if d > AGREEMENT:
                raise AssertionError(f"Ω = {w:g}: {code}'s converged tip differs from rigidfem's by {d:.3g} m "
                                     f"(allowed {AGREEMENT:g} m)")
            rows.append({"code": code, "setting": "reference vs rigidfem's reference", "omega": w,
                         "tip_rms_error_m": rms(refs[w][code], refs[w]["rigidfem"]), "max_m": d, "chosen": ""})
    chosen = {}
    for code, options in candidates(s).items():
        for label, value in options:
            try:
                tips = tips_of(s, code, value, ends)
            except SimulationError as e:  # unstable at some Ω: the next finer setting
                rows += [{"code": code, "setting": label, "omega": w, "tip_rms_error_m": np.inf, "max_m": np.inf,
                          "chosen": str(e)[:60]} for w in ends]
                continue
            errors = [rms(tip, refs[w][code]) for tip, w in zip(tips, ends)]
            ok = max(errors) <= target
            for w, e in zip(ends, errors):
                rows.append({"code": code, "setting": label, "omega": w, "tip_rms_error_m": e,
                             "max_m": float(np.max(np.linalg.norm(tips[ends.index(w)] - refs[w][code], axis=1))),
                             "chosen": "yes" if ok else ""})
            if ok:
                chosen[code] = (label, value)
                break
        else:
            raise AssertionError(f"{code}: no setting reaches {target:g} m at Ω = {ends}")
    # the rollout's control array drives the hub as kane_peers' callback does (implicitfast)
    dt = chosen["MuJoCo"][1]
    callback = s.tips(MujocoAt(s.scene, ends[-1]).run("implicitfast", "dt", dt))
    array = tips_of(s, "MuJoCo", dt, ends[-1:])[0]
    d = float(np.max(np.linalg.norm(callback - array, axis=1)))
    rows.append({"code": "MuJoCo", "setting": "rollout (control array) vs mj_step (callback)", "omega": ends[-1],
                 "tip_rms_error_m": rms(array, callback), "max_m": d, "chosen": ""})
    if d > 1e-9:
        raise AssertionError(f"MuJoCo: the rollout's control array differs from the callback by {d:.3g} m")
    return chosen, Table(rows, ("code", "setting", "omega", "tip_rms_error_m", "max_m", "chosen"))


def rms(tip, reference) -> float:
    return kp.rms_error(tip, reference)


# ---------------------------------------------------------------------------------------------
# The sweeps, timed
# ---------------------------------------------------------------------------------------------

def executors(s: Study, chosen: dict, omegas, client=None) -> dict:
    """name -> (code, per-run work, the sweep as a function returning the tips (runs, OUTPUTS, 3))."""
    rtol = chosen["rigidfem"][1]
    cases = [{"omega": w, "elements": s.elements, "rtol": rtol} for w in omegas]

    def rigid(executor, workers, function=rigidfem_case):
        def go():
            table = rf.sweep(function, cases, executor=executor, workers=workers, as_frame=False, errors="raise")
            return np.array([row["tip"] for row in table.rows])
        return go

    def exudyn(processes):
        return lambda: np.array([s.tips(q) for q in exudyn_sweep(s.tree, omegas, "TrapezoidalIndex2",
                                                                 chosen["Exudyn"][1], processes)])

    def mujoco(nthread):
        return lambda: np.array([s.tips(q) for q in mujoco_sweep(s.xml, s.address, omegas, chosen["MuJoCo"][1],
                                                                 nthread)])

    build = f"build + compile + {chosen['rigidfem'][0]}"
    out = {"rigidfem serial": ("rigidfem", build, rigid("serial", None)),
           f"rigidfem threads ({WORKERS})": ("rigidfem", build, rigid("threads", WORKERS)),
           f"rigidfem processes ({WORKERS})": ("rigidfem", build, rigid("processes", WORKERS))}
    if client is not None:
        out[f"rigidfem Dask LocalCluster ({WORKERS} workers × 1 thread)"] = ("rigidfem", build, rigid(client, None))
    shared = f"with_parameters(Ω) + {chosen['rigidfem'][0]}"
    out["rigidfem serial, one shared System"] = ("rigidfem", shared, rigid("serial", None, rigidfem_shared_case))
    out[f"rigidfem threads ({WORKERS}), one shared System"] = ("rigidfem", shared,
                                                              rigid("threads", WORKERS, rigidfem_shared_case))
    exu_work = f"build + assemble + {chosen['Exudyn'][0]}"
    out["Exudyn ParameterVariation serial"] = ("Exudyn", exu_work, exudyn(None))
    out[f"Exudyn ParameterVariation ({WORKERS} processes)"] = ("Exudyn", exu_work, exudyn(WORKERS))
    mj_work = f"{chosen['MuJoCo'][0]}, control array J θ̈(t_k) (model compiled once per sweep)"
    out["MuJoCo rollout serial (nthread = 0)"] = ("MuJoCo", mj_work, mujoco(0))
    out[f"MuJoCo rollout (nthread = {WORKERS})"] = ("MuJoCo", mj_work, mujoco(WORKERS))
    return out


def agreement(omegas, tips: dict, bound: float) -> Table:
    """Per Ω: each code's largest tip deflection (m) and its tip RMS distance from rigidfem's (m);
    raises ``AssertionError`` where a code differs from rigidfem by more than ``bound`` m."""
    rows = []
    for k, w in enumerate(omegas):
        row = {"omega": w}
        for code, tip in tips.items():
            row[f"{code}_max_deflection_m"] = float(np.max(np.abs(tip[k][:, 1])))
        for code, tip in tips.items():
            if code != "rigidfem":
                d = rms(tip[k], tips["rigidfem"][k])
                row[f"{code}_vs_rigidfem_rms_m"] = d
                if d > bound:
                    raise AssertionError(f"Ω = {w:g}: {code}'s tip differs from rigidfem's by {d:.3g} m RMS "
                                         f"(allowed {bound:g} m)")
        rows.append(row)
    columns = ("omega", *(f"{c}_max_deflection_m" for c in tips), *(f"{c}_vs_rigidfem_rms_m" for c in tips
                                                                      if c != "rigidfem"))
    return Table(rows, columns)


def measure(elements: int = ELEMENTS, omegas=OMEGAS, rounds: int = 3, dask: bool = True, target: float = TARGET,
            log=print) -> dict:
    """Choose the settings (each code's coarsest reaching a tip RMS error ``target`` m), check the
    sweeps' results against each other, time every executor in interleaved rounds (wall time, the
    least of ``rounds``). ``dask``: with the LocalCluster row. Returns {"settings", "timing",
    "agreement"} Tables."""
    start = time.perf_counter()
    s = study(elements)
    chosen, checks = choose(s, omegas, target)
    log(f"[{time.perf_counter() - start:6.1f} s] m = {elements}: settings chosen: "
        + "; ".join(f"{c} {label}" for c, (label, _) in chosen.items()))
    client = cluster = None
    startup = float("nan")
    if dask:
        from distributed import Client, LocalCluster

        t0 = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            cluster = LocalCluster(n_workers=WORKERS, threads_per_worker=1, processes=True, dashboard_address=None)
        client = Client(cluster)
        client.run(importlib.import_module, __name__)  # the workers' first import, part of the start-up
        startup = time.perf_counter() - t0
    try:
        todo = executors(s, chosen, omegas, client)
        best = {name: np.inf for name in todo}
        tips = {}
        for r in range(rounds):
            for name, (code, _, go) in todo.items():
                t0 = time.perf_counter()
                result = go()
                best[name] = min(best[name], time.perf_counter() - t0)
                if r == 0:
                    if code in tips:  # every executor of a code gives the same results
                        d = float(np.max(np.abs(result - tips[code])))
                        if d > 1e-12:
                            raise AssertionError(f"{name}: results differ from the same code's first sweep by "
                                                 f"{d:.3g} m")
                    else:
                        tips[code] = result
            log(f"[{time.perf_counter() - start:6.1f} s] round {r + 1}/{rounds}: "
                + ", ".join(f"{name} {best[name]:.3g} s" for name in todo))
    finally:
        if client is not None:
            client.close()
            cluster.close()
    agree = agreement(omegas, tips, 2.0 * target + AGREEMENT)
    fastest = min(best[name] for name, (code, _, _) in todo.items() if code == "rigidfem")
    serial = {work: best[name] for name, (code, work, _) in todo.items() if "serial" in name}
    rows = [{"executor": name, "per_run_work": work, "runs": len(omegas), "wall_time_s": best[name],
             "runs_per_s": len(omegas) / best[name], "time_over_rigidfem_best": best[name] / fastest,
             "speed_up_over_serial": serial[work] / best[name],
             "startup_s": startup if "Dask" in name else 0.0} for name, (code, work, _) in todo.items()]
    timing = Table(rows, ("executor", "per_run_work", "runs", "wall_time_s", "runs_per_s", "time_over_rigidfem_best",
                          "speed_up_over_serial", "startup_s"))
    return {"settings": checks, "timing": timing, "agreement": agree}


def versions() -> dict:
    import distributed

    info = kp.versions()
    info["distributed"] = distributed.__version__
    return info


def run(output_dir="bench", quick: bool = False) -> dict:
    """``python -m benchmarks sweep_peers``: m = 20, 64 spin rates, 3 interleaved rounds (``quick``:
    m = 4, 6 spin rates, one round). Writes sweep_peers_{settings,timing,agreement}.csv."""
    print(common.versions_line(versions()), flush=True)
    if quick:
        tables = measure(4, tuple(np.linspace(4.0, 11.0, 6)), rounds=1)
    else:
        tables = measure()
    runs = tables["timing"].rows[0]["runs"]
    return report({
        "sweep_peers_settings": ("Sweeps, each code's setting: tip RMS error against its own reference at the lowest and "
                                 "highest Ω (m); the references against rigidfem's", tables["settings"]),
        "sweep_peers_agreement": ("Sweeps, agreement per Ω: largest tip deflection per code and the tip RMS distance from "
                                  "rigidfem's (m)", tables["agreement"]),
        "sweep_peers_timing": (f"Sweeps, wall time per executor: the sweep of {runs} runs (s), least of the rounds",
                               tables["timing"]),
    }, output_dir)
