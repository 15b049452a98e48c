"""The offshore crane with a hoisting rope on a moving base, side by side: rigidfem, Exudyn and MuJoCo
(issue 29, row 3).

The scene, a shorter ``notebooks/06_offshore_crane.ipynb`` that every code can build identically:

- the **vessel** (``Model.add_moving_base``) heaves, rolls and pitches by prescribed sums of two
  harmonics each (``rigidfem.motion.harmonics``; cosines, so the base starts at rest, displaced:
  ``BASE``), surge, sway and yaw held at 0;
- the **column** (8 t, 12 m) stands on the deck at (0, 8, 4) m, not slewing (welded to the deck);
- the **boom**: the notebook's steel tube (24 m, 800 × 25 mm, E = 210 GPa, material damping 2e-3 s),
  modified RFEM, 6 sdes / 7 rfes bending in both planes and twisting (``deform=("bend_y", "bend_z",
  "torsion")``: three spring-damped rotations Rz Ry Rx per joint), at a **fixed luffing angle** of
  45°: rfe 0 welded to the column at the pin (the notebook holds it by a luffing cylinder, a distance
  loop; left out here for all codes, see below);
- the **payload**, a 5 t point mass on a custom x-y-z joint from the ground, hangs from the boom tip
  on the **hoisting rope** (``Model.add_rope``: massless, tension only, T = (EA (l − l_u) + D_A (l̇ −
  l̇_u))/l_u while positive, EA = 1e8 N, D_A 5 % of critical at l_u = 14 m), paid in by the winch
  from l_u = 14 m to 12 m between t = 1 and 6 s (``motion.rest_to_rest``, quintic);
- start: the static equilibrium of the crane on the vessel frozen in its pose at t = 0
  (``rigidfem.static_equilibrium(..., t=0)``), at rest (the base's rates are 0 at t = 0); 8 s, the
  payload's position at 161 outputs. The rope stays taut (tension 0.90 … 1.09 m g).

Each code runs against its OWN converged solution (``verify`` first checks those equal rigidfem's):
a run's error is the largest distance over the outputs between its payload and the reference's,
divided by the payload's motion amplitude max_t |p(t) − p(0)| of rigidfem's reference (5.65 m).

How the peers express the model (no Python per step in either):

- Exudyn (``ExudynCrane``): one ``ObjectKinematicTree`` read from the System of the same model
  with the base's joint free (``peers.describe``): the bodies welded to their parents (column, rfe
  0) merged into them, each rfe's three rotations three links (two massless), the payload a second
  root on three prismatic links; springs and dampers its P and D control, its gravity. The base's
  heave, pitch and roll are held on their profiles by ``ObjectConnectorCoordinate``s with the
  profile and its rate as symbolic user functions (C++ expression trees); the rope is an
  ``ObjectConnectorSpringDamper`` between ``MarkerKinematicTreeRigid`` markers whose force is a
  symbolic ``springForceUserFunction`` of t, the length and its rate (the rope's law with the
  winch's quintic l_u(t)). Only the implicit solvers run (GeneralizedAlpha, TrapezoidalIndex2,
  with Exudyn's Newton tolerances and tight ones): Exudyn's explicit solvers drop a coordinate
  constraint's time-dependent offset (``kane_peers``), and the flywheel that replaces it there
  cannot hold the roll here (the crane's heeling moment, ~2e6 N·m, makes a rotor of J drift by
  M t²/(2J): 6e-7 rad over 8 s at J = 1e14 kg·m², 2e-5 m at the tip).
- MuJoCo (``MujocoCrane``): the MJCF of ``peers.to_mjcf`` (welded bodies as bodies without joints),
  the rope a spatial tendon between sites at the boom tip and the payload driven by a ``motor``
  actuator whose force −T the ``mjcb_control`` callback (C, compiled against MuJoCo's headers)
  computes from ``ten_length``, ``ten_velocity`` and t at every stage. MuJoCo has no prescribed
  joint motion (a joint equality holds a constant or a polynomial of another joint, not a function
  of time; a mocap body moves kinematically, with no velocity or acceleration in the dynamics, so
  the crane would not feel the base's accelerations), so the base's joints are servoed flywheels,
  as ``loop_peers``' crank: armature J = 1e10 (kg or kg·m²) and a ``general`` actuator kp·ctrl −
  kp q − kv q̇ (kp = J·300², kv = 2J·300), ctrl = θ + (J θ̈ + kv θ̇)/kp set by the same callback:
  the heeling moment moves the roll by ~2e-9 rad (``verify``'s base_error). MuJoCo's own tendon
  spring cannot be this rope: its ``springlength`` dead band (0, l_u) makes a tension-only spring,
  but its stiffness and dead band are constants of the model (the winch changes both), and its
  damping acts when slack too.

``run`` verifies, sweeps each code's solvers (coarse to fine; a method stops at its first run within
the tightest threshold or after a run over its budget), times the contenders in interleaved rounds
(CPU time, ``time.process_time``, least over the rounds) and prints the cheapest setting per code::

    python -m benchmarks crane_peers [--quick] [--output DIR]

Needs the peer codes: ``pip install exudyn mujoco``. SI units: m, rad, kg, s, N, N·m.
"""

from __future__ import annotations

import ctypes
import dataclasses
import math
import time
import warnings
from dataclasses import dataclass

