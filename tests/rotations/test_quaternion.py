import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from conftest import random_quaternions, rotation_angle
from strapdown import quaternion as quat

UNITS = {
    "1": [1.0, 0, 0, 0],
    "i": [0, 1.0, 0, 0],
    "j": [0, 0, 1.0, 0],
    "k": [0, 0, 0, 1.0],
}
# Hamilton's table: i j = k, j k = i, k i = j, i² = j² = k² = -1 (Gajda 2.2).
TABLE = {
    ("i", "j"): ("k", 1),
    ("j", "i"): ("k", -1),
    ("j", "k"): ("i", 1),
    ("k", "j"): ("i", -1),
    ("k", "i"): ("j", 1),
    ("i", "k"): ("j", -1),
    ("i", "i"): ("1", -1),
    ("j", "j"): ("1", -1),
    ("k", "k"): ("1", -1),
}


@pytest.mark.parametrize(("a", "b"), list(TABLE))
def test_multiply_hamilton_table(a, b):
    unit, sign = TABLE[(a, b)]
    np.testing.assert_array_equal(quat.multiply(UNITS[a], UNITS[b]), sign * np.array(UNITS[unit]))


def test_multiply_matches_scipy_composition(rng):
    p = random_quaternions(10_000, rng)
    q = random_quaternions(10_000, rng)
    ours = quat.multiply(p, q)
    ref = (Rotation.from_quat(p, scalar_first=True) * Rotation.from_quat(q, scalar_first=True)).as_quat(
        scalar_first=True
    )
    assert rotation_angle(ours, ref).max() < 1e-15
    # Not only the same rotation: the product of unit quaternions is unit without normalising.
    assert np.abs(np.linalg.norm(ours, axis=-1) - 1).max() < 1e-15


def test_multiply_is_bilinear_for_non_unit(rng):
    p = rng.standard_normal((50, 4))
    q = rng.standard_normal((50, 4))
    # |p ⊗ q| = |p| |q| for any quaternions (the norm is multiplicative).
    np.testing.assert_allclose(
        np.linalg.norm(quat.multiply(p, q), axis=-1),
        np.linalg.norm(p, axis=-1) * np.linalg.norm(q, axis=-1),
        rtol=1e-14,
    )
    np.testing.assert_allclose(quat.multiply(3 * p, q), 3 * quat.multiply(p, q), rtol=1e-13, atol=1e-14)


def test_multiply_broadcasts(rng):
    p = random_quaternions(6, rng).reshape(2, 3, 4)
    q = random_quaternions(3, rng)
    out = quat.multiply(p, q)
    assert out.shape == (2, 3, 4)
    for a in range(2):
        for b in range(3):
            np.testing.assert_allclose(out[a, b], quat.multiply(p[a, b], q[b]), atol=1e-16)
    single = quat.multiply(q[0], p)
    np.testing.assert_allclose(single[1, 2], quat.multiply(q[0], p[1, 2]), atol=1e-16)
    # (2, 1, 4) against (3, 4): a true broadcast of both operands
    out = quat.multiply(p[:, :1], q)
    assert out.shape == (2, 3, 4)
    np.testing.assert_allclose(out[1, 2], quat.multiply(p[1, 0], q[2]), atol=1e-16)


@pytest.mark.parametrize(
    "func",
    [
        lambda q: quat.multiply(q, q),
        quat.conjugate,
        quat.inverse,
        quat.normalize,
        quat.exp,
        quat.log,
        lambda q: quat.power(q, np.float32(0.3)),
        lambda q: quat.slerp(q, q[::-1], np.float32(0.3)),
        quat.canonical,
    ],
)
def test_float32_stays_float32(func, rng):
    q = random_quaternions(8, rng).astype(np.float32)
    assert func(q).dtype == np.float32


def test_integers_widen_to_float64():
    assert quat.multiply([1, 0, 0, 0], [0, 1, 0, 0]).dtype == np.float64
    assert quat.norm([0, 3, 4, 0]).dtype == np.float64


def test_conjugate_and_inverse(rng):
    q = rng.standard_normal((100, 4))
    one = quat.multiply(q, quat.inverse(q))
    np.testing.assert_allclose(one, np.tile([1.0, 0, 0, 0], (100, 1)), atol=1e-15)
    # q ⊗ q* = |q|² (a real number)
    qq = quat.multiply(q, quat.conjugate(q))
    np.testing.assert_allclose(qq[:, 0], np.sum(q * q, axis=-1), rtol=1e-14)
    np.testing.assert_allclose(qq[:, 1:], 0, atol=1e-14)


