"""Shared helpers: integrate a compiled system with SciPy (the reference integrator here)."""

import os

# One BLAS thread, set before NumPy loads OpenBLAS: the suite's matrices are small (and on 2 cores a threaded
# eigh measured 3-7 times slower). The exit hang once seen after tests/test_interrupt.py (gotoblas_quit joining a
# server thread) was a LAPACK call still in flight in a worker a Ctrl-C had left: rigidfem.base._interrupt now waits
# for such workers at exit.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402
import pytest
import scipy.linalg
from scipy.integrate import solve_ivp


def integrate(system, t_end, q0, qd0, *, rtol=1e-12, atol=1e-12, t_eval=None, events=None, method="DOP853"):
    """solve_ivp of system.rhs from (q0, qd0); returns the OdeResult (dense output on)."""
    y0 = np.concatenate([np.asarray(q0, float), np.asarray(qd0, float)])
    sol = solve_ivp(
        system.rhs, (0.0, t_end), y0, method=method, rtol=rtol, atol=atol, t_eval=t_eval, events=events,
        dense_output=True,
    )
    assert sol.success, sol.message
    return sol


DOUBLE_PENDULUM_Y0 = np.array([1.0, 0.5, 0.0, 0.0])


@pytest.fixture(scope="module")
def pendulum2():
    """Planar double pendulum released from (1, 0.5) rad; reference by SciPy's DOP853 at 1e-13."""
    import rigidfem as rf

    model, _ = rf.samples.double_pendulum()
    system = model.compile()
    y0 = DOUBLE_PENDULUM_Y0
    return system, integrate(system, 1.0, y0[:2], y0[2:], rtol=1e-13, atol=1e-13)


@pytest.fixture
def rng():
    return np.random.default_rng(20261121)


def hermite_cantilever_frequencies(L, EI, rhoA, rhoI, tension=None, softening=0.0, n_el=200, n=3):
    """Reference frequencies (rad/s) of a cantilever clamped at x = 0: Euler–Bernoulli with
    rotary inertia (Rayleigh) by cubic Hermite elements, 6-point Gauss quadrature of the
    varying properties EI(x), ρA(x), ρI(x). Optional axial ``tension(x)`` (geometric
    stiffness ∫ T v'²) and a lateral ``softening`` −s ∫ ρA v² (in-plane rotation: s = Ω²)."""
    xg, wg = np.polynomial.legendre.leggauss(6)
    h = L / n_el
    K = np.zeros((2 * n_el + 2,) * 2)
    M = np.zeros_like(K)
    for e in range(n_el):
        Ke = np.zeros((4, 4))
        Me = np.zeros((4, 4))
        for xi, w in zip(xg, wg):
            t = 0.5 * (xi + 1)
            x = (e + t) * h
            N = np.array([1 - 3 * t**2 + 2 * t**3, h * (t - 2 * t**2 + t**3), 3 * t**2 - 2 * t**3, h * (t**3 - t**2)])
            dN = np.array([-6 * t + 6 * t**2, h * (1 - 4 * t + 3 * t**2), 6 * t - 6 * t**2, h * (3 * t**2 - 2 * t)]) / h
            d2N = np.array([-6 + 12 * t, h * (-4 + 6 * t), 6 - 12 * t, h * (6 * t - 2)]) / h**2
            Ke += 0.5 * h * w * (EI(x) * np.outer(d2N, d2N) - softening * rhoA(x) * np.outer(N, N))
            if tension is not None:
                Ke += 0.5 * h * w * tension(x) * np.outer(dN, dN)
            Me += 0.5 * h * w * (rhoA(x) * np.outer(N, N) + rhoI(x) * np.outer(dN, dN))
        K[2 * e:2 * e + 4, 2 * e:2 * e + 4] += Ke
        M[2 * e:2 * e + 4, 2 * e:2 * e + 4] += Me
    w2 = scipy.linalg.eigh(K[2:, 2:], M[2:, 2:], eigvals_only=True)[:n]  # clamped at x = 0
    return np.sqrt(w2)