import numpy as np

import rigidfem as rf
from rigidfem import SimulationError, simulate
from rigidfem.studies.study import Table

from ._common import compile_mujoco_callback, report
from ._peers_common import (CODES, OutputTimes, check_agreement, exudyn_settings, first_run, least_cpu_times,
                            peer_guard, peer_self_checks, summary_table, versions, versions_line)
from .peers import Link, describe, to_mjcf

_peer = peer_guard("crane_peers")

THRESHOLDS = (1e-4, 1e-6)   #: largest payload error over the outputs, relative to its motion amplitude
AGREEMENT = 1e-6            #: relative: largest difference allowed between converged solutions
G = 9.81

# The crane: notebooks/06_offshore_crane.ipynb's numbers
CRANE = (0.0, 8.0, 4.0)                 #: column foot on the deck, m
H_COL, PIN_X, BOOM, LUFF = 12.0, 1.0, 24.0, math.radians(45.0)
M_COL, M_PAY = 8000.0, 5000.0
EA, LU0, LU1 = 1.0e8, 14.0, 12.0        #: rope N; unstretched length before and after hoisting, m
DA = 0.05 * 2.0 * math.sqrt(EA / LU0 * M_PAY) * LU0     #: rope damping D_A, N·s (5 % of critical at l_u0)
WINCH = (1.0, 5.0)                      #: the winch's pay-in: start, duration (s)
ELEMENTS = 6
T_END, OUTPUTS = 8.0, 161

#: The base's motion: coordinate -> (amplitudes, omegas) of a sum of cosines (m or rad, rad/s).
BASE = {"z": ((0.4, 0.2), (0.8, 1.3)),
        "ry": ((math.radians(1.0), math.radians(0.5)), (0.9, 1.4)),
        "rx": ((math.radians(2.0), math.radians(0.8)), (0.7, 1.2))}
SHIP_NAMES = {"z": "heave", "ry": "pitch", "rx": "roll"}

FLYWHEEL = 1e10      #: kg or kg·m², MuJoCo's base joints: flywheels ...
SERVO = 300.0        #: rad/s, ... held on their profiles by critically damped servos
TIGHT_NEWTON = (1e-12, 1e-14)   #: Exudyn's Newton tolerances (relative, absolute) for its references and tight runs


def base_profile(coordinate: str):
    amplitudes, omegas = BASE[coordinate]
    return rf.motion.harmonics(amplitudes, omegas, [math.pi / 2] * len(amplitudes))


def base_motion(t: float, coordinate: str) -> tuple:
    """(q, q̇, q̈) of the base's coordinate at t."""
    a, w = (np.array(v) for v in BASE[coordinate])
    return (float(np.sum(a * np.cos(w * t))), float(-np.sum(a * w * np.sin(w * t))),
            float(-np.sum(a * w * w * np.cos(w * t))))


# ---------------------------------------------------------------------------------------------
# The scene
# ---------------------------------------------------------------------------------------------

def _model(driven: bool, elements: int):
    steel = rf.Material(E=210e9, rho=7850.0, nu=0.3, retardation=2e-3)
    model = rf.Model(gravity=(0.0, 0.0, -G))
    if driven:
        vessel = model.add_moving_base("vessel", {SHIP_NAMES[c]: base_profile(c) for c in BASE})
    else:  # the same model with the base's joint free: the peers' coordinates
        vessel = model.add_body("vessel", model.ground, rf.Joint.free(), mass=1e-6, inertia=(1e-6, 1e-6, 1e-6))
    column = model.add_body("column", vessel, rf.Joint.fixed(), mass=M_COL, inertia=(1e5, 1e5, 5e3),
                            com=(0.0, 0.0, H_COL / 2), placement=rf.transform(CRANE))
    boom = model.add_beam("boom", column, BOOM, steel, rf.Section.tube(0.800, 0.750), elements, formulation="modified",
                          deform=("bend_y", "bend_z", "torsion"), joint=rf.Joint.fixed(),
                          placement=rf.transform((PIN_X, 0.0, H_COL), (0.0, -LUFF, 0.0)))
    tip = np.array(CRANE) + [PIN_X + BOOM * math.cos(LUFF), 0.0, H_COL + BOOM * math.sin(LUFF)]
    payload = model.add_body("payload", model.ground, rf.Joint.custom(["x", "y", "z"]), mass=M_PAY,
                             inertia=(1.0, 1.0, 1.0), placement=rf.transform(tuple(tip - [0.0, 0.0, LU0])))
    model.add_rope("rope", boom.tip, payload, EA=EA, length=rf.motion.rest_to_rest(LU0, LU1, *WINCH), DA=DA)
    return model.compile(), boom.tip, payload


@dataclass
class Crane(OutputTimes):
    """The compiled scene: ``system`` as simulated (the base prescribed) and ``free`` (the base's
    joint free; its chain ``chain``), the rope's ends (``tip``, ``payload``: Point, Body), the initial
    state q0 (``system``'s) and the outputs. ``positions(Q)`` of a code's result Q (N, 3: the
    payload's x, y, z coordinates) is Q itself (the joint frame's offset cancels in every error)."""

    name: str
    system: object
    free: object
    chain: object
    tip: object
    payload: object
    q0: np.ndarray
    t_eval: np.ndarray
    amplitude: float = np.nan

    @property
    def payload_index(self) -> list:
        return [self.system.coordinate_index(f"payload.{c}") for c in "xyz"]

    @staticmethod
    def positions(Q) -> np.ndarray:
        return np.asarray(Q)

    def flexible(self) -> list:
        """The names of ``system``'s coordinates other than the payload's (the boom's)."""
        return [n for n in self.system.coordinate_names if not n.startswith("payload.")]


