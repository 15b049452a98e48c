"""A whippy strip released from rest side by side: rigidfem, Exudyn and MuJoCo (issue 29, row 2).

The scene: ``benchmarks.accuracy.strip(m)`` — a steel strip of 1 m, 20 × 2 mm, clamped
horizontally, bending in the vertical plane only, undamped, released straight from rest under
gravity (g = 9.81 m/s² along −y), simulated over 2 s and observed at its tip at 401 output times
(every 5 ms). It excites every mode of the strip: the highest natural frequency of the chain,
ω_max, grows as m² (6.8e3, 2.7e4, 1.07e5 rad/s at m = 16, 32, 64), and the high modes' phases
weigh at 1e-6 m: at m = 16 generalised-α at h = 0.02 ms is still 7e-7 m off, RK4 is 6e-7 m off at
h ω_max = 1.35 and 1.1e-8 m at 0.34.

Five models, each run against its own converged solution:

- ``rigidfem``: the modified-RFEM chain of the compiled System (rfe 0 clamped, rfes 1..m on
  revolute joints about z with springs c = EI m / L).
- ``Exudyn``: the same chain read from the compiled System (``peers.describe``) as one
  ``ObjectKinematicTree`` (links on RevoluteZ joints, springs as its P control, its gravity), so
  the two models are identical;
- ``Exudyn ANCF``: m ``ObjectANCFCable2D`` elements (cubic Hermite, planar, extensible: a
  different discretisation), clamped by coordinate constraints at the root, with the EI and ρA of
  the System and the strip's axial stiffness EA (E and the section read from the System too:
  ``Section``);
- ``MuJoCo``: the chain as MJCF by ``peers.to_mjcf`` (hinges with stiffness), identical to
  rigidfem's;
- ``MuJoCo flex``: a 1D ``flexcomp`` (MuJoCo 4's discrete elastic rod, which replaced the cable
  composite and its plugin) of m edges, a different discretisation: point masses at the
  vertices, bending springs EI/ℓ at the interior vertices (a circular section of the strip's I,
  ``dof="2d"``: in-plane only), edges kept at their length by MuJoCo's (soft) edge equality
  constraints (time constant 1 ms), clamped by pinning a ghost edge before the root
  (``MujocoFlex`` says why each).

``reference`` computes each model's converged solution and its self-check (against a run at twice
the step or a 10 times looser tolerance), within ``REF_BUDGET``; a threshold is measured for a
model only where that self-check is at most a third of it (``Reference.measures``). ``verify``
checks before any timing that the identical models' converged tip histories equal rigidfem's
(within ``AGREEMENT`` m) and reports how far the different discretisations' converged tips are
from rigidfem's (informative). ``sweep`` runs each code's solvers over their steps or
tolerances (a run predicted over ``RUN_BUDGET`` is not run: the row says so), ``timed`` times the
cheapest runs that reach the thresholds in interleaved rounds (CPU time, ``time.process_time``,
least over the rounds), ``cheapest`` picks the cheapest setting per code and threshold. The tip
error is the LARGEST distance over the output times between the tip and the code's own
converged tip (the same measure for every code)::

    python -m benchmarks strip_peers [--quick] [--output DIR]

Needs the peer codes: ``pip install exudyn mujoco``. SI units: m, rad, kg, s, N.
"""

from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from rigidfem import SimulationError, simulate
from rigidfem.studies.study import Table

from . import _peers_common as common
from ._common import report
from ._peers_common import INSTALL_HINT  # noqa: F401 - kept: this module's name for it
from ._peers_common import (exudyn_settings, exudyn_solve, first_run, least_cpu_times, mujoco_fixed_step,
                            mujoco_outputs, setting_text, summary_columns, summary_table)
from .accuracy import strip
from .kane_peers import _rotation
from .peers import Chain, describe, to_mjcf

AGREEMENT = 1e-6          #: m, largest tip difference allowed between the identical models' converged solutions
THRESHOLDS = (1e-4, 1e-6)  #: m, largest tip errors
CODES = ("rigidfem", "Exudyn", "Exudyn ANCF", "MuJoCo", "MuJoCo flex")
PEERS = {"Exudyn": ("Exudyn", "Exudyn ANCF"), "MuJoCo": ("MuJoCo", "MuJoCo flex")}
ANCF_NEWTON_RTOL = (1e-6, 1e-5)  #: Exudyn's Newton relative tolerances on the ANCF cable (see ExudynANCF)
TOLERANCES = [1e-3, 5e-4, 2e-4, 1e-4, 5e-5, 2e-5, 1e-5, 5e-6, 2e-6, 1e-6, 5e-7, 2e-7, 1e-7, 5e-8, 2e-8, 1e-8]
DIVISIONS = (1, 2, 4, 8, 16, 32, 64, 128, 256, 512)  #: fixed steps: the output interval (5 ms) over these
STABLE = (1.0, 1.5, 2.0, 3.0, 4.0, 6.0, 8.0)       #: explicit steps: the stability limit over these
EULER = (1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0)     #: first-order explicit steps: the limit over these
RUN_BUDGET = 15.0   #: s, a sweep's run predicted to take longer is skipped (and its method stops)
REF_BUDGET = 45.0   #: s, a reference predicted to take longer gives way to the next, cheaper one
LONG = 2.0          #: s, a run whose first took longer is timed once (its first run)
EDGE_SOLREF = 1e-3  #: s, the time constant of MuJoCo's edge equality constraints on the flex rod (MujocoFlex)


_peer = common.peer_guard("strip_peers")


# ---------------------------------------------------------------------------------------------
# The scene, read from rigidfem's compiled System
# ---------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class Section:
    """The strip's beam data read from the compiled chain: length L (m), bending stiffness EI
    (N·m²), mass per length ρA (kg/m), the rectangle's width (z) and thickness (y) (m) from the
    rfes' inertias, and so E (Pa), A (m²), EA (N) and I (m⁴)."""

    length: float
    EI: float
    rhoA: float
    width: float
    thickness: float

    @property
    def A(self) -> float:
        return self.width * self.thickness

    @property
    def I(self) -> float:  # noqa: E743 - the second moment of area
        return self.width * self.thickness**3 / 12.0

    @property
    def E(self) -> float:
        return self.EI / self.I

    @property
    def EA(self) -> float:
        return self.E * self.A


