"""The beam builder (book ch. 3.1–3.6, 4.5): division of a link into rfes and sdes, their
parameters, sections and materials, the Beam handles, deformation options, the linear
model, the tip body, small/large static deflections and bad input.

Every reference is a closed form (or a SciPy quadrature / shooting solution) written here:
ρAΔ masses, ∫x² dm pseudo-inertias, EA/Δ … EI/Δ springs, Saint-Venant torsion table values,
the discrete cantilever deflection FL³/(3EI)(1 − 1/(4m²)) of sdes at mid-segments, the
shear deflection FL/(κGA) of the classical formulation and Euler's elastica.
"""

import math
import re

import numpy as np
import pytest
from scipy.integrate import quad, solve_ivp
from scipy.optimize import brentq

import rigidfem as rf

STEEL = dict(E=2.1e11, rho=7850.0, nu=0.3)
NAMES = ("axial", "shear_y", "shear_z", "torsion", "bend_y", "bend_z")
COORD = {"axial": "x", "shear_y": "y", "shear_z": "z", "torsion": "rx", "bend_y": "ry", "bend_z": "rz"}
BOOK_ORDER = ("x", "y", "z", "rz", "ry", "rx")


def steel(**kw):
    return rf.Material(**{**STEEL, **kw})


def strip():
    return rf.Section.rectangle(width=0.05, height=0.01)


def rot(axis, a):
    c, s = math.cos(a), math.sin(a)
    return {"x": np.array([[1, 0, 0], [0, c, -s], [0, s, c]]),
            "y": np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]),
            "z": np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])}[axis]


def pose(r, phi3, phi2, phi1):
    """Trans(r) R3(φ3) R2(φ2) R1(φ1), written out here."""
    T = np.eye(4)
    T[:3, :3] = rot("z", phi3) @ rot("y", phi2) @ rot("x", phi1)
    T[:3, 3] = r
    return T


def cantilever(L=2.0, m=5, material=None, section=None, gravity=None, **kw):
    model = rf.Model(gravity=gravity)
    beam = model.add_beam("b", model.ground, L, material or steel(), section or strip(), m, **kw)
    return model, beam


def seg_pieces(L, m):
    """(start, end, frame) of rfe 0..m, written from the book's ch. 3.1."""
    d = L / m
    out = [(0.0, d / 2, 0.0)]
    for i in range(1, m + 1):
        out.append(((i - 0.5) * d, min((i + 0.5) * d, L), (i - 0.5) * d))
    return out


def x2(a, b, x0):
    return ((b - x0) ** 3 - (a - x0) ** 3) / 3.0


# ----------------------------------------------------------------------------------------
# 1. Division and parameters of a uniform beam
# ----------------------------------------------------------------------------------------

@pytest.mark.parametrize("m", [1, 2, 5])
@pytest.mark.parametrize("formulation,ndef", [("modified", 3), ("classical", 6)])
def test_uniform_division_counts_and_frames(m, formulation, ndef):
    L = 2.0
    model, beam = cantilever(L, m, formulation=formulation)
    system = model.compile()
    d = L / m
    assert len(beam.rfes) == m + 1
    assert system.nbodies == m + 1
    assert system.nq == m * ndef
    assert beam.length == L and beam.elements == m and beam.formulation == formulation
    np.testing.assert_allclose(beam.frames, [0.0] + [(i - 0.5) * d for i in range(1, m + 1)], rtol=0, atol=1e-15)
    assert [b.name for b in beam.rfes] == [f"b.rfe{i}" for i in range(m + 1)]
    assert list(system.parent) == [-1] + list(range(m))  # a chain rfe0 <- rfe1 <- ... (nonlinear)


@pytest.mark.parametrize("m", [1, 5])
def test_uniform_rfe_parameters_closed_form(m):
    L = 2.0
    mat, sec = steel(), strip()
    model, beam = cantilever(L, m, mat, sec)
    system = model.compile()
    rho, A, Iy, Iz = mat.rho, 0.05 * 0.01, 0.05 * 0.01**3 / 12, 0.01 * 0.05**3 / 12
    d = L / m
    total = 0.0
    for i, (a, b, x0) in enumerate(seg_pieces(L, m)):
        p = beam.rfe[i]
        l = b - a
        assert l == pytest.approx(d / 2 if i in (0, m) else d, rel=1e-14)
        assert p.mass == pytest.approx(rho * A * l, rel=1e-13)
        # c.o.m. in the rfe frame: Δ/4 for rfe 0 and rfe m, Δ/2 for the inner ones
        np.testing.assert_allclose(p.com, [d / 4 if i in (0, m) else d / 2, 0, 0], rtol=1e-13, atol=1e-16)
        H = np.zeros((4, 4))
        H[0, 0] = rho * A * x2(a, b, x0)
        H[1, 1] = rho * Iz * l      # ∫y² dm: rotary inertia of the section
        H[2, 2] = rho * Iy * l      # ∫z² dm
        H[0, 3] = H[3, 0] = rho * A * ((b - x0) ** 2 - (a - x0) ** 2) / 2
        H[3, 3] = rho * A * l
        np.testing.assert_allclose(p.H, H, rtol=1e-12, atol=1e-18)
        # inertia about the c.o.m.: rod + section rotary inertia
        I = np.diag([rho * (Iy + Iz) * l, rho * A * l**3 / 12 + rho * Iy * l, rho * A * l**3 / 12 + rho * Iz * l])
        np.testing.assert_allclose(p.inertia, I, rtol=1e-10, atol=1e-18)
        # the body the model got has that pseudo-inertia
        np.testing.assert_allclose(system.pseudo_inertias[beam.rfes[i].index], H, rtol=1e-10, atol=1e-15)
        total += p.mass
    assert total == pytest.approx(rho * A * L, rel=1e-13)


