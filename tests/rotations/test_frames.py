import numpy as np
import pytest

from conftest import random_quaternions, rotation_angle
from strapdown import as_euler, as_matrix, change_frame, frame_matrix, frame_quaternion, from_euler
from strapdown import quaternion as quat

# v = 1 north, 2 east, 3 down, written in each reference frame (by hand)
V_REF = {"NED": [1, 2, 3], "ENU": [2, 1, -3], "NWU": [1, -2, -3], "SEU": [-1, 2, -3]}
# v = 1 forward, 2 right, 3 down, in each body frame
V_BODY = {"FRD": [1, 2, 3], "FLU": [1, -2, -3], "RFU": [2, 1, -3]}


@pytest.mark.parametrize("table", [V_REF, V_BODY])
def test_frame_matrix_by_hand(table):
    for src, v_src in table.items():
        for dst, v_dst in table.items():
            m = frame_matrix(src, dst)
            np.testing.assert_array_equal(m @ v_src, v_dst)
            assert np.linalg.det(m) == pytest.approx(1.0)
            np.testing.assert_allclose(quat.rotate(frame_quaternion(src, dst), v_src), v_dst, atol=1e-15)


def test_ned_frd_yaw_pitch_roll_in_nwu_flu(rng):
    """The same physical attitude: NED/FRD yaw ψ, pitch θ, roll φ is, in NWU/FLU, yaw -ψ, pitch -θ, roll φ."""
    ypr = np.column_stack([rng.uniform(-3, 3, 100), rng.uniform(-1.5, 1.5, 100), rng.uniform(-3, 3, 100)])
    q_ned = from_euler(ypr, "ZYX")
    q_nwu = change_frame(q_ned, ref_from="NED", ref_to="NWU", body_from="FRD", body_to="FLU")
    np.testing.assert_allclose(as_euler(q_nwu, "ZYX"), ypr * [-1, -1, 1], atol=1e-12)


def test_change_frame_keeps_the_physical_attitude(rng):
    """Body-frame vector -> reference vector must agree whichever frames express it."""
    q = random_quaternions(200, rng)
    v_frd = rng.standard_normal((200, 3))
    v_ned = quat.rotate(q, v_frd)
    q2 = change_frame(q, ref_from="NED", ref_to="ENU", body_from="FRD", body_to="RFU")
    v_rfu = v_frd @ frame_matrix("FRD", "RFU").T
    np.testing.assert_allclose(quat.rotate(q2, v_rfu), v_ned @ frame_matrix("NED", "ENU").T, atol=1e-14)
    back = change_frame(q2, ref_from="ENU", ref_to="NED", body_from="RFU", body_to="FRD")
    assert rotation_angle(back, q).max() < 1e-15


def test_identity_maps_to_identity():
    for ref, body in (("ENU", "RFU"), ("NWU", "FLU")):
        q = change_frame([1.0, 0, 0, 0], ref_from="NED", ref_to=ref, body_from="FRD", body_to=body)
        np.testing.assert_allclose(as_matrix(q), np.eye(3), atol=1e-15)


def test_only_reference_or_only_body(rng):
    q = random_quaternions(10, rng)
    only_ref = change_frame(q, ref_from="NED", ref_to="ENU")
    np.testing.assert_allclose(as_matrix(only_ref), frame_matrix("NED", "ENU") @ as_matrix(q), atol=1e-15)
    only_body = change_frame(q, body_from="FRD", body_to="FLU")
    np.testing.assert_allclose(as_matrix(only_body), as_matrix(q) @ frame_matrix("FLU", "FRD"), atol=1e-15)


@pytest.mark.parametrize(
    ("src", "dst", "match"),
    [
        ("NEU", "ENU", "left-handed"),
        ("NNU", "ENU", "repeats a direction"),
        ("NED", "FRD", "reference frame and dst='FRD' a body frame"),
        ("NEX", "ENU", "mixes or misuses"),
        ("NE", "ENU", "three axis letters"),
    ],
)
def test_bad_frames(src, dst, match):
    with pytest.raises(ValueError, match=match):
        frame_matrix(src, dst)


def test_change_frame_needs_pairs():
    with pytest.raises(ValueError, match="ref_from and ref_to"):
        change_frame([1.0, 0, 0, 0], ref_from="NED")
