"""Statics and modal analysis of closed chains (f + Gᵀλ = 0, g = 0; modes in the null space of G).

References computed here, never read off the code: the four-bar's closed-form position analysis
(SymPy: law of cosines) with its potential energy minimised and its kinetic energy
T = ½ m_eff(θ) θ̇² differentiated, so ω² = V''(θ*)/m_eff(θ*); a pendulum's moment balance and
ω² = V''/I_O; a boom held by an actuator (moment balance for the cylinder force); and the same
pendulum built as a tree and closed by loops (with redundant rows), both engines.
"""

import functools

import numpy as np
import pytest
import sympy as sp
from scipy.optimize import brentq

import rigidfem as rf

A, B, C, D = 0.3, 0.8, 0.6, 0.7  # crank, coupler, rocker, ground link (m)
G0 = 9.81
K_CRANK, REST = 15.0, 1.2  # torsional spring on the crank (N·m/rad) and its rest angle (rad)
ENGINES = ["recursive", "lagrange"]


def rod(L, m=1.0):
    """A slender rod along x: mass m (kg), centre at L/2, I_zz = m L²/12 about its centre."""
    return dict(mass=m, inertia=(1e-4, m * L * L / 12, m * L * L / 12), com=(L / 2, 0, 0))


def wrap(angle):
    return np.angle(np.exp(1j * np.asarray(angle)))


def four_bar(algorithm="recursive", spring=True, gravity=True, damping=0.0):
    """Planar four-bar in the x–y plane, gravity −y, closed by a revolute loop at the coupler tip
    (3 of its 5 rows redundant in the plane). q = (crank, coupler relative to crank, rocker);
    a torsional spring (and damper, N·m·s/rad) on the crank."""
    m = rf.Model(gravity=(0, -G0, 0) if gravity else None)
    joint = (rf.Joint.revolute("z", stiffness=K_CRANK, rest=REST, damping=damping) if spring
             else rf.Joint.revolute("z"))
    crank = m.add_body("crank", m.ground, joint, **rod(A))
    coupler = m.add_body("coupler", crank, rf.Joint.revolute("z"), **rod(B), placement=rf.transform((A, 0, 0)))
    rocker = m.add_body("rocker", m.ground, rf.Joint.revolute("z"), **rod(C), placement=rf.transform((D, 0, 0)))
    m.add_loop_joint("C", "revolute", coupler.point((B, 0, 0)), rocker.point((C, 0, 0)))
    return m.compile(algorithm)


@functools.lru_cache(maxsize=None)
def four_bar_reference():
    """(θ*, V''(θ*), m_eff(θ*), dθ2/dθ, dθ3/dθ, closed-form angles) from the closed form in SymPy."""
    th = sp.symbols("theta")
    ex, ey = A * sp.cos(th) - D, A * sp.sin(th)
    e = sp.sqrt(ex**2 + ey**2)
    t3 = sp.atan2(ey, ex) + sp.acos((e**2 + C**2 - B**2) / (2 * e * C))  # rocker, absolute
    px, py = D + C * sp.cos(t3), C * sp.sin(t3)
    t2 = sp.atan2(py - A * sp.sin(th), px - A * sp.cos(th))  # coupler, absolute
    bodies = [  # centre x, y, absolute angle, length (all 1 kg)
        (A / 2 * sp.cos(th), A / 2 * sp.sin(th), th, A),
        (A * sp.cos(th) + B / 2 * sp.cos(t2), A * sp.sin(th) + B / 2 * sp.sin(t2), t2, B),
        (D + C / 2 * sp.cos(t3), C / 2 * sp.sin(t3), t3, C),
    ]
    V = K_CRANK / 2 * (th - REST) ** 2 + sum(G0 * y for _, y, _, _ in bodies)
    m_eff = sum(sp.diff(x, th) ** 2 + sp.diff(y, th) ** 2 + L * L / 12 * sp.diff(phi, th) ** 2
                for x, y, phi, L in bodies)
    dV, d2V = sp.lambdify(th, sp.diff(V, th)), sp.lambdify(th, sp.diff(V, th, 2))
    grid = np.linspace(-np.pi, np.pi, 361)
    slope = np.array([dV(x) for x in grid])
    minima = [brentq(dV, a, b, xtol=1e-15, rtol=1e-15) for a, b, sa, sb in
              zip(grid[:-1], grid[1:], slope[:-1], slope[1:]) if sa < 0 < sb]
    assert len(minima) == 1  # one stable equilibrium on this branch
    x = minima[0]
    angles = sp.lambdify(th, [t2, t3])
    rates = sp.lambdify(th, [sp.diff(t2, th), sp.diff(t3, th)])
    return x, float(d2V(x)), float(sp.lambdify(th, m_eff)(x)), [float(r) for r in rates(x)], angles