def crane(elements: int = ELEMENTS, t_end: float = T_END, outputs: int = OUTPUTS) -> Crane:
    system, tip, payload = _model(True, elements)
    free, _, _ = _model(False, elements)
    q = np.zeros(system.nq)
    k = [system.coordinate_index(f"payload.{c}") for c in "xyz"]
    q[k] = system.position(tip, 0.0, q) - system.position(payload, 0.0, q) - [0.0, 0.0, LU0 * (1.0 + M_PAY * G / EA)]
    eq = rf.static_equilibrium(system, q0=q, t=0.0)
    if not eq.converged:
        raise RuntimeError("crane: no static equilibrium at t = 0")
    return Crane(f"crane m={elements}", system, free, describe(free), tip, payload, np.asarray(eq.q),
                 np.linspace(0.0, t_end, outputs))


def omega_max(scene: Crane) -> float:
    """Highest natural frequency (rad/s) of the boom's springs at q0 (the rope left out)."""
    M = scene.system.mass_matrix(0.0, scene.q0)
    K = np.diag(scene.system.stiffness)
    return float(np.sqrt(np.max(np.linalg.eigvals(np.linalg.solve(M, K)).real)))


def peer_chain(scene: Crane) -> tuple:
    """The chain of ``free`` with the base keeping only its driven coordinates (z, ry, rx; its
    x, y, rz are 0: identities), as a tuple of ``Link``s in body order."""
    links = []
    for link in scene.chain.links:
        if link.name == "vessel":
            keep = [link.coordinates.index(c) for c in BASE]
            link = dataclasses.replace(link, coordinates=tuple(BASE), stiffness=link.stiffness[keep],
                                       damping=link.damping[keep], rest=link.rest[keep])
        links.append(link)
    return tuple(links)


def initial(scene: Crane, names) -> np.ndarray:
    """The initial coordinates named ``names`` ("body.axis"): the base's from its profiles at 0,
    the others from ``scene.q0``."""
    out = []
    for name in names:
        body, axis = name.rsplit(".", 1)
        out.append(base_motion(0.0, axis)[0] if body == "vessel" else scene.q0[scene.system.coordinate_index(name)])
    return np.array(out)


def winch(t: float) -> tuple:
    """(l_u, l̇_u) of the winch's quintic pay-in at t."""
    t0, T = WINCH
    tau = min(max((t - t0) / T, 0.0), 1.0)
    return (LU0 + (LU1 - LU0) * (10 * tau**3 - 15 * tau**4 + 6 * tau**5),
            (LU1 - LU0) * (30 * tau**2 - 60 * tau**3 + 30 * tau**4) / T)


# ---------------------------------------------------------------------------------------------
# The three codes: each ``run(method, setting, value, **options)`` returns the payload's x, y, z (outputs, 3)
# ---------------------------------------------------------------------------------------------

class RigidfemCrane:
    code = "rigidfem"

    def __init__(self, scene: Crane):
        self.scene = scene

    def run(self, method: str, setting: str, value: float, **options) -> np.ndarray:
        return np.asarray(self.simulation(method, setting, value, **options).q)[:, self.scene.payload_index]

    def simulation(self, method: str, setting: str, value: float, **options):
        """The run's ``rigidfem.Result`` (``run`` returns the payload's coordinates from it)."""
        kw = {setting: value, **options}
        if setting == "rtol":
            kw["atol"] = value * 1e-2
        s = self.scene
        return simulate(s.system, s.t_end, method=method, q0=s.q0, t_eval=s.t_eval, max_steps=10**8,
                        stiffness_warning=False, **kw)

    def reference(self, rtol: float = 1e-11) -> np.ndarray:
        return self.run("radau5", "rtol", rtol)


def _weld(parent: Link, child: Link) -> Link:
    """``parent`` with ``child`` (welded at its placement) merged into it: mass, centre of mass, inertia."""
    R, r = child.placement[:3, :3], child.placement[:3, 3]
    c_child = R @ child.com + r
    mass = parent.mass + child.mass
    com = (parent.mass * parent.com + child.mass * c_child) / mass

    def shifted(inertia, m, c):
        d = c - com
        return inertia + m * (d @ d * np.eye(3) - np.outer(d, d))

    inertia = shifted(parent.inertia, parent.mass, parent.com) + shifted(R @ child.inertia @ R.T, child.mass, c_child)
    return dataclasses.replace(parent, mass=mass, com=com, inertia=inertia)