def section(system, tip) -> Section:
    """``Section`` of a uniform strip chain: L from the tip at q = 0, EI = c ℓ (the joint springs
    and the rfe length ℓ = L/m), ρA = total mass / L, and the section's sides from an inner rfe's
    inertia about its centre of mass: I_zz = μ (ℓ² + t²)/12, I_yy = μ (ℓ² + w²)/12."""
    m = system.nq
    L = float(system.position(tip, 0.0, np.zeros(m))[0])
    ell = L / m
    c = np.asarray(system.stiffness)
    if not np.allclose(c, c[0], rtol=1e-12):
        raise ValueError("system: expected a uniform strip (equal joint springs)")
    mu, inertia = float(system.masses[1]), np.asarray(system.inertias[1])
    thickness = math.sqrt(12.0 * inertia[2, 2] / mu - ell**2)
    width = math.sqrt(12.0 * inertia[1, 1] / mu - ell**2)
    return Section(L, float(c[0]) * ell, float(np.sum(system.masses)) / L, width, thickness)


@dataclass
class Strip:
    """The compiled scene (``accuracy.strip``): its System, tip Point, chain (``peers.describe``),
    section and the chain's highest natural frequency at rest (rad/s)."""

    elements: int
    scene: object
    chain: Chain
    section: Section
    omega_max: float
    t_eval: np.ndarray = field(default=None)

    @property
    def system(self):
        return self.scene.system

    @property
    def t_end(self) -> float:
        return self.scene.t_end

    @property
    def interval(self) -> float:
        return float(self.t_eval[1] - self.t_eval[0])


def whippy_strip(elements: int) -> Strip:
    scene = strip(elements)
    system = scene.system
    M = system.mass_matrix(0.0, np.zeros(system.nq))
    omega_max = float(np.sqrt(np.max(np.linalg.eigvals(np.linalg.solve(M, np.diag(system.stiffness))).real)))
    return Strip(elements, scene, describe(system), section(system, scene.tip), omega_max, scene.t_eval)


def tip_position(s: Strip, q) -> np.ndarray:
    """The tip's global position (N, 3), m, from the chain's joint angles q (N, nq) in rigidfem's
    order: forward kinematics through the placements (the same for every chain model)."""
    q = np.atleast_2d(q)
    column = {name: k for k, name in enumerate(s.chain.coordinate_names)}
    frames = []
    for link in s.chain.links:
        T = np.tile(link.placement, (len(q), 1, 1)) if link.parent < 0 else frames[link.parent] @ link.placement
        for axis in link.coordinates:
            T = T @ _rotation(axis, q[:, column[f"{link.name}.{axis}"]])
        frames.append(T)
    return (frames[s.scene.tip.body] @ np.append(s.scene.tip.r, 1.0))[:, :3]


def max_error(tip, reference) -> float:
    """The largest distance over the output times between two tip histories (m)."""
    return float(np.max(np.linalg.norm(np.asarray(tip) - np.asarray(reference), axis=1)))


def _steps(s: Strip, h: float) -> float:
    """The largest step ≤ h dividing the output interval."""
    return s.interval / math.ceil(s.interval / h - 1e-12)


def _fine(s: Strip, omega_max: float) -> float:
    """The explicit references' step: h ω_max ≤ 0.35 (an eighth of RK4's stability limit) and at
    most interval/64. (The strip released from rest rings in every mode: at m = 16 RK4 is within
    1.1e-8 m of the exact chain at h ω_max = 0.34, 1.6e-7 m at 0.68, 6.1e-7 m at 1.35.)"""
    return _steps(s, min(0.35 / omega_max, s.interval / 64))


def _divisions(s: Strip, quick: bool) -> list:
    """Fixed steps of the implicit methods: the output interval over 1, 2, 4, ... (coarse to fine)."""
    return [s.interval / k for k in (DIVISIONS[::2] if quick else DIVISIONS)]


def _explicit(s: Strip, limit: float, quick: bool, factors=STABLE) -> list:
    """Explicit steps dividing the output interval from the stability limit (s) down by ``factors``."""
    return sorted({_steps(s, limit / f) for f in (factors[::3] if quick else factors)}, reverse=True)


# ---------------------------------------------------------------------------------------------
# The five models: each ``run(method, setting, value)`` returns what the code outputs (joint
# angles or tip positions) at the output times, ``tip`` turns it into the tip (N, 3)
# ---------------------------------------------------------------------------------------------

class _OnTheChain:
    """What the three models of rigidfem's chain share (rigidfem's, Exudyn's KinematicTree and
    MuJoCo's chain, all with the chain's coordinates): the tip by the chain's forward kinematics
    (``tip_position``) and the chain's highest natural frequency."""

    def tip(self, raw) -> np.ndarray:
        return tip_position(self.s, raw)

    @property
    def omega_max(self) -> float:
        return self.s.omega_max


class RigidfemStrip(_OnTheChain):
    code = "rigidfem"

    def __init__(self, s: Strip):
        self.s = s

    def run(self, method: str, setting: str, value: float, t_end: float | None = None) -> np.ndarray:
        return np.asarray(self.simulation(method, setting, value, t_end).q)

    def simulation(self, method: str, setting: str, value: float, t_end: float | None = None):
        """The run's ``rigidfem.Result`` (``run`` returns its coordinates)."""
        kw = {setting: value}
        if setting == "rtol":
            kw["atol"] = value * 1e-2
        elif setting == "atol":
            kw["rtol"] = 0.0  # the default asked for a largest tip error E: atol = E, rtol = 0
        t_end = self.s.t_end if t_end is None else t_end
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return simulate(self.s.system, t_end, method=method, t_eval=self.s.t_eval[self.s.t_eval <= t_end + 1e-12],
                            max_steps=10**8, stiffness_warning=False, **kw)

    def references(self) -> list:
        """radau5 at rtol = 1e-11 (its error on the bodies' displacements), checked at 1e-10."""
        return [("radau5", "rtol", 1e-11, 1e-10)]

    def methods(self, quick: bool) -> list:
        """auto (the default asked for a largest tip error E: atol = E, rtol = 0), radau5 and
        radau9 over rtol (atol = rtol/100), esdirk43 and dopri5 (holding the state), generalised-α and
        implicit_spring at fixed steps, rk4 from its stability limit."""
        tols = TOLERANCES[::3] if quick else TOLERANCES
        return [("auto", "atol", tols), ("radau5", "rtol", tols), ("radau9", "rtol", tols),
                ("esdirk43", "rtol", tols[::3]),
                ("dopri5", "rtol", tols[::3]), ("generalized_alpha", "dt", _divisions(self.s, quick)),
                ("implicit_spring", "dt", _divisions(self.s, quick)),
                ("rk4", "dt", _explicit(self.s, 2.785 / self.omega_max, quick))]


