"""Peer benchmarks: rigidfem against Pinocchio and MuJoCo on exactly equivalent chains.

The modified-RFEM 3D cantilever (``samples.cantilever`` with the deformations bend_y,
bend_z and torsion) is a chain of rigid finite elements (rfes): rfe 0 is clamped, rfe i
hangs on rfe i − 1 through a joint of three rotations Rz(φ3) Ry(φ2) Rx(φ1) with a linear
spring (c, rest value) and a viscous damper (b) on each coordinate.

- ``describe`` reads everything needed to rebuild such a chain (or any tree of joints
  with springs and dampers) from a compiled ``System``;
- ``to_pinocchio`` and ``to_mjcf`` (with ``PinocchioChain`` and ``MujocoChain``) rebuild it
  in the peer codes, with rigidfem's coordinates q;
- ``check_pinocchio``, ``check_mujoco`` and ``verify`` check that their accelerations
  equal rigidfem's at a random state, and raise otherwise;
- ``forward_dynamics_timing`` times one forward-dynamics call against nq;
  ``stiff_beam_accuracy`` and ``equal_accuracy`` compare the cost of simulating a steel
  cantilever to a given accuracy with each code's integrators (``RIGIDFEM_METHODS``,
  ``MUJOCO_METHODS``);
- ``run`` runs it all, writes the tables as CSV and prints them as markdown::

    python -m benchmarks peers [--quick] [--output DIR]

Needs the peer codes: ``pip install pin mujoco`` (Pinocchio's PyPI name is ``pin``). SI
units throughout: m, rad, kg, s, N, N·m.
"""

from __future__ import annotations

import functools
import importlib
import os
import time
import timeit
from dataclasses import dataclass

import numpy as np

import rigidfem
from rigidfem import Material, Point, SimulationError, samples, simulate, static_equilibrium
from rigidfem.studies.study import Table, cheapest

from ._common import cpp_seconds_per_call, machine, report

INSTALL_HINT = 'pip install ".[benchmarks]" (or: pip install pin mujoco)'

#: rigidfem's integrators in the accuracy study: (method, setting, values[, extra keyword arguments]).
#: A method this build does not know yet is skipped with a note, so a new one is one line here.
RIGIDFEM_METHODS = [
    ("rk4", "dt", [1e-4, 5e-5, 2e-5, 1e-5, 5e-6]),
    ("dopri5", "rtol", [1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9]),
    ("generalized_alpha", "dt", [1e-3, 5e-4, 2e-4, 1e-4, 5e-5, 2e-5, 1e-5, 5e-6, 2e-6]),
    ("implicit_spring", "dt", [1e-3, 5e-4, 2e-4, 1e-4, 5e-5, 2e-5, 1e-5, 5e-6, 2e-6]),
]

#: MuJoCo's integrators in the accuracy study, all at fixed steps dt (s) dividing the output
#: interval. "Euler" is MuJoCo's default, semi-implicit Euler with implicit joint damping;
#: "implicitfast" is implicit in all velocity forces but Coriolis; "discrete" is also
#: implicit in the joint stiffness (new in MuJoCo 4).
MUJOCO_METHODS = [
    ("Euler", "dt", [1e-4, 5e-5, 2e-5, 1e-5, 5e-6, 2e-6, 1e-6]),
    ("implicitfast", "dt", [1e-4, 5e-5, 2e-5, 1e-5, 5e-6, 2e-6, 1e-6]),
    ("RK4", "dt", [1e-4, 5e-5, 2e-5, 1e-5, 5e-6, 2e-6]),
    ("discrete", "dt", [1e-4, 5e-5, 2e-5, 1e-5, 5e-6, 2e-6, 1e-6]),
]


def _require(module: str, package: str):
    """Import a peer code, or raise an ImportError saying how to install it."""
    try:
        return importlib.import_module(module)
    except ImportError as e:
        raise ImportError(f"benchmarks.peers needs the '{package}' package ({module}): {INSTALL_HINT}") from e


# ---------------------------------------------------------------------------------------------
# The chain, read from a compiled System
# ---------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class Link:
    """One body of a chain (or tree) and the joint it hangs from."""

    name: str
    parent: int                 #: index of the parent link, -1 for the ground
    placement: np.ndarray       #: (4, 4) joint frame in the parent's body frame (B_p; m)
    coordinates: tuple          #: joint coordinates in rigidfem's order, from "x", "y", "z", "rz", "ry", "rx"
    mass: float                 #: kg
    com: np.ndarray             #: (3,) centre of mass in the body frame, m
    inertia: np.ndarray         #: (3, 3) inertia tensor about the centre of mass, body axes, kg·m²
    stiffness: np.ndarray       #: per coordinate, N/m or N·m/rad
    damping: np.ndarray         #: per coordinate, N·s/m or N·m·s/rad
    rest: np.ndarray            #: per coordinate, the springs' rest values, m or rad


