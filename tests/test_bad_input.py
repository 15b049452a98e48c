"""Bad input gives a ValueError whose message starts with the argument's name, leaves
the model unchanged, and never crashes the interpreter."""

import subprocess
import sys
import textwrap

import numpy as np
import pytest

import rigidfem as rf
from rigidfem import motion, samples

NAN, INF = float("nan"), float("inf")


def small():
    m = rf.Model()
    b = m.add_body("b", m.ground, rf.Joint.revolute("z"), mass=1.0, inertia=(0.1, 0.1, 0.1), com=(0.5, 0, 0))
    return m, b


def bigger_model_body():
    """The last body of a three-body model: its index does not exist in small()."""
    other = rf.Model()
    p = other.ground
    for name in ("a", "c", "d"):
        p = other.add_body(name, p, rf.Joint.revolute("z"), mass=1.0, inertia=(1, 1, 1))
    return p


def add(m, **kw):
    args = dict(name="new", parent="b", joint=rf.Joint.revolute("y"), mass=1.0, inertia=(0.1, 0.2, 0.25))
    args.update(kw)
    return m.add_body(**args)


def reflection():
    P = np.eye(4)
    P[0, 0] = -1.0
    return P


def scaled():
    P = np.eye(4)
    P[:3, :3] *= 2.0
    return P


def sheared():
    P = np.eye(4)
    P[0, 1] = 0.3
    return P


def bad_last_row():
    P = np.eye(4)
    P[3, 0] = 1.0
    return P