class _Exudyn:
    """What both Exudyn models share: fixed steps h dividing the output interval, the
    coordinates recorded by a ``SensorNode`` every output interval (in memory), no solution file;
    modified Newton and Exudyn's default spectral radius 0.9 of generalised-α."""

    code = "Exudyn"
    newton = {}

    def __init__(self, s: Strip):
        self.exu = _peer("exudyn", "exudyn")
        self.s = s

    def _settings(self, method: str, h: float, t_end: float):
        ss = exudyn_settings(self.exu, t_end, h, self.s.interval)
        ti = ss.timeIntegration
        for key, value in self.newton.items():
            setattr(ti.newton, key, value)
        if self.newton:
            ti.adaptiveStep = False  # a Newton failure fails the run instead of halving the step for minutes
        return ss

    def _solve(self, method: str, setting: str, h: float, t_end: float | None):
        if setting != "dt":
            raise ValueError(f"setting: expected dt for Exudyn, got {setting}")
        n = int(round(self.s.interval / h))
        if abs(n * h - self.s.interval) > 1e-9 * self.s.interval:
            raise ValueError(f"dt: expected a step dividing {self.s.interval} s, got {h}")
        t_end = self.s.t_end if t_end is None else t_end
        ss = self._settings(method, h, t_end)
        outputs = int(round(t_end / self.s.interval)) + 1
        return exudyn_solve(self.exu, self.mbs, ss, self.sensor, method, h, self.s.t_eval[:outputs],
                            text=lambda e: str(e).strip()[:60], bound=1e3)


class ExudynChain(_OnTheChain, _Exudyn):
    """The chain as one ``ObjectKinematicTree``: rfe 0 is clamped to the ground (no joint), so
    the tree's links are rfes 1..m, on RevoluteZ joints at rigidfem's placements (rfe 1's moved
    by rfe 0's), with their masses, centres of mass and inertias; the joint springs and dampers
    are the tree's P and D control (force c (rest − q) + b (0 − q̇)); gravity is the tree's.
    Solvers: GeneralizedAlpha, TrapezoidalIndex2 (implicit) and RK44 (explicit; its DOPRI5
    always adapts its step without landing on the output times, and explicit Euler is unstable
    on the undamped strip at any step)."""

    code = "Exudyn"

    def __init__(self, s: Strip):
        super().__init__(s)
        exu = self.exu
        from exudyn.itemInterface import NodeGenericODE2, ObjectKinematicTree, SensorNode

        clamped, index = {}, {}
        HTs, masses, coms, inertias, parents, c, b, rest = [], [], [], [], [], [], [], []
        for p, link in enumerate(s.chain.links):
            if not link.coordinates:
                if link.parent >= 0:
                    raise ValueError(f"chain: expected only the clamped rfe without joint, got {link.name}")
                clamped[p] = link.placement
                continue
            if link.coordinates != ("rz",):
                raise ValueError(f"chain: expected rfes on rz joints, got {link.coordinates} on {link.name}")
            if link.parent in clamped:
                HTs.append(clamped[link.parent] @ link.placement)
                parents.append(-1)
            else:
                HTs.append(link.placement)
                parents.append(index[link.parent])
            index[p] = len(masses)
            masses.append(link.mass)
            coms.append(link.com)
            inertias.append(link.inertia)
            c.append(float(link.stiffness[0]))
            b.append(float(link.damping[0]))
            rest.append(float(link.rest[0]))
        n = len(masses)
        self.container = exu.SystemContainer()
        mbs = self.mbs = self.container.AddSystem()
        node = mbs.AddNode(NodeGenericODE2(referenceCoordinates=[0.0] * n, initialCoordinates=[0.0] * n,
                                           initialCoordinates_t=[0.0] * n, numberOfODE2Coordinates=n))
        mbs.AddObject(ObjectKinematicTree(
            nodeNumber=node, gravity=[float(g) for g in s.chain.gravity], jointTypes=[exu.JointType.RevoluteZ] * n,
            linkParents=parents, jointTransformations=exu.Matrix3DList([H[:3, :3] for H in HTs]),
            jointOffsets=exu.Vector3DList([H[:3, 3] for H in HTs]), linkInertiasCOM=exu.Matrix3DList(inertias),
            linkCOMs=exu.Vector3DList(coms), linkMasses=masses, jointPControlVector=c, jointDControlVector=b,
            jointPositionOffsetVector=rest, jointVelocityOffsetVector=[0.0] * n))
        self.sensor = mbs.AddSensor(SensorNode(nodeNumber=node, storeInternal=True,
                                               outputVariableType=exu.OutputVariableType.Coordinates))
        mbs.Assemble()
        names = [link.name for link in s.chain.links if link.coordinates]
        if [f"{name}.rz" for name in names] != list(s.chain.coordinate_names):
            raise ValueError("chain: expected one rz coordinate per moving rfe, in body order")

    def run(self, method: str, setting: str, value: float, t_end: float | None = None) -> np.ndarray:
        return self._solve(method, setting, value, t_end)[:, 1:]

    def references(self) -> list:
        """RK44 at ``_fine`` steps, checked at twice the step; where that is beyond the budget
        (m = 64: 1.3 ms a step, 600,000 steps), generalised-α at h = interval/64 checked at
        interval/32: a reference for 1e-4 m only (generalised-α's error at interval/256 is still
        ~1e-6 m: the phases of the high modes, which ring at a few 1e-7 m each)."""
        h = _fine(self.s, self.omega_max)
        return [("RK44", "dt", h, _steps(self.s, 2.0 * h)),
                ("GeneralizedAlpha", "dt", self.s.interval / 64, self.s.interval / 32)]

    def methods(self, quick: bool) -> list:
        return [("GeneralizedAlpha", "dt", _divisions(self.s, quick)),
                ("TrapezoidalIndex2", "dt", _divisions(self.s, quick)),
                ("RK44", "dt", _explicit(self.s, 2.785 / self.omega_max, quick))]