@dataclass(frozen=True)
class Chain:
    """A multibody tree of ``Link``s in rigidfem's body order, with its gravity (m/s², global)."""

    links: tuple
    gravity: np.ndarray
    coordinate_names: tuple     #: "body.axis", in the order of q

    @property
    def nq(self) -> int:
        return len(self.coordinate_names)

    @functools.cached_property
    def stiffness(self) -> np.ndarray:
        """(nq,) N/m or N·m/rad."""
        return np.concatenate([link.stiffness for link in self.links])

    @functools.cached_property
    def damping(self) -> np.ndarray:
        """(nq,) N·s/m or N·m·s/rad."""
        return np.concatenate([link.damping for link in self.links])

    @functools.cached_property
    def rest(self) -> np.ndarray:
        """(nq,) m or rad."""
        return np.concatenate([link.rest for link in self.links])

    def joint_forces(self, q, qd) -> np.ndarray:
        """Spring and damper forces −c (q − q_rest) − b q̇ (nq,), N or N·m."""
        return -self.stiffness * (np.asarray(q) - self.rest) - self.damping * np.asarray(qd)


def describe(system) -> Chain:
    """Everything needed to rebuild ``system`` in another code: parents, placements, masses,
    centres of mass and inertias of the bodies, axes (from the coordinate names), springs,
    rest values and dampers of the coordinates, gravity.

    Loads, applied generalised forces and the linear beam model's couplings are not
    described: ``check_pinocchio``/``check_mujoco`` catch such a model, whose accelerations
    will not match. Prescribed coordinates are refused.
    """
    if system.np:
        raise ValueError(f"system: expected no prescribed coordinates, got {system.np} ({system.prescribed_names})")
    # each of the System's properties read once (each read copies it from C++: inside the loop the
    # description took 100 s at 10^4 bodies)
    names, coordinate_names = list(system.body_names), list(system.coordinate_names)
    index = {name: p for p, name in enumerate(names)}
    coordinates = [[] for _ in names]
    for k, full in enumerate(coordinate_names):
        body, axis = full.rsplit(".", 1)
        coordinates[index[body]].append(k)
    c, b, r = system.stiffness, system.damping, system.rest
    masses, centres, inertias = system.masses, system.centres_of_mass, system.inertias
    links = []
    for p, (name, parent, B) in enumerate(zip(names, system.parent, system.placements)):
        idx = coordinates[p]
        axes = tuple(coordinate_names[k].rsplit(".", 1)[1] for k in idx)
        links.append(Link(name, int(parent), np.array(B), axes, float(masses[p]),
                          np.array(centres[p]), np.array(inertias[p]), c[idx], b[idx], r[idx]))
    return Chain(tuple(links), np.array(system.gravity), tuple(coordinate_names))


def agreement(system, q, qd, qdd) -> dict:
    """How well accelerations ``qdd`` computed elsewhere match rigidfem's at the state (q, q̇).

    Returns ``forward``, ‖qdd − q̈‖/‖q̈‖ with q̈ = ``system.forward_dynamics(0, q, q̇)``;
    ``backward``, the componentwise (Oettli–Prager) backward error of qdd in rigidfem's
    equations, max_i |A qdd − f|_i / (|A| |qdd| + |f|)_i, which is ~1e-13 for equal models
    whatever the conditioning of A; and ``tolerance``, the forward error that rounding
    alone can explain, ε cond(A) (ε = 2.2e-16; on the steel beam cond(A) grows fast with
    the number of rfes: 9e5 at nq = 30, 1.4e8 at nq = 300, 2.3e9 at nq = 900).
    """
    reference = system.forward_dynamics(0.0, q, qd)
    A, f = system.mass_matrix(0.0, q), system.generalized_forces(0.0, q, qd)
    eigenvalues = np.linalg.eigvalsh(A)
    return {"forward": float(np.linalg.norm(qdd - reference) / np.linalg.norm(reference)),
            "backward": float(np.max(np.abs(A @ qdd - f) / (np.abs(A) @ np.abs(qdd) + np.abs(f)))),
            "tolerance": float(np.finfo(float).eps * eigenvalues[-1] / eigenvalues[0])}


def verify(system, q, qd, qdd, rtol: float, peer: str) -> dict:
    """``agreement`` of a peer's accelerations; raises ``AssertionError`` unless the forward
    error is at most max(rtol, ε cond(A)) and the backward error at most 1e-10. (On long
    beams rtol is out of reach of any pair of codes: rigidfem's recursive and Lagrange
    algorithms differ by 1.6e-8 at nq = 900, where ε cond(A) = 5e-7.)"""
    errors = agreement(system, q, qd, qdd)
    if not (errors["forward"] <= max(rtol, errors["tolerance"]) and errors["backward"] <= 1e-10):
        raise AssertionError(f"{peer} and rigidfem disagree at nq = {system.nq}: relative q̈ error "
                             f"{errors['forward']:.3g} (allowed {max(rtol, errors['tolerance']):.3g}), backward error "
                             f"{errors['backward']:.3g} (allowed 1e-10)")
    return errors