def closed_q(theta):
    t2, t3 = four_bar_reference()[4](theta)
    return np.array([theta, t2 - theta, t3])


# --------------------------------------------------------------------------- the four-bar

@pytest.mark.parametrize("algorithm", ENGINES)
def test_four_bar_statics_and_frequency_against_the_closed_form(algorithm):
    """Equilibrium angle from minimising the closed-form potential, ω² = V''/m_eff, the mode shape
    from the closed-form velocity ratios, and λ as the dynamics' multipliers at rest."""
    theta, V2, m_eff, (r2, r3), _ = four_bar_reference()
    s = four_bar(algorithm)
    assert (s.nq, s.nl) == (3, 5)
    eq = rf.static_equilibrium(s, q0=closed_q(0.4) + 0.05)  # off the loop: closed first, then Newton
    assert eq.converged and eq.constraint_residual < 1e-12 and eq.residual < 1e-10
    np.testing.assert_allclose(wrap(eq.q - closed_q(theta)), 0.0, atol=1e-10)
    assert eq.multipliers.shape == (5,)
    np.testing.assert_allclose(eq.multipliers, s.loop_multipliers(0.0, eq.q, np.zeros(3)), atol=1e-8)

    modes = rf.modal_analysis(s, q=eq.q)
    assert modes.omega.shape == (1,) and modes.shapes.shape == (3, 1) and modes.basis.shape == (3, 1)
    np.testing.assert_allclose(modes.omega[0] ** 2, V2 / m_eff, rtol=1e-6)
    shape = np.array([1.0, r2 - 1.0, r3])  # δq per δθ of the crank
    shape /= shape[np.argmax(np.abs(shape))]
    phi = modes.shapes[:, 0] * np.sign(modes.shapes[:, 0] @ shape)
    np.testing.assert_allclose(phi, shape, atol=1e-9)
    G = s.loop_constraints(0.0, eq.q, np.zeros(3))[2]
    assert np.abs(G @ modes.shapes).max() < 1e-12
    assert modes.stable and modes.damping_ratios[0] == 0.0


@pytest.mark.parametrize("algorithm", ENGINES)
def test_four_bar_damping_ratio_from_the_effective_inertia(algorithm):
    """A damper c on the crank: m_eff θ̈ + c θ̇ + V'' θ = 0, ζ = c / (2 √(V'' m_eff)), and the root
    −ζω + iω√(1 − ζ²)."""
    theta, V2, m_eff, _, _ = four_bar_reference()
    c = 0.3
    s = four_bar(algorithm, damping=c)
    eq = rf.static_equilibrium(s, q0=closed_q(theta + 0.2))
    modes = rf.modal_analysis(s, q=eq.q)
    w, zeta = np.sqrt(V2 / m_eff), c / (2 * np.sqrt(V2 * m_eff))
    np.testing.assert_allclose(modes.omega, [w], rtol=1e-6)
    np.testing.assert_allclose(modes.damping_ratios, [zeta], rtol=1e-6)
    np.testing.assert_allclose(modes.eigenvalues, [w * (-zeta + 1j * np.sqrt(1 - zeta**2))], rtol=1e-6)