def single_axis_tree(links) -> tuple:
    """``links`` (body order) as a tree of one-coordinate links for Exudyn's KinematicTree:
    jointless links welded into their parents (their children's placements composed), a link of k
    coordinates k links (the first at its placement, the others at identity, the body on the last,
    massless before). Returns (tree, where): tree a list of dicts (name, parent, placement, axis,
    mass, com, inertia, stiffness, damping, rest), ``where`` body index -> (tree index of its
    body's link, placement of the body in that link's frame)."""
    tree, where = [], {}
    for p, link in enumerate(links):
        if not link.coordinates:  # welded: merged into its parent's last link
            k, B = where[link.parent]
            host = tree[k]
            merged = _weld(Link(host["name"], -1, np.eye(4), (), host["mass"], host["com"], host["inertia"],
                                np.zeros(0), np.zeros(0), np.zeros(0)),
                           dataclasses.replace(link, placement=B @ link.placement))
            host.update(mass=merged.mass, com=merged.com, inertia=merged.inertia)
            where[p] = (k, B @ link.placement)
            continue
        parent, placement = (-1, link.placement) if link.parent < 0 else \
            (where[link.parent][0], where[link.parent][1] @ link.placement)
        for j, axis in enumerate(link.coordinates):
            last = j == len(link.coordinates) - 1
            tree.append(dict(name=f"{link.name}.{axis}", parent=parent, placement=placement if j == 0 else np.eye(4),
                             axis=axis, mass=link.mass if last else 0.0, com=link.com if last else np.zeros(3),
                             inertia=link.inertia if last else np.zeros((3, 3)), stiffness=float(link.stiffness[j]),
                             damping=float(link.damping[j]), rest=float(link.rest[j])))
            parent = len(tree) - 1
        where[p] = (parent, np.eye(4))
    return tree, where


class ExudynCrane:
    """The scene as one ``ObjectKinematicTree`` (module docstring): the base's coordinates held on
    their profiles by coordinate constraints, the rope a spring-damper with a symbolic force law.
    Fixed steps h dividing the output interval; a ``SensorNode`` records the coordinates at the
    outputs (in memory)."""

    code = "Exudyn"
    METHODS = ("GeneralizedAlpha", "TrapezoidalIndex2")

    def __init__(self, scene: Crane):
        self.exu = _peer("exudyn", "exudyn")
        self.scene = scene
        self.keep = []  # symbolic user functions must outlive the system
        self.sc, self.mbs, self.sensor, self.columns = self._build(scene)

    def _build(self, scene: Crane):
        exu = self.exu
        from exudyn.advancedUtilities import CreateSymbolicUserFunction
        from exudyn.itemInterface import (MarkerKinematicTreeRigid, MarkerNodeCoordinate, NodeGenericODE2,
                                          NodePointGround, ObjectConnectorCoordinate, ObjectConnectorSpringDamper,
                                          ObjectKinematicTree, SensorNode)

        tree, where = single_axis_tree(peer_chain(scene))
        kinds = {"rx": exu.JointType.RevoluteX, "ry": exu.JointType.RevoluteY, "rz": exu.JointType.RevoluteZ,
                 "x": exu.JointType.PrismaticX, "y": exu.JointType.PrismaticY, "z": exu.JointType.PrismaticZ}
        names = [t["name"] for t in tree]
        n = len(tree)
        sc = exu.SystemContainer()
        mbs = sc.AddSystem()
        node = mbs.AddNode(NodeGenericODE2(referenceCoordinates=[0.0] * n,
                                           initialCoordinates=[float(v) for v in initial(scene, names)],
                                           initialCoordinates_t=[0.0] * n, numberOfODE2Coordinates=n))
        body = mbs.AddObject(ObjectKinematicTree(
            nodeNumber=node, jointTypes=[kinds[t["axis"]] for t in tree], linkParents=[t["parent"] for t in tree],
            jointTransformations=exu.Matrix3DList([t["placement"][:3, :3] for t in tree]),
            jointOffsets=exu.Vector3DList([t["placement"][:3, 3] for t in tree]),
            linkInertiasCOM=exu.Matrix3DList([t["inertia"] for t in tree]),
            linkCOMs=exu.Vector3DList([t["com"] for t in tree]), linkMasses=[t["mass"] for t in tree],
            gravity=[float(v) for v in scene.chain.gravity],
            jointPControlVector=[t["stiffness"] for t in tree], jointDControlVector=[t["damping"] for t in tree],
            jointPositionOffsetVector=[t["rest"] for t in tree], jointVelocityOffsetVector=[0.0] * n))
        esym = exu.symbolic
        ground = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=mbs.AddNode(NodePointGround()), coordinate=0))
        def cosines(a, w):  # Σ a cos(ω t) and its rate, as symbolic user functions of t
            def value(mbs, t, itemNumber, lOffset):
                return sum(ak * esym.cos(wk * t) for ak, wk in zip(a, w))

            def rate(mbs, t, itemNumber, lOffset):
                return sum(-ak * wk * esym.sin(wk * t) for ak, wk in zip(a, w))
            return value, rate

        for axis, (amplitudes, omegas) in BASE.items():
            f, f_t = (CreateSymbolicUserFunction(mbs, g, name, itemTypeName="ObjectConnectorCoordinate")
                      for g, name in zip(cosines(amplitudes, omegas), ("offsetUserFunction", "offsetUserFunction_t")))
            self.keep += [f, f_t]
            marker = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=node, coordinate=names.index(f"vessel.{axis}")))
            mbs.AddObject(ObjectConnectorCoordinate(markerNumbers=[ground, marker], offsetUserFunction=f,
                                                    offsetUserFunction_t=f_t))
        t0, T = WINCH

        def tension(mbs, t, itemNumber, deltaL, deltaL_t, stiffness, damping, force):
            tau = esym.min(esym.max((t - t0) / T, 0.0), 1.0)
            lu = LU0 + (LU1 - LU0) * tau * tau * tau * (10.0 - 15.0 * tau + 6.0 * tau * tau)
            lu_t = (LU1 - LU0) * 30.0 * tau * tau * (1.0 - 2.0 * tau + tau * tau) / T
            return esym.max((EA * (deltaL - lu) + DA * (deltaL_t - lu_t)) / lu, 0.0)

        law = CreateSymbolicUserFunction(mbs, tension, "springForceUserFunction",
                                         itemTypeName="ObjectConnectorSpringDamper")
        self.keep.append(law)
        ends = []
        for point in (scene.tip, scene.payload.point((0.0, 0.0, 0.0))):
            k, B = where[point.body]
            ends.append(mbs.AddMarker(MarkerKinematicTreeRigid(objectNumber=body, linkNumber=k,
                                                               localHT=(B @ rf.transform(tuple(point.r))).tolist())))
        mbs.AddObject(ObjectConnectorSpringDamper(markerNumbers=ends, referenceLength=0.0, springForceUserFunction=law))
        sensor = mbs.AddSensor(SensorNode(nodeNumber=node, storeInternal=True,
                                          outputVariableType=exu.OutputVariableType.Coordinates))
        mbs.Assemble()
        return sc, mbs, sensor, {"payload": [names.index(f"payload.{c}") for c in "xyz"],
                                 "base": [names.index(f"vessel.{c}") for c in BASE]}

    def run(self, method: str, setting: str, value: float, newton=None, base: bool = False) -> np.ndarray:
        """``newton``: Newton's (relative, absolute) tolerances, Exudyn's (1e-8, 1e-10) by default;
        ``base``: return the base's coordinates (z, ry, rx) instead of the payload's."""
        if setting != "dt":
            raise ValueError(f"setting: expected dt for Exudyn, got {setting}")
        s, exu = self.scene, self.exu
        ss = exudyn_settings(exu, s.t_end, value, s.interval, end_accelerations=None)
        if newton is not None:
            ss.timeIntegration.newton.relativeTolerance, ss.timeIntegration.newton.absoluteTolerance = newton
        console = exu.config.printToConsole
        exu.config.printToConsole = False
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                ok = self.mbs.SolveDynamic(ss, solverType=getattr(exu.DynamicSolverType, method))
            except Exception as e:  # noqa: BLE001 - Exudyn's solver errors
                raise SimulationError(f"Exudyn {method} dt={value:g}: {str(e)[:60]}") from e
            finally:
                exu.config.printToConsole = console
        data = np.asarray(self.mbs.GetSensorStoredData(self.sensor))
        if ok is False or len(data) != len(s.t_eval) or not np.all(np.isfinite(data)):
            raise SimulationError(f"Exudyn {method} dt={value:g}: failed or unstable")
        if np.max(np.abs(data[:, 0] - s.t_eval)) > 1e-6:
            raise RuntimeError(f"Exudyn {method}: sensor times off the output grid")
        return data[:, 1:][:, self.columns["base" if base else "payload"]]

    def reference(self, step: float | None = None) -> np.ndarray:
        return self.run("GeneralizedAlpha", "dt", step or self.reference_step(), newton=TIGHT_NEWTON)

    def reference_step(self) -> float:
        return self.scene.interval / 512


