"""Cantilever natural frequencies by modal analysis against the continuum: Euler–Bernoulli
bending (both formulations), torsion, extension, 3D with Iy ≠ Iz, a tapered beam against a
Hermite finite-element reference computed here, and Kelvin–Voigt modal damping."""

import numpy as np
import pytest
from conftest import hermite_cantilever_frequencies

import rigidfem as rf

BETA_L = np.array([1.8751040687, 4.6940911330, 7.8547574382, 10.9955407349, 14.1371683910])
E, RHO, L = 2.1e11, 7850.0, 1.0
# A slender section (radius of gyration 1e-4 L): rotary inertia and shear change the first
# five frequencies by < 1e-5, far below the discretisation error tested here.
SLENDER = rf.Section(A=1e-4, Iy=2e-12, Iz=1e-12, J=3e-12)


def cantilever(m, formulation="modified", deform=("bend_z",), section=SLENDER, material=None, **kw):
    model = rf.Model(gravity=None)
    beam = model.add_beam("beam", model.ground, L, material or rf.Material(E, RHO, nu=0.3), section, m,
                          formulation=formulation, deform=deform, **kw)
    return model.compile(), beam


def euler_bernoulli(I, A=SLENDER.A):
    return BETA_L**2 * np.sqrt(E * I / (RHO * A * L**4))


def family(modes, system, suffix):
    """Frequencies of the modes whose largest shape entry is a coordinate named '*.suffix'."""
    names = np.array(system.coordinate_names)
    dominant = names[np.argmax(np.abs(modes.shapes), axis=0)]
    return modes.omega[np.char.endswith(dominant.astype(str), "." + suffix)]


@pytest.mark.parametrize("formulation,deform", [("modified", ("bend_z",)), ("classical", ("axial", "shear_y", "bend_z"))])
def test_bending_frequencies_converge_at_second_order(formulation, deform):
    # m = 20 -> 40 -> 80: all five modes resolved, each doubling divides the error by 4 (order
    # 2, not more: an error that falls faster is round-off, not convergence). The classical model
    # of this extreme section (rotary inertia ρ I l ~ 1e-13 kg m² beside rfe masses ~ 1e-2 kg,
    # axial springs: ω_max²/ω₁² ≈ 2e11 at m = 80) keeps its mode 1 on the O(m⁻²) line only
    # because modal_analysis takes the low modes from the flexibility form (μ = 1/ω²); the
    # stiffness form K φ = ω² M φ alone is accurate to ε ω_max²/ω₁² ≈ 4e-5 there.
    ms = (10, 20, 40, 80)
    ref = euler_bernoulli(SLENDER.Iz)
    errors = []
    for m in ms:
        system, _ = cantilever(m, formulation, deform)
        w = family(rf.modal_analysis(system), system, "rz")[:5]
        errors.append(np.abs(w / ref - 1))
    errors = np.array(errors)
    assert errors[0, 0] < 3e-3  # first frequency within 0.3 % at m = 10
    order = np.log2(errors[1:-1] / errors[2:])
    assert np.all((order >= 1.9) & (order <= 2.1)), order
    assert np.all(errors[-1] < (5e-4 if formulation == "modified" else 1.5e-3))
    assert errors[-1, 0] < 4e-5  # mode 1 at m = 80: 3.6e-5 (the O(m⁻²) line), both formulations


def check_wave_family(make_system, c):
    """Fixed–free wave equation with speed c: ω_n = (2n − 1) π c/(2L). The RFEM chain is the
    lumped fixed–free chain (m springs, inner masses per Δ, half mass at the free end), whose
    frequencies are exactly ω_n = (2c/Δ) sin((2n − 1) π/(4m))."""
    n = np.arange(1, 6)
    continuum = (2 * n - 1) * np.pi * c / (2 * L)
    errors = []
    for m in (10, 20, 40):
        w = rf.modal_analysis(make_system(m)).omega[:5]
        np.testing.assert_allclose(w, 2 * c * m / L * np.sin((2 * n - 1) * np.pi / (4 * m)), rtol=1e-8)
        errors.append(np.abs(w / continuum - 1))
    errors = np.array(errors)
    assert np.all(np.log2(errors[:-1] / errors[1:]) >= 1.9)
    assert np.all(errors[-1] < 6e-3)


def test_torsional_frequencies():
    # Circle: J = I0, so c = sqrt(GJ/(ρ I0)) = sqrt(G/ρ).
    mat = rf.Material(E, RHO, nu=0.3)
    check_wave_family(
        lambda m: cantilever(m, "modified", ("torsion",), section=rf.Section.circle(0.01), material=mat)[0],
        np.sqrt(mat.G / RHO))


def test_axial_frequencies():
    check_wave_family(lambda m: cantilever(m, "classical", ("axial",))[0], np.sqrt(E / RHO))


@pytest.mark.parametrize("formulation", ["modified", "classical"])
def test_out_of_plane_bending_in_3d_gives_both_families(formulation):
    system, _ = cantilever(40, formulation, None)  # default: every deformation the formulation has
    modes = rf.modal_analysis(system)
    for suffix, I in (("rz", SLENDER.Iz), ("ry", SLENDER.Iy)):
        w = family(modes, system, suffix)[:4]
        np.testing.assert_allclose(w, euler_bernoulli(I)[:4], rtol=1.5e-3)
    assert SLENDER.Iy != SLENDER.Iz


def test_tapered_beam_against_a_converged_reference():
    h = 0.01  # along z
    width = lambda s: 0.03 * (1 - 0.6 * s / L)  # noqa: E731  along y: bend_z stiffness h w³/12 tapers
    ref = hermite_cantilever_frequencies(
        L, EI=lambda x: E * h * width(x) ** 3 / 12, rhoA=lambda x: RHO * h * width(x),
        rhoI=lambda x: RHO * h * width(x) ** 3 / 12,
    )
    errors = []
    for m in (10, 20, 40):
        system, _ = cantilever(m, "modified", ("bend_z",), section=lambda s: rf.Section.rectangle(width(s), h))
        errors.append(np.abs(rf.modal_analysis(system).omega[:3] / ref - 1))
    errors = np.array(errors)
    assert np.all(np.log2(errors[:-1] / errors[1:]) >= 1.8), errors
    assert errors[-1, 0] < 2e-4
    # The taper matters: a uniform beam of the mean width would be off by far more.
    assert abs(euler_bernoulli(h * 0.021**3 / 12, h * 0.021)[0] / ref[0] - 1) > 0.05


def test_kelvin_voigt_damping_gives_modal_ratio_mu_omega_over_two():
    mu = 2e-4  # retardation time, s
    system, _ = cantilever(20, "modified", ("bend_z",), material=rf.Material(E, RHO, nu=0.3, retardation=mu))
    modes = rf.modal_analysis(system)
    undamped = rf.modal_analysis(cantilever(20, "modified", ("bend_z",))[0])
    np.testing.assert_allclose(modes.omega[:6], undamped.omega[:6], rtol=1e-6)
    np.testing.assert_allclose(modes.damping_ratios[:6], mu * undamped.omega[:6] / 2, rtol=1e-5)
    assert np.all(undamped.damping_ratios == 0)
