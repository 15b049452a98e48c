"""Size side by side: one second of a beam of 10³ and 10⁴ elements in rigidfem, Exudyn and MuJoCo
(issue 29, row 4).

The scene: ``strip_peers``' whippy strip (``benchmarks.accuracy.strip(m, t_end=1)``: a steel strip
of 1 m, 20 × 2 mm, clamped horizontally, bending in the vertical plane, undamped, released from
rest under gravity) at m = 1000 and 10000 rfes, 1 s, its tip at 401 outputs (every 2.5 ms). Its
highest natural frequency grows as m² (9.3e6 rad/s at m = 1000, ~9.3e8 at 10⁴): explicit steps
would be below 0.3 µs and 3 ns, so only methods implicit in the elastic forces can run, at steps
set by accuracy.

The same chain in each code (identical models; the codes' other beams are discussed in
docs/peers.md):

- ``rigidfem``: the compiled modified-RFEM chain (rfe 0 clamped, rfes 1..m on revolute joints about
  z with springs EI m / L); its implicit methods solve an O(n) system per Newton iteration
  (GMRES preconditioned by the spring matrix: ``simulate``'s Krylov iteration matrix);
- ``Exudyn``: the chain in redundant coordinates, so that Exudyn's sparse solver
  (``linearSolver.solverType = EigenSparse``) applies: one ``NodeRigidBody2D`` +
  ``ObjectRigidBody2D`` per moving rfe at its centre of mass (its mass and inertia about z),
  ``ObjectJointRevolute2D`` at the joints, the joint springs as ``ObjectConnectorCoordinateSpringDamper``
  between the bodies' rotation coordinates (rfe 1's against the ground), gravity a
  ``LoadForceVector`` m g at each centre of mass. (``strip_peers``' ``ObjectKinematicTree`` is
  the same chain in joint coordinates, but its mass matrix and Jacobian are dense n × n:
  0.32 s a generalised-α step at m = 1000 with EigenSparse, 0.83 s with the dense solver,
  against 5 ms here; ``kinematic_tree_probe`` measures it at m = 1000.)
- ``MuJoCo``: the chain built by ``mujoco.MjSpec`` (bodies nested m deep: MJCF text nests too deep
  for MuJoCo's XML parser beyond ~500 bodies), hinges with stiffness, as ``peers.to_mjcf``.
  Its mass matrix of a chain is dense (n(n+1)/2 entries: 5e5 at m = 1000, 5e7 at 10⁴) and
  factorised every step; beyond ``MUJOCO_UP_TO`` rfes it is not built.

Error: the largest distance over the outputs between the tip and the chain's converged tip,
which is the same for the three identical models: rigidfem's radau5 at rtol 1e-6, atol 1e-8
(``REFERENCE``; its self-check against rtol 1e-5 must be at most a third of a threshold). A peer's
own converged solution at 10⁴ rfes is beyond reach (Exudyn's generalised-α at h = 78 µs: 12,800
steps of 83 ms = 18 min; MuJoCo: not built), so the models are checked equal instead, before any
timing (``verify``): Exudyn's tip over the first ``CHECK_SPAN`` s at h = interval/16 against
rigidfem's at rtol 1e-8 (within ``AGREEMENT``), MuJoCo's inverse dynamics of rigidfem's
accelerations in the straight state (relative 1e-8); and each peer's errors in the sweep fall at
its order toward that solution.

``sweep`` runs each code's methods coarse to fine (a run predicted over the budget is not run:
the row says so, with the prediction), ``least_cpu_times`` times the cheapest runs per code and
threshold (CPU time, ``time.process_time``, least of 3 interleaved rounds at m = 1000; at 10⁴
one run each, the first), ``summary_table`` picks the cheapest. ``step_costs`` checks that
rigidfem's cost per step grows as O(n)::

    python -m benchmarks size_peers [--quick] [--output DIR]

Needs the peer codes: ``pip install exudyn mujoco``. SI units: m, rad, kg, s, N.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import scipy.linalg

from rigidfem import simulate
from rigidfem.studies.study import Table

from . import _peers_common as common
from ._common import cpp_seconds_per_call, report
from ._peers_common import first_run, least_cpu_times, peer_guard, summary_table
from .accuracy import strip
from .peers import describe
from .strip_peers import (MujocoChain, Reference, RigidfemStrip, Strip, _Exudyn, _steps, _worth_going_on,
                          max_error, predicted, reference, section)

_peer = peer_guard("size_peers")

SIZES = (1000, 10000)
QUICK_SIZES = (40, 80)
T_END = 1.0                  #: s, the span simulated
THRESHOLDS = (1e-3, 1e-4)    #: m, largest tip errors (the tip moves by 0.27 m)
TOLERANCES = (1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 3e-5)   #: rigidfem's rtol (radau5) and atol (auto)
DIVISIONS = (1, 2, 4, 8, 16, 32)  #: fixed steps: the output interval (2.5 ms) over these
REFERENCE = ("radau5", "rtol", 1e-6, 1e-5)  #: the chain's converged solution, checked against rtol 1e-5
RUN_BUDGET = 300.0           #: s, a run predicted to take longer is not run (its method stops)
LONG = 3.0                   #: s, a run whose first took longer is timed once (its first run)
MUJOCO_UP_TO = 2000          #: rfes; MuJoCo's dense chain is not built beyond
EIG_UP_TO = 2000             #: rfes; ω_max by a dense eigenvalue problem up to here, beyond by m² from m = 1000
CHECK_SPAN = 0.02            #: s, the span of Exudyn's equality check
AGREEMENT = 1e-6             #: m, Exudyn's tip against rigidfem's over CHECK_SPAN
CODES = ("rigidfem", "Exudyn", "MuJoCo")


def omega_max(elements: int) -> float:
    """The chain's highest natural frequency at rest (rad/s): the largest generalised eigenvalue
    of (K, M) up to ``EIG_UP_TO`` rfes, beyond that m = 1000's times (m/1000)² (it grows as m²:
    6.8e3, 2.7e4, 1.07e5, 9.3e6 rad/s at m = 16, 32, 64, 1000)."""
    if elements > EIG_UP_TO:
        return omega_max(1000) * (elements / 1000.0) ** 2
    system = strip(elements).system
    n = system.nq
    M = system.mass_matrix(0.0, np.zeros(n))
    top = scipy.linalg.eigh(np.diag(system.stiffness), M, eigvals_only=True, subset_by_index=[n - 1, n - 1])
    return float(np.sqrt(top[0]))


def size_strip(elements: int, t_end: float = T_END) -> Strip:
    """``strip_peers.Strip`` of ``accuracy.strip(elements, t_end)`` (401 outputs)."""
    scene = strip(elements, t_end)
    return Strip(elements, scene, describe(scene.system), section(scene.system, scene.tip), omega_max(elements),
                 scene.t_eval)


def _divisions(s: Strip, quick: bool) -> list:
    return [s.interval / k for k in (DIVISIONS[:4] if quick else DIVISIONS)]


# ---------------------------------------------------------------------------------------------
# The three codes (``strip_peers``' runner protocol: run(method, setting, value, t_end) -> raw,
# tip(raw) -> (N, 3), methods(quick), references(), and here cost(method, value): predicted s)
# ---------------------------------------------------------------------------------------------

class RigidfemSize(RigidfemStrip):
    """rigidfem's chain: auto (atol = E, rtol = 0), radau5 (rtol, atol = rtol/100) and
    generalised-α at fixed steps, each with its default iteration matrix (Krylov at these sizes)."""

    def references(self) -> list:
        return [REFERENCE]

    def methods(self, quick: bool) -> list:
        tols = TOLERANCES[::2] if quick else TOLERANCES
        return [("auto", "atol", tols), ("radau5", "rtol", tols), ("generalized_alpha", "dt", _divisions(self.s, quick))]

    def cost(self, method: str, value: float) -> float:
        return 0.0  # adaptive or cheap: not predicted


class ExudynSparseChain(_Exudyn):
    """The chain in Exudyn's redundant coordinates, solved with its sparse solver (module
    docstring): 3 coordinates per rfe and 2 constraint rows per joint; GeneralizedAlpha
    (spectral radius 0.9, Exudyn's default) and TrapezoidalIndex2 at fixed steps, modified Newton
    with Exudyn's default tolerances. The tip is a ``SensorBody`` position on the last rfe."""

    code = "Exudyn"

    def __init__(self, s: Strip):
        super().__init__(s)
        exu = self.exu
        from exudyn.itemInterface import (LoadForceVector, MarkerBodyPosition, MarkerNodeCoordinate,
                                          NodePointGround, NodeRigidBody2D, ObjectConnectorCoordinateSpringDamper,
                                          ObjectGround, ObjectJointRevolute2D, ObjectRigidBody2D, SensorBody)

        self.container = exu.SystemContainer()
        mbs = self.mbs = self.container.AddSystem()
        g = np.asarray(s.chain.gravity, float)
        ground = mbs.AddObject(ObjectGround())
        ground_angle = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=mbs.AddNode(NodePointGround()), coordinate=0))
        frames, centres, bodies, angles = {}, {}, {}, {}
        for p, link in enumerate(s.chain.links):
            frame = link.placement if link.parent < 0 else frames[link.parent] @ link.placement
            if abs(frame[0, 1]) > 1e-12 or abs(frame[2, 3]) > 1e-12:
                raise ValueError("chain: expected a straight planar chain in the x-y plane")
            frames[p], centres[p] = frame, frame[:3, :3] @ link.com + frame[:3, 3]
            if not link.coordinates:
                continue
            if link.coordinates != ("rz",):
                raise ValueError(f"chain: expected rfes on rz joints, got {link.coordinates} on {link.name}")
            c = centres[p]
            node = mbs.AddNode(NodeRigidBody2D(referenceCoordinates=[c[0], c[1], 0.0]))
            bodies[p] = mbs.AddObject(ObjectRigidBody2D(nodeNumber=node, mass=link.mass, inertia=link.inertia[2, 2]))
            angles[p] = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=node, coordinate=2))
            centre = mbs.AddMarker(MarkerBodyPosition(bodyNumber=bodies[p], localPosition=[0.0, 0.0, 0.0]))
            mbs.AddLoad(LoadForceVector(markerNumber=centre, loadVector=list(link.mass * g)))
            joint = frame[:3, 3]
            if link.parent in bodies:
                other = mbs.AddMarker(MarkerBodyPosition(bodyNumber=bodies[link.parent],
                                                         localPosition=list(joint - centres[link.parent])))
                other_angle = angles[link.parent]
            else:
                other = mbs.AddMarker(MarkerBodyPosition(bodyNumber=ground, localPosition=list(joint)))
                other_angle = ground_angle
            mine = mbs.AddMarker(MarkerBodyPosition(bodyNumber=bodies[p], localPosition=list(joint - c)))
            mbs.AddObject(ObjectJointRevolute2D(markerNumbers=[other, mine]))
            mbs.AddObject(ObjectConnectorCoordinateSpringDamper(
                markerNumbers=[other_angle, angles[p]], stiffness=float(link.stiffness[0]),
                damping=float(link.damping[0]), offset=float(link.rest[0])))
        tip = s.scene.tip
        if tip.body not in bodies:
            raise ValueError("scene: expected the tip on a moving rfe")
        at = frames[tip.body] @ np.append(tip.r, 1.0)
        self.sensor = mbs.AddSensor(SensorBody(bodyNumber=bodies[tip.body], localPosition=list(at[:3] - centres[tip.body]),
                                               storeInternal=True, outputVariableType=exu.OutputVariableType.Position))
        mbs.Assemble()

    def _settings(self, method: str, h: float, t_end: float):
        ss = super()._settings(method, h, t_end)
        ss.linearSolver.solverType = self.exu.LinearSolverType.EigenSparse
        return ss

    def run(self, method: str, setting: str, value: float, t_end: float | None = None) -> np.ndarray:
        return self._solve(method, setting, value, t_end)[:, 1:4]

    def tip(self, raw) -> np.ndarray:
        return np.asarray(raw)

    def methods(self, quick: bool) -> list:
        return [("GeneralizedAlpha", "dt", _divisions(self.s, quick)),
                ("TrapezoidalIndex2", "dt", _divisions(self.s, quick))]

    def cost(self, method: str, value: float) -> float:
        """Predicted CPU s of a run: a run over one output interval, scaled up."""
        return predicted(self, method, "dt", value, probe=self.s.interval / self.s.t_end)