class MujocoCrane:
    """The scene in MJCF (module docstring): ``peers.to_mjcf`` of the chain, the base's joints servoed
    flywheels, the rope a tendon pulled by a motor; one ``mjcb_control`` callback in C sets the four
    controls. Contacts and constraints disabled; ``mj_step(model, data, nstep)`` between outputs."""

    code = "MuJoCo"
    _lib = None

    def __init__(self, scene: Crane, flywheel: float = FLYWHEEL, servo: float = SERVO):
        mujoco = self.mujoco = _peer("mujoco", "mujoco")
        links = peer_chain(scene)
        chain = dataclasses.replace(scene.chain, links=links)
        xml = to_mjcf(chain, sites={"tip": scene.tip, "hook": scene.payload.point((0.0, 0.0, 0.0))}, timestep=1e-3)
        kp, kv = flywheel * servo**2, 2.0 * flywheel * servo
        actuators = []
        for axis in BASE:
            kind = "hinge" if axis.startswith("r") else "slide"
            old = (f'name="vessel.{axis}" type="{kind}" axis="{ {"z": "0 0 1", "ry": "0 1 0", "rx": "1 0 0"}[axis] }" '
                   'stiffness="0.0" damping="0.0" springref="0.0" armature="0"')
            if old not in xml:
                raise RuntimeError(f"MJCF: the base's joint vessel.{axis} not found")
            xml = xml.replace(old, old[:-3] + f'"{float(flywheel)!r}"')
            actuators.append(f'    <general name="base.{axis}" joint="vessel.{axis}" gainprm="{kp!r}" '
                             f'biastype="affine" biasprm="0 {-kp!r} {-kv!r}"/>')
        actuators.append('    <motor name="rope" tendon="rope" gear="1"/>')
        extra = ["  <tendon>", '    <spatial name="rope">', '      <site site="tip"/>', '      <site site="hook"/>',
                 "    </spatial>", "  </tendon>", "  <actuator>", *actuators, "  </actuator>"]
        self.xml = xml.replace("</mujoco>", "\n".join(extra) + "\n</mujoco>")
        self.model = mujoco.MjModel.from_xml_string(self.xml)
        self.data = mujoco.MjData(self.model)
        names = [f"{link.name}.{axis}" for link in links for axis in link.coordinates]
        self.address = np.array([self.model.joint(name).qposadr[0] for name in names])
        self.q0 = initial(scene, names)
        self.payload = self.address[[names.index(f"payload.{c}") for c in "xyz"]]
        self.base = self.address[[names.index(f"vessel.{c}") for c in BASE]]
        self.gains = (flywheel, kp, kv)
        self.native = self._callback() is not None
        self.scene = scene

    def _callback(self):
        if MujocoCrane._lib is None:
            MujocoCrane._lib = compile_mujoco_callback(self.mujoco, _DRIVE_C, "crane_peers_") or False
        return MujocoCrane._lib or None

    def install(self) -> None:
        """This model's callback (process-wide in MuJoCo)."""
        J, kp, kv = self.gains
        lib = self._callback()
        if lib is not None:
            for name, v in (("cp_J", J), ("cp_kp", kp), ("cp_kv", kv), ("cp_EA", EA), ("cp_DA", DA),
                            ("cp_lu0", LU0), ("cp_lu1", LU1), ("cp_t0", WINCH[0]), ("cp_T", WINCH[1])):
                ctypes.c_double.in_dll(lib, name).value = v
            for k, (amplitudes, omegas) in enumerate(BASE.values()):
                for j, (a, w) in enumerate(zip(amplitudes, omegas)):
                    (ctypes.c_double * 6).in_dll(lib, "cp_a")[2 * k + j] = a
                    (ctypes.c_double * 6).in_dll(lib, "cp_w")[2 * k + j] = w
            self.mujoco.set_mjcb_control(lib.cp_drive)
            return

        def drive(model, data):
            t = data.time
            for k, axis in enumerate(BASE):
                q, qd, qdd = base_motion(t, axis)
                data.ctrl[k] = q + (J * qdd + kv * qd) / kp
            lu, lu_t = winch(t)
            data.ctrl[3] = -max((EA * (data.ten_length[0] - lu) + DA * (data.ten_velocity[0] - lu_t)) / lu, 0.0)
        self.mujoco.set_mjcb_control(drive)

    def run(self, method: str, setting: str, value: float, base: bool = False) -> np.ndarray:
        mujoco, model, data, s = self.mujoco, self.model, self.data, self.scene
        n = int(round(s.interval / value))
        if setting != "dt" or abs(n * value - s.interval) > 1e-9 * s.interval:
            raise ValueError(f"dt: expected a step dividing {s.interval} s, got {setting}={value}")
        model.opt.timestep = value
        model.opt.integrator = getattr(mujoco.mjtIntegrator, f"mjINT_{method.upper()}")
        self.install()
        mujoco.mj_resetData(model, data)
        data.qpos[self.address] = self.q0
        which = self.base if base else self.payload
        out = np.empty((len(s.t_eval), len(which)))
        out[0] = data.qpos[which]
        printer = mujoco.get_mju_user_warning()
        mujoco.set_mju_user_warning(lambda message: None)
        try:
            for k in range(1, len(s.t_eval)):
                mujoco.mj_step(model, data, nstep=n)
                out[k] = data.qpos[which]
        finally:
            mujoco.set_mju_user_warning(printer)
        if data.warning[mujoco.mjtWarning.mjWARN_BADQACC].number or not np.all(np.isfinite(out)):
            raise SimulationError(f"MuJoCo {method} dt={value:g}: unstable")
        return out

    def reference_step(self) -> float:
        return self.scene.interval / 512

    def reference(self, step: float | None = None) -> np.ndarray:
        return self.run("RK4", "dt", step or self.reference_step())