def test_uniform_sde_parameters_closed_form_and_damping():
    L, m, mu = 2.0, 5, 2.5e-4
    mat, sec = steel(retardation=mu), strip()
    model, beam = cantilever(L, m, mat, sec)
    d = L / m
    E, G = 2.1e11, 2.1e11 / 2.6
    A, Iy, Iz = 5e-4, 0.05 * 0.01**3 / 12, 0.01 * 0.05**3 / 12
    ref = {"axial": E * A / d, "shear_y": 5 / 6 * G * A / d, "shear_z": 5 / 6 * G * A / d,
           "torsion": G * sec.J / d, "bend_y": E * Iy / d, "bend_z": E * Iz / d}
    assert len(beam.sde) == m
    for s in beam.sde:
        assert set(s.stiffness) == set(NAMES) and set(s.damping) == set(NAMES)
        for k in NAMES:
            assert s.stiffness[k] == pytest.approx(ref[k], rel=1e-12), k
            assert s.damping[k] == pytest.approx(mu * ref[k], rel=1e-12), k


def test_springs_and_dampers_sit_on_the_right_coordinates(rng):
    """V = ½ Σ c_k q_k², dissipated power Σ b_k q̇_k² with c, b from the closed forms."""
    L, m, mu = 2.0, 4, 1e-3
    mat, sec = steel(retardation=mu), strip()
    model, beam = cantilever(L, m, mat, sec, formulation="classical")
    system = model.compile()
    d = L / m
    E, G = mat.E, mat.G
    c = {"x": E * sec.A / d, "y": 5 / 6 * G * sec.A / d, "z": 5 / 6 * G * sec.A / d,
         "rx": G * sec.J / d, "ry": E * sec.Iy / d, "rz": E * sec.Iz / d}
    cq = np.array([c[n.rsplit(".", 1)[1]] for n in system.coordinate_names])
    q = rng.uniform(-1e-3, 1e-3, system.nq)
    qd = rng.uniform(-1, 1, system.nq)
    assert system.elastic_energy(0.0, q) == pytest.approx(0.5 * np.sum(cq * q**2), rel=1e-12)
    assert system.dissipated_power(0.0, q, qd) == pytest.approx(mu * np.sum(cq * qd**2), rel=1e-12)


def test_rfe_parameters_function_directly():
    mat, sec = steel(), strip()
    rho, A = mat.rho, sec.A
    # piece [0.3, 0.7] with its frame in its middle: c.o.m. at the frame
    p = rf.rfe_parameters(mat, sec, 0.3, 0.7, origin=0.5)
    assert p.mass == pytest.approx(rho * A * 0.4, rel=1e-13)
    np.testing.assert_allclose(p.com, [0, 0, 0], atol=1e-14)
    assert p.H[0, 0] == pytest.approx(rho * A * x2(0.3, 0.7, 0.5), rel=1e-12)
    assert p.H[1, 1] == pytest.approx(rho * sec.Iz * 0.4, rel=1e-12)
    assert p.H[2, 2] == pytest.approx(rho * sec.Iy * 0.4, rel=1e-12)
    # default origin = start; frame outside the piece
    p = rf.rfe_parameters(mat, sec, 0.3, 0.7)
    np.testing.assert_allclose(p.com, [0.2, 0, 0], rtol=1e-12)
    assert p.H[0, 0] == pytest.approx(rho * A * 0.4**3 / 3, rel=1e-12)
    p = rf.rfe_parameters(mat, sec, 0.3, 0.7, origin=-1.0)
    assert p.H[0, 3] == pytest.approx(rho * A * 0.4 * 1.5, rel=1e-12)
    assert p.H[0, 0] == pytest.approx(rho * A * x2(0.3, 0.7, -1.0), rel=1e-12)


def test_sde_parameters_function_directly():
    mat, sec = rf.Material(E=7e10, rho=2700, G=2.6e10, retardation=0.01), rf.Section.circle(0.03)
    s = rf.sde_parameters(mat, sec, 1.0, 1.25)
    d = 0.25
    ref = {"axial": 7e10 * sec.A / d, "shear_y": 0.9 * 2.6e10 * sec.A / d, "shear_z": 0.9 * 2.6e10 * sec.A / d,
           "torsion": 2.6e10 * sec.J / d, "bend_y": 7e10 * sec.Iy / d, "bend_z": 7e10 * sec.Iz / d}
    for k in NAMES:
        assert s.stiffness[k] == pytest.approx(ref[k], rel=1e-12), k
        assert s.damping[k] == pytest.approx(0.01 * ref[k], rel=1e-12), k


