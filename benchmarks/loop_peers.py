"""Closed loops side by side: rigidfem, Exudyn and MuJoCo (issue 29, row 1).

Two scenes, each built once in rigidfem and rebuilt in the peers from the compiled System (bodies,
masses, centres of mass, inertias, placements, joint axes, springs), with the same loop frames:

- ``slider_crank(m)``: tests/test_slider_crank.py's mechanism, rebuilt here from its documented
  numbers (its builder lives in the test only; the two Systems run identically, bit for bit). Planar, no gravity: a rigid crank of R = 0.15 m
  driven by Kane's spin-up θ(t) = (Ω/T)[t²/2 + (T/2π)²(cos 2πt/T − 1)] to Ω = 50 rad/s over
  T = 0.2 s; a flexible aluminium rod of L = 0.6 m (E = 70 GPa, ρ = 2700 kg/m³, 5 × 20 mm, m sdes
  bending in the plane, modified formulation) pinned to the crank; a 0.1 kg slider on a guide along
  x; a revolute loop joint closing the slider pin (3 of its 5 rows redundant in the plane). Run
  0.45 s from the dead centre at rest, 91 outputs; observed: the rod's midpoint.
- ``bricard()``: a rigid Bricard linkage, the orthogonal one: six revolute joints at the corners of
  the cube's skew hexagon (0,0,0) → (1,0,0) → (1,1,0) → (1,1,1) → (0,1,1) → (0,0,1) → back, axes
  y, z, x, y, z, x (each normal to both links it joins: all links 1 m, twists 90°, no offsets);
  five 1 m rods of 1 kg (0.1 m square sections) on five revolute joints from the ground, the sixth
  joint a revolute loop joint from the last rod to the ground. The tree has 5 coordinates and the
  loop 5 rows, so Grübler counts 0 degrees of freedom; the linkage has 1 (G has rank 4: one row
  is redundant, and not always the same one). Released at rest under gravity −9.81 m/s² along y,
  10 s, 201 outputs; observed: the joint between rods 3 and 4, starting at (1, 1, 1) m and moving
  up to 3.17 m from there.

Each code is run against its OWN converged solution (``verify`` first checks those equal
rigidfem's): the error of a run is the largest distance over the outputs between its point and the
reference's, divided by the point's motion amplitude A = max_t |p(t) − p(0)| of rigidfem's
reference (A = 0.300 m on the slider-crank, 3.17 m on the Bricard). The loop closure a code keeps
is max |g| over the outputs, with g rigidfem's loop rows (m for positions, cosines for the
directions of the revolute's axis) evaluated at that code's own coordinates, the crank's angle
included (``Scene.free``: the same model with every joint free).

How the peers express the models (no Python per step in either):

- Exudyn (``ExudynLoops``): one ``ObjectKinematicTree`` of the chain (several roots: the slider is
  a second root on a PrismaticX joint), springs as its P control; each loop an
  ``ObjectJointGeneric`` between ``MarkerKinematicTreeRigid`` markers (or a ground marker) at the
  loop's frames. The slider pin constrains x and y of the pin only (``constrainedAxes`` 1,1,0,0,0,0:
  its other rows vanish identically in the plane and would make Exudyn's Jacobian singular); the
  Bricard's closing revolute holds all 5 rows (1,1,1,1,1,0), and its redundant row is handled by
  Eigen's full-pivoting LU (``linearSolver.solverType = EigenDense``,
  ``ignoreSingularJacobian = True``: Exudyn's default dense solver stops on the singular
  Jacobian). The crank's drive is an ``ObjectConnectorCoordinate`` with θ(t) and θ̇(t) as
  symbolic user functions (C++ expression trees). Only the implicit solvers run: Exudyn's
  explicit solvers take no constraints but coordinate constraints (its documentation), so
  GeneralizedAlpha (index 3) and TrapezoidalIndex2 at fixed steps, each with Exudyn's Newton
  tolerances (relative 1e-8, absolute 1e-10) and with tight ones (``TIGHT_NEWTON``): the defaults
  leave an error floor that no step size removes (1.1e-5 of the amplitude on the Bricard over
  10 s). Its references: GeneralizedAlpha with the tight tolerances.
- MuJoCo (``MujocoLoops``): the MJCF of ``peers.to_mjcf`` (hinges and slides with their springs)
  with constraints enabled and the loops as ``connect`` equalities between sites: the slider pin
  one connect (its z row vanishes identically), the Bricard's revolute two connects, at the joint
  and 1 m along its axis (6 rows for 5; the connects leave the rotation about the axis free).
  MuJoCo's constraints are soft: solref (1e-6, 1), which its refsafe rule raises to a time
  constant of 2 steps, the stiffest it allows at each step, and solimp (0.9999, 0.9999, 0.001,
  0.5, 2), the hardest impedance it takes; as the step goes to 0 the constraint's softness goes
  with it, so MuJoCo's converged solution is the rigid loop's. The crank's drive: MuJoCo has no
  prescribed joint motion (a joint equality holds a joint at a constant or a polynomial of
  another joint, not a function of time), so the crank is a servoed flywheel: rotor inertia
  (armature) J = 1e8 kg·m² and a ``general`` actuator of force kp·ctrl − kp q − kv q̇ (affine
  bias, kp = J·300², kv = 2J·300: a critically damped 300 rad/s servo) whose control
  ctrl = θ + (J θ̈ + kv θ̇)/kp an ``mjcb_control`` callback compiled in C sets at every stage
  (without a C compiler a Python callback, and the times say so): the torque is J θ̈(t) plus
  kp (θ − q) + kv (θ̇ − q̇), so the loop's reaction (8 N·m at most) leaves the crank within
  1e-12 rad of θ(t) (``verify``'s drive_error_rad). (``kane_peers``' pure flywheel, J = 1e10 and
  the torque J θ̈ alone, fails here: θ̈ reaches 500 rad/s² and MuJoCo drops a control above 1e10
  as "huge"; a lighter flywheel lets the reaction move the crank by 1e-7 rad.) Integrators Euler
  (semi-implicit), implicitfast, RK4 and discrete (new in MuJoCo 4; implicit in the joint
  springs), fixed steps, ``mj_step(model, data, nstep)`` between outputs.

``run`` verifies, sweeps each code's solvers (coarse to fine; a method stops at its first run
within the tightest threshold or after a run over its budget), times the contenders reaching a
threshold in interleaved rounds (CPU time, ``time.process_time``, least over the rounds) and prints
the cheapest setting per code::

    python -m benchmarks loop_peers [--quick] [--output DIR]

Needs the peer codes: ``pip install exudyn mujoco``. SI units: m, rad, kg, s, N, N·m.
"""