class ExudynANCF(_Exudyn):
    """Exudyn's planar ANCF cable: m ``ObjectANCFCable2D`` elements of length L/m on m + 1
    ``NodePoint2DSlope1`` nodes (position and slope, 4 coordinates each) along x, with the strip's
    EI, ρA and axial stiffness EA (the cable is extensible: the chain is not), gravity as a
    ``LoadMassProportional`` on each element, no damping; the root node clamped by three
    ``ObjectConnectorCoordinate`` to the ground (x, y and the slope's y). A different
    discretisation (cubic Hermite, consistent mass): compared against its own converged solution.

    The axial stiffness puts ω_max at 7.9e5 rad/s at m = 16 (Exudyn's ODE2 eigenvalues; the
    chain's is 6.8e3): RK44 would need 570,000 steps at its stability limit, so only the implicit
    solvers run. Newton's relative tolerance is 1e-6 (the value of Exudyn's ANCF examples): at its
    default 1e-8 round-off in the axial forces keeps Newton from converging, and the adaptive step
    then halves the step down to 5e-7 s (409 s of CPU for 2 s at m = 16); with 1e-6 and 1e-7 the tips
    differ by ~1e-8 m. Where Newton cannot reach 1e-6 either (m = 64 at h = interval/256: it fails
    in the first steps) the step runs at 1e-5 (remembered per step, so the timing rounds do not
    repeat the failed attempt). A Newton failure fails the run (no adaptive step)."""

    code = "Exudyn ANCF"

    def __init__(self, s: Strip):
        super().__init__(s)
        exu = self.exu
        from exudyn.itemInterface import (LoadMassProportional, MarkerBodyMass, MarkerNodeCoordinate,
                                          NodePoint2DSlope1, NodePointGround, ObjectANCFCable2D,
                                          ObjectConnectorCoordinate, SensorNode)

        m, sec = s.elements, s.section
        g = np.asarray(s.chain.gravity, float)
        if g[2] != 0.0 or not np.allclose(tip_position(s, np.zeros((1, s.system.nq)))[0], [sec.length, 0, 0]):
            raise ValueError("strip: expected a strip along x in the x-y plane")
        self.container = exu.SystemContainer()
        mbs = self.mbs = self.container.AddSystem()
        ell = sec.length / m
        nodes = [mbs.AddNode(NodePoint2DSlope1(referenceCoordinates=[i * ell, 0.0, 1.0, 0.0])) for i in range(m + 1)]
        for i in range(m):
            cable = mbs.AddObject(ObjectANCFCable2D(length=ell, massPerLength=sec.rhoA, bendingStiffness=sec.EI,
                                                    axialStiffness=sec.EA, nodeNumbers=[nodes[i], nodes[i + 1]]))
            mbs.AddLoad(LoadMassProportional(markerNumber=mbs.AddMarker(MarkerBodyMass(bodyNumber=cable)),
                                             loadVector=[float(g[0]), float(g[1]), 0.0]))
        ground = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=mbs.AddNode(NodePointGround()), coordinate=0))
        for coordinate in (0, 1, 3):  # x, y and the slope's y of the root: clamped
            root = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=nodes[0], coordinate=coordinate))
            mbs.AddObject(ObjectConnectorCoordinate(markerNumbers=[ground, root]))
        self.sensor = mbs.AddSensor(SensorNode(nodeNumber=nodes[-1], storeInternal=True,
                                               outputVariableType=exu.OutputVariableType.Position))
        mbs.Assemble()

        self._omega_max = None
        self.tolerance = {}  # (method, dt) -> the Newton tolerance that worked

    def run(self, method: str, setting: str, value: float, t_end: float | None = None) -> np.ndarray:
        key = (method, value)
        for tolerance in ANCF_NEWTON_RTOL:
            if self.tolerance.get(key, tolerance) != tolerance:
                continue  # this step needed a looser one before
            self.newton = {"relativeTolerance": tolerance}
            try:
                data = self._solve(method, setting, value, t_end)
            except SimulationError:
                if tolerance == ANCF_NEWTON_RTOL[-1]:
                    raise
                continue
            self.tolerance[key] = tolerance
            return data[:, 1:4]

    def tip(self, raw) -> np.ndarray:
        return np.asarray(raw)

    @property
    def omega_max(self) -> float:
        """Highest natural frequency at rest (rad/s): Exudyn's ODE2 eigenvalues with the
        constraints."""
        if self._omega_max is None:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                values = self.mbs.ComputeODE2Eigenvalues(useAbsoluteValues=True)[0]
            self._omega_max = float(np.sqrt(np.max(values)))
        return self._omega_max

    def references(self) -> list:
        """Generalised-α at h = interval/64 checked at interval/32: a reference for 1e-4 m only.
        (Its only converging solvers are second order: at interval/256, 400 steps an output
        interval, generalised-α's self-check is still 1.7e-6 m at m = 16 and 1.9e-6 m at m = 32,
        so 1e-6 m is out of reach of any reference the run can afford.)"""
        return [("GeneralizedAlpha", "dt", self.s.interval / 64, self.s.interval / 32)]

    def methods(self, quick: bool) -> list:
        """Generalised-α; RK44 from its stability limit (skipped where beyond the budget: the
        axial modes). (TrapezoidalIndex2 gives generalised-α's errors at its cost on the chain; it
        is left out here to keep the run short.)"""
        return [("GeneralizedAlpha", "dt", _divisions(self.s, quick)),
                ("RK44", "dt", _explicit(self.s, 2.785 / self.omega_max, quick))]


