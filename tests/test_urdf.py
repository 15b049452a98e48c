"""Robots from URDF (``Model.from_urdf``): the UR5 arm of ``tests/data/ur5.urdf`` (BSD licence, beside it) and
random trees written here, against an independent reference computed in this file (the file read again with
xml.etree, and the recursive Newton–Euler algorithm in numpy, on every link with fixed joints as joints of no
coordinate, in world-frame vectors), and against Pinocchio's ``buildModelFromUrdf`` where it is installed; a
flexible forearm in Kane-style spin-ups (deflection ∝ 1/E: it converges to the rigid arm) and a free swing
that keeps its energy; every bad input refused naming its argument."""

import math
import pickle
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
import rigidfem as rf

UR5 = Path(__file__).parent / "data" / "ur5.urdf"
ARM_JOINTS = ("shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint",
              "wrist_3_joint")
ALUMINIUM = rf.Material(E=7.0e10, rho=2700.0)
TUBE = rf.Section.tube(0.05, 0.044)


# --- the reference: the file read again, and Newton–Euler in numpy ---------------------------------------------


def _vec(e, attribute, default):
    return np.array([float(x) for x in e.get(attribute).split()]) if e is not None and e.get(attribute) else \
        np.array(default, dtype=float)


def _rotation(rpy):
    r, p, y = rpy
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    Rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    Ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    Rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    return Rz @ Ry @ Rx  # URDF: fixed axes x, y, z


def _pose(e):
    o = e.find("origin") if e is not None else None
    return _vec(o, "xyz", (0, 0, 0)), _rotation(_vec(o, "rpy", (0, 0, 0)))


def _axis_rotation(a, angle):
    K = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + math.sin(angle) * K + (1 - math.cos(angle)) * K @ K