from __future__ import annotations

import ctypes
import math
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

import rigidfem as rf
from rigidfem import simulate
from rigidfem.studies.study import Table

from . import _peers_common as common
from ._common import compile_mujoco_callback, report
from ._peers_common import CODES, INSTALL_HINT  # noqa: F401 - INSTALL_HINT kept: this module's name for it
from ._peers_common import (exudyn_settings, exudyn_solve, first_run, least_cpu_times, mujoco_fixed_step,
                            mujoco_outputs, summary_columns, summary_table)
from .kane_peers import exudyn_spin_up
from .peers import Chain, describe, to_mjcf

THRESHOLDS = (1e-4, 1e-6)   #: largest point error over the outputs, relative to the point's motion amplitude
AGREEMENT = 1e-7            #: relative: largest difference allowed between converged solutions
CRANK_ARMATURE = 1e8        #: kg·m², MuJoCo's crank: a flywheel ...
CRANK_SERVO = 300.0         #: rad/s, ... held on θ(t) by a critically damped servo of this frequency

# The slider-crank: tests/test_slider_crank.py's numbers
CRANK, ROD = 0.15, 0.6                    #: crank and rod lengths (m)
E_ROD, RHO_ROD = 70e9, 2700.0             #: aluminium (Pa, kg/m³)
WIDTH, DEPTH = 0.005, 0.02                #: rod section: width in the plane of motion, depth (m)
M_SLIDER = 0.1                            #: kg
OMEGA, T_SPIN = 50.0, 0.2                 #: crank speed (rad/s) reached after the spin-up time (s)
CRANK_MASS, CRANK_INERTIA_C = 1.0, 2e-3   #: kg, kg·m² about the crank's centre (R/2)
SLIDER_CRANK_END, SLIDER_CRANK_OUTPUTS = 0.45, 91

# The Bricard linkage
BRICARD_LINK, BRICARD_MASS, BRICARD_SIDE = 1.0, 1.0, 0.1   #: m, kg, m (square section)
BRICARD_END, BRICARD_OUTPUTS = 10.0, 201


_peer = common.peer_guard("loop_peers")


# ---------------------------------------------------------------------------------------------
# The scenes
# ---------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class Loop:
    """A revolute loop joint between frame A on body ``a`` and frame B on body ``b`` (indices in
    the System, -1 the ground; frames (4, 4) in the body frames, z the joint's axis), as given to
    ``Model.add_loop_joint``. ``held``: the rows a peer keeps, in frame A (x, y, z, rx, ry, rz)."""

    name: str
    a: int
    frame_a: np.ndarray
    b: int
    frame_b: np.ndarray
    held: tuple = (1, 1, 1, 1, 1, 0)


@dataclass
class Scene(common.OutputTimes):
    """A scene: rigidfem's System as simulated (``system``, the crank prescribed) and the same
    model with every joint free (``free``: the peers' coordinates, for positions and closure);
    the chain read from ``free``; its loops, observed point, initial state (``free`` coordinates),
    drive (the free coordinate prescribed in ``system`` and its Profile) and outputs."""

    name: str
    system: object
    free: object
    chain: Chain
    loops: tuple
    point: object
    q0: np.ndarray
    t_eval: np.ndarray
    drive: tuple | None = None          #: (coordinate name, Profile) or None
    planar: bool = False
    omega_max: float = 0.0              #: highest natural frequency at q0 (rad/s), of the free tree
    amplitude: float = field(default=np.nan)

    def system_state(self):
        """(q0, q̇0) of ``system`` (the drive's coordinate removed)."""
        names = list(self.free.coordinate_names)
        keep = [names.index(n) for n in self.system.coordinate_names]
        return self.q0[keep], np.zeros(len(keep))

    def to_free(self, t, q) -> np.ndarray:
        """``system``'s q (N, nq) at the times t as ``free`` coordinates (N, nq + np)."""
        names = list(self.free.coordinate_names)
        out = np.empty((len(t), len(names)))
        out[:, [names.index(n) for n in self.system.coordinate_names]] = q
        if self.drive is not None:
            coordinate, profile = self.drive
            out[:, names.index(coordinate)] = [profile(float(s))[0] for s in t]
        return out

    def positions(self, Q) -> np.ndarray:
        """The observed point (N, 3), m, at the free coordinates Q (N, nq)."""
        return np.array([self.free.position(self.point, 0.0, q) for q in Q])

    def drive_error(self, Q):
        """max |q − θ(t)| (rad) of the driven coordinate over the outputs, or "-" without a drive."""
        if self.drive is None:
            return "-"
        coordinate, profile = self.drive
        k = list(self.free.coordinate_names).index(coordinate)
        return float(max(abs(q[k] - profile(float(t))[0]) for t, q in zip(self.t_eval, Q)))

    def closure(self, Q) -> float:
        """max |g| over the rows and outputs (m or cosine) at the free coordinates Q."""
        zero = np.zeros(Q.shape[1])
        return float(max(np.max(np.abs(self.free.loop_constraints(0.0, q, zero)[0])) for q in Q))