def _random_state(system, seed: int = 0, angle: float = 0.3, rate: float = 1.0):
    """q uniform in ±angle (rad), q̇ uniform in ±rate (rad/s)."""
    rng = np.random.default_rng(seed)
    return rng.uniform(-angle, angle, system.nq), rng.uniform(-rate, rate, system.nq)


# ---------------------------------------------------------------------------------------------
# Pinocchio
# ---------------------------------------------------------------------------------------------

_PIN_JOINTS = {"x": "JointModelPX", "y": "JointModelPY", "z": "JointModelPZ",
               "rz": "JointModelRZ", "ry": "JointModelRY", "rx": "JointModelRX"}


def to_pinocchio(chain: Chain, spherical: bool = False):
    """A ``pinocchio.Model`` of the chain.

    Every coordinate is its own joint (PX, PY, PZ, RZ, RY, RX, in rigidfem's order, each in
    the frame moved by the previous ones), with massless bodies between them; with
    ``spherical``, a joint (rz, ry, rx) is instead one ``JointModelSphericalZYX`` (its
    configuration is the Euler angles (φ3, φ2, φ1) and its velocity their rates, with the
    rotation Rz Ry Rx, exactly rigidfem's). A link without coordinates is merged into the
    body it is welded to. q, v and the joint torques have rigidfem's order and units.
    """
    pin = _require("pinocchio", "pin")
    model = pin.Model()
    model.gravity = pin.Motion(np.asarray(chain.gravity, float), np.zeros(3))
    carrier = []  # per link: (Pinocchio joint id moving it, its body frame in that joint's frame)
    for link in chain.links:
        joint, frame = (0, np.eye(4)) if link.parent < 0 else carrier[link.parent]
        placement = frame @ link.placement
        if spherical and link.coordinates == ("rz", "ry", "rx"):
            joint = model.addJoint(joint, pin.JointModelSphericalZYX(), _se3(pin, placement), link.name)
            placement = np.eye(4)
        else:
            for axis in link.coordinates:
                joint = model.addJoint(joint, getattr(pin, _PIN_JOINTS[axis])(), _se3(pin, placement),
                                       f"{link.name}.{axis}")
                placement = np.eye(4)
        model.appendBodyToJoint(joint, pin.Inertia(link.mass, link.com, link.inertia), _se3(pin, placement))
        carrier.append((joint, placement))
    if model.nq != chain.nq or model.nv != chain.nq:
        raise ValueError(f"chain: expected a Pinocchio model with nq = nv = {chain.nq}, got {model.nq}, {model.nv}")
    return model


def _se3(pin, T):
    return pin.SE3(np.array(T[:3, :3]), np.array(T[:3, 3]))


class PinocchioChain:
    """A chain in Pinocchio: ``forward_dynamics(q, qd)`` by ABA with the joint springs and
    dampers as joint torques, like ``System.forward_dynamics(t, q, qd)``.

    Measured with pin 4.1 on the steel beam: with ``spherical`` (SphericalZYX) joints, ABA
    loses accuracy geometrically along the chain (relative q̈ error 1e-12 at 10 rfes, 3e-10
    at 30, 3e-4 at 50, O(1) from 60 on, in the LOCAL and WORLD conventions) although
    Pinocchio's CRBA and RNEA with the same joints agree with rigidfem (solving M q̈ = τ − b
    gives 5e-10 at 100 rfes, within rounding); three revolute joints per rfe are accurate.
    """

    def __init__(self, chain: Chain, spherical: bool = False):
        self.pin = _require("pinocchio", "pin")
        self.chain = chain
        self.model = to_pinocchio(chain, spherical)
        self.data = self.model.createData()

    def forward_dynamics(self, q, qd) -> np.ndarray:
        """q̈ (nq,) in rad/s² (m/s²)."""
        tau = self.chain.joint_forces(q, qd)
        return self.pin.aba(self.model, self.data, q, qd, tau)


def check_pinocchio(system, spherical: bool = False, seed: int = 0, rtol: float = 1e-9) -> dict:
    """``verify`` Pinocchio's ABA against rigidfem at a random state (q within ±0.3 rad, q̇
    within ±1 rad/s). With ``spherical`` joints it fails on long beams (see
    ``PinocchioChain``)."""
    peer = PinocchioChain(describe(system), spherical)
    q, qd = _random_state(system, seed)
    name = f"Pinocchio ({'SphericalZYX' if spherical else 'revolute'} joints)"
    return verify(system, q, qd, peer.forward_dynamics(q, qd), rtol, name)


# ---------------------------------------------------------------------------------------------
# MuJoCo
# ---------------------------------------------------------------------------------------------

_AXIS = {"x": "1 0 0", "y": "0 1 0", "z": "0 0 1"}


def _numbers(values) -> str:
    """Floats as round-trip text (repr), so the XML loses nothing."""
    return " ".join(repr(float(v)) for v in np.ravel(values))


