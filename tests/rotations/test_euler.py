import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from conftest import ALL_SEQUENCES, random_quaternions, rotation_angle, wrapped
from strapdown import as_euler, from_euler


def _is_proper(seq):
    return seq[0].lower() == seq[2].lower()


def _outer(seq):
    """Column of the angle about a reference-frame axis (yaw for "ZYX")."""
    return 0 if seq.isupper() else 2


@pytest.fixture(scope="module")
def scipy_rotations():
    rot = Rotation.random(100_000, rng=np.random.default_rng(7))
    return rot, rot.as_quat(scalar_first=True)


@pytest.mark.parametrize("seq", ALL_SEQUENCES)
def test_from_euler_matches_scipy(seq, scipy_rotations):
    rot, _ = scipy_rotations
    angles = rot.as_euler(seq)
    ours = from_euler(angles, seq)
    ref = Rotation.from_euler(seq, angles).as_quat(scalar_first=True)
    assert rotation_angle(ours, ref).max() <= 1e-12
    # from_euler is the plain product of elementary quaternions, like scipy's: same sign too.
    assert np.abs(ours - ref).max() <= 1e-12


@pytest.mark.parametrize("seq", ALL_SEQUENCES)
def test_as_euler_matches_scipy(seq, scipy_rotations):
    rot, q = scipy_rotations
    ours = as_euler(q, seq)
    ref = rot.as_euler(seq)
    # random rotations are away from gimbal lock, where the triple is unique: compare angles directly
    assert np.abs(wrapped(ours - ref)).max() <= 1e-12
    # and the rotation they describe, with scipy rebuilding it
    back = Rotation.from_euler(seq, ours).as_quat(scalar_first=True)
    assert rotation_angle(back, q).max() <= 1e-12


@pytest.mark.parametrize("seq", ALL_SEQUENCES)
def test_ranges(seq, rng):
    q = random_quaternions(20_000, rng)
    q[:1000] = from_euler(rng.choice([-np.pi, -np.pi / 2, 0, np.pi / 2, np.pi], (1000, 3)), seq)
    for degrees in (False, True):
        half = 180.0 if degrees else np.pi
        a = as_euler(q, seq, degrees=degrees)
        for col in (0, 2):
            assert (a[:, col] > -half).all() and (a[:, col] <= half).all()
        if _is_proper(seq):
            assert (a[:, 1] >= 0).all() and (a[:, 1] <= half).all()
        else:
            assert (a[:, 1] >= -half / 2).all() and (a[:, 1] <= half / 2).all()
        pos = as_euler(q, seq, degrees=degrees, yaw_range="positive")
        outer = _outer(seq)
        assert (pos[:, outer] >= 0).all() and (pos[:, outer] < 2 * half).all()
        other = [c for c in range(3) if c != outer]
        np.testing.assert_array_equal(pos[:, other], a[:, other])
        assert np.abs(wrapped((a[:, outer] - pos[:, outer]) * (np.pi / half))).max() <= 1e-12


def test_positive_range_never_returns_full_turn():
    # yaw = -1e-17 rad: adding 2π rounds to exactly 2π, which is outside [0, 2π)
    q = from_euler([-1e-17, 0.3, 0.2], "ZYX")
    yaw = as_euler(q, "ZYX", yaw_range="positive")[0]
    assert 0 <= yaw < 2 * np.pi
    yaw_deg = as_euler(from_euler([-1e-15, 0.3, 0.2], "ZYX"), "ZYX", True, "positive")[0]
    assert 0 <= yaw_deg < 360


def _gimbal_cases(seq, rng, n=400):
    """(middle, quaternions) for the middle angle at and within 10^-k (k = 1..15) of each limit."""
    limits = (0.0, np.pi) if _is_proper(seq) else (-np.pi / 2, np.pi / 2)
    for lim in limits:
        inward = 1.0 if lim == limits[0] else -1.0
        for k in range(16):
            middle = lim if k == 0 else lim + inward * 10.0**-k
            angles = np.column_stack([rng.uniform(-np.pi, np.pi, n), np.full(n, middle), rng.uniform(-np.pi, np.pi, n)])
            # scipy builds the test attitudes: independent of from_euler
            yield middle, Rotation.from_euler(seq, angles).as_quat(scalar_first=True)