def _slider_crank_model(m: int, driven: bool):
    model = rf.Model(gravity=None)
    crank = model.add_body("crank", model.ground, rf.Joint.revolute("z"), mass=CRANK_MASS, com=(CRANK / 2, 0, 0),
                           inertia=(1e-4, CRANK_INERTIA_C, CRANK_INERTIA_C))
    if driven:
        model.prescribe(crank, rf.motion.spin_up(OMEGA, T_SPIN))
    rod = model.add_beam("rod", crank, ROD, rf.Material(E=E_ROD, rho=RHO_ROD),
                         rf.Section.rectangle(width=WIDTH, height=DEPTH), elements=m, deform=("bend_z",),
                         joint=rf.Joint.revolute("z"), placement=rf.transform((CRANK, 0, 0)))
    slider = model.add_body("slider", model.ground, rf.Joint.prismatic("x"), mass=M_SLIDER,
                            inertia=(1e-5, 1e-5, 1e-5))
    tip = rod.tip
    loop = Loop("slider pin", slider.index, np.eye(4), tip.body, rf.transform(tuple(tip.r)), (1, 1, 0, 0, 0, 0))
    model.add_loop_joint(loop.name, "revolute", slider, rod.rfes[-1], frame_a=loop.frame_a, frame_b=loop.frame_b)
    return model.compile(), rod, loop


def _omega_max(system, q) -> float:
    """Highest natural frequency (rad/s) of the tree (loops open) at q."""
    M = system.mass_matrix(0.0, q)
    K = np.diag(system.stiffness)
    return float(np.sqrt(max(np.max(np.linalg.eigvals(np.linalg.solve(M, K)).real), 0.0)))


def slider_crank(m: int = 16, outputs: int = SLIDER_CRANK_OUTPUTS, t_end: float = SLIDER_CRANK_END) -> Scene:
    """The slider-crank with m sdes in the rod (tests/test_slider_crank.py's model)."""
    system, _, loop = _slider_crank_model(m, driven=True)
    free, rod, _ = _slider_crank_model(m, driven=False)
    q0 = np.zeros(free.nq)
    q0[free.coordinate_index("slider.x")] = CRANK + ROD      # the dead centre, rod straight
    scene = Scene(f"slider-crank m={m}", system, free, describe(free), (loop,), rod.point(ROD / 2), q0,
                  np.linspace(0.0, t_end, outputs), ("crank.rz", rf.motion.spin_up(OMEGA, T_SPIN)), planar=True,
                  omega_max=_omega_max(free, q0))
    _check_closed(scene)
    return scene


def bricard(outputs: int = BRICARD_OUTPUTS, t_end: float = BRICARD_END) -> Scene:
    """The orthogonal Bricard linkage released under gravity (module docstring)."""
    L, mass, side = BRICARD_LINK, BRICARD_MASS, BRICARD_SIDE
    model = rf.Model(gravity=(0.0, -9.81, 0.0))
    links = [(1, 0, 0), (0, 1, 0), (0, 0, 1), (-1, 0, 0), (0, -1, 0)]   # rods 1..5 at q = 0 (the sixth: the ground)
    axes = ["y", "z", "x", "y", "z"]                                   # joints at their first ends
    parent, start, rods = model.ground, np.zeros(3), []
    for k, (direction, axis) in enumerate(zip(links, axes)):
        d = np.array(direction, float)
        inertia = np.full(3, mass * (L * L + side * side) / 12)
        inertia[np.argmax(np.abs(d))] = mass * side * side / 6
        rod = model.add_body(f"rod{k + 1}", parent, rf.Joint.revolute(axis), mass=mass, inertia=inertia,
                             com=tuple(d * L / 2), placement=rf.transform(tuple(start)))
        rods.append(rod)
        parent, start = rod, d * L
    # The sixth joint, about x at (0, 0, 1): the end of rod 5 to the ground (z of the loop frames along x).
    along_x = (0.0, math.pi / 2, 0.0)
    loop = Loop("P5", rods[-1].index, rf.transform((0.0, -L, 0.0), along_x), -1, rf.transform((0.0, 0.0, L), along_x))
    model.add_loop_joint(loop.name, "revolute", rods[-1], model.ground, frame_a=loop.frame_a, frame_b=loop.frame_b)
    system = model.compile()
    q0 = np.zeros(system.nq)
    scene = Scene("Bricard", system, system, describe(system), (loop,), rods[2].point((0.0, 0.0, L)), q0,
                  np.linspace(0.0, t_end, outputs), omega_max=0.0)
    _check_closed(scene)
    G = system.loop_constraints(0.0, q0, q0)[2]
    rank = np.linalg.matrix_rank(G, 1e-9)
    if rank != system.nq - 1:
        raise AssertionError(f"Bricard: expected rank G = {system.nq - 1} (one degree of freedom), got {rank}")
    return scene