def to_mjcf(chain: Chain, sites: dict | None = None, timestep: float = 1e-4, integrator: str = "Euler") -> str:
    """MJCF text of the chain.

    Each link is a ``<body>`` at its placement (pos, quat) with an ``<inertial>`` (mass,
    centre of mass, full inertia tensor), and one joint per coordinate in rigidfem's order
    (``slide`` for x, y, z; ``hinge`` for rz, ry, rx), all at the body origin: MuJoCo
    applies the joints of a body in order, each about its axis in the frame moved by the
    previous ones, which is rigidfem's Trans(x, y, z) Rz Ry Rx. Each joint carries its
    ``stiffness``, ``damping`` and ``springref`` (the rest value; ``ref`` stays 0, so
    qpos equals rigidfem's q), no armature and no friction loss. Angles are in radians;
    contacts and constraints are disabled; gravity is the chain's. ``sites`` maps names
    to ``Point``s (body index, position in its frame, m), read back as ``site_xpos``.
    ``timestep`` in s; ``integrator`` one of MuJoCo's.
    """
    mujoco = _require("mujoco", "mujoco")
    children = {}
    for p, link in enumerate(chain.links):
        children.setdefault(link.parent, []).append(p)
    sites_of = {}
    for name, point in (sites or {}).items():
        sites_of.setdefault(point.body, []).append((name, point.r))

    def opening(p: int) -> list[str]:
        link = chain.links[p]
        q = np.zeros(4)
        mujoco.mju_mat2Quat(q, np.ascontiguousarray(link.placement[:3, :3]).ravel())
        I = link.inertia
        lines = [f'<body name="{link.name}" pos="{_numbers(link.placement[:3, 3])}" quat="{_numbers(q)}">',
                 f'  <inertial pos="{_numbers(link.com)}" mass="{link.mass!r}" '
                 f'fullinertia="{_numbers([I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]])}"/>']
        for axis, c, b, r in zip(link.coordinates, link.stiffness, link.damping, link.rest):
            kind = "hinge" if axis.startswith("r") else "slide"
            lines.append(f'  <joint name="{link.name}.{axis}" type="{kind}" axis="{_AXIS[axis[-1]]}" '
                         f'stiffness="{float(c)!r}" damping="{float(b)!r}" springref="{float(r)!r}" '
                         'armature="0" frictionloss="0"/>')
        lines += [f'  <site name="{name}" pos="{_numbers(r)}"/>' for name, r in sites_of.get(p, [])]
        return lines

    # Depth first without recursion (a beam of m rfes nests m + 1 bodies); no indentation by depth.
    worldbody, stack = [], [("open", p) for p in reversed(children.get(-1, []))]
    while stack:
        action, p = stack.pop()
        if action == "close":
            worldbody.append("</body>")
            continue
        worldbody += opening(p)
        stack.append(("close", p))
        stack += [("open", child) for child in reversed(children.get(p, []))]
    return "\n".join([
        '<mujoco model="rigidfem chain">',
        '  <compiler angle="radian" inertiafromgeom="false" autolimits="true"/>',
        f'  <option timestep="{float(timestep)!r}" integrator="{integrator}" gravity="{_numbers(chain.gravity)}">',
        '    <flag contact="disable" constraint="disable"/>',
        "  </option>",
        "  <worldbody>",
        *worldbody,
        "  </worldbody>",
        "</mujoco>",
    ])


class MujocoChain:
    """A chain in MuJoCo, its coordinates in rigidfem's order (``qpos[address]`` = q)."""

    def __init__(self, chain: Chain, sites: dict | None = None, timestep: float = 1e-4, integrator: str = "Euler"):
        self.mujoco = _require("mujoco", "mujoco")
        self.chain = chain
        self.xml = to_mjcf(chain, sites, timestep, integrator)
        self.model = self.mujoco.MjModel.from_xml_string(self.xml)
        self.data = self.mujoco.MjData(self.model)
        self.address = np.array([self.model.joint(name).qposadr[0] for name in chain.coordinate_names])
        if self.model.nq != chain.nq or self.model.nv != chain.nq:
            raise ValueError(f"chain: expected a MuJoCo model with nq = nv = {chain.nq}, got {self.model.nq}, "
                             f"{self.model.nv}")

    def set_state(self, q, qd) -> None:
        """Time 0 and the state (q, q̇) in rigidfem's order, no warnings recorded."""
        self.mujoco.mj_resetData(self.model, self.data)
        self.data.qpos[self.address] = q
        self.data.qvel[self.address] = qd

    def forward_dynamics(self, q, qd) -> np.ndarray:
        """q̈ (nq,) by ``mj_forward``: MuJoCo's continuous-time acceleration ``qacc``."""
        self.set_state(q, qd)
        self.mujoco.mj_forward(self.model, self.data)
        return self.data.qacc[self.address].copy()

    def site(self, name: str, q) -> np.ndarray:
        """Global position (3,) in m of a site at configuration q."""
        self.set_state(q, np.zeros_like(q))
        self.mujoco.mj_kinematics(self.model, self.data)
        return self.data.site(name).xpos.copy()