class _Mujoco:
    """What both MuJoCo models share: fixed steps dt dividing the output interval, ``mj_step(model,
    data, nstep)`` between outputs (no Python per step); a run whose qacc turned bad or non-finite
    is unstable."""

    INTEGRATORS = ()

    def references(self) -> list:
        """RK4 at ``_fine`` steps checked at twice the step, or (over the budget) at twice that
        checked at four times."""
        h = _fine(self.s, self.omega_max)
        return [("RK4", "dt", h, _steps(self.s, 2.0 * h)), ("RK4", "dt", _steps(self.s, 2.0 * h),
                                                            _steps(self.s, 4.0 * h))]

    def _step(self, method: str, value: float, t_end: float | None, read):
        mujoco, model, data = self.mujoco, self.model, self.data
        mujoco.set_mjcb_control(None)  # MuJoCo's callback is global: another driver's must not drive this chain
        n = mujoco_fixed_step(mujoco, model, data, method, value, self.s.interval)
        t_end = self.s.t_end if t_end is None else t_end
        outputs = int(round(t_end / self.s.interval)) + 1
        mujoco.mj_forward(model, data)
        return mujoco_outputs(mujoco, model, data, n, outputs, read, f"{method} dt={value:g}", bound=1e3)


class MujocoChain(_OnTheChain, _Mujoco):
    """The chain in MJCF by ``peers.to_mjcf`` (rfe 0 a body without joint, rfes 1..m on hinges
    with stiffness, damping and springref), contacts and constraints disabled. Integrators:
    Euler (semi-implicit; the springs explicit), implicitfast (implicit in the velocity forces:
    the springs still explicit), RK4, and discrete (new in MuJoCo 4: implicit in the joint
    stiffness too)."""

    code = "MuJoCo"
    INTEGRATORS = ("Euler", "implicitfast", "RK4", "discrete")

    def __init__(self, s: Strip):
        self.mujoco = _peer("mujoco", "mujoco")
        self.s = s
        self.xml = to_mjcf(s.chain, timestep=1e-4)
        self.model = self.mujoco.MjModel.from_xml_string(self.xml)
        self.data = self.mujoco.MjData(self.model)
        self.address = np.array([self.model.joint(name).qposadr[0] for name in s.chain.coordinate_names])

    def run(self, method: str, setting: str, value: float, t_end: float | None = None) -> np.ndarray:
        address = self.address
        return self._step(method, value, t_end, lambda data: data.qpos[address])

    def methods(self, quick: bool) -> list:
        """Steps from the stability limit (ω_max h ≤ 2 for Euler and implicitfast, whose springs
        are explicit; 2.785 for RK4); discrete at the implicit methods' steps."""
        w = self.omega_max
        return [("Euler", "dt", _explicit(self.s, 2.0 / w, quick, EULER)),
                ("implicitfast", "dt", _explicit(self.s, 2.0 / w, quick, EULER)),
                ("RK4", "dt", _explicit(self.s, 2.785 / w, quick)),
                ("discrete", "dt", _divisions(self.s, quick))]


