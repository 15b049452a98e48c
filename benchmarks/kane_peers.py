"""Kane's spin-up beam side by side: rigidfem, Exudyn and MuJoCo on the same chain (issue 16, item 5).

The scene: ``rigidfem.samples.kane_beam(omega=6.0, duration=15.0, elements=m)`` — a hub turned
about z by the spin-up profile θ(t) = (Ω/T)[t²/2 + (T/2π)²(cos(2πt/T) − 1)] (t < T, then
Ω(t − T/2); Ω = 6 rad/s, T = 15 s) carrying rfe 0 rigidly and rfes 1..m joined by revolute
joints about z with torsional springs (planar modified RFEM, no gravity), simulated over 20 s
and observed at the tip, in the hub frame, at 201 output times.

- ``kane`` compiles the scene; ``hub_chain`` reads the chain from the compiled System (masses,
  centres of mass, inertias, placements, springs, dampers), and ``tip_in_hub`` computes the tip
  position in the hub frame from joint angles by its own forward kinematics (the same for
  every code);
- ``RigidfemKane``, ``ExudynKane`` and ``MujocoKane`` rebuild and run it, each returning the
  joint angles of the beam at the output times;
- ``verify`` checks, before any timing, that each peer's tightly converged solution equals
  rigidfem's (tip histories within ``AGREEMENT`` m), and raises otherwise;
- ``sweep`` runs each code's solvers over their steps or tolerances (errors against that code's
  own converged solution), ``timed`` times the runs that reach the thresholds in interleaved
  rounds (CPU time, ``time.process_time``, least over the rounds), ``cheapest`` picks the
  cheapest setting per code and threshold;
- ``run`` does it all for m = 20 and 40 and prints the tables::

    python -m benchmarks kane_peers [--quick] [--output DIR]

The hub's prescribed rotation in the peers. Neither peer has a prescribed joint motion that
its explicit and implicit solvers all honour, so the hub is driven as a heavy flywheel: its
joint gets a rotor inertia ``HUB_INERTIA`` J = 1e12 kg·m² and the torque J θ̈(t). The beam's
reaction changes the hub's acceleration by (reaction torque)/J ≈ 1e-10 rad/s², far below every
error measured (the verification shows it). In Exudyn the torque is a ``LoadCoordinate`` on the
hub coordinate with a symbolic user function (Exudyn's expression trees, evaluated in C++, no
Python); in MuJoCo a ``motor`` actuator whose control is set by an ``mjcb_control`` callback
written in C (compiled here with the C compiler against MuJoCo's headers, loaded by ctypes: it
runs inside every ``mj_forward`` — every RK4 stage included — without Python; without a C
compiler a Python callback is used instead and the MuJoCo times say so). The hub angle is
integrated by each code with the rest; the tip is observed in each code's own hub frame.

Needs the peer codes: ``pip install exudyn mujoco``. SI units: m, rad, kg, s, N·m.
"""

from __future__ import annotations

import ctypes
import math
import time
from dataclasses import dataclass, field

import numpy as np

from rigidfem import samples, simulate
from rigidfem.studies.study import Table

from . import _peers_common as common
from ._common import compile_mujoco_callback, report
from ._peers_common import INSTALL_HINT  # noqa: F401 - kept: this module's name for it
from ._peers_common import (cheapest, exudyn_settings, exudyn_solve, first_run, least_cpu_times, mujoco_fixed_step,
                            mujoco_outputs, summary_table)
from .peers import Chain, Link, to_mjcf

OMEGA, SPIN_UP, T_END, OUTPUTS = 6.0, 15.0, 20.0, 201
INTERVAL = T_END / (OUTPUTS - 1)  #: 0.1 s between outputs; every fixed step divides it
HUB_INERTIA = 1e10                #: kg·m², the peers' flywheel hub
AGREEMENT = 1e-6                  #: m, largest tip difference allowed between converged solutions
THRESHOLDS = (1e-4, 1e-6)         #: m, tip RMS errors
REFERENCE_STEP = 0.5              #: the peers' references: RK4 at this fraction of its stability limit


_peer = common.peer_guard("kane_peers")