def check_mujoco(system, seed: int = 0, rtol: float = 1e-8) -> dict:
    """``verify`` MuJoCo's ``mj_forward`` against rigidfem at a random state (q within
    ±0.3 rad, q̇ within ±1 rad/s)."""
    peer = MujocoChain(describe(system))
    q, qd = _random_state(system, seed)
    return verify(system, q, qd, peer.forward_dynamics(q, qd), rtol, "MuJoCo")


# ---------------------------------------------------------------------------------------------
# Benchmarks
# ---------------------------------------------------------------------------------------------

STEEL = dict(E=2.1e11, rho=7850.0, nu=0.3)
DEFORM = ("bend_y", "bend_z", "torsion")


def cantilever(elements: int, gravity=(0.0, 0.0, -9.81), damping: float = 1e-6):
    """The compared chain: ``samples.cantilever`` (steel, 1 m, 20 × 5 mm) in the modified
    formulation with bending about y and z and torsion (nq = 3 · elements), Kelvin–Voigt
    retardation time ``damping`` (s), ``gravity`` in m/s². Returns (model, beam)."""
    material = Material(**STEEL, retardation=damping)
    model, handles = samples.cantilever(elements=elements, material=material, formulation="modified",
                                        deform=DEFORM, gravity=gravity)
    return model, handles["beam"]


def _batch(function):
    """A callable timing a batch of calls of ``function`` (at least 0.2 s) and returning
    the time per call (s)."""
    timer = timeit.Timer(function)
    number, _ = timer.autorange()
    return lambda: timer.timeit(number) / number


def _least_times(batches: dict, rounds: int = 5) -> dict:
    """Least time per call (s) of each batch over ``rounds`` rounds, the batches taking turns
    within a round so that a change of machine load hits them alike."""
    best = dict.fromkeys(batches, np.inf)
    for _ in range(rounds):
        for name, batch in batches.items():
            best[name] = min(best[name], batch())
    return best


def pinocchio_data_bytes(nv: int) -> int:
    """Memory of a ``pinocchio.Data`` (bytes), dominated by the four nv × nv × nv tensors of
    second-order derivatives that Pinocchio allocates and zeroes for every model."""
    return 8 * (4 * nv**3 + 6 * nv**2)


def _available_memory() -> int:
    """Available physical memory in bytes (Linux's MemAvailable, else all of it)."""
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")


TIMING_COLUMNS = ("m", "nq", "rigidfem_us", "rigidfem_cpp_us", "pin_aba_us", "pin_aba_tau_us", "pin_zyx_aba_us",
                  "mujoco_forward_us", "rigidfem/pin", "rigidfem/mujoco")
EQUIVALENCE_COLUMNS = ("m", "nq", "cond_A", "eps_cond_A", "lagrange_fwd", "pin_fwd", "pin_bwd", "pin_zyx_fwd",
                       "pin_zyx_bwd", "mujoco_fwd", "mujoco_bwd", "note")