# --------------------------------------------------------------------------- redundant loops

L_PAR, W_PAR, M_COUPLER, K_PAR, REST_PAR = 0.5, 1.0, 2.0, 30.0, 0.9


def parallelogram(algorithm):
    """Three parallel rockers (1 kg, 0.5 m, pins 1 m apart on the ground) under one coupler (2 kg,
    2 m) on the first's tip and closed onto the other two by revolute loops: in the plane 4 rows
    for 4 coordinates, yet one degree of freedom (the rows are dependent at every configuration:
    the classical overconstrained parallelogram). A spring on the first rocker."""
    m = rf.Model(gravity=(0, -G0, 0))
    r = [m.add_body(f"r{i}", m.ground, rf.Joint.revolute("z", stiffness=K_PAR if i == 0 else 0.0, rest=REST_PAR),
                    **rod(L_PAR), placement=rf.transform((i * W_PAR, 0, 0))) for i in range(3)]
    c = m.add_body("coupler", r[0], rf.Joint.revolute("z"), **rod(2 * W_PAR, M_COUPLER),
                   placement=rf.transform((L_PAR, 0, 0)))
    m.add_loop_joint("middle", "revolute", c.point((W_PAR, 0, 0)), r[1].point((L_PAR, 0, 0)))
    m.add_loop_joint("end", "revolute", c.point((2 * W_PAR, 0, 0)), r[2].point((L_PAR, 0, 0)))
    return m.compile(algorithm)


@pytest.mark.parametrize("algorithm", ENGINES)
def test_overconstrained_parallelogram_against_its_energy(algorithm):
    """All rockers at θ, the coupler translating (its relative angle −θ): V = k(θ − θ0)²/2 +
    g sin θ (3 m L/2 + m_c L), T = ½ (3 m L²/3 + m_c L²) θ̇²; rank G = 3 of 10 rows, one mode."""
    a = G0 * (3 * L_PAR / 2 + M_COUPLER * L_PAR)
    theta = brentq(lambda x: K_PAR * (x - REST_PAR) + a * np.cos(x), -1.0, 2.0, xtol=1e-15, rtol=1e-15)
    w2 = (K_PAR - a * np.sin(theta)) / (L_PAR**2 + M_COUPLER * L_PAR**2)
    s = parallelogram(algorithm)
    assert (s.nq, s.nl) == (4, 10)
    eq = rf.static_equilibrium(s, q0=[0.5, 0.52, 0.48, -0.5], load_steps=2)
    np.testing.assert_allclose(eq.q, [theta, theta, theta, -theta], atol=1e-12)
    # The split of the load between the dependent rows is the least-norm one, as in the dynamics.
    np.testing.assert_allclose(eq.multipliers, s.loop_multipliers(0.0, eq.q, np.zeros(4)), atol=1e-8)
    modes = rf.modal_analysis(s, q=eq.q)
    assert modes.omega.shape == (1,)
    np.testing.assert_allclose(modes.omega ** 2, [w2], rtol=1e-6)
    np.testing.assert_allclose(modes.shapes[:, 0] * np.sign(modes.shapes[0, 0]), [1, 1, 1, -1], atol=1e-9)


def test_four_bar_engines_agree():
    eqs = [rf.static_equilibrium(four_bar(a), q0=closed_q(1.5)) for a in ENGINES]
    np.testing.assert_allclose(eqs[0].q, eqs[1].q, atol=1e-12)
    np.testing.assert_allclose(eqs[0].multipliers, eqs[1].multipliers, rtol=1e-9, atol=1e-9)
    w = [rf.modal_analysis(four_bar(a), q=e.q).omega for a, e in zip(ENGINES, eqs)]
    np.testing.assert_allclose(w[0], w[1], rtol=1e-8)


