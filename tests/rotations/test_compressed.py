"""Liu Gongxu et al. (2019): compressed attitude-angle and quaternion spaces, ENU / right-forward-up, 3-1-2."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from conftest import random_quaternions, rotation_angle, wrapped
from strapdown import as_compressed, canonical, change_frame, from_compressed, from_euler


def liu_15(psi, theta, gamma):
    """Liu et al. (15) as derived in math.md §3.2 (half angles), scalar first."""
    cps, sps = np.cos(psi / 2), np.sin(psi / 2)
    cth, sth = np.cos(theta / 2), np.sin(theta / 2)
    cga, sga = np.cos(gamma / 2), np.sin(gamma / 2)
    return np.stack(
        [
            cps * cth * cga - sps * sth * sga,
            cps * sth * cga - sps * cth * sga,
            cps * cth * sga + sps * sth * cga,
            cps * sth * sga + sps * cth * cga,
        ],
        axis=-1,
    )


def liu_6(psi, theta, gamma):
    """Liu et al. (6): C_b^n = R_z(ψ) R_x(θ) R_y(γ)."""
    cps, sps, cth, sth, cga, sga = (
        np.cos(psi),
        np.sin(psi),
        np.cos(theta),
        np.sin(theta),
        np.cos(gamma),
        np.sin(gamma),
    )
    return np.array(
        [
            [cps * cga - sps * sth * sga, -sps * cth, cps * sga + sps * sth * cga],
            [sps * cga + cps * sth * sga, cps * cth, sps * sga - cps * sth * cga],
            [-cth * sga, sth, cth * cga],
        ]
    )


def _compressed_angles(n, rng, max_pitch_deg=90.0):
    psi = rng.uniform(-np.pi, np.pi, n)
    theta = rng.uniform(-np.radians(max_pitch_deg), np.radians(max_pitch_deg), n)
    gamma = rng.uniform(-np.pi, np.pi, n)
    return np.column_stack([psi, theta, gamma])


def test_eq_15_equals_the_product_and_scipy(rng):
    a = _compressed_angles(10_000, rng)
    ours = from_euler(a, "ZXY")
    np.testing.assert_allclose(ours, liu_15(*a.T), atol=4.5e-16)
    ref = Rotation.from_euler("ZXY", a).as_quat(scalar_first=True)
    np.testing.assert_allclose(ours, ref, atol=4.5e-16)
    q = from_compressed(a)
    assert rotation_angle(q, ours).max() < 1e-15
    assert (q[:, 0] >= 0).all()


def test_eq_6_is_the_matrix_of_the_quaternion(rng):
    from strapdown import as_matrix

    for psi, theta, gamma in _compressed_angles(50, rng):
        np.testing.assert_allclose(
            as_matrix(from_compressed([psi, theta, gamma])), liu_6(psi, theta, gamma), atol=1e-15
        )


def test_angle_round_trip_figure_4(rng):
    """10^6 random compressed angles with |pitch| <= 89° -> quaternion -> angles: max error <= 2e-12 deg
    (the paper's Figure 4 reports about 1e-11)."""
    a = np.degrees(_compressed_angles(1_000_000, rng, max_pitch_deg=89.0))
    back = as_compressed(from_compressed(a, degrees=True), degrees=True)
    err = np.abs(wrapped(np.radians(back - a)))
    assert np.degrees(err).max() <= 2e-12


def test_quaternion_round_trip_figure_5(rng):
    """Random quaternions -> angles -> quaternion, after canonical form: max component difference <= 2e-15
    (the paper's Figure 5 reports about 1e-15)."""
    q = canonical(random_quaternions(1_000_000, rng))
    back = from_compressed(as_compressed(q))
    assert np.abs(back - q).max() <= 2e-15


def test_singularity_test_figure_3(rng):
    """Pitch alternating ±90°, random roll and heading in (-180°, 180°]: the same rotation comes back every time,
    and the angles obey the lock rule (roll 0 whenever pitch is exactly ±90°)."""
    n = 100_000
    a = np.column_stack(
        [rng.uniform(-180, 180, n), np.where(np.arange(n) % 2 == 0, 90.0, -90.0), rng.uniform(-180, 180, n)]
    )
    q = from_compressed(a, degrees=True)
    back = as_compressed(q, degrees=True)
    assert np.isfinite(back).all()
    assert rotation_angle(from_compressed(back, degrees=True), q).max() <= 2e-15
    np.testing.assert_allclose(np.abs(back[:, 1]), 90.0, atol=1e-13)
    locked = np.abs(back[:, 1]) == 90.0
    assert locked.mean() > 0.5
    np.testing.assert_array_equal(back[locked, 2], 0.0)
    # At θ = +90° only ψ + γ is defined, at θ = -90° only ψ - γ (math.md §3.2).
    s = np.sign(a[:, 1])
    np.testing.assert_allclose(
        wrapped(np.radians(back[:, 0] + s * back[:, 2] - (a[:, 0] + s * a[:, 2]))), 0, atol=1e-13
    )


def test_one_to_one(rng):
    q = random_quaternions(100_000, rng)
    # both quaternions of an attitude give the bit-identical triple ...
    a = as_compressed(q)
    assert a.tobytes() == as_compressed(-q).tobytes()
    # ... and the triple gives back the attitude's one compressed quaternion
    back = from_compressed(a)
    assert np.abs(back - canonical(q)).max() <= 2e-15
    assert (back[:, 0] >= 0).all()


@pytest.mark.parametrize(
    ("edge", "expected"),
    [
        ([180.0, 0.0, 0.0], [180.0, 0.0, 0.0]),
        ([-180.0, 0.0, 0.0], [180.0, 0.0, 0.0]),
        ([0.0, 0.0, -180.0], [0.0, 0.0, 180.0]),
        ([0.0, 45.0, 180.0], [0.0, 45.0, 180.0]),
    ],
)
def test_boundaries_of_the_compressed_angle_space(edge, expected):
    """(-180°, 180°] for heading and roll makes the representative unique on the seams."""
    got = as_compressed(from_compressed(edge, degrees=True), degrees=True)
    np.testing.assert_allclose(got, expected, atol=1e-12)


@pytest.mark.parametrize(("pitch", "sign"), [(90.0, 1.0), (-90.0, -1.0)])
def test_lock_combination(pitch, sign):
    """At θ = ±90° the attitude fixes ψ ± γ only.  The quaternion of an exact ±90° input is, after rounding,
    at most an ulp off the lock: either θ comes back exactly ±90° with γ = 0, or an ulp inside with a split."""
    got = as_compressed(from_compressed([30.0, pitch, 20.0], degrees=True), degrees=True)
    assert got[1] == pytest.approx(pitch, abs=1e-13)
    assert got[0] + sign * got[2] == pytest.approx(30.0 + sign * 20.0, abs=1e-12)
    if got[1] == pitch:
        assert got[2] == 0.0


def test_heading_sign_against_ned_yaw(rng):
    """Liu's ψ turns North towards West; an aviation yaw (NED/FRD) turns North towards East, so ψ = -yaw."""
    ypr = np.column_stack([rng.uniform(-170, 170, 100), rng.uniform(-80, 80, 100), rng.uniform(-170, 170, 100)])
    q_ned = from_euler(ypr, "ZYX", degrees=True)
    q_enu = change_frame(q_ned, ref_from="NED", ref_to="ENU", body_from="FRD", body_to="RFU")
    liu = as_compressed(q_enu, degrees=True)
    np.testing.assert_allclose(liu[:, 0], -ypr[:, 0], atol=1e-10)