# ----------------------------------------------------------------------------------------
# 2. Varying sections and materials
# ----------------------------------------------------------------------------------------

def test_tapered_beam_from_a_function_of_s():
    L, m, h, w0 = 2.0, 4, 0.01, 0.05
    mat = steel()
    w = lambda s: w0 * (1.0 - 0.5 * s / L)  # noqa: E731
    model, beam = cantilever(L, m, mat, lambda s: rf.Section.rectangle(w(s), h))
    system = model.compile()
    rho, E = mat.rho, mat.E
    A = lambda s: w(s) * h  # noqa: E731
    Iz = lambda s: h * w(s) ** 3 / 12  # noqa: E731
    Iy = lambda s: w(s) * h**3 / 12  # noqa: E731
    mass = sum(p.mass for p in beam.rfe)
    first = sum(p.H[0, 3] + p.mass * x0 for p, (_, _, x0) in zip(beam.rfe, seg_pieces(L, m)))
    assert mass == pytest.approx(quad(lambda s: rho * A(s), 0, L)[0], rel=1e-10)
    assert first == pytest.approx(quad(lambda s: rho * A(s) * s, 0, L)[0], rel=1e-10)
    assert sum(system.pseudo_inertias[b.index][3, 3] for b in beam.rfes) == pytest.approx(mass, rel=1e-12)
    for p, (a, b, x0) in zip(beam.rfe, seg_pieces(L, m)):
        assert p.mass == pytest.approx(quad(lambda s: rho * A(s), a, b)[0], rel=1e-10)
        assert p.H[0, 0] == pytest.approx(quad(lambda s: rho * A(s) * (s - x0) ** 2, a, b)[0], rel=1e-10)
        assert p.H[1, 1] == pytest.approx(quad(lambda s: rho * Iz(s), a, b)[0], rel=1e-10)
        assert p.H[2, 2] == pytest.approx(quad(lambda s: rho * Iy(s), a, b)[0], rel=1e-10)
    d = L / m
    for i, s in enumerate(beam.sde, start=1):
        a, b = (i - 1) * d, i * d
        ref = 1.0 / quad(lambda x: 1.0 / (E * Iz(x)), a, b)[0]
        assert s.stiffness["bend_z"] == pytest.approx(ref, rel=1e-9)
        assert s.stiffness["axial"] == pytest.approx(1.0 / quad(lambda x: 1.0 / (E * A(x)), a, b)[0], rel=1e-9)
        # the documented choice (integrated compliance) is distinguishable from the midpoint value here
        assert abs(ref / (E * Iz(0.5 * (a + b)) / d) - 1) > 1e-3


def test_stepped_beam_from_a_list_per_segment():
    L, m, h = 2.0, 4, 0.01
    widths = [0.05, 0.04, 0.03, 0.02]
    Es = [2.1e11, 2.1e11, 7e10, 7e10]
    mats = [rf.Material(E=E, rho=7850.0) for E in Es]
    secs = [rf.Section.rectangle(wk, h) for wk in widths]
    model, beam = cantilever(L, m, mats, secs)
    d = L / m
    rho = 7850.0
    A = lambda s: widths[min(int(s / d), m - 1)] * h  # noqa: E731
    cuts = [k * d for k in range(1, m)]
    mass = sum(p.mass for p in beam.rfe)
    first = sum(p.H[0, 3] + p.mass * x0 for p, (_, _, x0) in zip(beam.rfe, seg_pieces(L, m)))
    assert mass == pytest.approx(rho * h * d * sum(widths), rel=1e-12)
    assert mass == pytest.approx(quad(lambda s: rho * A(s), 0, L, points=cuts)[0], rel=1e-10)
    assert first == pytest.approx(quad(lambda s: rho * A(s) * s, 0, L, points=cuts)[0], rel=1e-10)
    # an inner rfe straddles a step: half of each neighbouring segment
    for i in range(1, m):
        assert beam.rfe[i].mass == pytest.approx(rho * h * d / 2 * (widths[i - 1] + widths[i]), rel=1e-12)
    # each sde covers one segment: its own section and material
    for i, s in enumerate(beam.sde):
        assert s.stiffness["bend_z"] == pytest.approx(Es[i] * h * widths[i] ** 3 / 12 / d, rel=1e-12)
        assert s.stiffness["bend_y"] == pytest.approx(Es[i] * widths[i] * h**3 / 12 / d, rel=1e-12)


def test_stepped_list_of_wrong_length_names_section():
    secs = [strip()] * 3
    with pytest.raises(ValueError, match=r"^section:"):
        cantilever(2.0, 4, steel(), secs)
    with pytest.raises(ValueError, match=r"^section:"):
        cantilever(2.0, 4, steel(), [strip(), strip(), strip(), "x"])
    with pytest.raises(ValueError, match=r"^material:"):
        cantilever(2.0, 4, [steel()] * 5, strip())