def forward_dynamics_timing(elements=(10, 30, 100, 200, 300, 1000), mujoco_up_to: int = 300,
                            lagrange_up_to: int = 300, memory_fraction: float = 0.6, seed: int = 0):
    """Time per forward-dynamics call from Python (µs) against the number of rfes m (nq = 3m),
    with the verification of every peer first. Returns (timing, equivalence) Tables.

    At one random state (q within ±0.3 rad, q̇ within ±1 rad/s), all with gravity:
    ``rigidfem_us``, ``System.forward_dynamics(t, q, qd)`` (recursive algorithm, springs and
    dampers inside); ``rigidfem_cpp_us``, the same timed in rigidfem's C++ loop (no Python
    call); ``pin_aba_us``, ``pinocchio.aba(model, data, q, v, tau)`` on three revolute joints
    per rfe with tau = −c (q − q_rest) − b q̇ computed beforehand; ``pin_aba_tau_us``, the
    same with tau computed by numpy inside the timed call; ``pin_zyx_aba_us``, ABA on one
    SphericalZYX joint per rfe (timed, but not verified: see its error); and
    ``mujoco_forward_us``, MuJoCo's whole ``mj_forward`` (position, velocity and
    acceleration stages; a chain's mass matrix is dense: O(nq²) to build, O(nq³) to factor),
    for m ≤ ``mujoco_up_to`` (MuJoCo's XML parser refuses a chain of more than 496 bodies
    anyway: its elements nest too deep). Pinocchio is skipped where its Data would take
    more than ``memory_fraction`` of the available memory (``pinocchio_data_bytes``:
    6.9 GB at nq = 600, 23 GB at nq = 900).

    The equivalence table has ``agreement``'s forward (``*_fwd``) and backward (``*_bwd``)
    errors of each peer, cond(A) and ε cond(A), and, as a control, rigidfem's Lagrange
    algorithm against its recursive one (``lagrange_fwd``, m ≤ ``lagrange_up_to``). The
    Pinocchio revolute model and MuJoCo must pass ``verify`` (rtol 1e-9 and 1e-8) or an
    ``AssertionError`` is raised before any timing.
    """
    pin = _require("pinocchio", "pin")
    mujoco = _require("mujoco", "mujoco")
    timing, equivalence = [], []
    for m in elements:
        model, _ = cantilever(m)
        system = model.compile()
        q, qd = _random_state(system, seed)
        row, eq = {"m": m, "nq": system.nq}, {"m": m, "nq": system.nq, "note": ""}
        with_pinocchio = pinocchio_data_bytes(system.nq) <= memory_fraction * _available_memory()
        with_mujoco = m <= mujoco_up_to
        if not with_pinocchio:
            eq["note"] += f"Pinocchio skipped: its Data needs {pinocchio_data_bytes(system.nq) / 1e9:.3g} GB. "
        if not with_mujoco:
            eq["note"] += f"MuJoCo skipped (m > {mujoco_up_to})."
        if m <= lagrange_up_to:
            lagrange = model.compile("lagrange")
            eq["lagrange_fwd"] = agreement(system, q, qd, lagrange.forward_dynamics(0.0, q, qd))["forward"]
        if with_pinocchio or with_mujoco:
            chain = describe(system)
            tau = chain.joint_forces(q, qd)
            eq["eps_cond_A"] = agreement(system, q, qd, system.forward_dynamics(0.0, q, qd))["tolerance"]
            eq["cond_A"] = eq["eps_cond_A"] / np.finfo(float).eps
        batches = {"rigidfem_us": _batch(lambda: system.forward_dynamics(0.0, q, qd)),
                   "rigidfem_cpp_us": lambda: cpp_seconds_per_call(system, q, qd)}
        if with_pinocchio:
            # SphericalZYX first and on its own: two Pinocchio Data may not fit in memory together.
            zyx = PinocchioChain(chain, spherical=True)
            errors = agreement(system, q, qd, zyx.forward_dynamics(q, qd))
            eq["pin_zyx_fwd"], eq["pin_zyx_bwd"] = errors["forward"], errors["backward"]
            zyx_batch = _batch(lambda: pin.aba(zyx.model, zyx.data, q, qd, tau))
            row["pin_zyx_aba_us"] = 1e6 * _least_times({"zyx": zyx_batch})["zyx"]
            del zyx
            three = PinocchioChain(chain)
            errors = verify(system, q, qd, three.forward_dynamics(q, qd), 1e-9, "Pinocchio")
            eq["pin_fwd"], eq["pin_bwd"] = errors["forward"], errors["backward"]
            batches["pin_aba_us"] = _batch(lambda: pin.aba(three.model, three.data, q, qd, tau))
            batches["pin_aba_tau_us"] = _batch(lambda: three.forward_dynamics(q, qd))
        if with_mujoco:
            peer = MujocoChain(chain)
            errors = verify(system, q, qd, peer.forward_dynamics(q, qd), 1e-8, "MuJoCo")
            eq["mujoco_fwd"], eq["mujoco_bwd"] = errors["forward"], errors["backward"]
            peer.set_state(q, qd)
            batches["mujoco_forward_us"] = _batch(lambda: mujoco.mj_forward(peer.model, peer.data))
        row.update({name: 1e6 * t for name, t in _least_times(batches).items()})
        three = peer = None  # a Pinocchio Data may take gigabytes
        for timed, key in (("pin_aba_us", "rigidfem/pin"), ("mujoco_forward_us", "rigidfem/mujoco")):
            if timed in row:
                row[key] = row["rigidfem_us"] / row[timed]
        timing.append(row)
        equivalence.append(eq)
    return Table(timing, TIMING_COLUMNS), Table(equivalence, EQUIVALENCE_COLUMNS)


@dataclass
class StiffBeam:
    """The accuracy scene: a steel cantilever released from rest at its static deflection
    under a tip force (0, 20, 1) N and a tip torque (0.5, 0, 0) N·m (bending both ways and
    twisting), without gravity, observed at its tip over ``t_end`` (s). Its first natural
    frequency is 26 rad/s (period 0.24 s); its highest, 2.8e4 rad/s with 10 rfes and
    1.8e5 rad/s with 30, bound the explicit integrators' steps."""

    elements: int
    system: object
    chain: Chain
    tip: Point
    q0: np.ndarray
    t_end: float
    t_eval: np.ndarray

    @property
    def name(self) -> str:
        return f"steel cantilever m={self.elements}"