class MujocoFlex(_Mujoco):
    """The strip as MuJoCo 4's 1D ``flexcomp`` (the discrete elastic rod that replaced the cable
    composite and its elasticity plugin in MuJoCo 4.0), ``type="direct"``: points at x = −ℓ, 0,
    ℓ, ..., L (ℓ = L/m), the first two pinned (``<pin id="0 1"/>`` clamps the first edge: a ghost
    edge inside the wall holds the root's slope), the others point masses with ``dof="2d"``
    (slides along x and y: the vertical plane, as the chain's bending about z).

    - Bending: ``<elasticity young="E">`` with a circular section of the strip's I (its radius
      (4I/π)^¼), stiffness EI/ℓ at each interior vertex. MuJoCo's box section would give the
      strip's I too but needs ``dof="full"`` with a twist hinge per edge (3D motion and torsion
      that the planar strip does not have).
    - Mass: ρA ℓ per point (flexcomp gives every point the same mass); the tip's is set to half
      of that in the compiled model (``mj_setConst``), a lumped mass of the tip's half edge.
    - Length: no stretching in the rod elasticity; the edges keep their length by MuJoCo's
      edge equality constraints (``<edge equality="true"/>``), as MuJoCo's docs advise for an
      inextensible rod. They are soft: with the default solref (0.02 s) the rod stretched by 7 %
      at m = 64 as it swung (the tip at 1.023 m from the wall's plane at t = 0.3 s, the chain's at
      0.957 m), so their time constant is ``EDGE_SOLREF`` = 1 ms, critically damped (0.5 ms moves
      the tip by < 2e-4 m; MuJoCo's refsafe raises it to 2 dt at steps over 0.5 ms, a softer
      model for those runs). The rod is thus not undamped along its length, a difference of
      model. (Physical edge springs EA/ℓ instead run only under Euler and RK4, explicitly, at
      steps below 2/ω_axial ≈ ℓ/c, c = 5.2 km/s.)
    - Its clamp: the root vertex's spring EI/ℓ sits where the beam needs 2EI/ℓ (half its
      Voronoi cell is inside the wall), a first-order error: the static sag at m = 16 is 13 %
      more than the beam's (~2/m), and the converged tip differs from the chain's by 0.16, 0.08
      and 0.04 m (m = 16, 32, 64) over the 2 s; with the root spring doubled (not done here), by
      0.014 m at m = 16.

    Integrators: Euler and RK4 (explicit in the rod's elasticity) and discrete (implicit in it);
    implicit and implicitfast do not take 1D rod elasticity. A model is compiled per integrator
    and step (the discrete integrator factors M + (h² + h d) K_bend at compile time)."""

    code = "MuJoCo flex"
    INTEGRATORS = ("Euler", "RK4", "discrete")

    def __init__(self, s: Strip):
        self.mujoco = _peer("mujoco", "mujoco")
        self.s = s
        self.models = {}
        self._omega_max = None
        self.model, self.data = self._compile("Euler", 1e-4)

    def to_xml(self, integrator: str, dt: float) -> str:
        s, sec = self.s, self.s.section
        m, ell = s.elements, s.section.length / s.elements
        points = " ".join(f"{(i - 1) * ell!r} 0 0" for i in range(m + 2))
        elements = " ".join(f"{i} {i + 1}" for i in range(m + 1))
        radius = (4.0 * sec.I / math.pi) ** 0.25
        g = " ".join(repr(float(v)) for v in s.chain.gravity)
        return "\n".join([
            '<mujoco model="rigidfem strip, MuJoCo flex">',
            f'  <option timestep="{dt!r}" integrator="{integrator}" gravity="{g}">',
            '    <flag contact="disable"/>',
            "  </option>",
            "  <worldbody>",
            f'    <flexcomp name="strip" type="direct" dim="1" dof="2d" point="{points}" element="{elements}" '
            f'mass="{sec.rhoA * ell * (m + 2)!r}" radius="{radius!r}">',
            f'      <elasticity young="{sec.E!r}"/>',
            f'      <edge equality="true" solref="{EDGE_SOLREF!r} 1"/>',
            '      <pin id="0 1"/>',
            '      <contact contype="0" conaffinity="0" selfcollide="none"/>',
            "    </flexcomp>",
            "  </worldbody>",
            "</mujoco>"])

    def _compile(self, integrator: str, dt: float):
        key = (integrator, dt)
        if key not in self.models:
            mujoco = self.mujoco
            model = mujoco.MjModel.from_xml_string(self.to_xml(integrator, dt))
            data = mujoco.MjData(model)
            tip = model.body(f"strip_{self.s.elements + 1}").id
            model.body_mass[tip] *= 0.5
            mujoco.mj_setConst(model, data)
            adr = model.body_jntadr[tip]
            joints = range(adr, adr + model.body_jntnum[tip])
            self.tip_origin = np.array(model.body_pos[tip])
            self.tip_axes = np.array([model.jnt_axis[j] for j in joints])
            self.tip_address = np.array([model.jnt_qposadr[j] for j in joints])
            self.models[key] = (model, data)
        return self.models[key]

    def run(self, method: str, setting: str, value: float, t_end: float | None = None) -> np.ndarray:
        self.model, self.data = self._compile(method, value)
        address = self.tip_address
        return self._step(method, value, t_end, lambda data: data.qpos[address])

    def tip(self, raw) -> np.ndarray:
        return self.tip_origin + np.asarray(raw) @ self.tip_axes

    @property
    def omega_max(self) -> float:
        """Highest natural frequency of the rod's elasticity at rest (rad/s): its passive forces
        differentiated numerically, with MuJoCo's mass matrix (the soft edge constraints, ~1/0.02
        rad/s, do not count)."""
        if self._omega_max is None:
            mujoco, model = self.mujoco, self.model
            data = mujoco.MjData(model)
            nv, eps = model.nv, 1e-7
            K = np.zeros((nv, nv))
            for j in range(nv):
                for sign in (1.0, -1.0):
                    data.qpos[:] = model.qpos0
                    data.qpos[j] += sign * eps
                    mujoco.mj_forward(model, data)
                    K[:, j] -= sign * data.qfrc_passive / (2.0 * eps)
            data.qpos[:] = model.qpos0
            mujoco.mj_forward(model, data)
            M = np.zeros((nv, nv))
            mujoco.mj_fullM(model, data, M)
            self._omega_max = float(np.sqrt(np.max(np.abs(np.linalg.eigvals(np.linalg.solve(M, K))))))
        return self._omega_max

    def methods(self, quick: bool) -> list:
        w = self.omega_max
        return [("Euler", "dt", _explicit(self.s, 2.0 / w, quick, EULER)),
                ("RK4", "dt", _explicit(self.s, 2.785 / w, quick)),
                ("discrete", "dt", _divisions(self.s, quick))]


RUNNERS = {"rigidfem": RigidfemStrip, "Exudyn": ExudynChain, "Exudyn ANCF": ExudynANCF, "MuJoCo": MujocoChain,
           "MuJoCo flex": MujocoFlex}


# ---------------------------------------------------------------------------------------------
# References, verification, sweeps, timing
# ---------------------------------------------------------------------------------------------

def predicted(runner, method: str, setting: str, value: float, probe: float = 1.0 / 200.0) -> float:
    """CPU time (s) a fixed-step run would take: a run over ``probe`` of the span, scaled up
    (0 for tolerances: adaptive runs are not predicted)."""
    if setting != "dt":
        return 0.0
    span = runner.s.interval * max(1, round(probe * runner.s.t_end / runner.s.interval))
    start = time.process_time()
    try:
        runner.run(method, setting, value, t_end=span)
    except SimulationError:
        return 0.0  # unstable or failing: the full run says so, quickly or not
    return (time.process_time() - start) * runner.s.t_end / span


@dataclass
class Reference:
    """A code's converged solution: its tip (N, 3), how it was computed, and ``self_check``, the
    largest tip distance to the same code's check run (a looser tolerance or twice the step),
    an upper estimate of its error."""

    code: str
    tip: np.ndarray
    how: str
    self_check: float
    cpu_s: float

    def measures(self, threshold: float) -> bool:
        """Whether the reference can judge errors of ``threshold``: its self-check at most a third."""
        return self.self_check <= threshold / 3.0


def reference(runner, budget: float = REF_BUDGET) -> Reference:
    """The first of ``runner.references()`` predicted within ``budget`` that runs (else the last),
    and its check run."""
    plans = runner.references()
    for k, (method, setting, value, check) in enumerate(plans):
        if k + 1 < len(plans) and predicted(runner, method, setting, value) > budget:
            continue
        try:
            start = time.process_time()
            tip = runner.tip(runner.run(method, setting, value))
            cpu = time.process_time() - start
            error = max_error(runner.tip(runner.run(method, setting, check)), tip)
        except SimulationError:
            if k + 1 < len(plans):
                continue
            raise
        return Reference(runner.code, tip, f"{method} {setting}={value:.3g} (self-check: {check:.3g})", error, cpu)