class MujocoSpecChain(MujocoChain):
    """``strip_peers.MujocoChain`` built by ``mujoco.MjSpec`` instead of MJCF text (a chain of
    1000 bodies nests too deep for MuJoCo's XML parser): the same bodies (pos, quat, mass, centre
    of mass, full inertia), hinges with stiffness, damping and springref, contacts and
    constraints disabled. Integrators: discrete (implicit in the joint stiffness, first order) at
    the implicit steps; Euler, implicitfast (the springs explicit) and RK4 from their stability
    limits (2/ω_max, 2.785/ω_max), predicted (not run) when over the budget."""

    def __init__(self, s: Strip):
        mujoco = self.mujoco = _peer("mujoco", "mujoco")
        self.s = s
        spec = mujoco.MjSpec()
        spec.option.gravity = [float(v) for v in s.chain.gravity]
        spec.option.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONTACT) | int(mujoco.mjtDisableBit.mjDSBL_CONSTRAINT)
        bodies = {-1: spec.worldbody}
        for p, link in enumerate(s.chain.links):
            quat = np.zeros(4)
            mujoco.mju_mat2Quat(quat, np.ascontiguousarray(link.placement[:3, :3]).ravel())
            inertia = link.inertia
            body = bodies[link.parent].add_body(
                name=link.name, pos=link.placement[:3, 3], quat=quat, mass=link.mass, ipos=link.com,
                fullinertia=[inertia[0, 0], inertia[1, 1], inertia[2, 2], inertia[0, 1], inertia[0, 2], inertia[1, 2]],
                explicitinertial=True)
            for axis, c, b, rest in zip(link.coordinates, link.stiffness, link.damping, link.rest):
                if axis != "rz":
                    raise ValueError(f"chain: expected rfes on rz joints, got {axis} on {link.name}")
                body.add_joint(name=f"{link.name}.{axis}", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0.0, 0.0, 1.0],
                               stiffness=float(c), damping=float(b), springref=float(rest), armature=0.0)
            bodies[p] = body
        self.model = spec.compile()
        self.data = mujoco.MjData(self.model)
        self.address = np.array([self.model.joint(name).qposadr[0] for name in s.chain.coordinate_names])

    def methods(self, quick: bool) -> list:
        w = self.omega_max
        return [("discrete", "dt", _divisions(self.s, quick)), ("implicitfast", "dt", [_steps(self.s, 2.0 / w)]),
                ("Euler", "dt", [_steps(self.s, 2.0 / w)]), ("RK4", "dt", [_steps(self.s, 2.785 / w)])]

    def cost(self, method: str, value: float) -> float:
        """Predicted CPU s of a run at the step ``value``: 5 steps timed, scaled up."""
        mujoco, model, data = self.mujoco, self.model, self.data
        model.opt.integrator = getattr(mujoco.mjtIntegrator, f"mjINT_{method.upper()}")
        model.opt.timestep = value
        mujoco.mj_resetData(model, data)
        mujoco.set_mjcb_control(None)  # global: another driver's must not drive this chain
        start = time.process_time()
        mujoco.mj_step(model, data, nstep=5)
        return (time.process_time() - start) / 5 * self.s.t_end / value

    def residual(self, q, qd, qdd) -> float:
        """MuJoCo's inverse dynamics (``mj_inverse``) of the accelerations ``qdd`` at (q, q̇), in
        rigidfem's order: the generalised force left over (zero if MuJoCo's model moves as
        rigidfem's), relative to the largest of its passive and bias forces."""
        mujoco, model, data = self.mujoco, self.model, self.data
        mujoco.mj_resetData(model, data)
        data.qpos[self.address], data.qvel[self.address] = q, qd
        data.qacc[self.address] = qdd
        mujoco.mj_inverse(model, data)
        scale = max(np.max(np.abs(data.qfrc_bias)), np.max(np.abs(data.qfrc_passive)))
        return float(np.max(np.abs(data.qfrc_inverse)) / scale)


