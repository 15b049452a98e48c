"""Large deflections of a cantilever (book ch. 6) by the modified RFEM in the x–y plane,
against continuum references computed here:

- the elastica under a tip force of fixed direction and under a follower force, each
  solved with scipy.integrate.solve_bvp (tol 1e-10);
- a pure tip moment, which bends the elastica into a circular arc of radius EI/M (and
  the RFEM chain into an exact regular polygon, whose tip follows in closed form);
- the Euler–Bernoulli sag q L⁴/(8 EI) under a small self weight.

With sdes at segment middles and half-length end rfes, deflections converge as O(m⁻²)
(book ch. 3.1): the tip deflection is the midpoint rule applied to the
continuum's ∫ M(s)(L − s)/EI ds, so the errors quarter when m doubles.
"""

import functools

import numpy as np
import pytest
from scipy.integrate import solve_bvp

import rigidfem as rf

L = 2.0                                   # m
B, H = 0.02, 0.01                         # m, rectangular section, bending about z (thin side)
SECTION = rf.Section(A=B * H, Iy=H * B**3 / 12, Iz=B * H**3 / 12, J=0.0001)
MATERIAL = rf.Material(E=7e10, rho=2700.0)
EI = MATERIAL.E * SECTION.Iz              # N·m²
MS = (10, 20, 40)


# --------------------------------------------------------------------------- references

def _bvp(rhs, bc, k, with_parameter):
    """Continue in k from k/10 to k (a good start for the largest loads); s ∈ [0, 1]."""
    s = np.linspace(0.0, 1.0, 21)
    sol = None
    for kk in np.linspace(k / 10, k, 10):
        if sol is None:  # linear cantilever under a tip force
            y0 = np.vstack([kk * (s - s**2 / 2), kk * (1 - s), s, kk * (s**2 / 2 - s**3 / 6)])
            p0 = [kk / 2]
        else:
            s, y0, p0 = sol.x, sol.y, sol.p
        fun = functools.partial(rhs, k=kk)
        sol = solve_bvp(fun, bc, s, y0, p=p0 if with_parameter else None, tol=1e-10, max_nodes=200000)
        assert sol.success, sol.message
    return sol


@functools.lru_cache(maxsize=None)
def elastica_fixed(k):
    """Tip (x/L, y/L, θ) of the elastica under a tip force P = k EI/L² along +y (fixed).

    EI θ' = M(s) = P (x(L) − x(s)), so with s in units of L: θ'' = −k cos θ,
    θ(0) = 0, θ'(1) = 0 (free end), x' = cos θ, y' = sin θ, x(0) = y(0) = 0.
    """
    def rhs(s, y, k):
        return np.vstack([y[1], -k * np.cos(y[0]), np.cos(y[0]), np.sin(y[0])])

    def bc(a, b):
        return np.array([a[0], b[1], a[2], a[3]])

    sol = _bvp(rhs, bc, k, False)
    x1, y1, th1 = sol.y[2, -1], sol.y[3, -1], sol.y[0, -1]
    # First integral θ'² = 2k (sin θ1 − sin θ) at s = 0, where θ'(0) = k x(1): x(1) = √(2 sin θ1 / k).
    assert abs(x1 - np.sqrt(2 * np.sin(th1) / k)) < 1e-8
    return np.array([x1, y1, th1])


@functools.lru_cache(maxsize=None)
def elastica_follower(k):
    """Tip (x/L, y/L, θ1) under a follower force P = k EI/L² perpendicular to the tip tangent.

    The force is P (−sin θ1, cos θ1), θ1 the unknown tip angle (a solve_bvp parameter).
    The moment at s is (r(1) − r(s)) × F: EI θ' = P [(x1 − x) cos θ1 + (y1 − y) sin θ1],
    so θ'' = −k cos(θ − θ1), θ(0) = 0, θ'(1) = 0, θ(1) = θ1, x(0) = y(0) = 0.
    """
    def rhs(s, y, p, k):
        return np.vstack([y[1], -k * np.cos(y[0] - p[0]), np.cos(y[0]), np.sin(y[0])])

    def bc(a, b, p):
        return np.array([a[0], b[1], a[2], a[3], b[0] - p[0]])

    sol = _bvp(rhs, bc, k, True)
    x1, y1, th1 = sol.y[2, -1], sol.y[3, -1], sol.p[0]
    # First integral θ'² = 2k sin(θ1 − θ); at s = 0, θ'(0) = k (x1 cos θ1 + y1 sin θ1) = √(2k sin θ1).
    assert abs(x1 * np.cos(th1) + y1 * np.sin(th1) - np.sqrt(2 * np.sin(th1) / k)) < 1e-8
    return np.array([x1, y1, th1])


# --------------------------------------------------------------------------- RFEM

def cantilever(m, gravity=None, material=MATERIAL, deform=("bend_z",)):
    model = rf.Model(gravity=gravity)
    beam = model.add_beam("b", model.ground, L, material, SECTION, m, deform=deform)
    return model, beam