# --------------------------------------------------------------------------- tree against loops

M_ROD, L_ROD, F_TIP = 2.0, 1.0, 5.0


def pendulum(joint, algorithm, loop):
    """A rod (2 kg, 1 m) about z under gravity −y and a horizontal tip force F (N, +x); as a tree
    (``loop`` False), or on ``joint`` closed to the ground by a revolute loop."""
    mod = rf.Model(gravity=(0, -G0, 0))
    body = mod.add_body("rod", mod.ground, joint, **rod(L_ROD, M_ROD))
    mod.add_force("load0", body.point((L_ROD, 0, 0)), (F_TIP, 0.0, 0.0))
    if loop:
        mod.add_loop_joint("pin", "revolute", mod.ground, body)
    return mod.compile(algorithm)


@pytest.mark.parametrize("algorithm", ENGINES)
def test_pendulum_closed_by_a_loop_has_the_tree_statics_and_frequency(algorithm):
    """Equilibrium tan θ = −m g / (2F), ω² = V''/I_O = L √(F² + (mg/2)²) / (m L²/3); the tree, the
    free body closed by a revolute loop (5 rows, rank 5), the planar body closed by one (5 rows,
    rank 2) and the tree's own pin duplicated by one (5 rows, all zero) agree with it and with each
    other; the loop carries the pin's reaction −(weight + F) (moment balance: no torque), unless the
    tree's pin carries it."""
    theta = np.arctan2(-M_ROD * G0 / 2, F_TIP)
    w2 = L_ROD * np.hypot(F_TIP, M_ROD * G0 / 2) / (M_ROD * L_ROD**2 / 3)
    tree = pendulum(rf.Joint.revolute("z"), algorithm, loop=False)
    eq = rf.static_equilibrium(tree, q0=[-0.8])
    np.testing.assert_allclose(eq.q, [theta], atol=1e-12)
    np.testing.assert_allclose(rf.modal_analysis(tree, q=eq.q).omega ** 2, [w2], rtol=1e-9)
    for joint, nq, rank in ((rf.Joint.free(), 6, 5), (rf.Joint.planar("xy"), 3, 2), (rf.Joint.revolute("z"), 1, 0)):
        s = pendulum(joint, algorithm, loop=True)
        assert (s.nq, s.nl) == (nq, 5)
        guess = np.full(nq, 0.05)  # off the loop: closed first
        guess[s.coordinate_index("rod.rz")] = -0.8
        eq = rf.static_equilibrium(s, q0=guess, load_steps=3)
        i = s.coordinate_index("rod.rz")
        np.testing.assert_allclose(wrap(eq.q[i] - theta), 0.0, atol=1e-11)
        np.testing.assert_allclose(np.delete(eq.q, i), 0.0, atol=1e-11)
        np.testing.assert_allclose(eq.multipliers, s.loop_multipliers(0.0, eq.q, np.zeros(nq)), atol=1e-8)
        W = s.loop_reactions(0.0, eq.q, np.zeros(nq))[0]  # on the rod, ground axes
        np.testing.assert_allclose(W, [-F_TIP, M_ROD * G0, 0, 0, 0, 0] if rank else np.zeros(6), atol=1e-8)
        modes = rf.modal_analysis(s, q=eq.q)
        assert modes.omega.shape == (nq - rank,)
        np.testing.assert_allclose(modes.omega ** 2, [w2], rtol=1e-7)
        np.testing.assert_allclose(np.abs(modes.shapes[:, 0]), np.eye(nq)[i], atol=1e-9)