def pytest_collection_modifyitems(config, items):
    """Tests marked slow (long studies) run only when the marker expression names them (-m slow)."""
    if "slow" in (config.getoption("markexpr") or ""):
        return
    skip = pytest.mark.skip(reason="long study: select with -m slow")
    for item in items:
        if "slow" in item.keywords:
            item.add_marker(skip)


def central_jacobians(s, t, q, qd, h=1e-6):
    """(∂f/∂q, ∂f/∂q̇) of a system's generalized_forces at (t, q, q̇) by central differences."""
    n = len(q)
    Kq, Kqd = np.zeros((n, n)), np.zeros((n, n))
    for j in range(n):
        e = np.zeros(n)
        e[j] = h
        Kq[:, j] = (s.generalized_forces(t, q + e, qd) - s.generalized_forces(t, q - e, qd)) / (2 * h)
        Kqd[:, j] = (s.generalized_forces(t, q, qd + e) - s.generalized_forces(t, q, qd - e)) / (2 * h)
    return Kq, Kqd


def step_of(method: str, dt: float) -> dict:
    """The keyword for a step dt: dt for a fixed-step method, first_step for an adaptive one (a dt would set
    its first step with a UserWarning)."""
    import rigidfem as rf

    return {"first_step": dt} if rf.methods()[method].adaptive else {"dt": dt}


# ----------------------------------------------------------------- loops that a parameter moves


def luffed_boom():
    """A boom (revolute, sprung and damped) luffed by a cylinder "cylinder" from (0.5, 0) on the ground to the
    boom's point at 1 m, of length l(t) = c₀ + c₁ t (c = 0.9 m, 0.3 m/s): θ = arccos(1.25 − l²) by the law of
    cosines, whatever the boom's mass or spring. Returns (system, boom, q0, q̇0)."""
    import rigidfem as rf
    m = rf.Model(gravity=(0.0, -9.81, 0.0))
    boom = m.add_body("boom", m.ground, rf.Joint.revolute("z", stiffness=3.0, damping=0.5), 5.0,
                      (1e-4, 5.0 * 4 / 12, 5.0 * 4 / 12), com=(1.0, 0.0, 0.0))
    m.add_actuator("cylinder", m.ground.point((0.5, 0, 0)), boom.point((1.0, 0, 0)), rf.motion.polynomial([0.9, 0.3]))
    s = m.compile()
    q0, qd0 = s.assemble([np.arccos(1.25 - 0.81)], [0.0])
    return s, boom, q0, qd0


def boom_angle_derivative(t, c0=0.9, c1=0.3):
    """∂θ/∂c₀ of the luffed boom's θ = arccos(1.25 − l²), l = c₀ + c₁ t (∂θ/∂c₁ = t ∂θ/∂c₀)."""
    l = c0 + c1 * t
    return 2 * l / np.sqrt(1 - (1.25 - l * l) ** 2)


def slider_four_bar(profile):
    """A four-bar (crank sprung and damped, coupler, rocker: rods of 1 kg) whose rocker pivot rides on a slider
    "slider" driven along x by `profile`: the drive moves the loop C's g(q, t). Returns (system, coupler)."""
    import rigidfem as rf

    def rod(length):
        return dict(mass=1.0, inertia=(1e-4, length**2 / 12, length**2 / 12), com=(length / 2, 0, 0))
    m = rf.Model(gravity=(0.0, -9.81, 0.0))
    crank = m.add_body("crank", m.ground, rf.Joint.revolute("z", stiffness=5.0, damping=0.1), **rod(0.3))
    coupler = m.add_body("coupler", crank, rf.Joint.revolute("z"), **rod(0.8), placement=rf.transform((0.3, 0, 0)))
    slider = m.add_body("slider", m.ground, rf.Joint.prismatic("x"), 0.5, (0.01, 0.01, 0.01),
                        placement=rf.transform((0.7, 0, 0)))
    m.prescribe(slider, profile)
    rocker = m.add_body("rocker", slider, rf.Joint.revolute("z"), **rod(0.6))
    m.add_loop_joint("C", "revolute", coupler.point((0.8, 0, 0)), rocker.point((0.6, 0, 0)))
    return m.compile(), coupler