def tip_rotation(system, beam, q):
    """Angle of the last rfe about z from its transform (checked against Σ q for a planar chain)."""
    T = system.transform(beam.rfes[-1].index, 0.0, q)
    return np.arctan2(T[1, 0], T[0, 0])


@functools.lru_cache(maxsize=None)
def rfem_tip_force(m, k, follower):
    """Tip (x/L, y/L, θ) of the RFEM cantilever under P = k EI/L² along y (global or tip axes)."""
    model, beam = cantilever(m)
    model.add_force("load0", beam.tip, (0.0, k * EI / L**2, 0.0), follower=follower)
    system = model.compile()
    eq = rf.static_equilibrium(system, load_steps=10, tol=1e-12)
    assert eq.converged
    tip = system.position(beam.tip, 0.0, eq.q)
    theta = np.sum(eq.q)
    assert abs(tip_rotation(system, beam, eq.q) - theta) < 1e-12  # θ < π here
    return np.array([tip[0] / L, tip[1] / L, theta])


def errors_and_orders(k, follower):
    ref = elastica_follower(k) if follower else elastica_fixed(k)
    errors = np.array([np.abs(rfem_tip_force(m, k, follower) - ref) for m in MS])  # (m, [x, y, θ])
    orders = np.log2(errors[:-1] / errors[1:])
    return errors, orders


# --------------------------------------------------------------------------- 1. elastica, fixed force

@pytest.mark.parametrize("k", [0.5, 2.0, 5.0, 10.0])
def test_elastica_tip_force_converges_as_m_squared(k):
    errors, orders = errors_and_orders(k, follower=False)
    # Measured orders 2.00–2.04 for x, y and θ (m = 10, 20, 40).
    assert np.all(orders >= 1.8), (errors, orders)
    # At m = 40 the largest errors (k = 10): |Δx| 5.5e-5 L, |Δy| 2.5e-4 L, |Δθ| 8.4e-5 rad.
    assert np.all(errors[-1, :2] < 3e-4), errors
    assert errors[-1, 2] < 1e-4, errors
    if k == 0.5:  # near-linear: Δy/y → 1/(4m²), the midpoint rule's error on ∫ P (L − s)² ds / EI
        y_ref = elastica_fixed(k)[1]
        assert errors[:, 1] / y_ref * np.array(MS) ** 2 == pytest.approx(0.25, rel=0.05)


def test_elastica_reference_matches_bisshopp_drucker():
    """The k = 10 reference against the classical table (Bisshopp & Drucker 1945):
    vertical tip deflection 0.8106 L, horizontal 0.5550 L, tip angle 81.95°."""
    x1, y1, th1 = elastica_fixed(10.0)
    assert y1 == pytest.approx(0.8106, abs=1e-4)
    assert 1 - x1 == pytest.approx(0.5550, abs=1e-4)
    assert np.degrees(th1) == pytest.approx(81.95, abs=0.01)


# --------------------------------------------------------------------------- 2. pure moment

@pytest.mark.parametrize("m", MS)
def test_tip_moment_two_pi_rolls_a_full_circle(m):
    model, beam = cantilever(m)
    model.add_torque("load0", beam.rfes[-1], (0.0, 0.0, 2 * np.pi * EI / L))
    system = model.compile()
    eq = rf.static_equilibrium(system, load_steps=8, tol=1e-12)
    # Each sde turns by M Δ/EI = 2π/m: the sdes are the vertices of a closed regular m-gon and the
    # half-length end rfes meet at the root: closure is exact, not only O(m⁻²).
    tip = system.position(beam.tip, 0.0, eq.q)
    assert np.linalg.norm(tip) < 1e-9 * L
    assert np.sum(eq.q) == pytest.approx(2 * np.pi, abs=1e-10)
    np.testing.assert_allclose(eq.q, 2 * np.pi / m, atol=1e-10)
    T = system.transform(beam.rfes[-1].index, 0.0, eq.q)
    np.testing.assert_allclose(T[:3, :3], np.eye(3), atol=1e-10)  # tangent back along +x
    # The sde points are the vertices of a regular m-gon of side Δ whose edge midpoint is the root:
    # centre (0, (Δ/2) cot(π/m)), circumradius (Δ/2)/sin(π/m) → the continuum's EI/M = L/2π as O(m⁻²).
    d = L / m
    line = beam.centerline(system, eq.q)
    radii = np.linalg.norm(line[1:-1] - [0.0, 0.5 * d / np.tan(np.pi / m), 0.0], axis=1)
    np.testing.assert_allclose(radii, 0.5 * d / np.sin(np.pi / m), rtol=1e-10)
    assert abs(radii[0] / (L / (2 * np.pi)) - 1) < 1.7 / m**2  # (π/m)/sin(π/m) − 1 ≈ π²/(6m²)