@pytest.mark.parametrize("seq", ALL_SEQUENCES)
def test_gimbal_lock_sweep_round_trips_the_rotation(seq, rng):
    """Issue 2: at and within 10^-k of the lock, q -> euler -> q returns the same rotation within 3e-15 rad."""
    worst = 0.0
    for _, q in _gimbal_cases(seq, rng):
        angles = as_euler(q, seq)
        assert np.isfinite(angles).all()
        back = from_euler(angles, seq)
        worst = max(worst, rotation_angle(back, q, normalize=False).max())
        # the scipy oracle agrees that the returned angles describe the input rotation
        again = Rotation.from_euler(seq, angles).as_quat(scalar_first=True)
        assert rotation_angle(again, q).max() <= 1e-14
    assert worst <= 3e-15


@pytest.mark.parametrize("seq", ALL_SEQUENCES)
def test_lock_rule_third_angle_zero(seq, rng):
    """Whenever the returned middle angle is exactly at its limit, the third angle is exactly zero."""
    hits = 0
    for _, q in _gimbal_cases(seq, rng, n=200):
        for degrees in (False, True):
            for dtype in (np.float64, np.float32):
                a = as_euler(q.astype(dtype), seq, degrees=degrees)
                half = a.dtype.type(180.0 if degrees else np.pi)
                limits = (0, half) if _is_proper(seq) else (-half / 2, half / 2)
                locked = (a[:, 1] == limits[0]) | (a[:, 1] == limits[1])
                hits += locked.sum()
                assert (a[locked, 2] == 0).all()
    assert hits > 0  # the sweep does reach the exact lock


def test_kernel_atan2_rounds_like_libm_at_the_lock_limits(rng):
    """The kernel's vectorised atan2 gives libm's double wherever the result is within 1e-9 of a multiple of
    π/2 (the middle angle is compared with its limit exactly), and at the signed zeros (IEEE 754)."""
    import math

    from strapdown.rotations._euler_numba import atan2_vec

    tiny = 10.0 ** rng.uniform(-20, -9, 2000)
    one = 1.0 + rng.uniform(-1e-3, 1e-3, tiny.size)
    pairs = [(s * b, t * a) for a, b in zip(tiny, one, strict=True) for s in (1.0, -1.0) for t in (1.0, -1.0)]
    pairs += [
        (s * a, t * b) for a, b in zip(tiny[:500], one[:500], strict=True) for s in (1.0, -1.0) for t in (1.0, -1.0)
    ]
    pairs += [(y, x) for y in (0.0, -0.0, 1.0, -1.0) for x in (0.0, -0.0, 1.0, -1.0)]
    mismatches = [(y, x) for y, x in pairs if atan2_vec(y, x) != math.atan2(y, x)]
    assert not mismatches, f"{len(mismatches)} of {len(pairs)} differ from libm, e.g. {mismatches[:3]}"
    for y, x in pairs[-16:]:  # the sign of a zero result too
        assert math.copysign(1.0, atan2_vec(y, x)) == math.copysign(1.0, math.atan2(y, x))


@pytest.mark.parametrize(
    ("pitch", "combo"),
    [(90.0, lambda yaw, roll: yaw - roll), (-90.0, lambda yaw, roll: yaw + roll)],
)
def test_zyx_vertical_flight(pitch, combo, rng):
    """At pitch +90° only yaw - roll is defined, at -90° only yaw + roll (math.md §2.1).

    A quaternion built from pitch = ±90° is usually an ulp off the exact lock after rounding; then pitch comes
    back one ulp inside ±90° with both outer angles, and only their defined combination is meaningful.  When
    pitch comes back exactly ±90°, roll is 0 and yaw carries the combination.
    """
    yaw = rng.uniform(-180, 180, 2000)
    roll = rng.uniform(-180, 180, 2000)
    q = Rotation.from_euler("ZYX", np.column_stack([yaw, np.full(2000, pitch), roll]), degrees=True)
    a = as_euler(q.as_quat(scalar_first=True), "ZYX", degrees=True)
    np.testing.assert_allclose(a[:, 1], pitch, atol=1e-13)
    np.testing.assert_allclose(wrapped(np.radians(combo(a[:, 0], a[:, 2]) - combo(yaw, roll))), 0, atol=1e-13)
    exact = a[:, 1] == pitch
    assert exact.sum() > 100
    np.testing.assert_array_equal(a[exact, 2], 0.0)