def spin_up_acceleration(t: float) -> float:
    """θ̈(t) of Kane's spin-up (rad/s²)."""
    return OMEGA / SPIN_UP * (1.0 - math.cos(2.0 * math.pi * t / SPIN_UP)) if t < SPIN_UP else 0.0


# ---------------------------------------------------------------------------------------------
# The scene, read from rigidfem's compiled System
# ---------------------------------------------------------------------------------------------

@dataclass
class Kane:
    """The compiled scene: its System, the tip Point, the hub's body index and the chain
    (hub first, its prescribed rotation as coordinate "hub.rz")."""

    elements: int
    system: object
    tip: object
    chain: Chain
    omega_max: float          #: highest natural frequency of the beam at rest (rad/s), non-rotating
    hub: object = None        #: the hub's Body handle
    t_eval: np.ndarray = field(default_factory=lambda: np.linspace(0.0, T_END, OUTPUTS))

    @property
    def nq(self) -> int:
        return self.system.nq


def kane(elements: int) -> Kane:
    model, handles = samples.kane_beam(omega=OMEGA, duration=SPIN_UP, elements=elements)
    system = model.compile()
    chain = hub_chain(system)
    M = system.mass_matrix(0.0, np.zeros(system.nq))
    K = np.diag(system.stiffness)
    omega_max = float(np.sqrt(np.max(np.linalg.eigvals(np.linalg.solve(M, K)).real)))
    return Kane(elements, system, handles["beam"].tip, chain, omega_max, handles["hub"])


def hub_chain(system) -> Chain:
    """The chain of ``system`` with its prescribed coordinates as joints (springs and dampers
    zero): the links in rigidfem's body order, coordinates prescribed first then free, the
    names in ``Chain.coordinate_names``. Only revolute coordinates (rz, ry, rx) are read."""
    names = list(system.body_names)
    all_names = list(system.prescribed_names) + list(system.coordinate_names)
    axes = {}
    for full in all_names:
        body, axis = full.rsplit(".", 1)
        if not axis.startswith("r"):
            raise ValueError(f"system: expected revolute coordinates only, got {full}")
        axes.setdefault(body, []).append(axis)
    free = list(system.coordinate_names)
    links = []
    for p, (name, parent, B) in enumerate(zip(names, system.parent, system.placements)):
        ax = tuple(axes.get(name, ()))
        idx = [free.index(f"{name}.{a}") if f"{name}.{a}" in free else -1 for a in ax]
        pick = lambda v: np.array([v[k] if k >= 0 else 0.0 for k in idx])  # noqa: E731
        links.append(Link(name, int(parent), np.array(B), ax, float(system.masses[p]),
                          np.array(system.centres_of_mass[p]), np.array(system.inertias[p]),
                          pick(system.stiffness), pick(system.damping), pick(system.rest)))
    if np.any(np.asarray(system.gravity) != 0.0):
        raise ValueError("system: expected no gravity (Kane's beam)")
    return Chain(tuple(links), np.zeros(3), tuple(all_names))


def _rotation(axis: str, angle):
    """(N, 4, 4) rotations about x, y or z by the angles (N,)."""
    c, s = np.cos(angle), np.sin(angle)
    R = np.tile(np.eye(4), (len(angle), 1, 1))
    i, j = {"rx": (1, 2), "ry": (2, 0), "rz": (0, 1)}[axis]
    R[:, i, i], R[:, i, j], R[:, j, i], R[:, j, j] = c, -s, s, c
    return R


def tip_in_hub(scene: Kane, q) -> np.ndarray:
    """Tip position in the hub frame (N, 3), m, from the beam's joint angles q (N, nq) in
    rigidfem's order: forward kinematics through the placements with the hub held at 0."""
    q = np.atleast_2d(q)
    chain, N = scene.chain, len(q)
    npres = len(scene.system.prescribed_names)
    column = {name: k for k, name in enumerate(chain.coordinate_names)}
    frames = []
    for p, link in enumerate(chain.links):
        T = np.tile(link.placement, (N, 1, 1)) if link.parent < 0 else frames[link.parent] @ link.placement
        for axis in link.coordinates:
            k = column[f"{link.name}.{axis}"]
            angle = np.zeros(N) if k < npres else q[:, k - npres]
            T = T @ _rotation(axis, angle)
        frames.append(T)
    hub = frames[0]  # the hub's frame: body 0 (the only link without a parent here)
    tip = frames[scene.tip.body] @ np.append(scene.tip.r, 1.0)
    return np.einsum("nji,nj->ni", hub[:, :3, :3], tip[:, :3] - hub[:, :3, 3])