def test_normalize_exact(rng):
    q = rng.standard_normal((1000, 4)) * rng.uniform(1e-3, 1e3, (1000, 1))
    assert np.abs(np.linalg.norm(quat.normalize(q), axis=-1) - 1).max() < 3e-16


def test_normalize_series_reproduces_nabbla_part9():
    """nabbla part 9: 72 first-order steps of 5° about z give |Λ| = 1.0709; one series normalisation gives a norm
    of 0.9923, and normalising at steps 36 and 72 gives 0.9984 (the article prints 0.9983; math.md §4.1)."""
    a = np.radians(5) / 2  # M = 1 + (angle/2) k
    m = np.array([1.0, 0, 0, a])
    lam = np.array([1.0, 0, 0, 0])
    for _ in range(72):
        lam = quat.multiply(lam, m)
    assert np.linalg.norm(lam) == pytest.approx(1.0709, abs=5e-5)
    assert np.linalg.norm(quat.normalize(lam, method="series")) == pytest.approx(0.9923, abs=5e-5)
    lam = np.array([1.0, 0, 0, 0])
    for k in range(1, 73):
        lam = quat.multiply(lam, m)
        if k in (36, 72):
            lam = quat.normalize(lam, method="series")
    assert np.linalg.norm(lam) == pytest.approx(0.9984, abs=5e-5)


def test_normalize_series_error_is_second_order():
    # (3 - n²)/2 is one Newton step for 1/n: the norm error is -(3/8) ε² + O(ε³) with ε = n² - 1.
    for eps in (1e-2, 1e-3, 1e-4):
        q = np.array([np.sqrt(1 + eps), 0, 0, 0])
        err = np.linalg.norm(quat.normalize(q, method="series")) - 1
        assert err == pytest.approx(-3 / 8 * eps**2, rel=5 * eps)


def test_exp_closed_form(rng):
    axis = rng.standard_normal((100, 3))
    axis /= np.linalg.norm(axis, axis=-1, keepdims=True)
    angle = rng.uniform(-10, 10, 100)
    w = rng.uniform(-2, 2, 100)
    q = np.concatenate([w[:, None], axis * angle[:, None]], axis=-1)
    expected = np.exp(w)[:, None] * np.concatenate([np.cos(angle)[:, None], axis * np.sin(angle)[:, None]], axis=-1)
    np.testing.assert_allclose(quat.exp(q), expected, rtol=1e-13, atol=1e-13)


def test_exp_of_tiny_and_zero_vectors_has_no_division():
    out = quat.exp([[0.0, 0, 0, 0], [0.0, 1e-300, 0, 0], [0.0, 1e-9, -2e-9, 0]])
    np.testing.assert_array_equal(out[0], [1, 0, 0, 0])
    assert out[1, 1] == 1e-300
    np.testing.assert_allclose(out[2, 1:], [1e-9, -2e-9, 0], rtol=1e-15)


def test_log_closed_form_and_inverse_of_exp(rng):
    q = rng.standard_normal((1000, 4))
    lq = quat.log(q)
    np.testing.assert_allclose(lq[:, 0], np.log(np.linalg.norm(q, axis=-1)), rtol=1e-13, atol=1e-15)
    half = np.arctan2(np.linalg.norm(q[:, 1:], axis=-1), q[:, 0])
    np.testing.assert_allclose(np.linalg.norm(lq[:, 1:], axis=-1), half, rtol=1e-13)
    np.testing.assert_allclose(quat.exp(lq), q, rtol=1e-12, atol=1e-13)


def test_log_of_negative_real_quaternion():
    lq = quat.log([-2.0, 0, 0, 0])
    np.testing.assert_allclose(lq, [np.log(2), np.pi, 0, 0])
    np.testing.assert_allclose(quat.exp(lq), [-2.0, 0, 0, 0], atol=1e-15)


def test_power_halves_the_angle(rng):
    q = random_quaternions(500, rng)
    half = quat.power(q, 0.5)
    np.testing.assert_allclose(quat.multiply(half, half), q, atol=2e-15)
    np.testing.assert_allclose(quat.power(q, 1.0), q, atol=2e-15)
    np.testing.assert_allclose(quat.power(q, 0.0), np.tile([1.0, 0, 0, 0], (500, 1)), atol=1e-15)
    # integer powers are repeated products
    np.testing.assert_allclose(quat.power(q, 3.0), quat.multiply(quat.multiply(q, q), q), atol=5e-15)