# ----------------------------------------------------------------------------------------
# 3. Sections and materials
# ----------------------------------------------------------------------------------------

def test_rectangle_areas_and_second_moments():
    w, h = 0.05, 0.01
    s = rf.Section.rectangle(width=w, height=h)
    assert s.A == pytest.approx(w * h, rel=1e-14)
    assert s.Iy == pytest.approx(w * h**3 / 12, rel=1e-14)  # about y: height along z
    assert s.Iz == pytest.approx(h * w**3 / 12, rel=1e-14)
    assert s.kappa_y == pytest.approx(5 / 6) and s.kappa_z == pytest.approx(5 / 6)
    t = rf.Section.rectangle(width=h, height=w)  # turned by 90°: Iy, Iz swap, J unchanged
    assert t.Iy == pytest.approx(s.Iz, rel=1e-14) and t.Iz == pytest.approx(s.Iy, rel=1e-14)
    assert t.J == pytest.approx(s.J, rel=1e-14)


@pytest.mark.parametrize("ratio,beta", [(1.0, 0.1406), (1.5, 0.1958), (2.0, 0.2287), (3.0, 0.2633),
                                        (5.0, 0.2913), (10.0, 0.3123)])
def test_rectangle_torsion_constant_against_saint_venant_table(ratio, beta):
    b = 0.02
    a = ratio * b
    s = rf.Section.rectangle(width=a, height=b)
    assert s.J == pytest.approx(beta * a * b**3, rel=1e-3)
    assert s.J < a * b**3 / 3  # the thin-strip limit is an upper bound


def test_very_thin_rectangle_approaches_one_third():
    s = rf.Section.rectangle(width=1.0, height=0.001)
    # J = (a b³/3)(1 − 0.630 b/a) for a >> b
    assert s.J == pytest.approx(1.0 * 0.001**3 / 3 * (1 - 0.630 * 0.001), rel=1e-4)


def test_circle_and_tube():
    d = 0.04
    c = rf.Section.circle(d)
    assert c.A == pytest.approx(math.pi * d**2 / 4, rel=1e-14)
    assert c.Iy == pytest.approx(math.pi * d**4 / 64, rel=1e-14) and c.Iz == pytest.approx(c.Iy, rel=1e-14)
    assert c.J == pytest.approx(math.pi * d**4 / 32, rel=1e-14)
    assert c.J == pytest.approx(c.Iy + c.Iz, rel=1e-14)
    assert c.I0 == pytest.approx(c.Iy + c.Iz, rel=1e-14)
    D, di = 0.05, 0.04
    t = rf.Section.tube(D, di)
    assert t.A == pytest.approx(math.pi * (D**2 - di**2) / 4, rel=1e-13)
    assert t.Iy == pytest.approx(math.pi * (D**4 - di**4) / 64, rel=1e-13) and t.Iz == pytest.approx(t.Iy)
    assert t.J == pytest.approx(math.pi * (D**4 - di**4) / 32, rel=1e-13)
    full = rf.Section.tube(d, 0.0)
    assert (full.A, full.Iy, full.J) == pytest.approx((c.A, c.Iy, c.J), rel=1e-14)


def test_material_shear_modulus():
    assert rf.Material(E=2.0e11, rho=7800, nu=0.25).G == pytest.approx(2.0e11 / 2.5, rel=1e-14)
    assert rf.Material(E=2.0e11, rho=7800).G == pytest.approx(2.0e11 / 2.6, rel=1e-14)  # default nu 0.3
    assert rf.Material(E=2.0e11, rho=7800, nu=0.25, G=7.0e10).G == 7.0e10  # G overrides nu
    assert rf.Material(E=2.0e11, rho=7800, G=7.0e10).G == 7.0e10
    assert rf.Material(E=2.0e11, rho=7800).retardation == 0.0


# ----------------------------------------------------------------------------------------
# 4. Handles, placement, coordinate names, deformation options, linear model
# ----------------------------------------------------------------------------------------

def test_tip_and_point_handles():
    L, m = 2.0, 5
    d = L / m
    model, beam = cantilever(L, m)
    system = model.compile()
    tip = beam.tip
    assert tip.body == beam.rfes[m].index
    np.testing.assert_allclose(tip.r, [d / 2, 0, 0], atol=1e-15)
    pieces = seg_pieces(L, m)
    q0 = np.zeros(system.nq)
    for s in [0.0, 0.05, 0.19, 0.21, 0.3, 0.79, 1.0, 1.5, 1.79, 1.81, 1.95, 2.0]:
        p = beam.point(s)
        i = [b.index for b in beam.rfes].index(p.body)
        lo, hi, x0 = pieces[i]
        assert lo - 1e-12 <= s <= hi + 1e-12, (s, i)
        np.testing.assert_allclose(p.r, [s - x0, 0, 0], atol=1e-14)
        np.testing.assert_allclose(system.position(p, 0.0, q0), [s, 0, 0], atol=1e-14)
    # interior points (away from rfe ends) pick the unique rfe
    assert beam.point(0.05).body == beam.rfes[0].index
    assert beam.point(0.3).body == beam.rfes[1].index
    assert beam.point(1.95).body == beam.rfes[5].index