def verify(s: Strip, references: dict, tolerance: float = AGREEMENT) -> Table:
    """Each code's converged tip history against rigidfem's (largest and RMS distance, m), with
    each reference's self-check; raises ``AssertionError`` when an identical model (Exudyn's
    KinematicTree, MuJoCo's chain) differs by more than ``tolerance`` m, or twice its reference's
    self-check where that is larger (Exudyn at m = 64, whose affordable reference is
    generalised-α's, ~1e-5 m). The ANCF cable and the flex rod are other discretisations: their
    distance is reported, not checked."""
    mine = references["rigidfem"].tip
    rows = []
    for code, ref in references.items():
        d = np.linalg.norm(ref.tip - mine, axis=1)
        identical = code in ("rigidfem", "Exudyn", "MuJoCo")
        rows.append({"m": s.elements, "code": code, "model": "identical" if identical else "other discretisation",
                     "reference": ref.how, "reference_cpu_s": ref.cpu_s, "self_check_max_m": ref.self_check,
                     "vs_rigidfem_max_m": float(d.max()), "vs_rigidfem_rms_m": float(np.sqrt(np.mean(d**2))),
                     "max_tip_deflection_m": float(np.max(np.abs(mine[:, 1])))})
        allowed = max(tolerance, 2.0 * ref.self_check)
        if identical and d.max() > allowed:
            raise AssertionError(f"m = {s.elements}: {code}'s converged tip differs from rigidfem's by {d.max():.3g} m "
                                 f"(allowed {allowed:.3g} m): the models are not equal")
    return Table(rows, VERIFY_COLUMNS)


VERIFY_COLUMNS = ("m", "code", "model", "reference", "reference_cpu_s", "self_check_max_m", "vs_rigidfem_max_m",
                  "vs_rigidfem_rms_m", "max_tip_deflection_m")


def _worth_going_on(history: list, targets: list, budget: float):
    """Whether a fixed-step method should take its next, finer step: from its last two stable
    runs (dt, CPU s, error), its observed order p (at least 1, at most 6) and cost ∝ 1/dt predict
    the run reaching the largest target it has not reached; (False, why) if that run is over
    ``budget`` s."""
    if len(history) < 2:
        return True, ""
    (h1, _, e1), (h2, c2, e2) = history[-2], history[-1]
    unreached = [t for t in targets if t < e2]
    if not unreached or e1 <= 0 or e2 <= 0 or h1 <= h2:
        return True, ""
    order = min(6.0, max(1.0, math.log(e1 / e2) / math.log(h1 / h2)))
    target = max(unreached)
    cost = c2 * (e2 / target) ** (1.0 / order)
    if cost > budget:
        return False, f"stopped: {target:g} m needs ~{cost:.0f} s (order {order:.1f})"
    return True, ""


def sweep(s: Strip, runners: dict, references: dict, quick: bool = False, budget: float = RUN_BUDGET) -> list:
    """Each code's methods (``runner.methods``), coarse to fine, toward the thresholds its
    reference can judge; a method stops after its first run reaching the smallest of them, after
    a run over ``budget`` s, or (fixed steps) before a run predicted over ``budget`` s: the next
    one by a probe or by the last run's cost, or the one reaching the next threshold by the
    method's observed order (``_worth_going_on``); a row says so. Rows: m, code, method, setting,
    value, tip_error_max_m (against the code's own reference), first_cpu_s, note."""
    rows = []
    for code, runner in runners.items():
        ref = references[code].tip
        targets = [t for t in THRESHOLDS if references[code].measures(t)]
        for method, setting, values in runner.methods(quick):
            history = []  # the method's stable runs: (dt, CPU s, error)
            for value in values:
                row = {"m": s.elements, "code": code, "method": method, "setting": setting, "value": value, "note": ""}
                if setting == "dt":
                    guess = history[-1][1] * history[-1][0] / value if history else \
                        predicted(runner, method, setting, value)
                    go, why = _worth_going_on(history, targets, budget)
                    if guess > budget or not go:
                        row.update(first_cpu_s=guess, tip_error_max_m=np.inf,
                                   note=why or f"skipped: {guess:.0f} s predicted")
                        rows.append(row)
                        break
                first_run(row, lambda: runner.run(method, setting, value),
                          lambda raw: {"tip_error_max_m": max_error(runner.tip(raw), ref)}, "tip_error_max_m",
                          note=lambda e: " ".join(str(e).split())[:80])
                if np.isfinite(row["tip_error_max_m"]) and row["tip_error_max_m"] <= 1.0:
                    history.append((value, row["first_cpu_s"], row["tip_error_max_m"]))
                rows.append(row)
                if row["tip_error_max_m"] <= min(targets) or row["first_cpu_s"] > budget:
                    break
    return rows


def candidates(rows: list, references: dict) -> list:
    """The rows worth timing: per code and threshold (one the code's reference can judge), the
    runs reaching it whose first run took at most 1.5 times the cheapest's."""
    picked = []
    for code in {r["code"] for r in rows}:
        for tol in THRESHOLDS:
            if not references[code].measures(tol):
                continue
            ok = [r for r in rows if r["code"] == code and r["tip_error_max_m"] <= tol]
            if ok:
                least = min(r["first_cpu_s"] for r in ok)
                picked += [r for r in ok if r["first_cpu_s"] <= 1.5 * least and r not in picked]
    return picked


def timed(rows: list, runners: dict, references: dict, rounds: int, long: float = LONG) -> None:
    """Sets ``cpu_s`` of every row: for the ``candidates`` the least CPU time
    (``time.process_time``) over ``rounds`` rounds, the codes alternating run by run within a
    round (a change of machine load hits them alike); a run whose first took over ``long`` s
    keeps that time (its noise is small against it); other rows keep their first run's time."""
    for r in rows:
        r["cpu_s"] = r["first_cpu_s"]
    todo = {}
    for r in candidates(rows, references):
        if r["first_cpu_s"] <= long:
            todo.setdefault(r["code"], []).append(r)
    least_cpu_times(todo, lambda r: runners[r["code"]].run(r["method"], r["setting"], r["value"]), rounds)