def _check_closed(scene: Scene) -> None:
    g = scene.free.loop_constraints(0.0, scene.q0, np.zeros_like(scene.q0))[0]
    if np.max(np.abs(g)) > 1e-14:
        raise AssertionError(f"{scene.name}: the initial state does not close the loops "
                             f"(|g| = {np.max(np.abs(g)):.3g})")


# ---------------------------------------------------------------------------------------------
# The three codes: each ``run(method, setting, value)`` returns the free coordinates (outputs, nq)
# ---------------------------------------------------------------------------------------------

class RigidfemLoops:
    code = "rigidfem"

    def __init__(self, scene: Scene):
        self.scene = scene
        self.q0, self.qd0 = scene.system_state()

    def run(self, method: str, setting: str, value: float, **options) -> np.ndarray:
        """``options``: more of simulate's (e.g. newton_tol)."""
        kw = {setting: value, **options}
        if setting == "rtol":
            kw["atol"] = value * 1e-2
        s = self.scene
        r = simulate(s.system, s.t_end, method=method, q0=self.q0, qd0=self.qd0, t_eval=s.t_eval, max_steps=10**8,
                     stiffness_warning=False, **kw)
        return s.to_free(r.t, np.asarray(r.q))

    def reference(self) -> np.ndarray:
        return self.run("dopri5", "rtol", 1e-12)


class ExudynLoops:
    """The scene as one ``ObjectKinematicTree`` with ``ObjectJointGeneric`` loops (module
    docstring). Fixed steps h dividing the output interval; a ``SensorNode`` records the
    coordinates at the outputs (in memory), no solution file; modified Newton, spectral radius
    0.9 and Newton's tolerances are Exudyn's defaults."""

    code = "Exudyn"
    METHODS = ("GeneralizedAlpha", "TrapezoidalIndex2")

    def __init__(self, scene: Scene):
        self.exu = _peer("exudyn", "exudyn")
        self.scene = scene
        self.keep = []  # symbolic user functions must outlive the system
        self.sc, self.mbs, self.sensor = self._build(scene)

    def _build(self, scene: Scene):
        exu = self.exu
        from exudyn.itemInterface import (MarkerBodyRigid, MarkerKinematicTreeRigid, MarkerNodeCoordinate,
                                          NodeGenericODE2, ObjectGround, ObjectJointGeneric, ObjectKinematicTree,
                                          SensorNode)

        chain = scene.chain
        kinds = {"rx": exu.JointType.RevoluteX, "ry": exu.JointType.RevoluteY, "rz": exu.JointType.RevoluteZ,
                 "x": exu.JointType.PrismaticX, "y": exu.JointType.PrismaticY, "z": exu.JointType.PrismaticZ}
        for link in chain.links:
            if len(link.coordinates) != 1:
                raise ValueError(f"scene: expected one coordinate per body, got {link.coordinates} on {link.name}")
        if tuple(f"{link.name}.{link.coordinates[0]}" for link in chain.links) != chain.coordinate_names:
            raise ValueError("scene: expected the coordinates in body order")
        n = chain.nq
        sc = exu.SystemContainer()
        mbs = sc.AddSystem()
        q0 = [float(v) for v in scene.q0]
        node = mbs.AddNode(NodeGenericODE2(referenceCoordinates=[0.0] * n, initialCoordinates=q0,
                                           initialCoordinates_t=[0.0] * n, numberOfODE2Coordinates=n))
        tree = mbs.AddObject(ObjectKinematicTree(
            nodeNumber=node, jointTypes=[kinds[link.coordinates[0]] for link in chain.links],
            linkParents=[link.parent for link in chain.links],
            jointTransformations=exu.Matrix3DList([link.placement[:3, :3] for link in chain.links]),
            jointOffsets=exu.Vector3DList([link.placement[:3, 3] for link in chain.links]),
            linkInertiasCOM=exu.Matrix3DList([link.inertia for link in chain.links]),
            linkCOMs=exu.Vector3DList([link.com for link in chain.links]),
            linkMasses=[link.mass for link in chain.links],
            gravity=[float(v) for v in chain.gravity],
            jointPControlVector=[float(v) for v in chain.stiffness],
            jointDControlVector=[float(v) for v in chain.damping],
            jointPositionOffsetVector=[float(v) for v in chain.rest],
            jointVelocityOffsetVector=[0.0] * n))
        ground = None

        def marker(body: int, frame: np.ndarray):
            """A rigid marker at the loop's frame (4, 4) on a link of the tree, or on the ground."""
            nonlocal ground
            if body >= 0:
                return mbs.AddMarker(MarkerKinematicTreeRigid(objectNumber=tree, linkNumber=body,
                                                              localHT=frame.tolist()))
            if ground is None:
                ground = mbs.AddObject(ObjectGround())
            return mbs.AddMarker(MarkerBodyRigid(bodyNumber=ground, localHT=frame.tolist()))

        for loop in scene.loops:
            mbs.AddObject(ObjectJointGeneric(markerNumbers=[marker(loop.a, loop.frame_a), marker(loop.b, loop.frame_b)],
                                             constrainedAxes=list(loop.held)))
        if scene.drive is not None:
            coordinate, _ = scene.drive
            driven = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=node,
                                                        coordinate=chain.coordinate_names.index(coordinate)))
            self.keep += exudyn_spin_up(exu, mbs, driven, OMEGA, T_SPIN)
        sensor = mbs.AddSensor(SensorNode(nodeNumber=node, storeInternal=True,
                                          outputVariableType=exu.OutputVariableType.Coordinates))
        mbs.Assemble()
        return sc, mbs, sensor

    def settings(self, method: str, h: float, newton=None):
        """Exudyn's settings for a run at the step h; ``newton``: Newton's (relative, absolute)
        tolerances instead of Exudyn's (1e-8, 1e-10)."""
        exu, s = self.exu, self.scene
        ss = exudyn_settings(exu, s.t_end, h, s.interval, end_accelerations=None)
        ti = ss.timeIntegration
        if not s.planar:  # the Bricard's redundant row: Eigen's full-pivoting LU
            ss.linearSolver.solverType = exu.LinearSolverType.EigenDense
            ss.linearSolver.ignoreSingularJacobian = True
        if newton is not None:
            ti.newton.relativeTolerance, ti.newton.absoluteTolerance = newton
        return ss

    def run(self, method: str, setting: str, value: float, newton=None) -> np.ndarray:
        """``newton``: Newton's (relative, absolute) tolerances, Exudyn's (1e-8, 1e-10) by default."""
        if setting != "dt":
            raise ValueError(f"setting: expected dt for Exudyn, got {setting}")
        ss = self.settings(method, value, newton)
        data = exudyn_solve(self.exu, self.mbs, ss, self.sensor, method, value, self.scene.t_eval,
                            text=lambda e: str(e)[:60], quiet=True)
        return data[:, 1:]

    def reference_step(self) -> float:
        return self.scene.interval / REFERENCE_STEPS[self.scene.planar][0]

    def reference(self, step: float | None = None) -> np.ndarray:
        return self.run("GeneralizedAlpha", "dt", step or self.reference_step(), newton=TIGHT_NEWTON)