def rms_error(tip, reference) -> float:
    """RMS over the output times of the tip distance (m)."""
    return float(np.sqrt(np.mean(np.sum((tip - reference) ** 2, axis=1))))


# ---------------------------------------------------------------------------------------------
# The three codes: each ``run(method, setting, value)`` returns the beam's q (OUTPUTS, nq)
# ---------------------------------------------------------------------------------------------

class RigidfemKane:
    code = "rigidfem"

    def __init__(self, scene: Kane):
        self.scene = scene

    def run(self, method: str, setting: str, value: float) -> np.ndarray:
        kw = {setting: value}
        if setting == "rtol":
            kw["atol"] = value * 1e-2
        r = simulate(self.scene.system, T_END, method=method, t_eval=self.scene.t_eval, max_steps=10**8,
                     stiffness_warning=False, **kw)
        return np.asarray(r.q)

    def reference(self) -> np.ndarray:
        return self.run("dopri5", "rtol", 1e-12)

    @staticmethod
    def knows(method: str) -> bool:
        """Whether this build's simulate has ``method``."""
        model, _ = samples.kane_beam(elements=2)
        try:
            simulate(model.compile(), 1e-3, method=method, dt=1e-3)
        except ValueError as e:
            if str(e).startswith("method"):
                return False
        except Exception:  # noqa: BLE001 - another failure is not "unknown"
            pass
        return True