ASYMMETRIC = np.array([[1.0, 0.1, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
INDEFINITE_TENSOR = np.array([[1.0, 2.0, 0.0], [2.0, 1.0, 0.0], [0.0, 0.0, 1.0]])  # eigenvalues -1, 1, 3

# (id, argument named in the message, add_body keywords)
ADD_BODY_CASES = [
    ("mass-zero", "mass", dict(mass=0.0)),
    ("mass-negative", "mass", dict(mass=-1.0)),
    ("mass-nan", "mass", dict(mass=NAN)),
    ("mass-inf", "mass", dict(mass=INF)),
    ("inertia-negative", "inertia", dict(inertia=(1.0, 1.0, -1.0))),
    ("inertia-zeros", "inertia", dict(inertia=(0.0, 0.0, 0.0))),
    ("inertia-zero-tensor", "inertia", dict(inertia=np.zeros((3, 3)))),
    ("inertia-indefinite-tensor", "inertia", dict(inertia=INDEFINITE_TENSOR)),
    ("inertia-triangle", "inertia", dict(inertia=(1.0, 1.0, 3.0))),
    ("inertia-triangle-tensor", "inertia", dict(inertia=np.diag([3.0, 1.0, 1.0]))),
    ("inertia-asymmetric", "inertia", dict(inertia=ASYMMETRIC)),
    ("inertia-shape-2", "inertia", dict(inertia=(1.0, 1.0))),
    ("inertia-shape-4", "inertia", dict(inertia=(1.0, 1.0, 1.0, 1.0))),
    ("inertia-shape-2x2", "inertia", dict(inertia=np.eye(2))),
    ("inertia-nan", "inertia", dict(inertia=(1.0, NAN, 1.0))),
    ("parent-unknown", "parent", dict(parent="nope")),
    ("parent-other-model", "parent", dict(parent=bigger_model_body())),
    ("parent-not-a-body", "parent", dict(parent=3.5)),
    ("name-duplicate", "name", dict(name="b")),
    ("name-ground", "name", dict(name="ground")),
    ("name-empty", "name", dict(name="")),
    ("com-shape", "com", dict(com=(0.1, 0.2))),
    ("com-shape-2d", "com", dict(com=np.zeros((3, 1)))),
    ("com-nan", "com", dict(com=(0.0, NAN, 0.0))),
    ("com-inf", "com", dict(com=(INF, 0.0, 0.0))),
    ("placement-3x3", "placement", dict(placement=np.eye(3))),
    ("placement-3x4", "placement", dict(placement=np.eye(4)[:3])),
    ("placement-scaled", "placement", dict(placement=scaled())),
    ("placement-reflection", "placement", dict(placement=reflection())),
    ("placement-sheared", "placement", dict(placement=sheared())),
    ("placement-last-row", "placement", dict(placement=bad_last_row())),
    ("placement-nan", "placement", dict(placement=np.full((4, 4), NAN))),
    ("joint-not-a-joint", "joint", dict(joint="revolute")),
]


@pytest.mark.parametrize("argument, kw", [c[1:] for c in ADD_BODY_CASES], ids=[c[0] for c in ADD_BODY_CASES])
def test_add_body_bad_input(argument, kw):
    m, _ = small()
    with pytest.raises(ValueError, match=rf"^{argument}\b"):
        add(m, **kw)
    # nothing half-added: the model is unchanged and still compiles
    assert m.nbodies == 1 and m.body_names == ["b"]
    assert m.compile().nq == 1


def test_good_body_is_accepted():
    """The baseline of the cases above: only the bad keyword makes them fail."""
    m, _ = small()
    add(m, com=(0.1, 0.0, 0.0), placement=rf.transform((0.0, 0.0, 1.0), (0.3, 0.2, 0.1)))
    assert m.nbodies == 2


# --- joints --------------------------------------------------------------------------------

JOINT_CASES = [
    ("revolute-w", "axis", lambda: rf.Joint.revolute("w")),
    ("revolute-rz", "axis", lambda: rf.Joint.revolute("rz")),
    ("prismatic-q", "axis", lambda: rf.Joint.prismatic("q")),
    ("cylindrical-X", "axis", lambda: rf.Joint.cylindrical("X")),
    ("custom-bad-name", "coordinates", lambda: rf.Joint.custom(["x", "w"])),
    ("custom-bad-single", "coordinates", lambda: rf.Joint.custom("q")),
    ("custom-repeated", "coordinates", lambda: rf.Joint.custom(["rz", "x", "rz"])),
    ("custom-repeated-alias", "coordinates", lambda: rf.Joint.custom(["phi1", "rx"])),
    ("stiffness-negative", "stiffness", lambda: rf.Joint.revolute("z", stiffness=-1.0)),
    ("stiffness-negative-entry", "stiffness", lambda: rf.Joint.cylindrical("z", stiffness=[1.0, -1.0])),
    ("stiffness-nan", "stiffness", lambda: rf.Joint.prismatic("x", stiffness=NAN)),
    ("stiffness-count", "stiffness", lambda: rf.Joint.spherical(stiffness=[1.0, 2.0])),
    ("stiffness-count-1", "stiffness", lambda: rf.Joint.revolute("z", stiffness=[1.0, 2.0])),
    ("damping-negative", "damping", lambda: rf.Joint.prismatic("y", damping=-0.5)),
    ("damping-count", "damping", lambda: rf.Joint.free(damping=[0.1] * 5)),
    ("rest-nan", "rest", lambda: rf.Joint.revolute("z", rest=NAN)),
    ("rest-count", "rest", lambda: rf.Joint.planar("xy", rest=[0.0, 1.0])),
]


@pytest.mark.parametrize("argument, make", [c[1:] for c in JOINT_CASES], ids=[c[0] for c in JOINT_CASES])
def test_joint_bad_input(argument, make):
    with pytest.raises(ValueError, match=rf"^{argument}\b"):
        make()


def test_spring_values_set_on_the_spec_are_checked_by_add_body():
    m, _ = small()
    j = rf.Joint.revolute("x")
    j.stiffness = [-3.0]
    with pytest.raises(ValueError, match=r"^stiffness\b"):
        add(m, joint=j)
    j = rf.Joint.revolute("x")
    j.damping = [1.0, 2.0]  # wrong count
    with pytest.raises(ValueError, match=r"^joint\b"):
        add(m, joint=j)
    assert m.nbodies == 1


def test_compile_empty_model():
    with pytest.raises(ValueError, match=r"^model\b"):
        rf.Model().compile()


# --- System evaluation ---------------------------------------------------------------------


def _systems():
    m1, h1 = samples.pendulum()
    m2, h2 = samples.double_pendulum()
    m3, h3 = samples.spring_mass()
    return {
        "pendulum": (m1.compile(), h1["tip"]),
        "double_pendulum": (m2.compile(), h2["tip"]),
        "spring_mass": (m3.compile(), h3["block"].point((0.1, 0.0, 0.0))),
    }


SYSTEMS = _systems()


def _calls(s, point):
    """name -> f(t, q, qd) calling one System method."""
    return {
        "forward_dynamics": lambda t, q, qd: s.forward_dynamics(t, q, qd),
        "mass_matrix": lambda t, q, qd: s.mass_matrix(t, q),
        "position": lambda t, q, qd: s.position(point, t, q),
        "velocity": lambda t, q, qd: s.velocity(point, t, q, qd),
        "rhs": lambda t, q, qd: s.rhs(t, np.concatenate([q, qd])),
        "kinetic_energy": lambda t, q, qd: s.kinetic_energy(t, q, qd),
        "generalized_forces": lambda t, q, qd: s.generalized_forces(t, q, qd),
    }


USES_QD = {"forward_dynamics", "velocity", "rhs", "kinetic_energy", "generalized_forces"}
METHODS = list(_calls(None, None))


@pytest.mark.parametrize("system", SYSTEMS)
@pytest.mark.parametrize("method", METHODS)
def test_system_bad_state(system, method):
    s, point = SYSTEMS[system]
    call = _calls(s, point)[method]
    n = s.nq
    q, qd = np.full(n, 0.3), np.full(n, -0.2)
    call(0.0, q, qd)  # baseline: the good state is accepted

    def expect(argument, t, q_, qd_):
        # rhs takes y = [q, qd]: a wrong length is reported on y, a NaN on y or its q or qd half
        if method == "rhs" and argument != "t":
            argument = "y" if len(q_) + len(qd_) != 2 * n else f"(y|{argument})"
        with pytest.raises(ValueError, match=rf"^{argument}\b"):
            call(t, q_, qd_)

    expect("q", 0.0, np.zeros(n + 1), qd)
    expect("q", 0.0, np.zeros(max(n - 1, 0)), qd)
    for bad in (NAN, INF, -INF):
        expect("q", 0.0, np.where(np.arange(n) == n - 1, bad, q), qd)
        expect("t", bad, q, qd)
        if method in USES_QD:
            expect("qd", 0.0, q, np.where(np.arange(n) == 0, bad, qd))
    if method in USES_QD and method != "rhs":
        expect("qd", 0.0, q, np.zeros(n + 1))


# --- prescribe, add_force ------------------------------------------------------------------


def test_prescribe_needs_the_coordinate_of_a_multi_coordinate_joint():
    m, h = samples.double_pendulum(spatial=True)
    with pytest.raises(ValueError, match=r"^coordinate\b"):
        m.prescribe(h["link1"], motion.constant(0.1))
    for missing in ("x", "z"):  # not coordinates of a spherical joint
        with pytest.raises(ValueError, match=r"^coordinate\b"):
            m.prescribe(h["link1"], motion.constant(0.1), coordinate=missing)
    with pytest.raises(ValueError, match=r"^coordinate\b"):
        m.prescribe(h["link1"], motion.constant(0.1), coordinate="w")
    m, h = samples.pendulum()
    with pytest.raises(ValueError, match=r"^coordinate\b"):
        m.prescribe(h["link"], motion.constant(0.1), coordinate="rz")  # the joint turns about y
    # the failed calls prescribed nothing
    assert m.compile().np == 0
    m.prescribe(h["link"], motion.constant(0.1), coordinate="ry")
    assert m.compile().np == 1


@pytest.mark.parametrize("bad", [1.0, None, lambda t: (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), "constant"])
def test_prescribe_needs_a_motion(bad):
    m, h = samples.pendulum()
    with pytest.raises(ValueError, match=r"^motion\b"):
        m.prescribe(h["link"], bad)


def test_prescribe_needs_a_body_of_the_model():
    m, h = samples.pendulum()
    for body in (m.ground, bigger_model_body()):
        with pytest.raises(ValueError, match=r"^body\b"):
            m.prescribe(body, motion.constant(0.0))


@pytest.mark.parametrize("force", [(1.0, 0.0), np.zeros(4), np.zeros((3, 1)), np.eye(3), (0.0, NAN, 0.0), 2.0])
def test_add_force_bad_force(force):
    m, h = samples.pendulum()
    with pytest.raises(ValueError, match=r"^force\b"):
        m.add_force("push", h["tip"], force)


def test_add_force_point_of_another_model():
    m, h = samples.pendulum()
    other = bigger_model_body()
    for point in (other, other.point((0.0, 0.0, 1.0)), m.ground, rf.Point(-7, np.zeros(3))):
        with pytest.raises(ValueError, match=r"^point\b"):
            m.add_force("push", point, (1.0, 0.0, 0.0))
    with pytest.raises(ValueError, match=r"^point\b"):
        m.add_force("push", (0.0, 0.0, 1.0), (1.0, 0.0, 0.0))  # a position is not a Point


# --- the interpreter survives --------------------------------------------------------------


def _run(code):
    return subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True, timeout=60
    )


def test_bad_input_does_not_crash_the_interpreter():
    """Every bad add_body and joint above, and bad System calls, in a fresh process."""
    code = f"""
        import importlib.util, numpy as np
        spec = importlib.util.spec_from_file_location("cases", {__file__!r})
        t = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(t)
        for name, argument, kw in t.ADD_BODY_CASES:
            m, _ = t.small()
            try:
                t.add(m, **kw)
            except ValueError:
                pass
            else:
                raise SystemExit("no error: " + name)
        for name, argument, make in t.JOINT_CASES:
            try:
                make()
            except ValueError:
                pass
            else:
                raise SystemExit("no error: " + name)
        s, point = t.SYSTEMS["double_pendulum"]
        for bad in ([], [1.0] * 50, [np.nan, 0.0], [np.inf, 0.0]):
            for f in t._calls(s, point).values():
                try:
                    f(0.0, np.asarray(bad, float), np.zeros(s.nq))
                except ValueError:
                    pass
                else:
                    raise SystemExit("no error")
        for index in (-1, 2, 10**6):
            point = t.rf.Point(index, np.zeros(3))
            for f in (lambda: s.transform(index, 0.0, np.zeros(2)), lambda: s.position(point, 0.0, np.zeros(2))):
                try:
                    f()
                except ValueError:
                    pass
                else:
                    raise SystemExit("no error for body index %d" % index)
        print("survived")
        """
    r = _run(code)
    assert r.returncode == 0, r.stderr[-2000:] + r.stdout[-2000:]
    assert "survived" in r.stdout


@pytest.mark.parametrize("stage", ["kinematics", "generalized_forces", "mass_matrix", "accelerations"])
@pytest.mark.parametrize("workspace", ["smaller_system", "same_sizes_fewer_free"])
def test_stages_reject_a_workspace_of_another_system(stage, workspace):
    """A Data made for another system must give ValueError ('data: ...'), not corrupt memory."""
    code = f"""
        import numpy as np
        import rigidfem as rf
        from rigidfem import samples, stages
        if {workspace!r} == "smaller_system":
            s = samples.double_pendulum()[0].compile()          # 2 bodies, nq = 2
            d = samples.pendulum()[0].compile().make_data()     # 1 body,  nq = 1
            q = np.zeros(2)
        else:
            s = samples.pendulum()[0].compile()                 # nq = 1
            m, h = samples.pendulum()
            m.prescribe(h["link"], rf.motion.constant(0.2))
            d = m.compile().make_data()                         # same nbodies and nc, nq = 0
            q = np.zeros(1)
        try:
            if {workspace!r} == "same_sizes_fewer_free":
                stages.set_state(s, d, 0.0, q, q)
                stages.kinematics(s, d)
            getattr(stages, {stage!r})(s, d)  # straight on the foreign workspace
        except Exception as e:
            print(type(e).__name__ + ":", e)
        else:
            print("accepted")
        """
    r = _run(code)
    assert r.returncode == 0, f"interpreter died with code {r.returncode}: {r.stderr[-500:]}"
    assert r.stdout.startswith("ValueError: data"), r.stdout