_DRIVE_C = r"""
#include <math.h>
#include <mujoco/mujoco.h>
/* Actuators 0-2: the base's servos (z, ry, rx), force kp ctrl - kp q - kv qdot on a flywheel J, so
   ctrl = th + (J thdd + kv thd)/kp with th a sum of two cosines a cos(w t); actuator 3: the rope, a
   motor on the tendon, force -T with T = max(0, (EA (l - lu) + DA (ldot - ludot))/lu), lu the winch's
   quintic from lu0 to lu1 over [t0, t0 + T]. */
double cp_J = 0.0, cp_kp = 1.0, cp_kv = 0.0, cp_a[6], cp_w[6];
double cp_EA = 0.0, cp_DA = 0.0, cp_lu0 = 1.0, cp_lu1 = 1.0, cp_t0 = 0.0, cp_T = 1.0;
void cp_drive(const mjModel* m, mjData* d) {
  double t = d->time;
  for (int k = 0; k < 3; k++) {
    double th = 0.0, thd = 0.0, thdd = 0.0;
    for (int j = 2 * k; j < 2 * k + 2; j++) {
      double a = cp_a[j], w = cp_w[j], c = cos(w * t), s = sin(w * t);
      th += a * c; thd -= a * w * s; thdd -= a * w * w * c;
    }
    d->ctrl[k] = th + (cp_J * thdd + cp_kv * thd) / cp_kp;
  }
  double tau = (t - cp_t0) / cp_T;
  tau = tau < 0.0 ? 0.0 : (tau > 1.0 ? 1.0 : tau);
  double lu = cp_lu0 + (cp_lu1 - cp_lu0) * tau * tau * tau * (10.0 - 15.0 * tau + 6.0 * tau * tau);
  double lud = (cp_lu1 - cp_lu0) * 30.0 * tau * tau * (1.0 - 2.0 * tau + tau * tau) / cp_T;
  double T = (cp_EA * (d->ten_length[0] - lu) + cp_DA * (d->ten_velocity[0] - lud)) / lu;
  d->ctrl[3] = T > 0.0 ? -T : 0.0;
}
"""