def runners_for(s: Strip) -> dict:
    """The codes' runners at this size (MuJoCo up to ``MUJOCO_UP_TO`` rfes)."""
    out = {"rigidfem": RigidfemSize(s), "Exudyn": ExudynSparseChain(s)}
    if s.elements <= MUJOCO_UP_TO:
        out["MuJoCo"] = MujocoSpecChain(s)
    return out


# ---------------------------------------------------------------------------------------------
# The models checked equal, the sweeps, the tables
# ---------------------------------------------------------------------------------------------

def verify(s: Strip, runners: dict, span: float = CHECK_SPAN, seed: int = 0) -> Table:
    """Before any timing: Exudyn's tip over ``span`` (generalised-α at interval/16) against
    rigidfem's (radau5 rtol 1e-8), within ``AGREEMENT`` m; MuJoCo's inverse dynamics of rigidfem's
    forward dynamics in the straight state at random rates (±1 rad/s), leaving at most 1e-8 of its
    bias forces. (Bent by ±0.01 rad, the springs' torques drive accelerations whose inertial forces
    cancel to 1e-6 of the applied ones at m = 1000, 1e-7 at 300, 3e-9 at 100, round-off of the
    ill-conditioned chain: straight, 1.6e-13. Straight, the rates' forces act along the chain: this
    checks the masses, placements and gravity; Exudyn's run checks the springs and inertias, and
    ``tests/test_benchmarks.py`` a bent state at m = 8.) Raises ``AssertionError`` otherwise."""
    mine = runners["rigidfem"]
    tip = mine.tip(mine.run("radau5", "rtol", 1e-8, t_end=span))
    rows = []
    start = time.process_time()
    theirs = runners["Exudyn"].tip(runners["Exudyn"].run("GeneralizedAlpha", "dt", s.interval / 16, t_end=span))
    d = max_error(theirs, tip)
    rows.append({"m": s.elements, "code": "Exudyn", "check": f"tip over {span:g} s, generalised-α h = interval/16",
                 "difference": d, "allowed": AGREEMENT, "cpu_s": time.process_time() - start})
    if d > AGREEMENT:
        raise AssertionError(f"m = {s.elements}: Exudyn's tip differs from rigidfem's by {d:.3g} m: the models differ")
    if "MuJoCo" in runners:
        rng = np.random.default_rng(seed)
        q, qd = np.zeros(s.system.nq), rng.uniform(-1.0, 1.0, s.system.nq)
        start = time.process_time()
        d = runners["MuJoCo"].residual(q, qd, s.system.forward_dynamics(0.0, q, qd))
        rows.append({"m": s.elements, "code": "MuJoCo", "check": "inverse dynamics of rigidfem's accelerations at a "
                     "straight state, random rates (relative)", "difference": d, "allowed": 1e-8, "cpu_s": time.process_time() - start})
        if d > 1e-8:
            raise AssertionError(f"m = {s.elements}: MuJoCo's inverse dynamics of rigidfem's accelerations leaves {d:.3g}")
    return Table(rows, VERIFY_COLUMNS)