#: Exudyn's Newton tolerances (relative, absolute) for its references and its "tight" runs: its
#: defaults (1e-8, 1e-10) leave an error floor (1.1e-5 of the amplitude on the Bricard over 10 s,
#: the same at h = interval/256 and /1024), as rigidfem's newton_tol does (``TIGHT_NEWTON_TOL``).
TIGHT_NEWTON = (1e-12, 1e-14)
TIGHT_NEWTON_TOL = 1e-13

#: The peers' reference steps: (Exudyn's GeneralizedAlpha, MuJoCo's RK4) as divisors of the output
#: interval, by scene kind (planar slider-crank: True; Bricard: False).
REFERENCE_STEPS = {True: (512, 128), False: (2048, 512)}


class MujocoLoops:
    """The scene in MJCF (module docstring): ``peers.to_mjcf`` of the chain with constraints
    enabled, the loops as site-to-site ``connect`` equalities, the crank (if driven) a flywheel
    whose torque an ``mjcb_control`` callback in C sets. Contacts disabled; ``mj_step(model,
    data, nstep)`` between outputs (no Python per step)."""

    code = "MuJoCo"
    SOLREF = "1e-06 1"
    SOLIMP = "0.9999 0.9999 0.001 0.5 2"

    _lib = None

    def __init__(self, scene: Scene, armature: float = CRANK_ARMATURE, servo: float = CRANK_SERVO):
        mujoco = self.mujoco = _peer("mujoco", "mujoco")
        chain = scene.chain
        sites, world, equalities = {}, [], []
        for k, loop in enumerate(scene.loops):
            # connect 0 at the joint; for a 3D revolute, connect 1 one metre along its axis
            offsets = [np.zeros(3)] if scene.planar else [np.zeros(3), np.array([0.0, 0.0, 1.0])]
            for j, offset in enumerate(offsets):
                names = []
                for side, (body, frame) in enumerate(((loop.a, loop.frame_a), (loop.b, loop.frame_b))):
                    name = f"loop{k}.{j}.{'ab'[side]}"
                    r = frame[:3, :3] @ offset + frame[:3, 3]
                    if body >= 0:
                        sites[name] = _Site(body, r)
                    else:
                        world.append(f'    <site name="{name}" pos="{" ".join(repr(float(v)) for v in r)}"/>')
                    names.append(name)
                equalities.append(f'    <connect site1="{names[0]}" site2="{names[1]}" solref="{self.SOLREF}" '
                                  f'solimp="{self.SOLIMP}"/>')
        xml = to_mjcf(chain, sites=sites, timestep=1e-3)
        flag = '<flag contact="disable" constraint="disable"/>'
        if flag not in xml:
            raise RuntimeError("MJCF: flags not found")
        xml = xml.replace(flag, '<flag contact="disable"/>')
        xml = xml.replace("  <worldbody>\n", "  <worldbody>\n" + "".join(w + "\n" for w in world), 1)
        extra = ["  <equality>", *equalities, "  </equality>"]
        self.driven = scene.drive is not None
        if self.driven:
            joint = scene.drive[0]
            old = f'name="{joint}" type="hinge" axis="0 0 1" stiffness="0.0" damping="0.0" springref="0.0" armature="0"'
            if old not in xml:
                raise RuntimeError("MJCF: the crank's joint not found")
            xml = xml.replace(old, old[:-3] + f'"{float(armature)!r}"')
            kp, kv = armature * servo**2, 2.0 * armature * servo
            extra += ["  <actuator>", f'    <general name="drive" joint="{joint}" gainprm="{kp!r}" '
                      f'biastype="affine" biasprm="0 {-kp!r} {-kv!r}"/>', "  </actuator>"]
        self.xml = xml.replace("</mujoco>", "\n".join(extra) + "\n</mujoco>")
        self.model = mujoco.MjModel.from_xml_string(self.xml)
        self.data = mujoco.MjData(self.model)
        self.address = np.array([self.model.joint(name).qposadr[0] for name in chain.coordinate_names])
        self.gains = (armature, armature * servo**2, 2.0 * armature * servo)
        self.native = not self.driven or self._callback() is not None
        self.scene = scene

    def _callback(self):
        """The drive's control callback in C (a ctypes library), or None without a C compiler."""
        if MujocoLoops._lib is None:
            MujocoLoops._lib = _compile_drive(self.mujoco) or False
        return MujocoLoops._lib or None

    def install(self) -> None:
        """This model's control callback (process-wide in MuJoCo): the crank's servo, or none."""
        if not self.driven:
            self.mujoco.set_mjcb_control(None)
            return
        lib = self._callback()
        J, kp, kv = self.gains
        if lib is not None:
            for name, value in (("lp_omega", OMEGA), ("lp_T", T_SPIN), ("lp_J", J), ("lp_kp", kp), ("lp_kv", kv)):
                ctypes.c_double.in_dll(lib, name).value = value
            self.mujoco.set_mjcb_control(lib.lp_drive)
        else:
            profile = self.scene.drive[1]

            def drive(model, data):
                th, thd, thdd = profile(data.time)
                data.ctrl[0] = th + (J * thdd + kv * thd) / kp
            self.mujoco.set_mjcb_control(drive)

    def run(self, method: str, setting: str, value: float) -> np.ndarray:
        """(MuJoCo's constraint solver keeps its defaults: Newton, tolerance 1e-8.)"""
        mujoco, model, data, s = self.mujoco, self.model, self.data, self.scene
        if setting != "dt":
            raise ValueError(f"dt: expected a step dividing {s.interval} s, got {setting}={value}")
        n = mujoco_fixed_step(mujoco, model, data, method, value, s.interval)
        self.install()
        address = self.address
        data.qpos[address] = s.q0
        return mujoco_outputs(mujoco, model, data, n, len(s.t_eval), lambda d: d.qpos[address],
                              f"{method} dt={value:g}")

    def reference_step(self) -> float:
        return self.scene.interval / REFERENCE_STEPS[self.scene.planar][1]

    def reference(self, step: float | None = None) -> np.ndarray:
        return self.run("RK4", "dt", step or self.reference_step())