class Reference:
    """The tree of a URDF file as this test reads it: links in depth-first order from the root, each with its
    joint (origin, axis, type), mass, centre of mass and inertia in the link frame; ``free`` prepends the six
    joints of Joint.free(): translations x, y, z and rotations about z, y, x (massless links between)."""

    def __init__(self, path, free=False):
        robot = ET.parse(path).getroot()
        links = {}
        for e in robot.findall("link"):
            i = e.find("inertial")
            m = float(i.find("mass").get("value")) if i is not None else 0.0
            c, R = _pose(i)
            t = i.find("inertia") if i is not None else None
            g = {k: float(t.get(k)) if t is not None else 0.0 for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")}
            I = np.array([[g["ixx"], g["ixy"], g["ixz"]], [g["ixy"], g["iyy"], g["iyz"]], [g["ixz"], g["iyz"], g["izz"]]])
            links[e.get("name")] = (m, c, R @ I @ R.T)
        joints = [(j.get("type"), j.find("parent").get("link"), j.find("child").get("link"), *_pose(j),
                   _vec(j.find("axis"), "xyz", (1, 0, 0)) / np.linalg.norm(_vec(j.find("axis"), "xyz", (1, 0, 0))))
                  for j in robot.findall("joint")]
        root = next(n for n in links if n not in {j[2] for j in joints})
        self.bodies = []  # (parent index or -1, type, origin p, origin R, axis, m, c, I)
        parent = -1
        if free:
            for kind, axis in (("prismatic", 0), ("prismatic", 1), ("prismatic", 2), ("revolute", 2),
                               ("revolute", 1), ("revolute", 0)):
                self.bodies.append((parent, kind, np.zeros(3), np.eye(3), np.eye(3)[axis], 0.0, np.zeros(3),
                                    np.zeros((3, 3))))
                parent = len(self.bodies) - 1
        self.bodies.append((parent, "fixed", np.zeros(3), np.eye(3), np.zeros(3), *links[root]))
        stack = [(root, len(self.bodies) - 1)]
        while stack:
            name, index = stack.pop(0)
            for kind, p, child, xyz, R, axis in joints:
                if p == name:
                    self.bodies.append((index, kind, xyz, R, axis, *links[child]))
                    stack.insert(0, (child, len(self.bodies) - 1))
        # depth first in the file's order, as the model adds them: reorder by a recursive walk
        order, children = [], {}
        for k, b in enumerate(self.bodies):
            children.setdefault(b[0], []).append(k)

        def walk(k):
            order.append(k)
            for c in children.get(k, []):
                walk(c)

        for k in children[-1]:
            walk(k)
        new = {old: n for n, old in enumerate(order)}
        self.bodies = [(new.get(self.bodies[k][0], -1), *self.bodies[k][1:]) for k in order]
        self.moving = [k for k, b in enumerate(self.bodies) if b[1] != "fixed"]
        self.nq = len(self.moving)

    def rnea(self, q, qd, qdd, gravity):
        """τ (nq,) by Newton–Euler in world-frame vectors (rotations and points in the global frame)."""
        n = len(self.bodies)
        R, o, w, dw, a = [None] * n, [None] * n, [None] * n, [None] * n, [None] * n
        F, N, c = [None] * n, [None] * n, [None] * n
        slot = {k: i for i, k in enumerate(self.moving)}
        for k, (p, kind, xyz, Ro, axis, m, com, I) in enumerate(self.bodies):
            Rp, op = (np.eye(3), np.zeros(3)) if p < 0 else (R[p], o[p])
            wp, dwp, ap = (np.zeros(3), np.zeros(3), -np.asarray(gravity)) if p < 0 else (w[p], dw[p], a[p])
            Rj = Rp @ Ro  # the joint frame
            u = Rj @ axis  # the axis, global
            x, v, acc = (q[slot[k]], qd[slot[k]], qdd[slot[k]]) if k in slot else (0.0, 0.0, 0.0)
            r = Rp @ xyz  # parent origin -> joint origin
            if kind in ("revolute", "continuous"):
                R[k], o[k] = Rj @ _axis_rotation(axis, x), op + r
                w[k], dw[k] = wp + u * v, dwp + u * acc + np.cross(wp, u * v)
                a[k] = ap + np.cross(dwp, r) + np.cross(wp, np.cross(wp, r))
            else:  # prismatic, fixed (v = 0)
                R[k], o[k] = Rj, op + r + u * x
                w[k], dw[k] = wp, dwp
                d = r + u * x
                a[k] = ap + np.cross(dwp, d) + np.cross(wp, np.cross(wp, d)) + u * acc + 2 * np.cross(wp, u * v)
            c[k] = R[k] @ com
            ac = a[k] + np.cross(dw[k], c[k]) + np.cross(w[k], np.cross(w[k], c[k]))
            Iw = R[k] @ I @ R[k].T
            F[k], N[k] = m * ac, Iw @ dw[k] + np.cross(w[k], Iw @ w[k])
        f, t = [np.zeros(3) for _ in range(n)], [np.zeros(3) for _ in range(n)]
        tau = np.zeros(self.nq)
        for k in reversed(range(n)):  # f: force on k by its parent; t: moment about o[k]
            f[k] = f[k] + F[k]
            t[k] = t[k] + N[k] + np.cross(c[k], F[k])
            p, kind, _, Ro, axis = self.bodies[k][:5]
            if k in slot:
                u = (np.eye(3) if p < 0 else R[p]) @ Ro @ axis
                tau[slot[k]] = u @ (t[k] if kind in ("revolute", "continuous") else f[k])
            if p >= 0:
                f[p] = f[p] + f[k]
                t[p] = t[p] + t[k] + np.cross(o[k] - o[p], f[k])
        return tau

    def mass_matrix(self, q):
        zero = np.zeros(self.nq)
        return np.column_stack([self.rnea(q, zero, e, (0, 0, 0)) for e in np.eye(self.nq)])

    def forward_dynamics(self, q, qd, gravity, M=None):
        M = self.mass_matrix(q) if M is None else M
        return np.linalg.solve(M, -self.rnea(q, qd, np.zeros(self.nq), gravity))


def random_urdf(path, seed, free_joints=False):
    """A random tree of 7 links: revolute, continuous and prismatic joints about random (oblique, negative) axes,
    fixed joints carrying masses, branches, random origins, rpy and full inertia tensors; ``free_joints`` adds a
    floating and a planar joint."""
    rng = np.random.default_rng(seed)

    def numbers(x):
        return " ".join(f"{v:.17g}" for v in x)

    def inertial():
        moments = np.sort(rng.uniform(0.05, 1.0, 3))
        moments[2] = min(moments[2], 0.95 * (moments[0] + moments[1]))
        Q = _rotation(rng.uniform(-3, 3, 3))
        I = Q @ np.diag(moments) @ Q.T
        return (f'<inertial><origin xyz="{numbers(rng.uniform(-0.4, 0.4, 3))}" rpy="{numbers(rng.uniform(-3, 3, 3))}"/>'
                f'<mass value="{rng.uniform(0.5, 3):.17g}"/><inertia ixx="{I[0, 0]:.17g}" ixy="{I[0, 1]:.17g}" '
                f'ixz="{I[0, 2]:.17g}" iyy="{I[1, 1]:.17g}" iyz="{I[1, 2]:.17g}" izz="{I[2, 2]:.17g}"/></inertial>')

    axes = [rng.normal(size=3), (0, 0, -1), (0, 1, 0), rng.normal(size=3), (-1, 0, 0), rng.normal(size=3)]
    kinds = ["revolute", "prismatic", "revolute", "fixed", "continuous", "revolute"]
    if free_joints:
        kinds[1], kinds[4] = "floating", "planar"
    parents = [0, 1, 1, 2, 4, 3]
    text = ['<robot name="random">', f'<link name="l0">{inertial()}</link>']
    for k, (kind, axis, parent) in enumerate(zip(kinds, axes, parents), start=1):
        text.append(f'<joint name="j{k}" type="{kind}"><parent link="l{parent}"/><child link="l{k}"/>'
                    f'<origin xyz="{numbers(rng.uniform(-1, 1, 3))}" rpy="{numbers(rng.uniform(-3, 3, 3))}"/>'
                    f'<axis xyz="{numbers(axis)}"/><limit lower="-1" upper="1" effort="10" velocity="1"/></joint>')
        text.append(f'<link name="l{k}">{inertial()}</link>')
    text.append("</robot>")
    path.write_text("\n".join(text))
    return path


def states(nq, count, seed=0):
    rng = np.random.default_rng(seed)
    return [(rng.uniform(-np.pi, np.pi, nq), rng.normal(0.0, 2.0, nq)) for _ in range(count)]


def largest_differences(system, reference, gravity, count=10, pitch=None):
    """The largest differences of M and q̈ over random states; ``pitch``: a free base's ZYX pitch (its fifth
    coordinate) kept within ±pitch rad, away from the angles' singularity at ±π/2."""
    dM = dqdd = 0.0
    for q, qd in states(system.nq, count):
        if pitch is not None:
            q[4] = np.clip(q[4], -pitch, pitch)
        M = reference.mass_matrix(q)
        qdd = reference.forward_dynamics(q, qd, gravity, M)
        dM = max(dM, np.abs(system.mass_matrix(0.0, q) - M).max())
        # in units of the forward error the round-off of M allows, eps cond(M) max|q̈| (a free base's ZYX angles
        # make cond(M) ~ 1e4-1e5): within 1e-10 where that is below it
        allowed = max(1e-10, 10 * np.finfo(float).eps * np.linalg.cond(M) * np.abs(qdd).max())
        dqdd = max(dqdd, np.abs(system.forward_dynamics(0.0, q, qd) - qdd).max() / allowed * 1e-10)
    return dM, dqdd


# --- rigid: against the reference and Pinocchio ----------------------------------------------------------------


def test_the_ur5_loads_with_its_six_joints_and_notes_what_it_does_not_use():
    model = rf.Model.from_urdf(UR5)
    system = model.compile()
    u = model.urdf
    assert system.nq == 6 and system.nbodies == 6  # base_link, world, base, ee_link and tool0 merged or grounded
    assert [u.coordinates[j] for j in ARM_JOINTS] == [(n,) for n in system.coordinate_names]
    assert u.bodies["tool0"] is u.bodies["wrist_3_link"] and u.bodies["base_link"].index == -1
    assert u.robot.joints["elbow_joint"].limits["upper"] == pytest.approx(math.pi)
    assert any("limits not enforced" in note for note in u.notes)
    assert u.visuals["forearm_link"][0].filename.endswith("forearm.dae")
    assert sum(body_mass for body_mass in system.masses) == pytest.approx(3.7 + 8.393 + 2.275 + 2 * 1.219 + 0.1879)


def test_the_ur5_mass_matrix_and_accelerations_match_the_reference():
    system = rf.Model.from_urdf(UR5).compile()
    dM, dqdd = largest_differences(system, Reference(UR5), (0, 0, -9.81))
    assert dM < 1e-10 and dqdd < 1e-10, (dM, dqdd)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_random_trees_match_the_reference(tmp_path, seed):
    path = random_urdf(tmp_path / "tree.urdf", seed)
    gravity = (0.5, -1.0, -9.81)
    system = rf.Model.from_urdf(path, gravity=gravity).compile()
    dM, dqdd = largest_differences(system, Reference(path), gravity, count=8)
    assert dM < 1e-10 and dqdd < 1e-10, (dM, dqdd)


def test_a_free_base_is_a_free_joint_of_zyx_angles(tmp_path):
    path = random_urdf(tmp_path / "tree.urdf", 4)
    system = rf.Model.from_urdf(path, base="free").compile()
    reference = Reference(path, free=True)
    assert system.nq == reference.nq == 11
    dM, dqdd = largest_differences(system, reference, (0, 0, -9.81), count=6, pitch=1.2)
    assert dM < 1e-10 and dqdd < 1e-10, (dM, dqdd)


def test_floating_and_planar_joints_are_free_and_planar_joints(tmp_path):
    path = random_urdf(tmp_path / "tree.urdf", 5, free_joints=True)
    model = rf.Model.from_urdf(path)
    assert [len(model.urdf.coordinates[f"j{k}"]) for k in range(1, 7)] == [1, 6, 1, 0, 3, 1]
    system = model.compile()
    q, qd = states(system.nq, 1)[0]
    assert np.all(np.isfinite(system.forward_dynamics(0.0, q, qd)))


def test_pinocchio_agrees_on_the_ur5_and_random_trees(tmp_path):
    pin = pytest.importorskip("pinocchio")
    for path in (UR5, random_urdf(tmp_path / "a.urdf", 6), random_urdf(tmp_path / "b.urdf", 7)):
        text = Path(path).read_text().replace('type="continuous"', 'type="revolute"')  # Pinocchio: cos, sin
        Path(tmp_path / "pin.urdf").write_text(text)
        peer = pin.buildModelFromUrdf(str(tmp_path / "pin.urdf"))
        data = peer.createData()
        system = rf.Model.from_urdf(path).compile()
        assert peer.nq == system.nq
        dM = dqdd = 0.0
        for q, qd in states(system.nq, 20):
            M = pin.crba(peer, data, q)
            M = np.triu(M) + np.triu(M, 1).T
            dM = max(dM, np.abs(system.mass_matrix(0.0, q) - M).max())
            qdd = pin.aba(peer, data, q, qd, np.zeros(system.nq))
            dqdd = max(dqdd, np.abs(system.forward_dynamics(0.0, q, qd) - qdd).max())
        assert dM < 1e-10 and dqdd < 1e-10, (path, dM, dqdd)


def test_a_continuous_joint_is_a_revolute_one_and_damping_is_kept(tmp_path):
    path = random_urdf(tmp_path / "tree.urdf", 8)
    text = path.read_text()
    revolute = tmp_path / "revolute.urdf"
    revolute.write_text(text.replace('type="continuous"', 'type="revolute"'))
    a, b = (rf.Model.from_urdf(p).compile() for p in (path, revolute))
    q, qd = states(a.nq, 1)[0]
    np.testing.assert_array_equal(a.forward_dynamics(0.0, q, qd), b.forward_dynamics(0.0, q, qd))
    damped = tmp_path / "damped.urdf"
    damped.write_text(text.replace("</joint>", '<dynamics damping="0.5" friction="0.1"/></joint>'))
    model = rf.Model.from_urdf(damped)
    assert any("friction not modelled" in note for note in model.urdf.notes)
    system = model.compile()
    assert system.potential_energy(0.0, q) == pytest.approx(a.potential_energy(0.0, q))
    M = system.mass_matrix(0.0, q)
    # the damping's generalised force −c q̇ on each moving joint's coordinate
    np.testing.assert_allclose(M @ (system.forward_dynamics(0.0, q, qd) - a.forward_dynamics(0.0, q, qd)),
                               -0.5 * qd, atol=1e-10)


def test_a_model_from_urdf_pickles_with_its_description():
    model = rf.Model.from_urdf(UR5, flexible={"forearm_link": {"elements": 3, "material": ALUMINIUM, "section": TUBE}})
    copy = pickle.loads(pickle.dumps(model))
    assert copy.urdf.coordinates == model.urdf.coordinates and copy.compile().nq == model.compile().nq


# --- a flexible forearm ----------------------------------------------------------------------------------------


def flexible_ur5(elements=4, material=ALUMINIUM, section=TUBE, gravity=None, **spec):
    return rf.Model.from_urdf(UR5, flexible={"forearm_link": dict(elements=elements, material=material,
                                                                    section=section, **spec)}, gravity=gravity)


def test_the_forearm_beam_runs_from_the_elbow_to_the_wrist_and_keeps_the_links_frames():
    model = flexible_ur5()
    u = model.urdf
    beam = u.beams["forearm_link"]
    assert beam.length == pytest.approx(0.39225) and len(beam.rfes) == 5
    assert u.coordinates["elbow_joint"] == ("forearm_link.rfe0.rz",)  # z: the elbow's axis
    assert u.bodies["wrist_1_link"].name == "wrist_1_link"
    rigid_model = rf.Model.from_urdf(UR5)
    flexible, rigid = model.compile(), rigid_model.compile()
    for q, _ in states(6, 3):
        qf = np.zeros(flexible.nq)
        qf[[flexible.coordinate_index(u.coordinates[j][0]) for j in ARM_JOINTS]] = q
        for link in ("forearm_link", "wrist_1_link", "tool0"):
            np.testing.assert_allclose(flexible.position(u.point(link, (0.1, -0.2, 0.3)), 0.0, qf),
                                       rigid.position(rigid_model.urdf.point(link, (0.1, -0.2, 0.3)), 0.0, q),
                                       atol=1e-14)


def test_undeformed_the_flexible_arm_is_the_rigid_arm_with_the_beams_inertia(tmp_path):
    """The file's forearm inertial replaced by a rigid tube's (m = ρAL, c.o.m. at L/2 on the link's z axis,
    ρ(Iy + Iz)L about it, m L²/12 + ρ I L across): the mass matrix of the arm's six coordinates equals the flexible
    model's at zero deformation."""
    L, rho = 0.39225, ALUMINIUM.rho
    m = rho * TUBE.A * L
    across, axial = m * L**2 / 12 + rho * TUBE.Iy * L, rho * (TUBE.Iy + TUBE.Iz) * L
    text = UR5.read_text()
    old = text[text.index('<inertial>', text.index('<link name="forearm_link">')):]
    old = old[:old.index("</inertial>") + len("</inertial>")]
    new = (f'<inertial><mass value="{m!r}"/><origin rpy="0 0 0" xyz="0 0 {L / 2!r}"/><inertia ixx="{across!r}" '
           f'ixy="0" ixz="0" iyy="{across!r}" iyz="0" izz="{axial!r}"/></inertial>')
    (tmp_path / "tube.urdf").write_text(text.replace(old, new))
    rigid = rf.Model.from_urdf(tmp_path / "tube.urdf", gravity=None).compile()
    model = flexible_ur5(elements=5)
    flexible = model.compile()
    index = [flexible.coordinate_index(model.urdf.coordinates[j][0]) for j in ARM_JOINTS]
    for q, _ in states(6, 5):
        qf = np.zeros(flexible.nq)
        qf[index] = q
        np.testing.assert_allclose(flexible.mass_matrix(0.0, qf)[np.ix_(index, index)], rigid.mass_matrix(0.0, q),
                                   rtol=0, atol=1e-12)


def spin_up(model, omega=4.0, duration=1.0):
    """Kane's spin-up on the first joint; the others held at zero (the arm stretched horizontally)."""
    for joint, body in model.urdf.joint_bodies.items():
        model.prescribe(body, rf.motion.spin_up(omega, duration) if joint == "shoulder_pan_joint" else
                        rf.motion.constant(0.0))
    return model.compile()


def test_a_stiffer_forearm_converges_to_the_rigid_arm_in_a_spin_up():
    """The wrist's deviation from where the rigid arm puts it falls as 1/E: 10x stiffer, 10x smaller (to 1 %)."""
    deviations = []
    for E in (7e10, 7e11, 7e12):
        model = flexible_ur5(material=rf.Material(E=E, rho=2700.0))
        system = spin_up(model)
        assert system.nq == 3 * 4  # only the forearm's deformations are free
        result = rf.simulate(system, 1.5, t_eval=np.linspace(0.0, 1.5, 151), rtol=1e-9, atol=1e-12)
        wrist = model.urdf.point("wrist_1_link")
        rigid = np.array([system.position(wrist, t, np.zeros(system.nq)) for t in result.t])
        deviations.append(np.abs(result.position(wrist) - rigid).max())
    assert deviations[0] > 1e-5
    assert deviations[0] / deviations[1] == pytest.approx(10.0, rel=0.01)
    assert deviations[1] / deviations[2] == pytest.approx(10.0, rel=0.01)


def test_a_spin_up_bends_the_forearm_back_then_lets_it_ring_about_straight():
    """During the spin-up the wrist lags behind the rigid arm (in the plane of rotation: the beam's bend_y);
    after it, at constant speed, it vibrates about the small centrifugal stretch."""
    model = flexible_ur5(material=rf.Material(E=7e9, rho=2700.0), elements=6)
    system = spin_up(model, omega=4.0, duration=1.0)
    result = rf.simulate(system, 2.0, t_eval=np.linspace(0.0, 2.0, 401), rtol=1e-8, atol=1e-10)
    wrist = model.urdf.point("wrist_1_link")
    rigid = np.array([system.position(wrist, t, np.zeros(system.nq)) for t in result.t])
    delta = result.position(wrist) - rigid
    # the direction of travel of the rigid wrist: z × r (spin about the global z axis)
    travel = np.cross([0.0, 0.0, 1.0], rigid)
    travel /= np.linalg.norm(travel, axis=1)[:, None]
    lag = np.einsum("ij,ij->i", delta, travel)
    accelerating = (result.t > 0.2) & (result.t < 0.5)
    assert np.all(lag[accelerating] < 0.0)
    assert np.abs(lag[result.t > 1.0]).max() < np.abs(lag[result.t < 1.0]).max()


def test_a_free_swing_of_the_flexible_arm_keeps_its_energy():
    model = flexible_ur5(material=rf.Material(E=7e9, rho=2700.0), gravity=(0.0, 0.0, -9.81))
    system = model.compile()
    q0 = np.zeros(system.nq)
    q0[[system.coordinate_index(model.urdf.coordinates[j][0]) for j in ARM_JOINTS]] = [0.3, -0.8, 0.9, -0.5, 0.4, 0.2]
    result = rf.simulate(system, 0.3, q0=q0, method="dop853", rtol=1e-11, atol=1e-12,
                         t_eval=np.linspace(0.0, 0.3, 31))
    E = np.array([system.kinetic_energy(t, q, qd) + system.potential_energy(t, q)
                  for t, q, qd in zip(result.t, result.q, result.qd)])
    exchanged = max(system.kinetic_energy(t, q, qd) for t, q, qd in zip(result.t, result.q, result.qd))
    assert exchanged > 1.0
    assert np.abs(E - E[0]).max() < 1e-7 * exchanged


def test_match_mass_gives_the_beam_the_links_mass_and_other_keys_reach_add_beam():
    model = flexible_ur5(match_mass=True, deform=("bend_y", "bend_z"), tip_mass=0.1)
    beam = model.urdf.beams["forearm_link"]
    assert sum(r.mass for r in beam.rfe) == pytest.approx(2.275 + 0.1)
    assert beam.deform == ("bend_y", "bend_z")
    assert any("replaces the file's inertial (2.275 kg)" in note for note in model.urdf.notes)


# --- bad input -------------------------------------------------------------------------------------------------


def write(tmp_path, text, name="bad.urdf"):
    path = tmp_path / name
    path.write_text(text)
    return path


LINK = '<link name="{0}"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/>' \
       '</inertial></link>'


def joint(name, parent, child, kind="revolute", extra=""):
    return f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>{extra}</joint>'


def two_links(extra):
    return f"<robot>{LINK.format('a')}{LINK.format('b')}{joint('j1', 'a', 'b', extra=extra)}</robot>"


@pytest.mark.parametrize("text, match", [
    ("<robot><link name='a'>", r"^path: expected a URDF file \(XML\)"),
    ("<sdf><model name='a'/></sdf>", r"^path: expected a URDF file whose root element is <robot>, got <sdf>"),
    ('<robot xmlns:xacro="http://www.ros.org/wiki/xacro"><xacro:property name="l" value="1"/></robot>', "xacro"),
    ((f"<robot>{LINK.format('a')}{LINK.format('b')}{LINK.format('c')}{joint('j1', 'a', 'c')}{joint('j2', 'b', 'c')}"
     "</robot>"), r"^path: expected a tree .* link 'c' the child of joints 'j1' and 'j2': a closed chain"),
    (f"<robot>{LINK.format('a')}{LINK.format('b')}{joint('j1', 'a', 'b')}{joint('j2', 'b', 'a')}</robot>",
     r"^path: expected one root link"),
    (f"<robot>{LINK.format('a')}{joint('j1', 'a', 'ghost')}</robot>",
     r"^path: expected the child of joint 'j1' to be a link of the file, got 'ghost'"),
    (f"<robot>{LINK.format('a')}{LINK.format('b')}{joint('j1', 'a', 'b', 'ball')}</robot>",
     r"^path: expected a joint type from .* got 'ball'"),
    (two_links(extra="<mimic joint='j0'/>"),
     r"^path: expected joints without <mimic>"),
    (two_links(extra="<axis xyz='0 0 0'/>"),
     r"^path: expected a nonzero axis of joint 'j1'"),
    (two_links(extra="<origin xyz='1 2'/>"),
     r"^path: expected 3 finite numbers in xyz"),
    (f"<robot>{LINK.format('a')}<link name='b'/>{joint('j1', 'a', 'b')}</robot>",
     r"^path: expected a mass > 0 and a positive definite inertia of link 'b'"),
])
def test_a_file_that_is_not_a_urdf_tree_is_refused_naming_path(tmp_path, text, match):
    with pytest.raises(ValueError, match=match):
        rf.Model.from_urdf(write(tmp_path, text))


def test_a_missing_file_or_a_path_that_is_no_path():
    with pytest.raises(FileNotFoundError):
        rf.Model.from_urdf("no/such/robot.urdf")
    with pytest.raises(ValueError, match="^path: expected a file path"):
        rf.Model.from_urdf(None)


def test_a_floating_base_is_supported_or_refused_with_the_reason(tmp_path):
    with pytest.raises(ValueError, match=r"^base: expected 'fixed' .* or 'free'"):
        rf.Model.from_urdf(UR5, base="floating")
    # the UR5 set free: its 'world' link carries base_link (fixed to it), 4 kg
    system = rf.Model.from_urdf(UR5, base="free").compile()
    assert system.nq == 12 and system.coordinate_names[:6] == ["world." + c for c in ("x", "y", "z", "rz", "ry", "rx")]
    dM, dqdd = largest_differences(system, Reference(UR5, free=True), (0, 0, -9.81), count=5, pitch=1.2)
    assert dM < 1e-10 and dqdd < 1e-10, (dM, dqdd)
    # a massless root with nothing fixed to it: nothing to set free
    massless = write(tmp_path, f"<robot><link name='a'/>{LINK.format('b')}{joint('j1', 'a', 'b')}</robot>")
    with pytest.raises(ValueError, match=r"^base: expected a mass > 0 .* of link 'a'"):
        rf.Model.from_urdf(massless, base="free")


@pytest.mark.parametrize("flexible, match", [
    ({"forearm": {"elements": 4, "material": ALUMINIUM, "section": TUBE}},
     r"^flexible: expected names of links of the file .* got 'forearm'"),
    (["forearm_link"], r"^flexible: expected a dict of link names"),
    ({"forearm_link": 4}, r"^flexible\['forearm_link'\]: expected a dict of add_beam's arguments"),
    ({"forearm_link": {"elements": 4, "material": ALUMINIUM}}, (r"^flexible\['forearm_link'\]: expected the keys .* no "
                                                               r"\['section'\]")),
    ({"forearm_link": {"elements": 4, "material": ALUMINIUM, "section": TUBE, "length": 1.0}},
     r"^flexible\['forearm_link'\]: expected the keys .* unknown \['length'\]"),
    ({"forearm_link": {"elements": 40, "material": ALUMINIUM, "section": TUBE}},
     r"^flexible\['forearm_link'\]: expected 'elements' at most 23 on a link of 0.3922 m .* too short for 40 elements"),
    ({"forearm_link": {"elements": 0, "material": ALUMINIUM, "section": TUBE}},
     r"^flexible\['forearm_link'\]: expected 'elements' a positive integer"),
    ({"tool0": {"elements": 2, "material": ALUMINIUM, "section": TUBE}},
     r"^flexible\['tool0'\]: expected a link with a child joint .* got a leaf"),
    ({"forearm_link": {"elements": 2, "material": ALUMINIUM, "section": TUBE, "to": "elbow_joint"}},
     r"^flexible\['forearm_link'\]: expected 'to' to name a child joint of the link \(wrist_1_joint\)"),
    ({"forearm_link": {"elements": 2, "material": ALUMINIUM, "section": TUBE, "match_mass": True},
      "world": {"elements": 1, "material": ALUMINIUM, "section": TUBE, "match_mass": True}},
     r"^flexible\['world'\]: expected a link whose end joint 'world_joint' lies away from its joint frame"),
])
def test_a_bad_flexible_link_is_refused_naming_flexible(flexible, match):
    with pytest.raises(ValueError, match=match):
        rf.Model.from_urdf(UR5, flexible=flexible)


def test_an_oblique_joint_axis_on_a_flexible_link_is_refused_with_the_reason(tmp_path):
    text = (f"<robot>{LINK.format('a')}{LINK.format('b')}{LINK.format('c')}"
            + joint("j1", "a", "b", extra="<axis xyz='1 1 0'/>") + joint("j2", "b", "c", extra="<origin xyz='1 0 0'/>")
            + "</robot>")
    with pytest.raises(ValueError, match=r"^flexible\['b'\]: expected a link whose joint axis is perpendicular to it "
                                         r"or along it .* 45 degrees"):
        rf.Model.from_urdf(write(tmp_path, text), flexible={"b": {"elements": 2, "material": ALUMINIUM, "section": TUBE}})


def test_a_flexible_links_other_children_hang_from_the_rfe_nearest_their_origin(tmp_path):
    """A sensor fixed on the flexible link (with mass: a body of its own, fixed on an rfe) and a massless tool
    frame beside its end joint: at zero deformation every link is where the rigid model puts it."""
    inertia = '<inertia ixx="0.01" iyy="0.02" izz="0.02" ixy="0" ixz="0" iyz="0"/>'
    text = ('<robot name="r"><link name="base"/>'
            f'<link name="arm"><inertial><origin xyz="0.4 0 0"/><mass value="2"/>{inertia}</inertial></link>'
            f'<link name="sensor"><inertial><mass value="0.3"/>{inertia}</inertial></link><link name="tool"/>'
            f'<link name="fore"><inertial><origin xyz="0.2 0 0"/><mass value="1"/>{inertia}</inertial></link>'
            + joint("shoulder", "base", "arm", extra="<origin xyz='0 0 0.1' rpy='0.2 0 0'/><axis xyz='0 -1 0'/>")
            + joint("mount", "arm", "sensor", "fixed", "<origin xyz='0.31 0.05 0' rpy='0 0 1'/>")
            + joint("flange", "arm", "tool", "fixed", "<origin xyz='0.2 0 0.1'/>")
            + joint("elbow", "arm", "fore", extra="<origin xyz='0.8 0 0'/><axis xyz='0 0 1'/>") + "</robot>")
    path = write(tmp_path, text, "arm.urdf")
    model = rf.Model.from_urdf(path, flexible={"arm": {"elements": 5, "material": ALUMINIUM, "section": TUBE}})
    rigid_model = rf.Model.from_urdf(path)
    u = model.urdf
    assert u.bodies["sensor"].name == "sensor" and u.bodies["tool"].name == "arm.rfe1"  # s = 0.2 m: rfe 1 of 5
    assert u.bodies["fore"].name == "fore" and u.coordinates["shoulder"] == ("arm.rfe0.rz",)  # z: the joint axis
    flexible, rigid = model.compile(), rigid_model.compile()
    for q, _ in states(2, 3):
        qf = np.zeros(flexible.nq)
        qf[[flexible.coordinate_index(u.coordinates[j][0]) for j in ("shoulder", "elbow")]] = q
        for link in ("arm", "sensor", "tool", "fore"):
            np.testing.assert_allclose(flexible.position(u.point(link, (0.1, 0.2, -0.3)), 0.0, qf),
                                       rigid.position(rigid_model.urdf.point(link, (0.1, 0.2, -0.3)), 0.0, q),
                                       atol=1e-14)


# --- visual geometry: primitives and meshes the viewer draws ---------------------------------------------------

#: A cube's 8 corners (m) and its 12 triangles, outward.
CUBE = np.array([[x, y, z] for x in (0.0, 0.2) for y in (0.0, 0.2) for z in (0.0, 0.2)]) - 0.1
CUBE_FACES = np.array([[0, 2, 3], [0, 3, 1], [4, 5, 7], [4, 7, 6], [0, 1, 5], [0, 5, 4], [2, 6, 7], [2, 7, 3],
                       [0, 4, 6], [0, 6, 2], [1, 3, 7], [1, 7, 5]])


def write_stl(path, vertices, faces, binary=True):
    """An STL file of the triangles ``faces`` (k, 3) of ``vertices`` (n, 3), binary or ASCII."""
    tri = np.asarray(vertices, dtype=float)[faces]
    if binary:
        facets = np.zeros(len(tri), dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
        facets["v"] = tri
        path.write_bytes(b"solid made by the test".ljust(80, b" ") + np.uint32(len(tri)).tobytes() + facets.tobytes())
    else:
        rows = "".join("facet normal 0 0 0\n outer loop\n" + "".join(f"  vertex {x:.17g} {y:.17g} {z:.17g}\n" for x, y, z in t)
                       + " endloop\nendfacet\n" for t in tri)
        path.write_text(f"solid cube\n{rows}endsolid cube\n")
    return path


#: The visuals of write_meshed_robot: the cube on "fore" (binary STL) and on "hand" (ASCII), origins and scales.
FORE_MESH = {"xyz": (0.25, 0.0, 0.02), "rpy": (0.0, 0.0, 0.4), "scale": (1.5, 1.0, 0.8)}
HAND_MESH = {"xyz": (0.05, 0.0, 0.0), "rpy": (0.3, 0.0, 0.0), "scale": (0.5, 0.5, 0.5)}


def write_meshed_robot(folder, mesh_dir=None):
    """A three-link arm (z up) in ``folder/meshpkg/urdf/arm.urdf`` whose visuals are a yellow box (the base, on the
    ground), a cylinder along the upper arm (no colour), a magenta cube of a binary STL on the forearm, and on the
    hand (fixed to the forearm) a cyan cube of an ASCII STL (a material of the robot named) and a mesh whose file
    is not there. The STL files are in ``meshpkg/meshes`` (or ``mesh_dir``), named ``package://meshpkg/meshes/...``."""
    package = Path(folder) / "meshpkg"
    (package / "urdf").mkdir(parents=True, exist_ok=True)
    meshes = Path(mesh_dir) if mesh_dir is not None else package / "meshes"
    meshes.mkdir(parents=True, exist_ok=True)
    write_stl(meshes / "cube.stl", CUBE, CUBE_FACES)
    write_stl(meshes / "cube_ascii.stl", CUBE, CUBE_FACES, binary=False)
    inertia = '<inertia ixx="0.01" iyy="0.05" izz="0.05" ixy="0" ixz="0" iyz="0"/>'

    def mesh(name, m, colour=""):
        return (f'<visual><origin xyz="{" ".join(map(str, m["xyz"]))}" rpy="{" ".join(map(str, m["rpy"]))}"/>'
                f'<geometry><mesh filename="package://meshpkg/meshes/{name}" scale="{" ".join(map(str, m["scale"]))}"/>'
                f'</geometry>{colour}</visual>')

    text = f"""<robot name="meshed">
  <material name="cyan"><color rgba="0.1 0.8 0.8 1"/></material>
  <link name="base"><visual><origin xyz="0 0 0.05"/><geometry><box size="0.3 0.3 0.1"/></geometry>
    <material name="yellow"><color rgba="0.9 0.8 0.1 1"/></material></visual></link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/><origin xyz="0 0 0.1"/>
    <axis xyz="0 0 1"/></joint>
  <link name="upper"><inertial><origin xyz="0.25 0 0"/><mass value="2"/>{inertia}</inertial>
    <visual><origin xyz="0.25 0 0" rpy="0 1.5707963267948966 0"/><geometry><cylinder radius="0.04" length="0.5"/>
    </geometry></visual></link>
  <joint name="elbow" type="revolute"><parent link="upper"/><child link="fore"/><origin xyz="0.5 0 0"/>
    <axis xyz="0 0 1"/></joint>
  <link name="fore"><inertial><origin xyz="0.25 0 0"/><mass value="1"/>{inertia}</inertial>
    {mesh("cube.stl", FORE_MESH, '<material name="magenta"><color rgba="0.8 0.1 0.8 1"/></material>')}</link>
  <joint name="wrist" type="fixed"><parent link="fore"/><child link="hand"/><origin xyz="0.5 0 0"/></joint>
  <link name="hand"><inertial><mass value="0.2"/>{inertia}</inertial>
    {mesh("cube_ascii.stl", HAND_MESH, '<material name="cyan"/>')}
    <visual><geometry><mesh filename="package://meshpkg/meshes/gone.dae"/></geometry></visual></link>
</robot>"""
    return write(package / "urdf", text, "arm.urdf")


def test_visuals_are_read_and_their_mesh_files_found_by_package_or_folder(tmp_path):
    """The box, the cylinder and the two cubes are kept with their colours (the cyan one a material of the robot);
    ``package://meshpkg/...`` is found above the URDF's folder, or through ``package_dirs`` (a folder holding the
    package, or a dict); the binary and the ASCII STL give the same cube; the missing file is one note."""
    path = write_meshed_robot(tmp_path / "one")
    model = rf.Model.from_urdf(path)
    u = model.urdf
    box, = u.visuals["base"]
    cylinder, = u.visuals["upper"]
    assert (box.kind, box.size, box.colour) == ("box", (0.3, 0.3, 0.1), (0.9, 0.8, 0.1, 1.0))
    assert (cylinder.kind, cylinder.size, cylinder.colour) == ("cylinder", (0.04, 0.5), None)
    fore, = u.visuals["fore"]
    hand, gone = u.visuals["hand"]
    assert fore.path == str(tmp_path / "one" / "meshpkg" / "meshes" / "cube.stl") and fore.colour == (0.8, 0.1, 0.8, 1.0)
    assert hand.colour == (0.1, 0.8, 0.8, 1.0) and gone.path is None and gone.mesh is None
    for v in (fore, hand):  # 8 corners, 12 triangles: identical vertices merged
        assert v.mesh.vertices.shape == (8, 3) and v.mesh.triangles.shape == (12, 3)
        np.testing.assert_allclose(np.sort(v.mesh.vertices, axis=0), np.sort(CUBE, axis=0), atol=1e-7)
    np.testing.assert_array_equal(fore.mesh.vertices, hand.mesh.vertices)
    np.testing.assert_array_equal(fore.mesh.triangles, hand.mesh.triangles)
    missing = [n for n in u.notes if n.startswith("mesh files not found")]
    assert missing == [("mesh files not found (not drawn; a body with no other visual shows its inertia's box): "
                        "package://meshpkg/meshes/gone.dae")]
    # the package elsewhere: found through package_dirs only
    elsewhere = write_meshed_robot(tmp_path / "a", mesh_dir=tmp_path / "b" / "meshpkg" / "meshes")
    assert rf.Model.from_urdf(elsewhere).urdf.visuals["fore"][0].mesh is None
    for dirs in (tmp_path / "b", [str(tmp_path / "b")], {"meshpkg": tmp_path / "b" / "meshpkg"}):
        found = rf.Model.from_urdf(elsewhere, package_dirs=dirs).urdf.visuals["fore"][0]
        assert found.path == str(tmp_path / "b" / "meshpkg" / "meshes" / "cube.stl") and found.mesh.size == 12
    with pytest.raises(ValueError, match=r"^package_dirs: expected a folder .* that exists.*, got .*nowhere"):
        rf.Model.from_urdf(path, package_dirs=[tmp_path / "nowhere"])
    assert pickle.loads(pickle.dumps(model)).urdf.visuals["fore"][0].mesh.size == 12


def test_the_viewer_gets_each_mesh_in_its_bodys_frame_and_primitives_by_their_matrices(tmp_path):
    """In the page's scene, a mesh's vertices are the file's times its scale, turned and moved by its origin into
    its link's frame, and by the link's frame in its body's (the hand is fixed to the forearm 0.5 m on): float32
    in base64, three uint32 indices a triangle; the base's box is on the ground (body -1), the cylinder's matrix is
    its origin; a body with visuals has no inertia's box."""
    import base64

    model = rf.Model.from_urdf(write_meshed_robot(tmp_path))
    system = model.compile()
    data = rf.view(system).data
    shown = {v["link"]: v for v in data["visuals"]}
    assert [(v["link"], v["kind"], v["body"]) for v in data["visuals"]] == [
        ("base", "box", -1), ("upper", "cylinder", model.urdf.bodies["upper"].index),
        ("fore", "mesh", model.urdf.bodies["fore"].index), ("hand", "mesh", model.urdf.bodies["fore"].index)]
    for link, m, frame in (("fore", FORE_MESH, np.eye(4)), ("hand", HAND_MESH, rf.transform((0.5, 0.0, 0.0)))):
        T = frame @ rf.transform(m["xyz"], m["rpy"][::-1])  # rf.transform's angles are ZYX: (yaw, pitch, roll)
        expected = (CUBE * m["scale"]) @ T[:3, :3].T + T[:3, 3]
        vertices = np.frombuffer(base64.b64decode(shown[link]["vertices"]), dtype="<f4").reshape(-1, 3)
        indices = np.frombuffer(base64.b64decode(shown[link]["indices"]), dtype="<u4").reshape(-1, 3)
        assert vertices.shape == (8, 3) and indices.shape == (12, 3) and shown[link]["triangles"] == 12
        distance = np.linalg.norm(expected[:, None, :] - vertices[None, :, :], axis=2)
        assert distance.min(axis=1).max() < 1e-6  # every corner of the file's cube where its origin puts it
        # the triangles are the file's: twice a face's area each pair, 2 (ab + bc + ca) in all
        a, b, c = (vertices[indices[:, k]].astype(float) for k in range(3))
        area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1).sum()
        sx, sy, sz = 0.2 * np.asarray(m["scale"])
        assert area == pytest.approx(2 * (sx * sy + sy * sz + sz * sx), rel=1e-5)
    assert shown["fore"]["colour"] == 0xCC1ACC and shown["upper"]["colour"] is None
    np.testing.assert_allclose(np.reshape(shown["base"]["matrix"], (4, 4)), rf.transform((0.0, 0.0, 0.05)))
    np.testing.assert_allclose(np.reshape(shown["upper"]["matrix"], (4, 4)),
                               rf.transform((0.25, 0.0, 0.0), (0.0, math.pi / 2, 0.0)), atol=1e-15)
    assert shown["upper"]["size"] == [0.04, 0.5] and all(b["box"] is None for b in data["bodies"])


def test_a_flexible_links_visuals_are_not_drawn_and_a_broken_mesh_is_a_note(tmp_path):
    """The forearm as a beam: its cube is left out of the scene (the tube is drawn) and said so in a note; a mesh
    file that is not STL, or a broken one, is a note and no error, and its body shows its inertia's box."""
    path = write_meshed_robot(tmp_path)
    model = rf.Model.from_urdf(path, flexible={"fore": {"elements": 4, "material": ALUMINIUM, "section": TUBE}})
    assert "visuals of flexible links not drawn (their beams' tubes are): fore" in model.urdf.notes
    data = rf.view(model.compile()).data
    assert [v["link"] for v in data["visuals"]] == ["base", "upper", "hand"] and len(data["beams"]) == 1
    (tmp_path / "meshpkg" / "meshes" / "cube.stl").write_bytes(b"not a mesh")
    (tmp_path / "meshpkg" / "meshes" / "cube_ascii.stl").write_text("solid x\n vertex 1 2\nendsolid\n")
    model = rf.Model.from_urdf(path)
    unread, = [n for n in model.urdf.notes if n.startswith("mesh files not read")]
    assert "package://meshpkg/meshes/cube.stl (not an STL file" in unread and "cube_ascii.stl (" in unread
    data = rf.view(model.compile()).data
    assert [v["link"] for v in data["visuals"]] == ["base", "upper"]
    assert data["bodies"][model.urdf.bodies["fore"].index]["box"] is not None


COLLADA = """<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="millimeter" meter="0.001"/><up_axis>Z_UP</up_axis></asset>
  <library_effects><effect id="paint"><profile_COMMON><technique sid="common"><phong>
    <diffuse><color sid="diffuse">0.2 0.4 0.6 1</color></diffuse></phong></technique></profile_COMMON></effect>
  </library_effects>
  <library_geometries><geometry id="quad"><mesh>
    <source id="quad-pos"><float_array id="quad-pos-array" count="15">0 0 0 100 0 0 100 100 0 0 100 0 50 50 80</float_array>
      <technique_common><accessor source="#quad-pos-array" count="5" stride="3"/></technique_common></source>
    <source id="quad-n"><float_array id="quad-n-array" count="3">0 0 1</float_array></source>
    <vertices id="quad-v"><input semantic="POSITION" source="#quad-pos"/></vertices>
    <polylist count="1"><input semantic="VERTEX" source="#quad-v" offset="0"/>
      <input semantic="NORMAL" source="#quad-n" offset="1"/><vcount>4</vcount><p>0 0 1 0 2 0 3 0</p></polylist>
    <triangles count="2"><input semantic="VERTEX" source="#quad-v" offset="0"/><p>0 1 4 1 2 4</p></triangles>
  </mesh></geometry></library_geometries>
  <library_visual_scenes><visual_scene id="scene"><node id="a"><translate>0 0 10</translate>
    <node id="b"><rotate>0 0 1 90</rotate><instance_geometry url="#quad"/></node></node></visual_scene>
  </library_visual_scenes>
  <scene><instance_visual_scene url="#scene"/></scene>
</COLLADA>"""


def test_a_collada_files_triangles_are_read_in_metres_where_its_nodes_put_them():
    """<polylist> fanned into triangles, <triangles> as they are (NORMAL indices interleaved and skipped), the nodes'
    <translate> and <rotate> (degrees) applied, millimetres to metres, the first diffuse colour kept."""
    import tempfile

    from rigidfem.model import meshes

    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "quad.dae"
        path.write_text(COLLADA)
        mesh = meshes.read(path)
    p = 1e-3 * np.array([[0, 0, 0], [100, 0, 0], [100, 100, 0], [0, 100, 0], [50, 50, 80]], dtype=float)
    p = p @ np.array([[0, -1, 0], [1, 0, 0], [0, 0, 1.0]]).T + [0, 0, 0.01]  # rotate 90° about z, then up 10 mm
    tri = np.array([[0, 1, 2], [0, 2, 3], [0, 1, 4], [1, 2, 4]])
    got = {tuple(sorted(map(tuple, np.round(mesh.vertices[t].astype(float), 6)))) for t in mesh.triangles}
    assert got == {tuple(sorted(map(tuple, np.round(p[t], 6)))) for t in tri}
    assert mesh.colour == (0.2, 0.4, 0.6, 1.0)


def test_fine_meshes_are_decimated_to_the_pages_triangles(tmp_path, monkeypatch):
    """Vertex clustering: a sphere of 20,000 triangles kept within 2,000 (and at least half of them), its vertices
    still on the sphere to within a cell; in the viewer, all the meshes of all the layers within MAX_TRIANGLES."""
    from rigidfem.model import meshes
    from rigidfem.viz import viewer

    n = 100
    theta, phi = np.meshgrid(np.linspace(0, np.pi, n + 1), np.linspace(0, 2 * np.pi, n + 1), indexing="ij")
    v = 0.1 * np.c_[(np.sin(theta) * np.cos(phi)).ravel(), (np.sin(theta) * np.sin(phi)).ravel(), np.cos(theta).ravel()]
    k = np.arange(n * (n + 1)).reshape(n, n + 1)[:, :n].ravel()
    t = np.r_[np.c_[k, k + n + 1, k + 1], np.c_[k + 1, k + n + 1, k + n + 2]]
    fine = meshes._merged(v, t)
    coarse = meshes.decimated(fine, 2000)
    assert fine.size > 19000 and 1000 <= coarse.size <= 2000
    assert np.abs(np.linalg.norm(coarse.vertices, axis=1) - 0.1).max() < 0.01
    path = write_meshed_robot(tmp_path)
    write_stl(tmp_path / "meshpkg" / "meshes" / "cube.stl", fine.vertices, fine.triangles)  # the forearm's a sphere
    system = rf.Model.from_urdf(path).compile()
    monkeypatch.setattr(viewer, "MAX_TRIANGLES", 2000)
    one = rf.view(system).data["visuals"]
    assert [v.get("triangles") for v in one][::3] == [None, 12] and 1000 < one[2]["triangles"] <= 1988
    run = rf.Result(system, [0.0, 1.0], np.zeros((2, system.nq)), np.zeros((2, system.nq)), {}, "none")
    both = rf.view([run, run]).data
    drawn = [v["triangles"] for v in both["visuals"] + both["layers"][0]["visuals"] if v["kind"] == "mesh"]
    assert sum(drawn) <= 2000 and min(drawn) > 0