def test_points_follow_their_rfe_when_deformed():
    """Bend only sde 3 (rz): points before it stay, points after it rotate about it."""
    L, m = 2.0, 5
    d = L / m
    model, beam = cantilever(L, m, deform="bend_z")
    system = model.compile()
    q = np.zeros(system.nq)
    phi = 0.3
    q[system.coordinate_index("b.rfe3.rz")] = phi
    xs = (3 - 0.5) * d  # sde 3
    for s in [0.1, 0.5, 0.9, 1.1, 1.5, 2.0]:
        r = system.position(beam.point(s), 0.0, q)
        ref = [s, 0, 0] if s < xs else [xs + (s - xs) * math.cos(phi), (s - xs) * math.sin(phi), 0]
        np.testing.assert_allclose(r, ref, atol=1e-13)


def _hub_beam(theta=0.0, **kw):
    model = rf.Model(gravity=None)
    hub = model.add_body("hub", model.ground, rf.Joint.revolute("z"), mass=1.0, inertia=(1.0, 1.0, 1.0))
    beam = model.add_beam("b", hub, 2.0, steel(), strip(), 5,
                          placement=rf.transform((1, 2, 3), (0.3, 0.2, 0.1)), **kw)
    return model, hub, beam


@pytest.mark.parametrize("linear", [False, True])
@pytest.mark.parametrize("theta", [0.0, 0.7])
def test_undeformed_centerline_is_the_placed_straight_line(linear, theta):
    L, m = 2.0, 5
    d = L / m
    xs = np.array([0.0] + [(i - 0.5) * d for i in range(1, m + 1)] + [L])
    # on the ground, no placement
    model, beam = cantilever(L, m, linear=linear)
    system = model.compile()
    line = beam.centerline(system, np.zeros(system.nq))
    assert line.shape == (m + 2, 3)
    np.testing.assert_allclose(line, np.c_[xs, np.zeros(m + 2), np.zeros(m + 2)], atol=1e-14)
    # on a hub turned by theta, placed by (1, 2, 3), ZYX (0.3, 0.2, 0.1)
    model, hub, beam = _hub_beam(linear=linear)
    system = model.compile()
    q = np.zeros(system.nq)
    q[system.coordinate_index("hub.rz")] = theta
    T = pose([0, 0, 0], theta, 0, 0) @ pose([1, 2, 3], 0.3, 0.2, 0.1)
    ref = (T @ np.c_[xs, np.zeros(m + 2), np.zeros(m + 2), np.ones(m + 2)].T).T[:, :3]
    np.testing.assert_allclose(beam.centerline(system, q), ref, atol=1e-13)


def test_coordinate_names_and_deform_options():
    m = 3
    cases = [
        (dict(deform="bend_z"), ["rz"]),
        (dict(deform=["bend_z"]), ["rz"]),
        (dict(), ["rz", "ry", "rx"]),                                   # modified default
        (dict(formulation="classical"), list(BOOK_ORDER)),              # classical default
        (dict(formulation="classical", deform=("bend_z", "axial")), ["x", "rz"]),  # book order
        (dict(formulation="classical", deform=("torsion", "shear_z", "bend_y")), ["z", "ry", "rx"]),
        (dict(deform=("bend_y", "torsion")), ["ry", "rx"]),
    ]
    for kw, coords in cases:
        for linear in (False, True):
            model, beam = cantilever(2.0, m, linear=linear, **kw)
            system = model.compile()
            assert system.nq == m * len(coords), kw
            assert list(system.coordinate_names) == [f"b.rfe{i}.{c}" for i in range(1, m + 1) for c in coords], kw
            assert set(beam.deform) == {k for k, v in COORD.items() if v in coords}


def test_elastic_energy_of_a_chosen_subset(rng):
    """Only the kept deformations carry springs, with their own constants."""
    L, m = 1.5, 3
    mat, sec = steel(), strip()
    model, beam = cantilever(L, m, mat, sec, formulation="classical", deform=("bend_z", "axial"))
    system = model.compile()
    d = L / m
    c = {"x": mat.E * sec.A / d, "rz": mat.E * sec.Iz / d}
    cq = np.array([c[n.rsplit(".", 1)[1]] for n in system.coordinate_names])
    q = rng.uniform(-1e-3, 1e-3, system.nq)
    assert system.elastic_energy(0.0, q) == pytest.approx(0.5 * np.sum(cq * q**2), rel=1e-12)