class ExudynKane:
    """The chain as one ``ObjectKinematicTree``: link 0 is the hub with rfe 0 welded on (its
    mass, centre of mass and inertia), links 1..m the rfes on RevoluteZ joints at rigidfem's
    placements; the joint springs and dampers are the tree's P and D control (force
    c (rest − q) + b (0 − q̇)). Two hubs, both with symbolic user functions (C++ expression
    trees, no Python while solving):

    - for the implicit solvers (GeneralizedAlpha, TrapezoidalIndex2), the exact prescribed
      rotation: an ``ObjectConnectorCoordinate`` between the ground and the hub coordinate
      with offset θ(t) and its derivative θ̇(t);
    - for the explicit solvers (RK44), which eliminate coordinate constraints but
      drop their time-dependent offset (the hub stays at 0), the flywheel: rotor inertia J
      and a ``LoadCoordinate`` J θ̈(t) on the hub coordinate. (The implicit solvers cannot use
      the flywheel: the torque J θ̈ ~ 1e10 N·m sets the scale of Newton's residual test, which
      then stops before the beam's equations converge.)

    Solvers run at fixed steps h dividing the output interval, recording the node's
    coordinates with a ``SensorNode`` every 0.1 s (in memory), no solution file; modified
    Newton and spectral radius 0.9 are Exudyn's defaults. (Exudyn's DOPRI5 always adapts its
    step, and its steps do not land on the output times, so it is not swept; RK44 has the
    widest stability interval per stage of Exudyn's explicit methods; explicit Euler is
    unstable on an undamped oscillator at any step.)"""

    code = "Exudyn"
    IMPLICIT = ("GeneralizedAlpha", "TrapezoidalIndex2")

    def __init__(self, scene: Kane, hub_inertia: float = HUB_INERTIA):
        self.exu = _peer("exudyn", "exudyn")
        self.scene = scene
        self.keep = []  # symbolic user functions must outlive the systems
        self.systems = {"constraint": self._build(scene, 0.0), "flywheel": self._build(scene, hub_inertia)}

    def _build(self, scene: Kane, hub_inertia: float):
        exu = self.exu
        from exudyn.advancedUtilities import CreateSymbolicUserFunction
        from exudyn.itemInterface import (LoadCoordinate, MarkerNodeCoordinate, NodeGenericODE2, ObjectKinematicTree,
                                          SensorNode)

        chain = scene.chain
        hub, welded = chain.links[0], chain.links[1]
        if hub.coordinates != ("rz",) or welded.coordinates or welded.parent != 0:
            raise ValueError("scene: expected a hub on rz carrying rfe 0 rigidly")
        B0 = welded.placement  # rfe 0's inertia moved into the hub's frame
        com0 = B0[:3, :3] @ welded.com + B0[:3, 3]
        I0 = B0[:3, :3] @ welded.inertia @ B0[:3, :3].T + np.diag([0.0, 0.0, hub_inertia])
        links = chain.links[2:]
        n = 1 + len(links)
        HTs, masses, coms, inertias = [np.eye(4)], [welded.mass], [com0], [I0]
        for link in links:
            if link.coordinates != ("rz",) or link.parent < 1:
                raise ValueError(f"scene: expected rfes on rz joints, got {link.coordinates} on {link.name}")
            HTs.append((B0 if link.parent == 1 else np.eye(4)) @ link.placement)
            masses.append(link.mass)
            coms.append(link.com)
            inertias.append(link.inertia)
        sc = exu.SystemContainer()
        mbs = sc.AddSystem()
        node = mbs.AddNode(NodeGenericODE2(referenceCoordinates=[0.0] * n, initialCoordinates=[0.0] * n,
                                           initialCoordinates_t=[0.0] * n, numberOfODE2Coordinates=n))
        mbs.AddObject(ObjectKinematicTree(
            nodeNumber=node, jointTypes=[exu.JointType.RevoluteZ] * n,
            linkParents=[-1] + [link.parent - 1 for link in links],
            jointTransformations=exu.Matrix3DList([H[:3, :3] for H in HTs]),
            jointOffsets=exu.Vector3DList([H[:3, 3] for H in HTs]),
            linkInertiasCOM=exu.Matrix3DList(inertias), linkCOMs=exu.Vector3DList(coms), linkMasses=masses,
            jointPControlVector=[0.0] + [float(link.stiffness[0]) for link in links],
            jointDControlVector=[0.0] + [float(link.damping[0]) for link in links],
            jointPositionOffsetVector=[0.0] + [float(link.rest[0]) for link in links],
            jointVelocityOffsetVector=[0.0] * n))
        marker = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=node, coordinate=0))
        esym = exu.symbolic
        J, Om, Ts, w = hub_inertia, OMEGA, SPIN_UP, 2.0 * math.pi / SPIN_UP
        if hub_inertia > 0.0:
            def torque(mbs, t, load):
                return esym.IfThenElse(t < Ts, J * Om / Ts * (1.0 - esym.cos(w * t)), esym.Real(0.0))

            f = CreateSymbolicUserFunction(mbs, torque, "loadUserFunction", itemTypeName="LoadCoordinate")
            self.keep.append(f)
            mbs.AddLoad(LoadCoordinate(markerNumber=marker, load=0.0, loadUserFunction=f))
        else:
            self.keep += exudyn_spin_up(exu, mbs, marker, Om, Ts)
        sensor = mbs.AddSensor(SensorNode(nodeNumber=node, storeInternal=True,
                                          outputVariableType=exu.OutputVariableType.Coordinates))
        mbs.Assemble()
        return sc, mbs, sensor

    def run(self, method: str, setting: str, value: float) -> np.ndarray:
        exu = self.exu
        if setting != "dt":
            raise ValueError(f"setting: expected dt for Exudyn, got {setting}")
        _, mbs, sensor = self.systems["constraint" if method in self.IMPLICIT else "flywheel"]
        ss = exudyn_settings(exu, T_END, value, INTERVAL)
        data = exudyn_solve(exu, mbs, ss, sensor, method, value, self.scene.t_eval)
        return data[:, 2:]  # time, hub angle, then the beam's q

    def reference(self) -> np.ndarray:
        return self.run("RK44", "dt", _divide(REFERENCE_STEP * 2.785 / self.scene.omega_max))