_DRIVE_C = r"""
#include <math.h>
#include <mujoco/mujoco.h>
/* The crank's servo on Kane's spin-up theta(t): actuator 0 is a general actuator with force
   kp ctrl - kp q - kv qdot, so ctrl = theta + (J thetadd + kv thetad)/kp gives
   J thetadd + kp (theta - q) + kv (thetad - qdot). */
double lp_omega = 50.0, lp_T = 0.2, lp_J = 0.0, lp_kp = 1.0, lp_kv = 0.0;
void lp_drive(const mjModel* m, mjData* d) {
  double t = d->time, w = 2.0 * M_PI / lp_T, a = lp_omega / lp_T, th, thd, thdd;
  if (t < lp_T) {
    th = a * (0.5 * t * t + (cos(w * t) - 1.0) / (w * w));
    thd = a * (t - sin(w * t) / w);
    thdd = a * (1.0 - cos(w * t));
  } else {
    th = lp_omega * (t - 0.5 * lp_T);
    thd = lp_omega;
    thdd = 0.0;
  }
  d->ctrl[0] = th + (lp_J * thdd + lp_kv * thd) / lp_kp;
}
"""


def _compile_drive(mujoco):
    """``_DRIVE_C`` compiled against MuJoCo's headers, or None."""
    return compile_mujoco_callback(mujoco, _DRIVE_C, "loop_peers_")


@dataclass(frozen=True)
class _Site:
    body: int
    r: np.ndarray


# ---------------------------------------------------------------------------------------------
# Verification, sweeps, timing
# ---------------------------------------------------------------------------------------------

def error(scene: Scene, Q, reference_points) -> float:
    """Largest distance over the outputs between the point at Q and the reference's, relative to
    the point's motion amplitude."""
    return float(np.max(np.linalg.norm(scene.positions(Q) - reference_points, axis=1)) / scene.amplitude)


def verify(scene: Scene, runners: dict, references: dict, tolerance: float = AGREEMENT) -> Table:
    """Each code's converged point history against rigidfem's (largest distance relative to the
    amplitude), how converged each reference is (against the same code at rtol 100× looser for
    rigidfem, at twice the step for the peers) and the closure each keeps; raises
    ``AssertionError`` when a peer differs from rigidfem by more than ``tolerance``."""
    points = {code: scene.positions(Q) for code, Q in references.items()}
    checks = {"rigidfem": ("dopri5 rtol=1e-12 (self-check: rtol=1e-10)",
                           runners["rigidfem"].run("dopri5", "rtol", 1e-10)),
              **common.peer_self_checks(runners, TIGHT_NEWTON)}
    rows = []
    for code, (how, check) in checks.items():
        d = np.max(np.linalg.norm(points[code] - points["rigidfem"], axis=1)) / scene.amplitude
        rows.append({"scene": scene.name, "code": code, "reference": how,
                     "self_check_rel": error(scene, check, points[code]), "vs_rigidfem_rel": float(d),
                     "closure_max_g": scene.closure(references[code]),
                     "drive_error_rad": scene.drive_error(references[code]),
                     "amplitude_m": scene.amplitude})
        common.check_agreement(scene.name, code, d, tolerance)
    return Table(rows, VERIFY_COLUMNS)