def test_linear_model_structure_mass_and_first_order_kinematics(rng):
    L, m = 2.0, 5
    nl_model, nl = cantilever(L, m, formulation="classical")
    li_model, li = cantilever(L, m, formulation="classical", linear=True)
    s_nl, s_li = nl_model.compile(), li_model.compile()
    assert s_li.nq == s_nl.nq == 6 * m
    assert list(s_li.coordinate_names) == list(s_nl.coordinate_names)
    assert list(s_li.parent) == [-1] + [li.rfes[0].index] * m  # rfes i >= 1 hang on rfe 0
    mass = lambda s: sum(H[3, 3] for H in s.pseudo_inertias)  # noqa: E731
    assert mass(s_li) == pytest.approx(mass(s_nl), rel=1e-13)
    assert mass(s_li) == pytest.approx(7850 * 5e-4 * L, rel=1e-12)
    q0 = np.zeros(s_nl.nq)
    np.testing.assert_allclose(li.centerline(s_li, q0), nl.centerline(s_nl, q0), atol=1e-14)
    # same mass matrix in the undeformed configuration (same first-order kinematics)
    A_nl, A_li = s_nl.mass_matrix(0.0, q0), s_li.mass_matrix(0.0, q0)
    np.testing.assert_allclose(A_li, A_nl, rtol=1e-9, atol=1e-9 * np.max(np.abs(A_nl)))
    # small deformations: the centre lines agree to second order
    q = rng.uniform(-1, 1, s_nl.nq) * 1e-5
    u_nl = nl.centerline(s_nl, q) - nl.centerline(s_nl, q0)
    u_li = li.centerline(s_li, q) - li.centerline(s_li, q0)
    assert np.max(np.abs(u_nl)) > 1e-6
    assert np.max(np.abs(u_li - u_nl)) < 1e-3 * np.max(np.abs(u_nl))


def test_linear_model_is_linear_in_the_deformations():
    """Bending one sde in the linear model moves the tip by φ·(L − x_sde) along y, not on a circle."""
    L, m = 2.0, 4
    d = L / m
    model, beam = cantilever(L, m, deform="bend_z", linear=True)
    system = model.compile()
    q = np.zeros(system.nq)
    phi = 0.5
    q[system.coordinate_index("b.rfe2.rz")] = phi
    xs = 1.5 * d
    np.testing.assert_allclose(system.position(beam.tip, 0.0, q), [L, phi * (L - xs), 0], atol=1e-13)


# ----------------------------------------------------------------------------------------
# 5. Tip mass
# ----------------------------------------------------------------------------------------

@pytest.mark.parametrize("offset", [(0.0, 0.0, 0.0), (0.1, 0.0, 0.05)])
@pytest.mark.parametrize("linear", [False, True])
def test_tip_mass_total_mass_and_centre_of_mass(offset, linear):
    L, m, M0, g = 2.0, 5, 3.0, 9.81
    z0, pitch = 1.0, -0.4  # pitched up: z = z0 + x sin 0.4 − ... (R2(φ2) turns x into (cos φ2, 0, −sin φ2))
    mat, sec = steel(), strip()
    model = rf.Model(gravity=(0.0, 0.0, -g))
    beam = model.add_beam("b", model.ground, L, mat, sec, m, linear=linear, tip_mass=M0, tip_offset=offset,
                          placement=rf.transform((0.5, -0.2, z0), (0.2, pitch, 0.0)))
    system = model.compile()
    q0 = np.zeros(system.nq)
    rhoAL = mat.rho * sec.A * L
    total = sum(H[3, 3] for H in system.pseudo_inertias)
    assert total == pytest.approx(rhoAL + M0, rel=1e-12)
    assert sum(p.mass for p in beam.rfe) == pytest.approx(rhoAL + M0, rel=1e-12)
    z = lambda x, zl=0.0: z0 - math.sin(pitch) * x + math.cos(pitch) * zl  # noqa: E731
    ox, _, oz = offset
    V_ref = g * (mat.rho * sec.A * quad(z, 0, L)[0] + M0 * z(L + ox, oz))
    assert system.gravity_energy(0.0, q0) == pytest.approx(V_ref, rel=1e-11)
    # without the tip mass the same beam has V = g ρA ∫ z ds: the difference is M0 g z_tip
    model2 = rf.Model(gravity=(0.0, 0.0, -g))
    model2.add_beam("b", model2.ground, L, mat, sec, m, linear=linear,
                    placement=rf.transform((0.5, -0.2, z0), (0.2, pitch, 0.0)))
    V_bare = model2.compile().gravity_energy(0.0, q0)
    assert system.gravity_energy(0.0, q0) - V_bare == pytest.approx(M0 * g * z(L + ox, oz), rel=1e-10)