def exudyn_spin_up(exu, mbs, marker: int, omega: float, duration: float) -> list:
    """Holds the coordinate of ``marker`` (a MarkerNodeCoordinate of ``mbs``) on the spin-up θ(t) of
    ``rigidfem.motion.spin_up(omega, duration)`` by an ``ObjectConnectorCoordinate`` to the ground with θ(t) and
    θ̇(t) as symbolic user functions (C++ expression trees: no Python while solving). Returns the user functions,
    which must outlive the system."""
    from exudyn.advancedUtilities import CreateSymbolicUserFunction
    from exudyn.itemInterface import MarkerNodeCoordinate, NodePointGround, ObjectConnectorCoordinate

    esym = exu.symbolic
    Om, Ts, w = omega, duration, 2.0 * math.pi / duration

    def angle(mbs, t, itemNumber, lOffset):
        return esym.IfThenElse(t < Ts, Om / Ts * (0.5 * t * t + (esym.cos(w * t) - 1.0) / w**2), Om * (t - 0.5 * Ts))

    def rate(mbs, t, itemNumber, lOffset):
        return esym.IfThenElse(t < Ts, Om / Ts * (t - esym.sin(w * t) / w), esym.Real(Om))

    f = CreateSymbolicUserFunction(mbs, angle, "offsetUserFunction", itemTypeName="ObjectConnectorCoordinate")
    f_t = CreateSymbolicUserFunction(mbs, rate, "offsetUserFunction_t", itemTypeName="ObjectConnectorCoordinate")
    ground = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=mbs.AddNode(NodePointGround()), coordinate=0))
    mbs.AddObject(ObjectConnectorCoordinate(markerNumbers=[ground, marker], offsetUserFunction=f,
                                            offsetUserFunction_t=f_t))
    return [f, f_t]


class MujocoKane:
    """The chain in MJCF by ``peers.to_mjcf`` (hub body with hinge "hub.rz", rfe 0 welded to it
    as a body without joints, rfes 1..m on hinges with stiffness, damping, springref), the
    hub hinge with ``armature`` J and a ``motor`` actuator whose control J θ̈(d->time) is set
    by the ``mjcb_control`` callback in C. Contacts and constraints disabled; ``mj_step(model,
    data, nstep)`` between outputs (no Python per step)."""

    code = "MuJoCo"
    INTEGRATORS = ("Euler", "implicitfast", "RK4")

    _lib = None

    def __init__(self, scene: Kane, hub_inertia: float = HUB_INERTIA):
        mujoco = self.mujoco = _peer("mujoco", "mujoco")
        xml = to_mjcf(scene.chain, timestep=1e-3)
        old = 'name="hub.rz" type="hinge" axis="0 0 1" stiffness="0.0" damping="0.0" springref="0.0" armature="0"'
        if old not in xml:
            raise RuntimeError("MJCF: hub joint not found")
        xml = xml.replace(old, old[:-3] + f'"{float(hub_inertia)!r}"')
        xml = xml.replace("</mujoco>", '  <actuator>\n    <motor name="hub" joint="hub.rz" gear="1"/>\n  </actuator>\n'
                                       "</mujoco>")
        self.xml = xml
        self.model = mujoco.MjModel.from_xml_string(xml)
        self.data = mujoco.MjData(self.model)
        names = scene.chain.coordinate_names
        self.address = np.array([self.model.joint(name).qposadr[0] for name in names[1:]])
        self.hub_inertia = hub_inertia
        self.native = self._callback() is not None
        self.scene = scene

    def _callback(self):
        """The control callback in C (ctypes function), or None without a C compiler."""
        if MujocoKane._lib is None:
            MujocoKane._lib = _compile_drive(self.mujoco)
        return MujocoKane._lib

    def install(self) -> None:
        """Make this model's hub torque the control callback (process-wide in MuJoCo)."""
        lib = self._callback()
        if lib is not None:
            ctypes.c_double.in_dll(lib, "kp_J").value = self.hub_inertia
            ctypes.c_double.in_dll(lib, "kp_omega").value = OMEGA
            ctypes.c_double.in_dll(lib, "kp_T").value = SPIN_UP
            self.mujoco.set_mjcb_control(lib.kp_drive)
        else:
            J = self.hub_inertia

            def drive(model, data):
                data.ctrl[0] = J * spin_up_acceleration(data.time)
            self.mujoco.set_mjcb_control(drive)

    def run(self, method: str, setting: str, value: float) -> np.ndarray:
        mujoco, model, data = self.mujoco, self.model, self.data
        n = mujoco_fixed_step(mujoco, model, data, method, value, INTERVAL)
        self.install()
        address = self.address
        return mujoco_outputs(mujoco, model, data, n, OUTPUTS, lambda d: d.qpos[address], f"{method} dt={value:g}")

    def reference(self) -> np.ndarray:
        return self.run("RK4", "dt", _divide(REFERENCE_STEP * 2.785 / self.scene.omega_max))


