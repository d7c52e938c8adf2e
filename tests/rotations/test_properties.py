"""Algebraic properties that must hold for any input (hypothesis)."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from conftest import rotation_angle
from strapdown import as_euler, as_matrix, as_rotvec, from_euler, from_matrix, from_rotvec
from strapdown import quaternion as quat

finite = st.floats(-1e3, 1e3, allow_nan=False, allow_infinity=False)
vectors = arrays(np.float64, 3, elements=finite)


@st.composite
def unit_quaternions(draw):
    q = draw(arrays(np.float64, 4, elements=st.floats(-1, 1, allow_nan=False)))
    n = np.linalg.norm(q)
    if n < 1e-3:
        q = np.array([1.0, 0, 0, 0])
        n = 1.0
    return q / n


@given(unit_quaternions(), unit_quaternions())
def test_product_of_unit_quaternions_is_unit(p, q):
    assert abs(np.linalg.norm(quat.multiply(p, q)) - 1) <= 1e-15


@given(unit_quaternions(), unit_quaternions(), unit_quaternions())
def test_multiply_associative(p, q, r):
    left = quat.multiply(quat.multiply(p, q), r)
    right = quat.multiply(p, quat.multiply(q, r))
    np.testing.assert_allclose(left, right, atol=1e-15)


@given(unit_quaternions(), vectors)
def test_rotate_is_matrix_product(q, v):
    np.testing.assert_allclose(quat.rotate(q, v), as_matrix(q) @ v, atol=1e-12 * (1 + np.abs(v).max()))
    assert abs(np.linalg.norm(quat.rotate(q, v)) - np.linalg.norm(v)) <= 1e-12 * (1 + np.linalg.norm(v))


@given(arrays(np.float64, 4, elements=st.floats(-1e3, 1e3, allow_nan=False)).filter(lambda q: np.any(q != 0)))
def test_canonical_idempotent_and_sign_invariant(q):
    c = quat.canonical(q)
    assert quat.canonical(c).tobytes() == c.tobytes()
    assert quat.canonical(-q).tobytes() == c.tobytes()
    assert c[0] > 0 or (c[0] == 0 and (c[1] > 0 or (c[1] == 0 and (c[2] > 0 or (c[2] == 0 and c[3] > 0)))))


@given(unit_quaternions())
def test_exp_log_inverse(q):
    np.testing.assert_allclose(quat.exp(quat.log(q)), q, atol=1e-15)


@given(unit_quaternions(), st.sampled_from(["ZYX", "ZXY", "XYX", "zyz", "xyz", "yzx"]))
@settings(max_examples=200)
def test_euler_round_trip_any_rotation(q, seq):
    assert rotation_angle(from_euler(as_euler(q, seq), seq), q) <= 3e-15


@given(unit_quaternions())
def test_matrix_and_rotvec_round_trips(q):
    assert rotation_angle(from_matrix(as_matrix(q)), q) <= 2e-15
    assert rotation_angle(from_rotvec(as_rotvec(q)), q) <= 2e-15