VERIFY_COLUMNS = ("m", "code", "check", "difference", "allowed", "cpu_s")


def chain_references(runners: dict) -> dict:
    """The chain's converged solution (rigidfem's ``REFERENCE``), the same for the three
    identical models: code -> ``strip_peers.Reference``."""
    ref = reference(runners["rigidfem"])
    return {code: ref if code == "rigidfem" else Reference(code, ref.tip, f"rigidfem's {ref.how}", ref.self_check, 0.0)
            for code in runners}


def sweep(s: Strip, runners: dict, references: dict, quick: bool, budget: float) -> list:
    """Each code's methods coarse to fine toward the thresholds its reference judges. A fixed
    step is not run when predicted over ``budget`` s (by the runner's ``cost`` for the first, by
    the last run's cost times the step ratio after, or by the observed order toward the next
    threshold: ``strip_peers._worth_going_on``); the row then holds the prediction and says why.
    A method stops at its first run reaching the smallest threshold."""
    rows = []
    for code, runner in runners.items():
        targets = [t for t in THRESHOLDS if references[code].measures(t)]
        for method, setting, values in runner.methods(quick):
            done = []  # (dt, CPU s, error) of the method's stable runs
            for value in values:
                row = {"m": s.elements, "code": code, "method": method, "setting": setting, "value": value,
                       "note": ""}
                go, why = _worth_going_on(done, targets, budget) if setting == "dt" else (True, "")
                guess = (done[-1][1] * done[-1][0] / value if done else runner.cost(method, value)) \
                    if setting == "dt" else 0.0
                if guess > budget or not go:
                    rows.append({**row, "first_cpu_s": guess, "cpu_s": guess, "tip_error_max_m": np.inf,
                                 "note": why or f"not run: {guess:.3g} s predicted"})
                    break
                first_run(row, lambda: runner.run(method, setting, value),
                          lambda raw: {"tip_error_max_m": max_error(runner.tip(raw), references[code].tip)},
                          "tip_error_max_m", note=lambda e: " ".join(str(e).split())[:80])
                row["cpu_s"] = row["first_cpu_s"]
                rows.append(row)
                if np.isfinite(row["tip_error_max_m"]):
                    done.append((value, row["first_cpu_s"], row["tip_error_max_m"]))
                if row["tip_error_max_m"] <= min(targets) or row["first_cpu_s"] > budget:
                    break
            print(f"    {code} {method}: " + ", ".join(
                f"{r['value']:.3g} -> {r['tip_error_max_m']:.2g} m in {r['first_cpu_s']:.3g} s"
                for r in rows if r["code"] == code and r["method"] == method), flush=True)
    return rows