_DRIVE_C = r"""
#include <math.h>
#include <mujoco/mujoco.h>
/* Kane's spin-up as the torque J*thdd(t) of actuator 0 (the hub, rotor inertia J) */
double kp_J = 0.0, kp_omega = 6.0, kp_T = 15.0;
void kp_drive(const mjModel* m, mjData* d) {
  double t = d->time;
  d->ctrl[0] = t < kp_T ? kp_J * kp_omega / kp_T * (1.0 - cos(2.0 * M_PI * t / kp_T)) : 0.0;
}
"""


def _compile_drive(mujoco):
    """The C control callback compiled against MuJoCo's headers, or None."""
    return compile_mujoco_callback(mujoco, _DRIVE_C, "kane_peers_")


def _divide(h: float) -> float:
    """The largest step ≤ h dividing the output interval."""
    return INTERVAL / math.ceil(INTERVAL / h - 1e-12)


# ---------------------------------------------------------------------------------------------
# Verification, sweeps, timing
# ---------------------------------------------------------------------------------------------

def verify(scene: Kane, runners: dict, references: dict, tolerance: float = AGREEMENT) -> Table:
    """Each code's converged tip history against rigidfem's (largest and RMS distance, m);
    raises ``AssertionError`` when a peer differs by more than ``tolerance`` m. Also: how
    converged each reference is (``self_check_max_m``: against the same code at rtol 100×
    looser for rigidfem, at twice the step — RK4 at its stability limit — for the peers), and
    Exudyn's implicit model (the constraint hub) run by GeneralizedAlpha at a small step."""
    tip = {code: tip_in_hub(scene, q) for code, q in references.items()}
    limit = _divide(2.785 / scene.omega_max)
    h = _divide(REFERENCE_STEP * 2.785 / scene.omega_max)
    fine = INTERVAL / 256
    checks = {"rigidfem": ("dopri5 rtol=1e-12 (self-check: rtol=1e-10)", tip["rigidfem"],
                           runners["rigidfem"].run("dopri5", "rtol", 1e-10)),
              "Exudyn": (f"RK44 dt={h:.3g}, flywheel hub (self-check: dt={limit:.3g})", tip["Exudyn"],
                         runners["Exudyn"].run("RK44", "dt", limit)),
              "Exudyn implicit": (f"GeneralizedAlpha dt={fine:.3g}, constraint hub (self-check: against "
                                  "Exudyn's reference)", None, None),
              "MuJoCo": (f"RK4 dt={h:.3g}, flywheel hub (self-check: dt={limit:.3g})", tip["MuJoCo"],
                         runners["MuJoCo"].run("RK4", "dt", limit))}
    implicit = tip_in_hub(scene, runners["Exudyn"].run("GeneralizedAlpha", "dt", fine))
    checks["Exudyn implicit"] = (checks["Exudyn implicit"][0], implicit, references["Exudyn"])
    rows = []
    for code, (how, mine, check) in checks.items():
        self_error = float(np.max(np.linalg.norm(tip_in_hub(scene, check) - mine, axis=1)))
        d = np.linalg.norm(mine - tip["rigidfem"], axis=1)
        rows.append({"m": scene.elements, "code": code, "reference": how, "self_check_max_m": self_error,
                     "vs_rigidfem_max_m": float(d.max()), "vs_rigidfem_rms_m": rms_error(mine, tip["rigidfem"]),
                     "max_tip_deflection_m": float(np.max(np.abs(tip["rigidfem"][:, 1])))})
        if d.max() > tolerance:
            raise AssertionError(f"m = {scene.elements}: {code}'s converged tip differs from rigidfem's by "
                                 f"{d.max():.3g} m (allowed {tolerance:g} m): the models are not equal")
    return Table(rows, VERIFY_COLUMNS)