def test_tip_inertia_is_merged_into_the_last_rfe():
    """H_last = H_piece + ∫r rᵀ dm of the tip body: ½ tr(I) 1 − I + M c cᵀ, M c, M."""
    L, m, M0 = 2.0, 4, 2.0
    I0 = np.diag([0.1, 0.2, 0.25])
    offset = np.array([0.05, 0.0, -0.02])
    mat, sec = steel(), strip()
    model, beam = cantilever(L, m, mat, sec, tip_mass=M0, tip_inertia=(0.1, 0.2, 0.25), tip_offset=offset)
    system = model.compile()
    d = L / m
    rho, A = mat.rho, sec.A
    H = np.zeros((4, 4))
    H[0, 0] = rho * A * (d / 2) ** 3 / 3
    H[1, 1], H[2, 2] = rho * sec.Iz * d / 2, rho * sec.Iy * d / 2
    H[0, 3] = H[3, 0] = rho * A * (d / 2) ** 2 / 2
    H[3, 3] = rho * A * d / 2
    c = offset + [d / 2, 0, 0]  # from the last rfe's frame at L − Δ/2
    H[:3, :3] += 0.5 * np.trace(I0) * np.eye(3) - I0 + M0 * np.outer(c, c)
    H[:3, 3] += M0 * c
    H[3, :3] += M0 * c
    H[3, 3] += M0
    np.testing.assert_allclose(beam.rfe[m].H, H, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(system.pseudo_inertias[beam.rfes[m].index], H, rtol=1e-10, atol=1e-14)
    # the other rfes are untouched
    assert beam.rfe[m - 1].mass == pytest.approx(rho * A * d, rel=1e-13)


def test_material_varying_along_the_beam():
    L, m = 2.0, 3
    sec = strip()
    rho = lambda s: 7850.0 * (1.0 + 0.5 * s)  # noqa: E731
    model, beam = cantilever(L, m, lambda s: rf.Material(E=2.1e11, rho=rho(s)), sec)
    assert sum(p.mass for p in beam.rfe) == pytest.approx(quad(lambda s: rho(s) * sec.A, 0, L)[0], rel=1e-12)
    for p, (a, b, x0) in zip(beam.rfe, seg_pieces(L, m)):
        assert p.H[0, 3] == pytest.approx(quad(lambda s: rho(s) * sec.A * (s - x0), a, b)[0], rel=1e-10)
        assert p.H[1, 1] == pytest.approx(quad(lambda s: rho(s) * sec.Iz, a, b)[0], rel=1e-12)


# ----------------------------------------------------------------------------------------
# 6. Static deflections: classical vs modified, linear vs nonlinear
# ----------------------------------------------------------------------------------------

SQ = dict(width=0.02, height=0.02)


def tip_under_load(F, L=2.0, m=8, steps=1, **kw):
    model, beam = cantilever(L, m, steel(), rf.Section.rectangle(**SQ), **kw)
    model.add_force("load0", beam.tip, (0.0, F, 0.0))
    system = model.compile()
    eq = rf.static_equilibrium(system, load_steps=steps)
    assert eq.converged
    return system.position(beam.tip, 0.0, eq.q)


def test_small_tip_load_classical_modified_linear_nonlinear():
    L, m = 2.0, 8
    mat, sec = steel(), rf.Section.rectangle(**SQ)
    EI = mat.E * sec.Iz
    F = 1e-3 * 3 * EI / L**3  # tip deflection ≈ 1e-3 m
    mod = tip_under_load(F, L, m)
    cla = tip_under_load(F, L, m, formulation="classical")
    mod_lin = tip_under_load(F, L, m, linear=True)
    cla_lin = tip_under_load(F, L, m, formulation="classical", linear=True)
    # RFEM with sdes at mid-segments: δ = F Δ/(EI) Σ (L − x_i)² = FL³/(3EI) (1 − 1/(4m²))
    delta = F * L**3 / (3 * EI) * (1 - 1 / (4 * m * m))
    assert mod_lin[1] == pytest.approx(delta, rel=1e-9)
    assert mod[1] == pytest.approx(delta, rel=1e-5)
    assert abs(cla[1] - mod[1]) < 1e-3 * abs(mod[1])
    assert abs(mod_lin[1] - mod[1]) < 1e-5 * abs(mod[1])
    assert abs(cla_lin[1] - cla[1]) < 1e-5 * abs(cla[1])
    # classical adds the shear deflection of its m shear springs: F Σ Δ/(κGA) = FL/(κGA)
    shear = F * L / (sec.kappa_y * mat.G * sec.A)
    assert cla[1] - mod[1] == pytest.approx(shear, rel=1e-2)
    assert cla_lin[1] - mod_lin[1] == pytest.approx(shear, rel=1e-6)


def elastica_tip(alpha):
    """Euler's elastica of a cantilever with a dead transverse tip load, PL²/EI = alpha:
    θ'' = −α cos θ on s ∈ [0, 1], θ(0) = 0, θ'(1) = 0; returns (x, y)/L of the tip."""
    def run(k):
        return solve_ivp(lambda s, y: [y[1], -alpha * math.cos(y[0]), math.cos(y[0]), math.sin(y[0])],
                         (0, 1), [0, k, 0, 0], rtol=1e-12, atol=1e-12).y[:, -1]
    k = brentq(lambda k: run(k)[1], 0.0, alpha)
    return run(k)[2:]


def test_large_tip_load_linear_and_nonlinear_differ():
    L, m, alpha = 2.0, 10, 5.0
    mat, sec = steel(), rf.Section.rectangle(**SQ)
    F = alpha * mat.E * sec.Iz / L**2
    nl = tip_under_load(F, L, m, steps=10)
    li = tip_under_load(F, L, m, steps=10, linear=True)
    # the linear model is linear: δ = α L/3 (1 − 1/(4m²)), the tip stays at x = L
    assert li[1] == pytest.approx(alpha * L / 3 * (1 - 1 / (4 * m * m)), rel=1e-8)
    assert li[0] == pytest.approx(L, rel=1e-10)
    # the nonlinear one follows the elastica (x, y) ≈ (0.612, 0.714) L
    ex, ey = elastica_tip(alpha)
    assert nl[0] / L == pytest.approx(ex, rel=1e-2)
    assert nl[1] / L == pytest.approx(ey, rel=1e-2)
    assert nl[0] < 0.7 * L
    assert abs(li[1] - nl[1]) > 0.1 * abs(nl[1])


# ----------------------------------------------------------------------------------------
# 7. Bad input
# ----------------------------------------------------------------------------------------

def _raises(name, fn, *a, **kw):
    with pytest.raises(ValueError, match=rf"^{re.escape(name)}:"):
        fn(*a, **kw)


@pytest.mark.parametrize("length", [0.0, -1.0, float("nan"), float("inf")])
def test_bad_length(length):
    _raises("length", cantilever, length, 3)


@pytest.mark.parametrize("elements", [0, -1, 2.5, True, "3", None])
def test_bad_elements(elements):
    _raises("elements", cantilever, 2.0, elements)


@pytest.mark.parametrize("kw", [
    dict(formulation="other"),
    dict(formulation=None),
])
def test_bad_formulation(kw):
    _raises("formulation", cantilever, 2.0, 3, **kw)


@pytest.mark.parametrize("kw", [
    dict(deform="axial"),                                  # modified: rotations only
    dict(deform=("shear_y",)),
    dict(deform=("bend_z", "shear_z")),
    dict(deform="bend"),                                   # unknown
    dict(formulation="classical", deform=("twist",)),
    dict(deform=("bend_z", "bend_z")),                     # repeated
    dict(formulation="classical", deform=("axial", "bend_y", "axial")),
])
def test_bad_deform(kw):
    _raises("deform", cantilever, 2.0, 3, **kw)


@pytest.mark.parametrize("kw,name", [
    (dict(E=0.0), "E"), (dict(E=-1.0), "E"), (dict(E=float("nan")), "E"),
    (dict(rho=0.0), "rho"), (dict(rho=-7850.0), "rho"),
    (dict(G=0.0), "G"), (dict(G=-1e9), "G"),
    (dict(nu=0.7), "nu"), (dict(nu=-1.0), "nu"),
    (dict(retardation=-1e-3), "retardation"),
])
def test_bad_material(kw, name):
    _raises(name, steel, **kw)


@pytest.mark.parametrize("name", ["A", "Iy", "Iz", "J"])
@pytest.mark.parametrize("value", [0.0, -1e-6, float("nan")])
def test_bad_section(name, value):
    good = dict(A=1e-4, Iy=1e-9, Iz=1e-9, J=2e-9)
    _raises(name, rf.Section, **{**good, name: value})


def test_bad_section_constructors():
    _raises("width", rf.Section.rectangle, 0.0, 0.01)
    _raises("height", rf.Section.rectangle, 0.01, -0.01)
    _raises("d", rf.Section.circle, 0.0)
    _raises("d_in", rf.Section.tube, 0.05, 0.05)
    _raises("d_in", rf.Section.tube, 0.05, 0.06)


def test_section_function_returning_something_else():
    _raises("section", cantilever, 2.0, 3, steel(), lambda s: 1e-4)
    _raises("material", cantilever, 2.0, 3, lambda s: 7850.0, strip())
    _raises("section", cantilever, 2.0, 3, steel(), "rectangle")


def test_bad_tip_mass():
    _raises("tip_mass", cantilever, 2.0, 3, tip_mass=-1.0)


@pytest.mark.parametrize("s", [-1e-3, 2.0 + 1e-3, float("nan")])
def test_point_outside_the_beam(s):
    _, beam = cantilever(2.0, 4)
    _raises("s", beam.point, s)


def test_failed_add_beam_leaves_the_model_unchanged():
    m = rf.Model(gravity=None)
    mat, sec = rf.Material(E=2.1e11, rho=7850.0), rf.Section.rectangle(0.05, 0.01)
    with pytest.raises(ValueError, match=r"^tip_inertia\b"):
        m.add_beam("c", m.ground, 2.0, mat, sec, 4, tip_mass=2.0, tip_inertia=(0.1, 0.2, 0.5))  # 0.1 + 0.2 < 0.5
    assert m.body_names == []
    m.add_beam("c", m.ground, 2.0, mat, sec, 4, tip_mass=2.0)  # a point mass: zero inertia is fine
    with pytest.raises(ValueError, match=r"^name\b"):
        m.add_beam("c", m.ground, 2.0, mat, sec, 4)
    assert len(m.body_names) == 5