def time_cheapest(rows: list, runners: dict, rounds: int) -> None:
    """The least CPU time over ``rounds`` interleaved rounds of each code's runs within 1.5 times
    the cheapest first run reaching a threshold (``least_cpu_times``; a run over ``LONG`` s keeps
    its first time)."""
    groups = {}
    for code in runners:
        for tol in THRESHOLDS:
            ok = [r for r in rows if r["code"] == code and r["tip_error_max_m"] <= tol]
            least = min((r["first_cpu_s"] for r in ok), default=np.inf)
            for r in ok:
                if r["first_cpu_s"] <= 1.5 * least and r not in groups.setdefault(code, []):
                    groups[code].append(r)
    least_cpu_times(groups, lambda r: runners[r["code"]].run(r["method"], r["setting"], r["value"]), rounds, LONG)


def _missing(rows: list, runners: dict):
    def why(group, codes, tol) -> str:
        code = codes[0]
        if code not in runners:
            return f"not built (m > {MUJOCO_UP_TO}: a chain's mass matrix is dense in MuJoCo, n(n+1)/2 entries)"
        tried = [r for r in rows if r["code"] == code]
        reached = [r for r in tried if np.isfinite(r["tip_error_max_m"])]
        text = "; ".join(f"{r['method']}: {r['note']}" for r in tried if r["note"])
        if reached:
            best = min(reached, key=lambda r: r["tip_error_max_m"])
            text = f"best {best['tip_error_max_m']:.2g} m ({common.setting_text(best)}, {best['cpu_s']:.3g} s); " + text
        return text or "-"
    return why