VERIFY_COLUMNS = ("m", "code", "reference", "self_check_max_m", "vs_rigidfem_max_m", "vs_rigidfem_rms_m",
                  "max_tip_deflection_m")


def settings(scene: Kane, quick: bool = False) -> dict:
    """code -> [(method, setting, values)], coarse to fine; rigidfem's radau5 when this build
    has it. Fixed steps divide the output interval, ~√2 apart. Explicit steps start at each
    method's stability limit (ω_max h ≤ 2 for symplectic/semi-implicit Euler, Verlet and
    implicitfast, whose joint springs are explicit; 2.785 for RK4)."""
    w = scene.omega_max

    def steps(limit, factors):
        return sorted({_divide(limit / w / f) for f in factors}, reverse=True)

    gen = [INTERVAL / k for k in (2, 3, 4, 6, 8, 11, 16, 23, 32, 45, 64, 91, 128, 181, 256)]  # ~√2 apart
    rtols = [1e-3, 3e-4, 1e-4, 3e-5, 1e-5, 3e-6, 1e-6, 3e-7, 1e-7, 3e-8, 1e-8, 3e-9, 1e-9, 1e-10]
    fine = [1.0, 1.25, 1.5, 2.0]
    euler = [1.0, 1.5, 2.0, 3.0, 4.0, 6.0, 8.0, 12.0, 16.0, 24.0, 32.0, 48.0, 64.0]
    if quick:
        gen, rtols, fine, euler = gen[2:13:3], rtols[::3], fine[:4:3], euler[::4]
    rigid = [("auto", "rtol", rtols), ("esdirk43", "rtol", rtols), ("dopri5", "rtol", rtols),
             ("generalized_alpha", "dt", gen)]
    for extra in ("radau5", "radau"):
        if RigidfemKane.knows(extra):
            rigid.insert(2, (extra, "rtol", rtols))
            break
    return {
        "rigidfem": rigid,
        "Exudyn": [("GeneralizedAlpha", "dt", gen), ("TrapezoidalIndex2", "dt", gen),
                   ("RK44", "dt", steps(2.785, fine))],
        "MuJoCo": [("Euler", "dt", steps(2.0, euler)), ("implicitfast", "dt", steps(2.0, euler)),
                   ("RK4", "dt", steps(2.785, fine))],
    }


def sweep(scene: Kane, runners: dict, references: dict, todo: dict, budget: float = 20.0) -> list:
    """Each code's settings (``settings``), coarse to fine, a method stopping after its first
    run with an error ≤ min(THRESHOLDS) or once a run took more than ``budget`` s. Rows: m,
    code, method, setting, value, tip_rms_m (against that code's reference), first_cpu_s."""
    rows = []
    for code, methods in todo.items():
        runner, ref = runners[code], tip_in_hub(scene, references[code])
        for method, setting, values in methods:
            for value in values:
                row = {"m": scene.elements, "code": code, "method": method, "setting": setting, "value": value,
                       "note": ""}
                first_run(row, lambda: runner.run(method, setting, value),
                          lambda q: {"tip_rms_m": rms_error(tip_in_hub(scene, q), ref)}, "tip_rms_m")
                rows.append(row)
                if row["tip_rms_m"] <= min(THRESHOLDS) or row["first_cpu_s"] > budget:
                    break
    return rows


def timed(rows: list, runners: dict, rounds: int, long: float = 3.0) -> None:
    """Adds ``cpu_s`` to each row reaching max(THRESHOLDS): the least CPU time
    (``time.process_time``) over ``rounds`` rounds, the codes alternating run by run within a
    round (a change of machine load hits them alike); a run whose first took over ``long`` s
    keeps that time. Other rows get their first run's time."""
    todo = {}
    for r in rows:
        r["cpu_s"] = r["first_cpu_s"]
        if r["tip_rms_m"] <= max(THRESHOLDS):
            todo.setdefault(r["code"], []).append(r)
    least_cpu_times(todo, lambda r: runners[r["code"]].run(r["method"], r["setting"], r["value"]), rounds, long)