def stiff_beam(elements: int = 10, t_end: float = 0.2, outputs: int = 41, damping: float = 1e-6) -> StiffBeam:
    """The ``StiffBeam`` scene with ``elements`` rfes, ``outputs`` uniform output times over
    [0, t_end] (s) and the Kelvin–Voigt retardation time ``damping`` (s)."""
    loaded, beam = cantilever(elements, gravity=None, damping=damping)
    loaded.add_force("push", beam.tip, (0.0, 20.0, 1.0))
    loaded.add_torque("twist", beam.rfes[-1], (0.5, 0.0, 0.0))
    q0 = static_equilibrium(loaded.compile(), load_steps=2).q
    model, beam = cantilever(elements, gravity=None, damping=damping)
    system = model.compile()
    return StiffBeam(elements, system, describe(system), beam.tip, q0, t_end, np.linspace(0.0, t_end, outputs))


def _rigidfem_run(scene: StiffBeam, method: str, **settings):
    """The run's Result (q at the output times)."""
    return simulate(scene.system, scene.t_end, method=method, t_eval=scene.t_eval, q0=scene.q0,
                    stiffness_warning=False, max_steps=10**8, **settings)


def _mujoco_run(peer: MujocoChain, scene: StiffBeam, steps_per_output: int):
    """qpos at the output times (outputs, nq), or None when MuJoCo diverged (its bad-qacc
    warning, after which it resets the state, or a non-finite state)."""
    mujoco = peer.mujoco
    peer.set_state(scene.q0, np.zeros_like(scene.q0))
    states = [peer.data.qpos.copy()]
    printer = mujoco.get_mju_user_warning()
    mujoco.set_mju_user_warning(lambda message: None)  # an instability is reported in the table instead
    try:
        for _ in scene.t_eval[1:]:
            mujoco.mj_step(peer.model, peer.data, nstep=steps_per_output)
            states.append(peer.data.qpos.copy())
    finally:
        mujoco.set_mju_user_warning(printer)
    if peer.data.warning[mujoco.mjtWarning.mjWARN_BADQACC].number or not np.all(np.isfinite(states)):
        return None
    return np.array(states)


def _timed(run, repeats: int = 3):
    """(result, least wall time in s): repeated while one run takes under a second."""
    start = time.perf_counter()
    result = run()
    best = time.perf_counter() - start
    for _ in range(repeats - 1 if best < 1.0 else 0):
        start = time.perf_counter()
        run()
        best = min(best, time.perf_counter() - start)
    return result, best


ACCURACY_COLUMNS = ("scene", "code", "method", "setting", "value", "rel_error", "wall_s_per_s", "note")


def stiff_beam_accuracy(scene: StiffBeam, rigidfem_methods=None, mujoco_methods=None) -> Table:
    """Error and cost of each code and integrator on ``scene``.

    ``rigidfem_methods``, ``mujoco_methods``: lists like ``RIGIDFEM_METHODS`` (the default)
    and ``MUJOCO_METHODS``. The reference is rigidfem's Dormand–Prince at rtol = 1e-10,
    atol = 1e-12 (the MuJoCo chain is verified equal first, so it is both codes'
    reference). ``rel_error`` is the largest tip position error over the output times
    divided by the largest tip deflection of the reference; ``wall_s_per_s`` the least wall
    time of the run (s) per simulated second, outputs included but not the tip positions
    computed from them. MuJoCo steps by ``mj_step(model, data, nstep)`` between outputs (no
    Python per step, like rigidfem's C++ loop); a run whose qacc turned bad or non-finite is
    marked "unstable" with an infinite error; a rigidfem method this build lacks is noted.
    """
    rigidfem_methods = RIGIDFEM_METHODS if rigidfem_methods is None else rigidfem_methods
    mujoco_methods = MUJOCO_METHODS if mujoco_methods is None else mujoco_methods
    check_mujoco(scene.system)
    ref = _rigidfem_run(scene, "dopri5", rtol=1e-10, atol=1e-12).position(scene.tip)
    rest = scene.system.position(scene.tip, 0.0, np.zeros(scene.system.nq))
    deflection = np.max(np.linalg.norm(ref - rest, axis=1))
    rows = []

    def add(code, method, setting, value, tip=None, wall=np.nan, note=""):
        error = np.inf if tip is None else float(np.max(np.linalg.norm(tip - ref, axis=1)) / deflection)
        rows.append({"scene": scene.name, "code": code, "method": method, "setting": setting, "value": value,
                     "rel_error": error, "wall_s_per_s": wall / scene.t_end, "note": note})

    for method, setting, values, *extra in rigidfem_methods:
        for value in values:
            settings = dict(*extra, **{setting: value})
            if setting == "rtol":
                settings.setdefault("atol", value * 1e-2)
            try:
                result, wall = _timed(lambda: _rigidfem_run(scene, method, **settings))
                add("rigidfem", method, setting, value, result.position(scene.tip), wall)
            except ValueError as e:
                if not str(e).startswith("method:"):
                    raise
                add("rigidfem", method, setting, value, note="not in this build")
                break
            except SimulationError as e:
                add("rigidfem", method, setting, value, note=str(e)[:80])
    interval = scene.t_eval[1] - scene.t_eval[0]
    for integrator, setting, steps in mujoco_methods:
        for dt in steps:
            n = int(round(interval / dt))
            if abs(n * dt - interval) > 1e-9 * interval:
                raise ValueError(f"mujoco_methods: expected steps dividing the output interval {interval} s, got {dt}")
            peer = MujocoChain(scene.chain, {"tip": scene.tip}, timestep=dt, integrator=integrator)
            states, wall = _timed(lambda: _mujoco_run(peer, scene, n))
            if states is None:
                add("mujoco", integrator, setting, dt, note="unstable")
            else:
                add("mujoco", integrator, setting, dt, np.array([peer.site("tip", x[peer.address]) for x in states]),
                    wall)
    return Table(rows, ACCURACY_COLUMNS)