VERIFY_COLUMNS = ("scene", "code", "reference", "self_check_rel", "vs_rigidfem_rel", "closure_max_g", "drive_error_rad",
                  "amplitude_m")


def _steps(interval: float, divisors) -> list:
    return [interval / k for k in divisors]


def settings(scene: Scene, quick: bool = False) -> dict:
    """code -> [(method, setting, values[, options])], coarse to fine (``options``: the runner's
    keyword arguments, e.g. Newton's tolerances; they name the method in the tables). Fixed steps divide the output
    interval, ~√2 apart; explicit steps on the slider-crank start near the rod's stability limit
    (ω_max h ≤ 2 for MuJoCo's Euler and implicitfast, 2.785 for RK4)."""
    interval = scene.interval
    divisors = [1, 2, 3, 4, 6, 8, 11, 16, 23, 32, 45, 64, 91, 128, 181, 256, 362, 512, 724, 1024, 1448, 2048, 2896,
                4096, 5793, 8192]
    rtols = [1e-3, 3e-4, 1e-4, 3e-5, 1e-5, 3e-6, 1e-6, 3e-7, 1e-7, 3e-8, 1e-8, 3e-9, 1e-9, 3e-10, 1e-10, 3e-11, 1e-11]

    def steps(limit=None):
        k = divisors
        if limit is not None and scene.omega_max > 0:
            least = interval * scene.omega_max / limit
            k = [d for d in divisors if d >= least * 0.5]  # the loops lower ω_max: start below
        return _steps(interval, k[::3] if quick else k)

    if quick:
        rtols = rtols[::3]
    rigid = [("auto", "rtol", rtols), ("radau5", "rtol", rtols), ("esdirk43", "rtol", rtols),
             ("dopri5", "rtol", rtols), ("dop853", "rtol", rtols), ("rk4", "dt", steps(2.785)),
             ("generalized_alpha", "dt", steps()),
             ("generalized_alpha", "dt", steps(), {"newton_tol": TIGHT_NEWTON_TOL})]
    return {
        "rigidfem": rigid,
        "Exudyn": [(method, "dt", steps(), *options) for method in ExudynLoops.METHODS
                   for options in ((), ({"newton": TIGHT_NEWTON},))],
        "MuJoCo": [("Euler", "dt", steps(2.0)), ("implicitfast", "dt", steps(2.0)), ("discrete", "dt", steps()),
                   ("RK4", "dt", steps(2.785))],
    }


def _hopeless(history: list, failures: int, budget: float) -> str:
    """Why a fixed-step sweep should stop before its budget, or "": 10 failed runs in a row; an
    error floor (no gain over the last two steps, errors below 0.5); or the extrapolation of the
    last two errors in h (order p) putting the run within min(THRESHOLDS) beyond 20 budgets.
    ``history``: (h, error, cpu s) of the finished runs with errors below 0.5."""
    if failures >= 10:
        return "sweep stopped: 10 failures in a row"
    if len(history) >= 3 and history[-1][1] >= 0.9 * history[-2][1] and history[-2][1] >= 0.9 * history[-3][1]:
        return "sweep stopped: error floor (no gain over the last two steps)"
    if len(history) >= 2:
        (h0, e0, _), (h1, e1, c1) = history[-2:]
        p = math.log(e0 / e1) / math.log(h0 / h1)
        if p > 0.3:
            need = c1 * (e1 / min(THRESHOLDS)) ** (1.0 / p)
            if need > 20 * budget:
                return f"sweep stopped: would take ~{need:.2g} s (order {p:.2g} in h)"
    return ""


def sweep(scene: Scene, runners: dict, references: dict, todo: dict, budget: float = 20.0) -> list:
    """Each code's settings, coarse to fine, a method stopping after its first run within
    min(THRESHOLDS), once a run took more than ``budget`` s, or (fixed steps) when
    ``_hopeless`` says so. Rows: scene, code, method, setting, value, rel_error (against that
    code's reference), closure_max_g, first_cpu_s, note."""
    rows = []
    for code, methods in todo.items():
        runner, ref = runners[code], scene.positions(references[code])
        for method, setting, values, *extra in methods:
            options = extra[0] if extra else {}
            label = method + "".join(f" {k}={v}" for k, v in options.items())
            history, failures = [], 0
            for value in values:
                row = {"scene": scene.name, "code": code, "method": label, "setting": setting, "value": value,
                       "closure_max_g": np.nan, "note": "", "run": (method, options)}
                first_run(row, lambda: runner.run(method, setting, value, **options),
                          lambda Q: {"rel_error": error(scene, Q, ref), "closure_max_g": scene.closure(Q)}, "rel_error")
                rows.append(row)
                if row["rel_error"] <= min(THRESHOLDS) or row["first_cpu_s"] > budget:
                    break
                if setting == "dt":
                    failures = failures + 1 if not np.isfinite(row["rel_error"]) else 0
                    if row["rel_error"] < 0.5:
                        history.append((value, row["rel_error"], row["first_cpu_s"]))
                    why = _hopeless(history, failures, budget)
                    if why:
                        row["note"] = f"{row['note']}; {why}" if row["note"] else why
                        break
    return rows