def summary(rows: list, m: int) -> Table:
    """Per threshold: the cheapest run of each code (CPU s and setting) and the ratios."""
    return summary_table(rows, {"m": m}, "tip_rms_error_m", "tip_rms_m", THRESHOLDS)


def growth(rows: list, sizes) -> Table:
    """How each code's least cost grows from the first size to the last, per threshold."""
    a, b = sizes[0], sizes[-1]
    out = []
    for tol in THRESHOLDS:
        row = {"tip_rms_error_m": tol}
        for code in ("rigidfem", "Exudyn", "MuJoCo"):
            ra = cheapest([r for r in rows if r["m"] == a], code, "tip_rms_m", tol)
            rb = cheapest([r for r in rows if r["m"] == b], code, "tip_rms_m", tol)
            row[f"{code}_m{b}/m{a}"] = rb["cpu_s"] / ra["cpu_s"] if ra and rb else "-"
        out.append(row)
    return Table(out, ("tip_rms_error_m", *(f"{c}_m{b}/m{a}" for c in ("rigidfem", "Exudyn", "MuJoCo"))))


SWEEP_COLUMNS = ("m", "code", "method", "setting", "value", "tip_rms_m", "cpu_s", "first_cpu_s", "note")


def versions() -> dict:
    return common.versions(_peer)


def run(output_dir="bench", quick: bool = False) -> dict:
    """``python -m benchmarks kane_peers``: for m = 20 and 40 (``quick``: m = 6, fewer settings,
    one timing round), verify the peers' models against rigidfem's, sweep every code's
    solvers, time the runs reaching 1e-4 m in 3 interleaved rounds, and print the cheapest
    setting per code and threshold, the ratios and the growth from the smaller m to the larger.
    Writes kane_peers_{verification,sweep,summary,growth}.csv into ``output_dir``."""
    print(common.versions_line(versions()), flush=True)
    sizes = (4, 6) if quick else (20, 40)
    checks, rows, summaries = [], [], []
    for m in sizes:
        start = time.perf_counter()
        scene = kane(m)
        runners = {"rigidfem": RigidfemKane(scene), "Exudyn": ExudynKane(scene), "MuJoCo": MujocoKane(scene)}
        if not runners["MuJoCo"].native:
            print("note: no C compiler: MuJoCo's hub drive is a Python callback (its times include Python)")
        references = {code: runner.reference() for code, runner in runners.items()}
        checks += verify(scene, runners, references).rows
        print(f"[{time.perf_counter() - start:6.1f} s] m = {m}: models verified (ω_max = {scene.omega_max:.4g} rad/s)",
              flush=True)
        these = sweep(scene, runners, references, settings(scene, quick), budget=5.0 if quick else 20.0)
        print(f"[{time.perf_counter() - start:6.1f} s] m = {m}: swept {len(these)} runs", flush=True)
        timed(these, runners, rounds=1 if quick else 3)
        print(f"[{time.perf_counter() - start:6.1f} s] m = {m}: timed", flush=True)
        rows += these
        summaries += summary(these, m).rows
    s = summary(rows, 0)
    tables = report({
        "kane_peers_verification": ("Models verified equal: each code's converged tip history against rigidfem's "
                                    "(m)", Table(checks, VERIFY_COLUMNS)),
        "kane_peers_sweep": ("Every run: tip RMS error against the code's own converged solution (m), least CPU "
                             "time (s)", Table(rows, SWEEP_COLUMNS)),
        "kane_peers_summary": ("Cheapest CPU time (s) per code to reach each tip RMS error, and the peers' time "
                               "over rigidfem's", Table(summaries, s.columns)),
        "kane_peers_growth": (f"Cost growth from m = {sizes[0]} to m = {sizes[-1]} (least CPU time ratio)",
                              growth(rows, sizes)),
    }, output_dir)
    return {name[len("kane_peers_"):]: table for name, table in tables.items()}