@pytest.mark.parametrize("algorithm", ENGINES)
@pytest.mark.parametrize("driven", [False, True])
def test_boom_held_by_an_actuator_is_a_structure_without_modes(algorithm, driven):
    """A 5 kg, 2 m boom on a pin, held by a cylinder of length l = 0.9 m (or l(t) = 0.6 + 0.6 t at
    t = 0.5 s) from (0.5, 0) to the boom's point at 1 m: θ from the law of cosines and the cylinder
    force from the moment balance about the pin, F = m g cos θ l / (0.5 sin θ) (pushing); nothing
    left to vibrate."""
    m_, l = 5.0, 0.9
    mod = rf.Model(gravity=(0, -G0, 0))
    boom = mod.add_body("boom", mod.ground, rf.Joint.revolute("z"), **rod(2.0, m_))
    length, t = (rf.motion.polynomial([0.6, 0.6]), 0.5) if driven else (l, 0.0)
    mod.add_actuator("cylinder", mod.ground.point((0.5, 0, 0)), boom.point((1.0, 0, 0)), length)
    s = mod.compile(algorithm)
    theta = np.arccos(1.25 - l * l)
    eq = rf.static_equilibrium(s, q0=[1.0], t=t)
    np.testing.assert_allclose(eq.q, [theta], atol=1e-12)
    force = m_ * G0 * np.cos(theta) * l / (0.5 * np.sin(theta))
    np.testing.assert_allclose(eq.multipliers, [force], rtol=1e-9)  # λ of a distance row: the push
    if not driven:  # the dynamics' reaction at rest (with l̇ ≠ 0 the boom would be moving)
        np.testing.assert_allclose(s.loop_reactions(t, eq.q, [0.0])[0, 0], force, rtol=1e-9)
    if driven:  # the loop moves: q̇ = 0 does not follow it
        with pytest.raises(ValueError, match=r"^qd: expected rates that close every loop of \['cylinder'\]"):
            rf.modal_analysis(s, q=eq.q, t=t)
    modes = rf.modal_analysis(s, q=eq.q, qd=s.assemble(eq.q, None, t=t)[1], t=t)
    assert modes.omega.shape == (0,) and modes.shapes.shape == (1, 0) and modes.stable


# --------------------------------------------------------------------------- errors

def test_a_loop_that_cannot_be_closed_is_a_simulation_error_naming_it():
    mod = rf.Model()
    a = mod.add_body("a", mod.ground, rf.Joint.revolute("z"), **rod(1.0))
    mod.add_loop_joint("rope", "distance", mod.ground.point((0.0, 3.0, 0.0)), a.point((1, 0, 0)), length=0.5)
    with pytest.raises(rf.SimulationError, match=r"loop 'rope' \(distance, residual.*static_equilibrium"):
        rf.static_equilibrium(mod.compile(), q0=[0.0])


@pytest.mark.parametrize("algorithm", ENGINES)
def test_statics_that_cannot_converge_or_a_loose_mechanism_are_simulation_errors(algorithm):
    with pytest.raises(rf.SimulationError, match=r"^at t = 0(\.0)? s: statics: Newton did not converge in 1 iterations "
                                                  r"at load factor 0\.5 .*in loop 'C'"):
        rf.static_equilibrium(four_bar(algorithm), q0=closed_q(0.4), load_steps=2, max_iterations=1)
    # Neither spring nor gravity: the one motion the loop allows is free.
    term = r"[\d.·]*"
    with pytest.raises(rf.SimulationError, match=r"singular to working precision within the motions the loops allow: "
                       rf"nothing resists \(−?{term}crank\.rz [+−] {term}coupler\.rz [+−] {term}rocker\.rz\)"):
        rf.static_equilibrium(four_bar(algorithm, spring=False, gravity=False), q0=closed_q(0.4))


def test_modes_about_coordinates_off_the_loop_are_value_errors():
    s = four_bar()
    with pytest.raises(ValueError, match=r"^q: expected coordinates that close every loop of \['C'\] .*in loop 'C'"):
        rf.modal_analysis(s, q=closed_q(0.4) + 0.01)
    with pytest.raises(ValueError, match=r"^qd: expected rates that close every loop"):
        rf.modal_analysis(s, q=closed_q(0.4), qd=[1.0, 0.0, 0.0])