# ---------------------------------------------------------------------------------------------
# Verification, sweeps, timing
# ---------------------------------------------------------------------------------------------

def runners_for(scene: Crane) -> dict:
    return {"rigidfem": RigidfemCrane(scene), "Exudyn": ExudynCrane(scene), "MuJoCo": MujocoCrane(scene)}


def prepare(scene: Crane, runners: dict) -> dict:
    """Each code's converged payload history; sets the scene's amplitude from rigidfem's."""
    references = {code: runner.reference() for code, runner in runners.items()}
    p = references["rigidfem"]
    scene.amplitude = float(np.max(np.linalg.norm(p - p[0], axis=1)))
    return references


def error(scene: Crane, Q, reference) -> float:
    """Largest payload distance over the outputs to ``reference``, relative to the amplitude."""
    return float(np.max(np.linalg.norm(np.asarray(Q) - reference, axis=1)) / scene.amplitude)


def base_error(scene: Crane, runner) -> float:
    """max |q − θ(t)| (m or rad) of a peer's base coordinates against their profiles: MuJoCo's RK4
    at 1/128 of the output interval (within its stability limit; its servo's error hardly depends
    on the step), Exudyn's generalised-α at 1/32 (its constraint holds the profile at every step)."""
    B = runner.run("RK4", "dt", scene.interval / 128, base=True) if runner.code == "MuJoCo" else \
        runner.run("GeneralizedAlpha", "dt", scene.interval / 32, base=True)
    exact = np.array([[base_motion(float(t), axis)[0] for axis in BASE] for t in scene.t_eval])
    return float(np.max(np.abs(B - exact)))


def verify(scene: Crane, runners: dict, references: dict, tolerance: float = AGREEMENT) -> Table:
    """Each code's converged payload history against rigidfem's (largest distance relative to the
    amplitude), how converged each reference is (rigidfem against rtol 100× looser, the peers
    against twice the step), and how closely each peer's base follows its profiles; raises
    ``AssertionError`` when a peer differs from rigidfem by more than ``tolerance``."""
    checks = {"rigidfem": ("radau5 rtol=1e-11 (self-check: rtol=1e-9)", runners["rigidfem"].reference(1e-9), "-")}
    for code, (how, check) in peer_self_checks(runners, TIGHT_NEWTON).items():
        checks[code] = (how, check, base_error(scene, runners[code]))
    rows = []
    for code, (how, check, base) in checks.items():
        d = error(scene, references[code], references["rigidfem"])
        rows.append({"scene": scene.name, "code": code, "reference": how,
                     "self_check_rel": error(scene, check, references[code]), "vs_rigidfem_rel": d,
                     "vs_rigidfem_m": d * scene.amplitude, "base_error": base, "amplitude_m": scene.amplitude})
        check_agreement(scene.name, code, d, tolerance, "payload")
    return Table(rows, VERIFY_COLUMNS)


VERIFY_COLUMNS = ("scene", "code", "reference", "self_check_rel", "vs_rigidfem_rel", "vs_rigidfem_m", "base_error",
                  "amplitude_m")


def settings(scene: Crane, quick: bool = False) -> dict:
    """code -> [(method, setting, values[, options])], coarse to fine. Fixed steps divide the
    output interval, ~√2 apart (the explicit ones from near their stability limits up)."""
    divisors = [1, 2, 3, 4, 6, 8, 11, 16, 23, 32, 45, 64, 91, 128, 181, 256, 362, 512, 724, 1024]
    rtols = [1e-3, 3e-4, 1e-4, 3e-5, 1e-5, 3e-6, 1e-6, 3e-7, 1e-7, 3e-8, 1e-8, 3e-9, 1e-9, 1e-10]
    if quick:
        divisors, rtols = divisors[::3], rtols[::3]

    def steps(least: int = 1):
        return [scene.interval / k for k in divisors if k >= least]

    rigid = [("auto", "rtol", rtols), ("radau5", "rtol", rtols), ("radau9", "rtol", rtols), ("esdirk43", "rtol", rtols),
             ("dopri5", "rtol", rtols), ("rk4", "dt", steps(64)), ("generalized_alpha", "dt", steps()),
             ("generalized_alpha", "dt", steps(), {"newton_tol": 1e-13})]
    return {
        "rigidfem": rigid,
        "Exudyn": [(method, "dt", steps(), *options) for method in ExudynCrane.METHODS
                   for options in ((), ({"newton": TIGHT_NEWTON},))],
        "MuJoCo": [("Euler", "dt", steps(23)), ("implicitfast", "dt", steps(4)), ("discrete", "dt", steps(4)),
                   ("RK4", "dt", steps(45))],
    }