def test_tip_moment_pi_bends_a_half_circle():
    errors = []
    for m in MS:
        model, beam = cantilever(m)
        model.add_torque("load0", beam.rfes[-1], (0.0, 0.0, np.pi * EI / L))
        system = model.compile()
        eq = rf.static_equilibrium(system, load_steps=4, tol=1e-12)
        tip = system.position(beam.tip, 0.0, eq.q) / L
        assert np.sum(eq.q) == pytest.approx(np.pi, abs=1e-10)
        assert abs(tip[0]) < 1e-12 and tip[2] == 0.0
        # The polygon: y = Δ Σ_{j=1}^{m-1} sin(jπ/m) = (1/m) cot(π/2m) → 2/π as O(m⁻²).
        assert tip[1] == pytest.approx(1.0 / (m * np.tan(np.pi / (2 * m))), abs=1e-12)
        errors.append(abs(tip[1] - 2 / np.pi))
    errors = np.array(errors)  # measured 5.24e-3, 1.31e-3, 3.27e-4 (L)
    orders = np.log2(errors[:-1] / errors[1:])
    assert np.all(orders >= 1.8), (errors, orders)
    assert errors[-1] < 5e-4


# --------------------------------------------------------------------------- 3. follower force

@pytest.mark.parametrize("k", [2.0, 5.0])
def test_follower_tip_force_converges_as_m_squared(k):
    errors, orders = errors_and_orders(k, follower=True)
    # Measured orders 1.997–2.011; at m = 40 (k = 5): |Δx| 1.9e-4 L, |Δy| 1.7e-4 L, |Δθ| 3.1e-4 rad.
    assert np.all(orders >= 1.8), (errors, orders)
    assert np.all(errors[-1, :2] < 3e-4), errors
    assert errors[-1, 2] < 4e-4, errors
    # The follower force bends the beam further than the fixed one (its lever arm does not shrink).
    assert elastica_follower(k)[2] > elastica_fixed(k)[2]


# --------------------------------------------------------------------------- 4. gravity sag

G = 9.81
SAG = 1e-4  # target tip deflection / L: keeps the nonlinear (O(SAG²)) terms far below the O(m⁻²) error


@pytest.mark.parametrize("plane", ["xy", "xz"])
def test_gravity_sag_matches_euler_bernoulli(plane):
    if plane == "xy":
        gravity, deform, I, axis = (0.0, -G, 0.0), ("bend_z",), SECTION.Iz, 1
    else:
        gravity, deform, I, axis = (0.0, 0.0, -G), ("bend_y",), SECTION.Iy, 2
    EIp = MATERIAL.E * I
    rho = SAG * 8 * EIp / (SECTION.A * G * L**3)  # q L⁴ / (8 EI) = SAG L
    material = rf.Material(E=MATERIAL.E, rho=rho)
    exact = rho * SECTION.A * G * L**4 / (8 * EIp)
    rel = []
    for m in MS:
        model, beam = cantilever(m, gravity=gravity, material=material, deform=deform)
        system = model.compile()
        eq = rf.static_equilibrium(system, load_steps=1, tol=1e-14)
        tip = system.position(beam.tip, 0.0, eq.q)
        rel.append((-tip[axis] - exact) / exact)
    rel = np.array(rel)
    # Measured −5.0e-3, −1.25e-3, −3.1e-4: exactly −1/(2m²), the midpoint rule's error on
    # ∫ q (L − s)³ / (2 EI) ds (RFEM is slightly stiff). So at m = 20 it is 1.25e-3, not below 1e-3.
    np.testing.assert_allclose(rel * np.array(MS) ** 2, -0.5, rtol=1e-3)
    orders = np.log2(rel[:-1] / rel[1:])
    assert np.all(orders >= 1.8), (rel, orders)
    assert abs(rel[1]) < 1.3e-3
    assert abs(rel[2]) < 1e-3


# --------------------------------------------------------------------------- 5. solver report

def test_static_equilibrium_reports_convergence():
    model, beam = cantilever(20)
    P = 10.0 * EI / L**2
    model.add_force("load0", beam.tip, (0.0, P, 0.0))
    system = model.compile()
    eq = rf.static_equilibrium(system, load_steps=10, tol=1e-12)
    assert eq.converged is True
    assert eq.load_steps == 10 and len(eq.history) == 10
    assert eq.iterations == sum(h[1] for h in eq.history) >= 10
    assert [h[0] for h in eq.history] == pytest.approx(np.arange(1, 11) / 10)
    assert eq.residual < 1e-10 * P * L  # N·m
    assert eq.residual == pytest.approx(np.max(np.abs(system.static_forces(0.0, eq.q, 1.0))), abs=1e-12 * P * L)


def test_static_equilibrium_too_few_iterations_raises():
    model, beam = cantilever(20)
    model.add_force("load0", beam.tip, (0.0, 10.0 * EI / L**2, 0.0))
    system = model.compile()
    with pytest.raises(rf.SimulationError) as err:
        rf.static_equilibrium(system, load_steps=1, max_iterations=2)
    msg = str(err.value)
    assert "at t =" in msg
    assert "did not converge" in msg and "2 iterations" in msg and "load factor" in msg