def _judged(references: dict):
    """``admit(run, threshold)``: whether the run's code has a reference that can judge the threshold."""
    return lambda r, threshold: references[r["code"]].measures(threshold)


def cheapest(rows: list, codes, threshold: float, references: dict):
    """The cheapest run (least ``cpu_s``) of ``codes`` reaching ``threshold``, among the codes
    whose reference can judge it; None if none."""
    judged = _judged(references)
    return common.cheapest(rows, codes, "tip_error_max_m", threshold, lambda r: judged(r, threshold))


def _why(rows: list, code: str, threshold: float, references: dict) -> str:
    """Why a code has no run reaching ``threshold``."""
    if not references[code].measures(threshold):
        return f"reference self-check {references[code].self_check:.2g} m"
    tried = [r for r in rows if r["code"] == code]
    skipped = [r for r in tried if r["note"].startswith("skipped")]
    best = min((r["tip_error_max_m"] for r in tried), default=np.inf)
    text = f"not reached (best {best:.2g} m)"
    if skipped:
        text += f"; next runs {min(r['first_cpu_s'] for r in skipped):.0f}+ s"
    return text


def summary(rows: list, m: int, references: dict) -> Table:
    """Per threshold: the cheapest run of rigidfem, of Exudyn (KinematicTree or ANCF) and of
    MuJoCo (chain or flex), with the peers' time over rigidfem's."""
    return summary_table(
        rows, {"m": m}, "tip_error_max_m", "tip_error_max_m", THRESHOLDS, GROUPS, admit=_judged(references),
        setting=lambda group, r: (f"{r['code']}: " if group != "rigidfem" else "") + setting_text(r),
        missing=lambda group, codes, tol: "; ".join(f"{c}: {_why(rows, c, tol, references)}" for c in codes))


GROUPS = {"rigidfem": ("rigidfem",), **PEERS}  #: the summary's columns: rigidfem, then each peer's best model
SUMMARY_COLUMNS = summary_columns(("m",), "tip_error_max_m", GROUPS)


def per_model(rows: list, m: int, references: dict) -> Table:
    """Per threshold and model: the cheapest run (CPU s and setting) or why there is none."""
    out = []
    for tol in THRESHOLDS:
        for code in CODES:
            r = cheapest(rows, (code,), tol, references)
            out.append({"m": m, "tip_error_max_m": tol, "code": code, "cpu_s": r["cpu_s"] if r else "-",
                        "setting": setting_text(r) if r else _why(rows, code, tol, references),
                        "error_m": r["tip_error_max_m"] if r else "-"})
    return Table(out, MODELS_COLUMNS)


MODELS_COLUMNS = ("m", "tip_error_max_m", "code", "cpu_s", "setting", "error_m")


SWEEP_COLUMNS = ("m", "code", "method", "setting", "value", "tip_error_max_m", "cpu_s", "first_cpu_s", "note")


def versions() -> dict:
    return common.versions(_peer)


def run(output_dir="bench", quick: bool = False) -> dict:
    """``python -m benchmarks strip_peers``: for m = 16, 32 and 64 (``quick``: m = 4 and 8, fewer
    settings, smaller budgets, one timing round), compute each model's converged solution,
    verify the identical models against rigidfem's, sweep every code's solvers, time the
    cheapest runs reaching 1e-4 m and 1e-6 m in 3 interleaved rounds, and print the cheapest
    setting per code and threshold with the ratios. Writes
    strip_peers_{verification,sweep,models,summary}.csv into ``output_dir``."""
    print(common.versions_line(versions()), flush=True)
    sizes = (4, 8) if quick else (16, 32, 64)
    ref_budget, run_budget = (5.0, 3.0) if quick else (REF_BUDGET, RUN_BUDGET)
    checks, rows, models, summaries = [], [], [], []
    for m in sizes:
        start = time.perf_counter()
        s = whippy_strip(m)
        runners = {code: cls(s) for code, cls in RUNNERS.items()}
        references = {}
        for code, runner in runners.items():
            references[code] = reference(runner, ref_budget)
            print(f"[{time.perf_counter() - start:6.1f} s] m = {m}: {code} reference {references[code].how}, "
                  f"{references[code].cpu_s:.1f} s, self-check {references[code].self_check:.2g} m", flush=True)
        checks += verify(s, references).rows
        print(f"[{time.perf_counter() - start:6.1f} s] m = {m}: models verified (ω_max = {s.omega_max:.4g} rad/s)",
              flush=True)
        these = sweep(s, runners, references, quick, run_budget)
        print(f"[{time.perf_counter() - start:6.1f} s] m = {m}: swept {len(these)} runs", flush=True)
        timed(these, runners, references, rounds=1 if quick else 3)
        print(f"[{time.perf_counter() - start:6.1f} s] m = {m}: timed", flush=True)
        rows += these
        models += per_model(these, m, references).rows
        summaries += summary(these, m, references).rows
        tables = {
            "strip_peers_verification": ("The whippy strip, models verified equal: each model's converged solution against "
                                         "rigidfem's (m), the identical models checked", Table(checks, VERIFY_COLUMNS)),
            "strip_peers_sweep": ("The whippy strip, every run: largest tip error against the code's own converged "
                                  "solution (m), least CPU time (s)", Table(rows, SWEEP_COLUMNS)),
            "strip_peers_models": ("The whippy strip, cheapest run of each model: least CPU time (s) to reach each largest "
                                   "tip error",
                                   Table(models, MODELS_COLUMNS)),
            "strip_peers_summary": ("The whippy strip, cheapest runs: least CPU time (s) per code to reach each largest tip "
                                    "error, and the peers' time over rigidfem's", Table(summaries, SUMMARY_COLUMNS)),
        }
        for name, (_, table) in tables.items():  # what is done so far, in case a later size fails
            table.to_csv(Path(output_dir) / f"{name}.csv")
    tables = report(tables, output_dir)
    return {name[len("strip_peers_"):]: table for name, table in tables.items()}