def equal_accuracy(table: Table, thresholds=(1e-4, 1e-6)) -> Table:
    """Per scene, code and method: the cheapest run (s of wall time per simulated s, and its
    setting) whose ``rel_error`` is at most each threshold ("-" when none reaches it)."""
    groups = {}
    for r in table.rows:
        groups.setdefault((r["scene"], r["code"], r["method"]), []).append(r)
    rows = []
    for (scene, code, method), runs in groups.items():
        row = {"scene": scene, "code": code, "method": method}
        for tol in thresholds:
            best = cheapest(runs, "rel_error", "wall_s_per_s", tol)
            row[f"wall_s_per_s_to_{tol:g}"] = best["wall_s_per_s"] if best else "-"
            row[f"setting_to_{tol:g}"] = f"{best['setting']}={best['value']:g}" if best else "-"
        row["smallest_error"] = min(r["rel_error"] for r in runs)
        rows.append(row)
    columns = ("scene", "code", "method",
               *(c for tol in thresholds for c in (f"wall_s_per_s_to_{tol:g}", f"setting_to_{tol:g}")),
               "smallest_error")
    return Table(rows, columns)


def versions() -> dict:
    """Versions of the compared codes (and numpy)."""
    pin = _require("pinocchio", "pin")
    mujoco = _require("mujoco", "mujoco")
    return {"rigidfem": rigidfem.__version__, "pinocchio": pin.__version__, "mujoco": mujoco.__version__,
            "numpy": np.__version__}


def _fewer(methods, keep: slice):
    """The same methods with fewer settings (for quick runs)."""
    return [(method, setting, values[keep], *extra) for method, setting, values, *extra in methods]


def run(output_dir="bench", quick: bool = False) -> dict:
    """``python -m benchmarks peers``: the forward-dynamics timing against nq, the
    equivalence errors behind it, the stiff-beam accuracy and cost of every code and
    integrator (m = 10 and 30 rfes over 0.2 s), and the cheapest run of each reaching a tip
    error of 1e-4 and 1e-6 of the tip deflection; each written to ``output_dir`` as
    ``peers_<name>.csv`` and printed as markdown. Returns name -> Table (names
    "forward_dynamics", "equivalence", "accuracy", "equal_accuracy"). ``quick``: small
    chains, few settings, a 0.05 s span (a smoke run of about half a minute)."""
    info = versions()
    print(f"rigidfem {info['rigidfem']}, Pinocchio {info['pinocchio']}, MuJoCo {info['mujoco']}, numpy "
          f"{info['numpy']}; {machine()}", flush=True)
    timing, equivalence = forward_dynamics_timing(elements=(4, 10) if quick else (10, 30, 100, 200, 300, 1000))
    tables = report({
        "peers_forward_dynamics": ("Forward dynamics, µs per call from Python (3D steel cantilever, gravity on, "
                                   "random state)", timing),
        "peers_equivalence": ("Equivalence at that state: relative q̈ error (*_fwd) and backward error in "
                              "rigidfem's equations (*_bwd)", equivalence),
    }, output_dir)
    rows = []
    for m in (4,) if quick else (10, 30):
        start = time.perf_counter()
        if quick:
            scene = stiff_beam(m, t_end=0.05, outputs=11)
            table = stiff_beam_accuracy(scene, _fewer(RIGIDFEM_METHODS, slice(2, 4)),
                                        _fewer(MUJOCO_METHODS, slice(2, 4)))
        else:
            scene = stiff_beam(m)
            table = stiff_beam_accuracy(scene)
        rows += table.rows
        print(f"[{time.perf_counter() - start:6.1f} s] {scene.name}", flush=True)
    accuracy = Table(rows, ACCURACY_COLUMNS)
    tables.update(report({
        "peers_accuracy": ("Stiff beam: largest tip error relative to the largest tip deflection, wall time per "
                           "simulated second", accuracy),
        "peers_equal_accuracy": ("Equal accuracy: the cheapest run of each code and method reaching each relative "
                                 "tip error", equal_accuracy(accuracy)),
    }, output_dir))
    return {name[len("peers_"):]: table for name, table in tables.items()}