@pytest.mark.parametrize("seq", ALL_SEQUENCES)
def test_special_quaternions_never_nan(seq):
    s = np.sqrt(0.5)
    special = np.array(
        [
            [1, 0, 0, 0],
            [0, 1, 0, 0],
            [0, 0, 1, 0],
            [0, 0, 0, 1],
            [s, s, 0, 0],
            [s, 0, s, 0],
            [s, 0, 0, s],
            [0, s, s, 0],
            [0, s, 0, s],
            [0, 0, s, s],
            [0.5, 0.5, 0.5, 0.5],
            [0.5, -0.5, 0.5, -0.5],
            [-1, 0, 0, 0],
            [1e-300, 1, 0, 0],
            [1, 1e-300, 0, 0],
        ],
        dtype=np.float64,
    )
    a = as_euler(special, seq)
    assert np.isfinite(a).all()
    assert rotation_angle(from_euler(a, seq), special).max() <= 1e-15


def test_sign_and_scale_invariance(rng):
    q = random_quaternions(1000, rng)
    q[:20, 0] = 0.0  # 180° rotations: the sign rule falls to x
    a = as_euler(q, "ZYX")
    np.testing.assert_array_equal(as_euler(-q, "ZYX"), a)
    np.testing.assert_allclose(as_euler(5 * q, "ZYX"), a, atol=1e-15)


def test_degrees(rng):
    q = random_quaternions(100, rng)
    np.testing.assert_allclose(as_euler(q, "XYZ", degrees=True), np.degrees(as_euler(q, "XYZ")), rtol=1e-15)
    a = rng.uniform(-180, 180, (100, 3))
    np.testing.assert_allclose(from_euler(a, "zxz", degrees=True), from_euler(np.radians(a), "zxz"), atol=1e-16)


def test_float32(rng):
    q = random_quaternions(1000, rng).astype(np.float32)
    a = as_euler(q, "ZYX")
    assert a.dtype == np.float32
    assert from_euler(a, "ZYX").dtype == np.float32
    assert rotation_angle(from_euler(a.astype(np.float64), "ZYX"), q).max() < 2e-6


def test_intrinsic_is_reversed_extrinsic(rng):
    a = rng.uniform(-3, 3, (100, 3))
    np.testing.assert_allclose(from_euler(a, "ZYX"), from_euler(a[:, ::-1], "xyz"), atol=1e-16)


def test_leading_shapes(rng):
    q = random_quaternions(24, rng).reshape(2, 3, 4, 4)
    a = as_euler(q, "ZYZ")
    assert a.shape == (2, 3, 4, 3)
    assert from_euler(a, "ZYZ").shape == (2, 3, 4, 4)
    assert as_euler(q[0, 0, 0], "ZYZ").shape == (3,)


@pytest.mark.parametrize("seq", ["ZYXZ", "ZyX", "ZZY", "abc", "XYY", 3])
def test_bad_sequences(seq):
    with pytest.raises(ValueError, match="seq"):
        as_euler([1.0, 0, 0, 0], seq)
    with pytest.raises(ValueError, match="seq"):
        from_euler([0.0, 0, 0], seq)


def test_bad_angles():
    with pytest.raises(ValueError, match=r"angles\[1, 2\] is NaN"):
        from_euler([[0, 0, 0], [0, 0, np.nan]], "ZYX")
    with pytest.raises(ValueError, match=r"angles must have shape \(\.\.\., 3\)"):
        from_euler([0.0, 0.0], "ZYX")
    with pytest.raises(ValueError, match="yaw_range"):
        as_euler([1.0, 0, 0, 0], yaw_range="unsigned")
    with pytest.raises(ValueError, match="zero quaternion"):
        as_euler([0.0, 0, 0, 0])