def timed(rows: list, runners: dict, rounds: int, long: float = 3.0, contenders: float = 3.0) -> None:
    """Adds ``cpu_s`` to each row: the least CPU time over ``rounds`` more rounds for the
    contenders — per code and threshold, the runs within it whose first time is at most
    ``contenders`` times the least first time of that code's runs within it —, the codes
    alternating run by run within a round; a run whose first took over ``long`` s, and every
    other row, keeps its first time."""
    todo = {}
    for r in rows:
        r["cpu_s"] = r["first_cpu_s"]
    for code in dict.fromkeys(r["code"] for r in rows):
        chosen = []
        for tol in THRESHOLDS:
            within = [r for r in rows if r["code"] == code and r["rel_error"] <= tol]
            if within:
                least = min(r["first_cpu_s"] for r in within)
                chosen += [r for r in within if r["first_cpu_s"] <= contenders * least and r["first_cpu_s"] <= long]
        todo[code] = list({id(r): r for r in chosen}.values())
    least_cpu_times(todo, lambda r: runners[r["code"]].run(r["run"][0], r["setting"], r["value"], **r["run"][1]),
                    rounds)


def summary(rows: list, scene: str) -> Table:
    """Per threshold: the cheapest run of each code (CPU s, setting, closure) and the ratios."""
    return summary_table(rows, {"scene": scene}, "rel_error", "rel_error", THRESHOLDS,
                         extra={"closure": lambda r: r["closure_max_g"]})


SUMMARY_COLUMNS = summary_columns(("scene",), "rel_error", CODES, ("closure",))
SWEEP_COLUMNS = ("scene", "code", "method", "setting", "value", "rel_error", "closure_max_g", "cpu_s", "first_cpu_s",
                 "note")


def versions() -> dict:
    return common.versions(_peer)


def runners_for(scene: Scene) -> dict:
    return {"rigidfem": RigidfemLoops(scene), "Exudyn": ExudynLoops(scene), "MuJoCo": MujocoLoops(scene)}


def prepare(scene: Scene, runners: dict) -> dict:
    """Each code's converged solution (free coordinates at the outputs); sets the scene's
    amplitude from rigidfem's."""
    references = {code: runner.reference() for code, runner in runners.items()}
    p = scene.positions(references["rigidfem"])
    scene.amplitude = float(np.max(np.linalg.norm(p - p[0], axis=1)))
    return references


def run(output_dir="bench", quick: bool = False) -> dict:
    """``python -m benchmarks loop_peers``: the slider-crank (m = 4 and 16; ``quick``: m = 4) and the
    Bricard linkage (10 s; ``quick``: 2 s): verify the peers' models against rigidfem's, sweep
    every code's solvers, time the runs within 1e-4 in 3 interleaved rounds (``quick``: 1) and
    print the cheapest setting per code and threshold with the closure it keeps. Writes
    loop_peers_{verification,sweep,summary}.csv into ``output_dir``."""
    print(common.versions_line(versions()), flush=True)
    scenes = [lambda: slider_crank(4)] + ([] if quick else [lambda: slider_crank(16)]) + [
              lambda: bricard(outputs=41 if quick else BRICARD_OUTPUTS, t_end=2.0 if quick else BRICARD_END)]
    checks, rows, summaries = [], [], []
    for make in scenes:
        start = time.perf_counter()
        scene = make()
        runners = runners_for(scene)
        if not runners["MuJoCo"].native:
            print("note: no C compiler: MuJoCo's crank drive is a Python callback (its times include Python)")
        references = prepare(scene, runners)
        checks += verify(scene, runners, references).rows
        print(f"[{time.perf_counter() - start:6.1f} s] {scene.name}: models verified", flush=True)
        these = sweep(scene, runners, references, settings(scene, quick), budget=5.0 if quick else 20.0)
        print(f"[{time.perf_counter() - start:6.1f} s] {scene.name}: swept {len(these)} runs", flush=True)
        timed(these, runners, rounds=1 if quick else 3)
        print(f"[{time.perf_counter() - start:6.1f} s] {scene.name}: timed", flush=True)
        rows += these
        summaries += summary(these, scene.name).rows
        for name, table in (("verification", Table(checks, VERIFY_COLUMNS)), ("sweep", Table(rows, SWEEP_COLUMNS)),
                            ("summary", Table(summaries, SUMMARY_COLUMNS))):
            table.to_csv(Path(output_dir) / f"loop_peers_{name}.csv")  # so far (printed at the end)
    tables = report({
        "loop_peers_verification": ("Closed loops, models verified equal: each code's converged point history against "
                                    "rigidfem's (relative to the amplitude), its self-check and closure",
                                    Table(checks, VERIFY_COLUMNS)),
        "loop_peers_sweep": ("Closed loops, every run: point error relative to the amplitude against the code's own "
                             "converged solution, closure max |g|, least CPU time (s)", Table(rows, SWEEP_COLUMNS)),
        "loop_peers_summary": ("Closed loops, cheapest runs: least CPU time (s) per code to each relative point error, the "
                               "closure it keeps, and the peers' time over rigidfem's", Table(summaries, SUMMARY_COLUMNS)),
    }, output_dir)
    return {name[len("loop_peers_"):]: table for name, table in tables.items()}
