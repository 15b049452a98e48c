"""Rotation matrices, homogeneous transforms and joint transforms (book ch. 2.1).

Every reference is built here with numpy from the book's definitions.
"""

import itertools
import math

import mpmath
import numpy as np
import pytest

import rigidfem as rf

RNG = np.random.default_rng(20240601)
ANGLES = RNG.uniform(-np.pi, np.pi, size=(6, 3))
BOOK_ORDER = ("x", "y", "z", "rz", "ry", "rx")


# --- references written out from the book's definitions -----------------------------------


def rx(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def ry(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rz(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def hom(R=np.eye(3), r=(0.0, 0.0, 0.0)):
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = r
    return T


def reference_joint(coordinates, q):
    """Trans(x, y, z) R3(rz) R2(ry) R1(rx), the inactive coordinates zero; q in book order."""
    active = [c for c in BOOK_ORDER if c in coordinates]
    v = dict.fromkeys(BOOK_ORDER, 0.0)
    v.update(zip(active, q))
    return hom(r=(v["x"], v["y"], v["z"])) @ hom(rz(v["rz"])) @ hom(ry(v["ry"])) @ hom(rx(v["rx"]))


# --- elementary rotations and Euler angles -------------------------------------------------


@pytest.mark.parametrize("phi", [0.0, 0.3, -1.2, 2.9, np.pi])
def test_elementary_rotations_match_book_matrices(phi):
    np.testing.assert_allclose(rf.R1(phi), rx(phi), atol=1e-15)
    np.testing.assert_allclose(rf.R2(phi), ry(phi), atol=1e-15)
    np.testing.assert_allclose(rf.R3(phi), rz(phi), atol=1e-15)


def test_rotation_sines_and_cosines_are_within_an_ulp():
    """R1's cos φ and sin φ entries come from the core's own sin_cos, which every rotation of a joint
    uses: each within 0.9 ulp of the exact value (mpmath at 40 digits), from 1e-8 rad to 2^17 rad,
    next to multiples of π/2 (where the reduction cancels), on either side of 0.78 rad (below it no
    reduction) and beyond 2^17 rad (the library's)."""
    rng = np.random.default_rng(7)
    angles = [0.0, -0.0, math.pi / 4, -math.pi / 4, 2.0**17, -(2.0**17), 3e5, -1e9]
    angles += [s * x for s in (1, -1) for x in (0.78, math.nextafter(0.78, 0.0), math.nextafter(0.78, 1.0))]
    for scale in (1e-8, 1e-3, 0.5, 0.8, 2.0, 7.0, 100.0, 1e4, 2.0**17):
        angles += list(rng.uniform(-scale, scale, 300))
    for k in (1, 2, 3, 4, -5, 101, -2047, 65535, 83000):
        near = float(k * mpmath.pi / 2)
        angles += [near, math.nextafter(near, math.inf), math.nextafter(near, -math.inf)]
    mpmath.mp.dps = 40
    worst = 0.0
    for phi in angles:
        R = rf.R1(phi)
        for got, exact in ((R[1, 1], mpmath.cos(phi)), (R[2, 1], mpmath.sin(phi))):
            ulp = math.ulp(float(exact)) if exact != 0 else math.ulp(0.0)
            worst = max(worst, float(abs(mpmath.mpf(float(got)) - exact)) / ulp)
    assert worst <= 0.9, worst
    # the rotation's other entries are the same two numbers
    R = rf.R1(0.7)
    assert R[1, 2] == -R[2, 1] and R[2, 2] == R[1, 1]


def test_positive_angle_sign_conventions():
    e1, e2, e3 = np.eye(3)
    h = np.pi / 2
    np.testing.assert_allclose(rf.R1(h) @ e2, e3, atol=1e-15)  # y toward z
    np.testing.assert_allclose(rf.R2(h) @ e3, e1, atol=1e-15)  # z toward x
    np.testing.assert_allclose(rf.R3(h) @ e1, e2, atol=1e-15)  # x toward y
    # and each leaves its own axis alone
    np.testing.assert_allclose(rf.R1(0.7) @ e1, e1, atol=1e-15)
    np.testing.assert_allclose(rf.R2(0.7) @ e2, e2, atol=1e-15)
    np.testing.assert_allclose(rf.R3(0.7) @ e3, e3, atol=1e-15)


@pytest.mark.parametrize("phi3, phi2, phi1", ANGLES)
def test_rotations_are_proper_orthonormal(phi3, phi2, phi1):
    for R in (rf.R1(phi1), rf.R2(phi2), rf.R3(phi3), rf.euler_zyx(phi3, phi2, phi1)):
        R = np.asarray(R)
        assert R.shape == (3, 3)
        np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-14)
        assert np.linalg.det(R) == pytest.approx(1.0, abs=1e-14)


@pytest.mark.parametrize("phi3, phi2, phi1", ANGLES)
def test_euler_zyx_is_product_and_book_closed_form(phi3, phi2, phi1):
    E = rf.euler_zyx(phi3, phi2, phi1)
    np.testing.assert_allclose(E, rz(phi3) @ ry(phi2) @ rx(phi1), atol=1e-14)
    np.testing.assert_allclose(E, rf.R3(phi3) @ rf.R2(phi2) @ rf.R1(phi1), atol=1e-14)
    c1, s1 = np.cos(phi1), np.sin(phi1)
    c2, s2 = np.cos(phi2), np.sin(phi2)
    c3, s3 = np.cos(phi3), np.sin(phi3)
    book = np.array(  # eq. (2.7)
        [
            [c3 * c2, c3 * s2 * s1 - s3 * c1, c3 * s2 * c1 + s3 * s1],
            [s3 * c2, s3 * s2 * s1 + c3 * c1, s3 * s2 * c1 - c3 * s1],
            [-s2, c2 * s1, c2 * c1],
        ]
    )
    np.testing.assert_allclose(E, book, atol=1e-14)


def test_euler_zyx_argument_order():
    # Only the yaw: a pure rotation about z; only the roll: about x.
    np.testing.assert_allclose(rf.euler_zyx(0.4, 0.0, 0.0), rz(0.4), atol=1e-15)
    np.testing.assert_allclose(rf.euler_zyx(0.0, 0.4, 0.0), ry(0.4), atol=1e-15)
    np.testing.assert_allclose(rf.euler_zyx(0.0, 0.0, 0.4), rx(0.4), atol=1e-15)


# --- homogeneous transforms, inverse, skew -------------------------------------------------


@pytest.mark.parametrize("k", range(4))
def test_homogeneous_and_inverse(k):
    R = rz(ANGLES[k, 0]) @ ry(ANGLES[k, 1]) @ rx(ANGLES[k, 2])
    r = RNG.normal(size=3) * 3.0
    T = rf.homogeneous(R, r)
    expected = np.zeros((4, 4))
    expected[:3, :3], expected[:3, 3], expected[3, 3] = R, r, 1.0
    np.testing.assert_allclose(T, expected, atol=0.0)
    Ti = rf.inverse(T)
    np.testing.assert_allclose(Ti @ T, np.eye(4), atol=1e-14)
    np.testing.assert_allclose(T @ Ti, np.eye(4), atol=1e-14)
    np.testing.assert_allclose(Ti, np.linalg.inv(T), atol=1e-13)


@pytest.mark.parametrize("k", range(4))
def test_skew_is_cross_product(k):
    w, x = RNG.normal(size=(2, 3))
    S = rf.skew(w)
    np.testing.assert_allclose(S @ x, np.cross(w, x), atol=1e-14)
    np.testing.assert_allclose(S, -np.asarray(S).T, atol=0.0)
    np.testing.assert_allclose(S @ w, 0.0, atol=1e-14)


# --- joint transforms ----------------------------------------------------------------------

SUBSETS = [
    ("x",),
    ("y",),
    ("z",),
    ("rz",),
    ("ry",),
    ("rx",),
    ("z", "rz"),
    ("rz", "ry"),
    ("ry", "rx"),
    ("x", "y", "rz"),
    ("y", "z", "rx"),
    ("x", "z", "ry"),
    ("rz", "ry", "rx"),
    ("x", "y", "z"),
    BOOK_ORDER,
    # given out of the book's order: still applied (and q read) in the book's order
    ("rx", "x"),
    ("ry", "rz"),
    ("rx", "ry", "rz", "z", "y", "x"),
    ("rx", "z", "ry"),
]


def _q(n, seed):
    return np.random.default_rng(seed).uniform(-1.2, 1.2, size=n)


@pytest.mark.parametrize("coords", SUBSETS, ids="-".join)
def test_joint_transform_matches_product(coords):
    q = _q(len(coords), 1)
    np.testing.assert_allclose(rf.joint_transform(list(coords), q), reference_joint(coords, q), atol=1e-14)


def test_joint_transform_order_is_the_books_not_the_callers():
    a, b = 0.7, -0.4
    # q is in book order: first the translation x, then the roll rx
    T = rf.joint_transform(["rx", "x"], [a, b])
    np.testing.assert_allclose(T, hom(r=(a, 0, 0)) @ hom(rx(b)), atol=1e-15)
    # rotation before translation in the product: the translation is not rotated
    T = rf.joint_transform(["x", "rz"], [1.0, np.pi / 2])
    np.testing.assert_allclose(T[:3, 3], [1.0, 0.0, 0.0], atol=1e-15)
    # R3 R2 R1, not R1 R2 R3
    T = rf.joint_transform(["rx", "ry", "rz"], [0.3, 0.5, 0.7])  # rz=0.3, ry=0.5, rx=0.7
    np.testing.assert_allclose(T[:3, :3], rz(0.3) @ ry(0.5) @ rx(0.7), atol=1e-15)


def test_joint_transform_of_no_coordinates_is_identity():
    np.testing.assert_allclose(rf.joint_transform([], np.zeros(0)), np.eye(4), atol=0.0)


def test_phi_aliases_name_the_rotations():
    q = [0.3, -0.2, 0.9]
    np.testing.assert_allclose(
        rf.joint_transform(["phi3", "phi2", "phi1"], q), rf.joint_transform(["rz", "ry", "rx"], q), atol=0.0
    )


DERIVATIVE_SUBSETS = [BOOK_ORDER, ("rz", "ry", "rx"), ("x", "y", "rz"), ("z", "rz"), ("ry",), ("rx", "y")]


@pytest.mark.parametrize("coords", DERIVATIVE_SUBSETS, ids="-".join)
def test_joint_transform_derivative_finite_differences(coords):
    n, h = len(coords), 1e-6
    q = _q(n, 2)
    for i in range(n):
        dq = np.zeros(n)
        dq[i] = h
        fd = (reference_joint(coords, q + dq) - reference_joint(coords, q - dq)) / (2 * h)
        np.testing.assert_allclose(
            rf.joint_transform_derivative(list(coords), q, i), fd, atol=1e-8, err_msg=f"i={i}"
        )


@pytest.mark.parametrize("coords", DERIVATIVE_SUBSETS, ids="-".join)
def test_joint_transform_second_derivative_finite_differences(coords):
    n, h = len(coords), 1e-4
    q = _q(n, 3)
    T = lambda x: rf.joint_transform(list(coords), x)  # noqa: E731
    for i, j in itertools.product(range(n), repeat=2):
        ei, ej = np.eye(n)[i] * h, np.eye(n)[j] * h
        if i == j:
            fd = (T(q + ei) - 2 * T(q) + T(q - ei)) / h**2
        else:
            fd = (T(q + ei + ej) - T(q + ei - ej) - T(q - ei + ej) + T(q - ei - ej)) / (4 * h**2)
        d2 = rf.joint_transform_second_derivative(list(coords), q, i, j)
        np.testing.assert_allclose(d2, fd, atol=2e-6, err_msg=f"i={i}, j={j}")
        np.testing.assert_allclose(d2, rf.joint_transform_second_derivative(list(coords), q, j, i), atol=1e-14)


def test_first_derivative_is_not_the_transform():
    # A rotation's derivative has a zero last row and column (no affine part).
    d = rf.joint_transform_derivative(["rz"], [0.3], 0)
    np.testing.assert_allclose(d, hom(rz(0.3)) @ np.array([[0, -1, 0, 0], [1, 0, 0, 0], [0, 0, 0, 0], [0, 0, 0, 0]]))
    assert d[3, 3] == 0.0


@pytest.mark.parametrize("bad", [["w"], ["x", "q"], ["X"], ["rw"], ["rz", "rz"], ["rz", "phi3"]])
def test_bad_coordinate_names(bad):
    q = np.zeros(len(bad))
    with pytest.raises(ValueError, match=r"^coordinates\b"):
        rf.joint_transform(bad, q)
    with pytest.raises(ValueError, match=r"^coordinates\b"):
        rf.joint_transform_derivative(bad, q, 0)
    with pytest.raises(ValueError, match=r"^coordinates\b"):
        rf.joint_transform_second_derivative(bad, q, 0, 0)


def test_wrong_number_of_joint_coordinates():
    with pytest.raises(ValueError, match=r"^q\b"):
        rf.joint_transform(["x", "rz"], [0.1])
    with pytest.raises(ValueError, match=r"^q\b"):
        rf.joint_transform_derivative(["x"], [0.1, 0.2], 0)


@pytest.mark.parametrize("i", [2, 3, -2])
def test_derivative_index_out_of_range(i):
    with pytest.raises(ValueError, match="index"):
        rf.joint_transform_derivative(["x", "rz"], [0.1, 0.2], i)
    with pytest.raises(ValueError, match="index"):
        rf.joint_transform_second_derivative(["x", "rz"], [0.1, 0.2], 0, i)


def test_derivative_index_minus_one_is_not_silently_the_transform():
    """i = -1 is neither a valid index nor (as Python would read it) the last one:
    it must not return the undifferentiated transform."""
    q = [0.1, 0.2]
    try:
        d = rf.joint_transform_derivative(["x", "rz"], q, -1)
    except ValueError:
        return
    np.testing.assert_allclose(d, rf.joint_transform_derivative(["x", "rz"], q, 1))