def test_power_broadcasts_exponents():
    q = np.array([np.cos(0.3), np.sin(0.3), 0, 0])
    out = quat.power(q, [0.0, 1.0, 2.0])
    assert out.shape == (3, 4)
    np.testing.assert_allclose(out[:, 0], np.cos([0.0, 0.3, 0.6]), atol=1e-15)


def test_rotate_matches_scipy_apply(rng):
    q = random_quaternions(1000, rng)
    v = rng.standard_normal((1000, 3))
    ref = Rotation.from_quat(q, scalar_first=True).apply(v)
    np.testing.assert_allclose(quat.rotate(q, v), ref, atol=1e-14)
    # a non-unit quaternion applies the rotation of q/|q|
    np.testing.assert_allclose(quat.rotate(7 * q, v), ref, atol=1e-14)


def test_rotate_is_the_sandwich_product(rng):
    q = random_quaternions(100, rng)
    v = rng.standard_normal((100, 3))
    vq = np.concatenate([np.zeros((100, 1)), v], axis=-1)
    sandwich = quat.multiply(quat.multiply(q, vq), quat.conjugate(q))
    np.testing.assert_allclose(quat.rotate(q, v), sandwich[:, 1:], atol=1e-14)
    np.testing.assert_allclose(sandwich[:, 0], 0, atol=1e-14)


def test_angle_between(rng):
    p = random_quaternions(2000, rng)
    q = random_quaternions(2000, rng)
    np.testing.assert_allclose(quat.angle_between(p, q), rotation_angle(p, q), atol=1e-14)
    np.testing.assert_array_equal(quat.angle_between(p, q), quat.angle_between(-p, q))
    assert quat.angle_between(p, q).max() <= np.pi
    # tiny angles keep full relative precision
    tiny = np.array([np.cos(1e-12), np.sin(1e-12), 0, 0])
    assert quat.angle_between([1, 0, 0, 0], tiny) == pytest.approx(2e-12, rel=1e-14)


def test_slerp(rng):
    p = random_quaternions(500, rng)
    q = random_quaternions(500, rng)
    np.testing.assert_allclose(quat.slerp(p, q, 0.0), p, atol=1e-15)
    assert rotation_angle(quat.slerp(p, q, 1.0), q).max() < 1e-14
    # nabbla part 15: the midpoint is normalize(p + sgn(p·q) q)
    s = np.sign(np.sum(p * q, axis=-1))[:, None]
    mid = (p + s * q) / np.linalg.norm(p + s * q, axis=-1, keepdims=True)
    assert rotation_angle(quat.slerp(p, q, 0.5), mid).max() < 1e-14
    # constant angular speed along the shorter arc
    t = np.linspace(0, 1, 11)
    path = quat.slerp(p[0], q[0], t)
    total = rotation_angle(p[0], q[0])
    np.testing.assert_allclose(rotation_angle(p[0], path), t * total, atol=1e-14)
    np.testing.assert_allclose(np.linalg.norm(path, axis=-1), 1, atol=1e-15)


def test_slerp_between_identical_rotations():
    q = np.array([0.5, 0.5, 0.5, 0.5])
    np.testing.assert_allclose(quat.slerp(q, -q, [0.0, 0.3, 1.0]), np.tile(q, (3, 1)), atol=1e-16)


def test_canonical_rule():
    cases = [
        ([-0.5, 0.5, 0.5, 0.5], [0.5, -0.5, -0.5, -0.5]),
        ([0.0, -1.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0]),
        ([0.0, 0.0, -0.6, 0.8], [0.0, 0.0, 0.6, -0.8]),
        ([0.0, 0.0, 0.0, -1.0], [0.0, 0.0, 0.0, 1.0]),
        ([-0.0, -0.0, 0.6, -0.8], [0.0, 0.0, 0.6, -0.8]),
    ]
    for q, expected in cases:
        out = quat.canonical(q)
        np.testing.assert_array_equal(out, expected)
        assert not np.signbit(out[out == 0]).any(), "negative zeros must be cleaned"


def test_canonical_of_q_and_minus_q_are_bit_identical(rng):
    q = random_quaternions(10_000, rng)
    q[:100, 0] = 0.0  # ties in w
    q[:50, 1] = 0.0  # ties in w and x
    q[:10, 0] = -0.0
    a = quat.canonical(q)
    b = quat.canonical(-q)
    assert a.tobytes() == b.tobytes()
    assert (a[:, 0] >= 0).all()