def sweep(scene: Crane, runners: dict, references: dict, todo: dict, budget: float = 20.0) -> list:
    """Each code's settings, coarse to fine; a method stops after its first run within
    min(THRESHOLDS), once a run took more than ``budget`` s, after 6 failures in a row, or at an
    error floor (no gain by 10 % over two finer steps). Rows: scene, code, method, setting, value,
    rel_error (against that code's reference), first_cpu_s, note, run."""
    rows = []
    for code, methods in todo.items():
        runner, ref = runners[code], references[code]
        for method, setting, values, *extra in methods:
            options = extra[0] if extra else {}
            label = method + "".join(f" {k}={v}" for k, v in options.items())
            errors, failures = [], 0
            for value in values:
                row = {"scene": scene.name, "code": code, "method": label, "setting": setting, "value": value,
                       "note": "", "run": (method, options)}
                first_run(row, lambda: runner.run(method, setting, value, **options),
                          lambda Q: {"rel_error": error(scene, Q, ref)}, "rel_error")
                rows.append(row)
                e = row["rel_error"]
                failures = failures + 1 if not np.isfinite(e) or e > 1.0 else 0
                if e < 1.0:
                    errors.append(e)
                if e <= min(THRESHOLDS) or row["first_cpu_s"] > budget:
                    break
                if failures >= 6 or (len(errors) >= 3 and errors[-1] > 0.9 * errors[-2] > 0.81 * errors[-3]):
                    row["note"] = (row["note"] + "; " if row["note"] else "") + "sweep stopped: " + \
                        ("6 failures in a row" if failures >= 6 else "error floor")
                    break
    return rows


def timed(rows: list, runners: dict, rounds: int, long: float = 3.0, contenders: float = 3.0) -> None:
    """``cpu_s`` of each row: the least CPU time over ``rounds`` more interleaved rounds for the
    contenders (per code and threshold, the runs within it whose first time is at most
    ``contenders`` times the least first time, and at most ``long`` s), else its first time."""
    groups = {}
    for r in rows:
        r["cpu_s"] = r["first_cpu_s"]
    for code in dict.fromkeys(r["code"] for r in rows):
        chosen = {}
        for tol in THRESHOLDS:
            within = [r for r in rows if r["code"] == code and r["rel_error"] <= tol]
            if within:
                least = min(r["first_cpu_s"] for r in within)
                chosen.update({id(r): r for r in within if r["first_cpu_s"] <= min(contenders * least, long)})
        groups[code] = list(chosen.values())

    def again(r):
        method, options = r["run"]
        runners[r["code"]].run(method, r["setting"], r["value"], **options)
    least_cpu_times(groups, again, rounds)


def summary(rows: list, scene: Crane) -> Table:
    return summary_table(rows, {"scene": scene.name}, "rel_error", "rel_error", THRESHOLDS, CODES,
                         extra={"error_m": lambda r: r["rel_error"] * scene.amplitude})


SWEEP_COLUMNS = ("scene", "code", "method", "setting", "value", "rel_error", "cpu_s", "first_cpu_s", "note")


def run(output_dir="bench", quick: bool = False) -> dict:
    """``python -m benchmarks crane_peers``: the crane (8 s; ``quick``: 2 s, fewer settings, one
    timing round): verify the peers' models against rigidfem's, sweep every code's solvers, time
    the contenders in 3 interleaved rounds and print the cheapest setting per code and threshold.
    Writes crane_peers_{verification,sweep,summary}.csv into ``output_dir``."""
    print(versions_line(versions(_peer)), flush=True)
    start = time.perf_counter()
    scene = crane(t_end=2.0 if quick else T_END, outputs=41 if quick else OUTPUTS)
    runners = runners_for(scene)
    if not runners["MuJoCo"].native:
        print("note: no C compiler: MuJoCo's callback is in Python (its times include Python)")
    references = prepare(scene, runners)
    checks = verify(scene, runners, references)
    print(f"[{time.perf_counter() - start:6.1f} s] {scene.name}: models verified "
          f"(ω_max = {omega_max(scene):.4g} rad/s, amplitude {scene.amplitude:.4g} m)", flush=True)
    rows = sweep(scene, runners, references, settings(scene, quick), budget=5.0 if quick else 20.0)
    print(f"[{time.perf_counter() - start:6.1f} s] {scene.name}: swept {len(rows)} runs", flush=True)
    timed(rows, runners, rounds=1 if quick else 3)
    print(f"[{time.perf_counter() - start:6.1f} s] {scene.name}: timed", flush=True)
    s = summary(rows, scene)
    tables = report({
        "crane_peers_verification": ("The crane, models verified equal: each code's converged payload history against "
                                     "rigidfem's (relative to the amplitude), its self-check and how its base "
                                     "follows the profiles", checks),
        "crane_peers_sweep": ("The crane, every run: payload error relative to the amplitude against the code's own "
                              "converged solution, least CPU time (s)", Table(rows, SWEEP_COLUMNS)),
        "crane_peers_summary": ("The crane, cheapest runs: least CPU time (s) per code to each relative payload error, and "
                                "the peers' time over rigidfem's", s),
    }, output_dir)
    return {name[len("crane_peers_"):]: table for name, table in tables.items()}