def summary(rows: list, m: int, runners: dict) -> Table:
    return summary_table(rows, {"m": m}, "tip_error_max_m", "tip_error_max_m", THRESHOLDS, CODES,
                         extra={"error_m": lambda r: r["tip_error_max_m"]}, missing=_missing(rows, runners))


SUMMARY_COLUMNS = common.summary_columns(("m",), "tip_error_max_m", CODES, ("error_m",))
SWEEP_COLUMNS = ("m", "code", "method", "setting", "value", "tip_error_max_m", "cpu_s", "first_cpu_s", "note")


def step_costs(s: Strip, t_end: float = 0.1) -> list:
    """rigidfem's cost per step at this size (wall time over steps, ``simulate``'s stats, over
    ``t_end`` s): generalised-α at h = interval/2 and radau5 at rtol 1e-4, with one forward
    dynamics (timed in C++) for scale."""
    q = np.zeros(s.system.nq)
    fd = min(cpp_seconds_per_call(s.system, q, q, 20) for _ in range(3))
    rows = []
    for method, kw in (("generalized_alpha", {"dt": s.interval / 2}), ("radau5", {"rtol": 1e-4, "atol": 1e-6})):
        st = min((simulate(s.system, t_end, method=method, t_eval=[t_end], stiffness_warning=False, **kw).stats
                  for _ in range(2)), key=lambda st: st["wall_time"])
        rows.append({"m": s.elements, "nq": s.system.nq, "method": method, "steps": st["steps"],
                     "s_per_step": st["wall_time"] / st["steps"], "newton_per_step": st["newton_iterations"] / st["steps"],
                     "gmres_per_step": st.get("linear_iterations", 0) / st["steps"], "forward_dynamics_s": fd})
    return rows


STEP_COLUMNS = ("m", "nq", "method", "steps", "s_per_step", "newton_per_step", "gmres_per_step", "forward_dynamics_s",
                "growth_exponent")


def _growth(rows: list) -> None:
    """Per method, the slope of log(cost per step) against log(nq) between the sizes."""
    for method in {r["method"] for r in rows}:
        mine = sorted((r for r in rows if r["method"] == method), key=lambda r: r["nq"])
        for a, b in zip(mine, mine[1:]):
            b["growth_exponent"] = float(np.log(b["s_per_step"] / a["s_per_step"]) / np.log(b["nq"] / a["nq"]))