@pytest.mark.parametrize(
    ("call", "argname"),
    [
        (lambda bad: quat.multiply(bad, [1, 0, 0, 0]), "p"),
        (lambda bad: quat.multiply([1, 0, 0, 0], bad), "q"),
        (quat.conjugate, "q"),
        (quat.norm, "q"),
        (quat.inverse, "q"),
        (quat.normalize, "q"),
        (quat.exp, "q"),
        (quat.log, "q"),
        (lambda bad: quat.power(bad, 2.0), "q"),
        (lambda bad: quat.rotate(bad, [1.0, 0, 0]), "q"),
        (lambda bad: quat.slerp(bad, [1, 0, 0, 0], 0.5), "p"),  # once reported as q (issue 14)
        (lambda bad: quat.angle_between(bad, [1, 0, 0, 0]), "p"),
        (quat.canonical, "q"),
    ],
)
def test_nan_rejected_by_name(call, argname):
    bad = np.array([[1.0, 0, 0, 0], [np.nan, 0, 0, 1]])
    with pytest.raises(ValueError, match=rf"{argname}\[1, 0\] is NaN"):
        call(bad)


@pytest.mark.parametrize(
    "func",
    [
        quat.inverse,
        quat.normalize,
        quat.log,
        quat.canonical,
        lambda q: quat.rotate(q, [1.0, 0, 0]),
        lambda q: quat.angle_between([1, 0, 0, 0], q),
        lambda q: quat.power(q, 0.5),
    ],
)
def test_zero_quaternion_rejected(func):
    with pytest.raises(ValueError, match=r"\[2\] is a zero quaternion"):
        func(np.array([[1.0, 0, 0, 0], [0, 1, 0, 0], [0, 0, 0, 0]]))


def test_algebra_accepts_zero():
    np.testing.assert_array_equal(quat.multiply([0, 0, 0, 0], [1, 2, 3, 4]), [0, 0, 0, 0])
    assert quat.norm([0, 0, 0, 0]) == 0


def test_shape_errors():
    with pytest.raises(ValueError, match=r"q must have shape \(\.\.\., 4\)"):
        quat.normalize([1.0, 0, 0])
    with pytest.raises(ValueError, match=r"v must have shape \(\.\.\., 3\)"):
        quat.rotate([1.0, 0, 0, 0], [1.0, 0])
    with pytest.raises(ValueError, match="method must be one of"):
        quat.normalize([1.0, 0, 0, 0], method="fast")
    with pytest.raises(ValueError, match="must be real"):
        quat.normalize([1j, 0, 0, 0])
    with pytest.raises(ValueError, match=r"t\[1\] is infinite"):
        quat.power([1.0, 0, 0, 0], [0.5, np.inf])


def test_check_false_skips_value_checks():
    out = quat.multiply([np.nan, 0, 0, 0], [1, 0, 0, 0], check=False)
    assert np.isnan(out[0])


def test_extreme_norms_are_rejected_or_handled():
    tiny = np.full(4, 1e-300)
    # the sign rule needs no norm: a tiny quaternion is fine
    np.testing.assert_array_equal(quat.canonical(-tiny), tiny)
    # normalising needs no squared norm either: rows far from unit are scaled by a power of two first (issue 14)
    np.testing.assert_array_equal(quat.normalize(tiny), np.full(4, 0.5))
    np.testing.assert_array_equal(quat.normalize(np.full(4, 1e300)), np.full(4, 0.5))
    np.testing.assert_array_equal(quat.normalize([5e-324, 0, 0, 0]), [1.0, 0, 0, 0])
    f32 = quat.normalize(np.array([[1.0, 0, 0, 0], [1e-20, 0, 0, 0]], dtype=np.float32))
    assert f32.dtype == np.float32 and np.array_equal(f32, [[1, 0, 0, 0], [1, 0, 0, 0]])
    # the inverse needs |q|², which would underflow: refused by name
    with pytest.raises(ValueError, match=r"q has a norm too small .* underflows"):
        quat.inverse(tiny)
    with pytest.raises(ValueError, match=r"q has a norm too large .* overflows"):
        quat.inverse(np.full(4, 1e300))


def test_log_exp_with_subnormal_squares():
    """Found by hypothesis: vector parts below 1e-154 have subnormal squares; the direction must survive."""
    q = np.array([-1.0, 4.48e-159, 4.48e-159, 4.48e-159])
    lq = quat.log(q)
    np.testing.assert_allclose(lq[1:], np.pi / np.sqrt(3), rtol=1e-15)
    # exp of a half angle of float(π) has sin(π) = 1.2e-16, not 0: the round trip holds to that absolute level
    np.testing.assert_allclose(quat.exp(lq), q, rtol=0, atol=1e-15)