def kinematic_tree_probe(s: Strip) -> float:
    """CPU s per generalised-α step of ``strip_peers.ExudynChain`` (Exudyn's ObjectKinematicTree,
    dense n × n) with the sparse solver, over one output interval at h = interval/2."""
    from .strip_peers import ExudynChain

    class Sparse(ExudynChain):
        def _settings(self, method, h, t_end):
            ss = super()._settings(method, h, t_end)
            ss.linearSolver.solverType = self.exu.LinearSolverType.EigenSparse
            return ss

    tree = Sparse(s)
    start = time.process_time()
    tree.run("GeneralizedAlpha", "dt", s.interval / 2, t_end=s.interval)
    return (time.process_time() - start) / 2


def run(output_dir="bench", quick: bool = False) -> dict:
    """``python -m benchmarks size_peers``: for m = 1000 and 10000 (``quick``: 40 and 80, fewer
    settings, budget 5 s), the chain's converged solution, the models checked equal, every code's
    methods swept, the cheapest runs to 1e-3 m and 1e-4 m timed (3 rounds at m ≤ 1000, the first
    run above), rigidfem's cost per step. Writes size_peers_{verification,sweep,summary,steps}.csv."""
    print(common.versions_line(common.versions(_peer)), flush=True)
    budget = 5.0 if quick else RUN_BUDGET
    checks, rows, summaries, steps = [], [], [], []
    tables = {}
    for m in (QUICK_SIZES if quick else SIZES):
        start = time.perf_counter()
        s = size_strip(m)
        runners = runners_for(s)
        print(f"[{time.perf_counter() - start:6.1f} s] m = {m}: built (ω_max ≈ {s.omega_max:.3g} rad/s)", flush=True)
        steps += step_costs(s)
        _growth(steps)
        if not quick and m <= MUJOCO_UP_TO:
            per = kinematic_tree_probe(s)
            print(f"[{time.perf_counter() - start:6.1f} s] m = {m}: Exudyn ObjectKinematicTree (EigenSparse): "
                  f"{per:.3g} s per generalised-α step", flush=True)
        references = chain_references(runners)
        ref = references["rigidfem"]
        print(f"[{time.perf_counter() - start:6.1f} s] m = {m}: reference {ref.how}, {ref.cpu_s:.1f} s, "
              f"self-check {ref.self_check:.2g} m, largest deflection {np.max(np.abs(ref.tip[:, 1])):.3g} m", flush=True)
        checks += verify(s, runners).rows
        print(f"[{time.perf_counter() - start:6.1f} s] m = {m}: models checked equal", flush=True)
        these = sweep(s, runners, references, quick, budget)
        print(f"[{time.perf_counter() - start:6.1f} s] m = {m}: swept {len(these)} runs", flush=True)
        time_cheapest(these, runners, rounds=1 if quick or m > 1000 else 3)
        print(f"[{time.perf_counter() - start:6.1f} s] m = {m}: timed", flush=True)
        rows += these
        summaries += summary(these, m, runners).rows
        tables = {
            "size_peers_verification": ("Beams of 10³ and 10⁴ elements, models verified equal: the identical models checked", Table(checks, VERIFY_COLUMNS)),
            "size_peers_sweep": ("Beams of 10³ and 10⁴ elements, every run: largest tip error against the chain's "
                                 "converged solution (m), CPU time (s; inf: not run, the prediction in first_cpu_s)", Table(rows, SWEEP_COLUMNS)),
            "size_peers_steps": ("Beams of 10³ and 10⁴ elements, cost per step: rigidfem's cost per step (s) and its growth "
                                 "exponent in nq", Table(steps, STEP_COLUMNS)),
            "size_peers_summary": ("Beams of 10³ and 10⁴ elements, cheapest runs: least CPU time (s) per code to each largest "
                                   "tip error, and the peers' time over rigidfem's", Table(summaries, SUMMARY_COLUMNS)),
        }
        for name, (_, table) in tables.items():  # what is done so far, in case a later size fails
            table.to_csv(Path(output_dir) / f"{name}.csv")
    tables = report(tables, output_dir)
    return {name[len("size_peers_"):]: table for name, table in tables.items()}

