"""Finite input never gives a silent NaN, infinity or wrong finite number (issue 14, "silent NaN").

Each case is a reproduction from the issue: either the function now computes it in a scaled, overflow-free way
(the expected values are closed forms or scale invariance), or it refuses with a ValueError naming the argument
and the accepted range.
"""

import warnings

import numpy as np
import pytest

import strapdown as sd
from strapdown import quaternion as quat
from strapdown.fusion import tilt_from_up, tilt_rates
from strapdown.rotations.average import chordal_distance


def unit(q):
    q = np.asarray(q, dtype=np.float64)
    return q / np.linalg.norm(q)


Q = unit([0.8, -0.3, 0.4, 0.2])


# --- norms, products, exponentials -------------------------------------------------------------------------------
def test_norm_of_huge_and_tiny_quaternions_is_exact():
    np.testing.assert_array_equal(
        quat.norm([[1e200, 0, 0, 0], [1e-200, 0, 0, 0], [5e-324, 0, 0, 0]]), [1e200, 1e-200, 5e-324]
    )
    np.testing.assert_allclose(quat.norm([3e200, 0, 4e200, 0]), 5e200, rtol=1e-15)
    f32 = quat.norm(np.array([1e30, 0, 0, 1e30], dtype=np.float32))
    assert f32.dtype == np.float32 and np.isclose(f32, np.sqrt(2) * 1e30, rtol=1e-6)


def test_product_beyond_the_float_range_is_refused():
    with pytest.raises(ValueError, match=r"p ⊗ q overflows: \|p\| = 1e\+200 and \|q\| = 1e\+200"):
        quat.multiply([1e200, 0, 0, 0], [1e200, 0, 0, 0])
    # a product that fits is computed, even from huge factors
    np.testing.assert_array_equal(quat.multiply([1e200, 0, 0, 0], [1e-200, 0, 0, 0]), [1.0, 0, 0, 0])


def test_exp_overflow_is_refused_with_the_range():
    with pytest.raises(ValueError, match=r"q has w = 800.*w must lie in \[-708.4, 709.8\]"):
        quat.exp([800.0, 0, 0, 0])
    np.testing.assert_allclose(quat.exp([700.0, 0, 0, 0])[0], np.e**700, rtol=1e-13)


def test_power_out_of_range_is_refused():
    with pytest.raises(ValueError, match=r"t ln\|q\| = 1386.29"):
        quat.power([2.0, 0, 0, 0], 2000)
    # q^1e20 of a unit q: its angle is lost to rounding (it used to return a zero quaternion)
    with pytest.raises(ValueError, match="rounding leaves the angle of the result unknown"):
        quat.power([0.0, 1.0, 0.0, 0.0], 1e20)  # |q| = 1 exactly: only the angle is lost
    with pytest.raises(ValueError, match=r"t ln\|q\| = -5.*underflows"):
        quat.power(Q, 1e20)  # |q| = 1 - 1e-16 to rounding: |q|^1e20 underflows
    np.testing.assert_allclose(quat.power([2.0, 0, 0, 0], 1000)[0], 2.0**1000, rtol=1e-12)


def test_series_normalisation_far_from_unit_is_refused():
    with pytest.raises(ValueError, match=r"\|q\|² = 1e\+200: the series normalisation is for \|q\|² within 0.5"):
        quat.normalize([1e100, 0, 0, 0], "series")


# --- rotations of any norm -----------------------------------------------------------------------------------------
@pytest.mark.parametrize("scale", [1e154, 1e200, 1e-200, 5e-300])
def test_rotation_functions_do_not_depend_on_the_norm(scale):
    v = np.array([0.3, -1.2, 2.0])
    r = np.array(
        [
            [1 - 2 * (Q[2] ** 2 + Q[3] ** 2), 2 * (Q[1] * Q[2] - Q[0] * Q[3]), 2 * (Q[1] * Q[3] + Q[0] * Q[2])],
            [2 * (Q[1] * Q[2] + Q[0] * Q[3]), 1 - 2 * (Q[1] ** 2 + Q[3] ** 2), 2 * (Q[2] * Q[3] - Q[0] * Q[1])],
            [2 * (Q[1] * Q[3] - Q[0] * Q[2]), 2 * (Q[2] * Q[3] + Q[0] * Q[1]), 1 - 2 * (Q[1] ** 2 + Q[2] ** 2)],
        ]
    )
    big = Q * scale
    np.testing.assert_allclose(quat.rotate(big, v), r @ v, atol=1e-14)
    np.testing.assert_allclose(sd.as_matrix(big), r, atol=1e-15)
    np.testing.assert_allclose(sd.as_euler(big, "ZYX"), sd.as_euler(Q, "ZYX"), atol=1e-14)
    np.testing.assert_allclose(sd.as_rotvec(big), sd.as_rotvec(Q), atol=1e-14)
    np.testing.assert_allclose(quat.normalize(big), Q, atol=1e-15)
    assert quat.angle_between(big, Q) < 1e-7


def test_compressed_angles_of_scaled_quaternions():
    # as_compressed skipped the norm check: q * 1e199 gave pitch 0 instead of -14.12 deg, 5e-324 gave -90 deg
    angles = np.array([30.0, -14.12, 10.0])
    q = sd.from_compressed(angles, degrees=True)
    np.testing.assert_allclose(sd.as_compressed(q * 1e199, degrees=True), angles, atol=1e-10)
    np.testing.assert_allclose(sd.as_compressed([5e-324, 0, 0, 0], degrees=True), [0, 0, 0], atol=0)


def test_chordal_distance_off_the_unit_sphere_including_float32():
    theta = 0.7
    p = np.array([1.0, 0, 0, 0])
    q = np.array([np.cos(theta / 2), 0, np.sin(theta / 2), 0])
    want = 2 * np.sqrt(2) * np.sin(theta / 2)  # ‖R(p) - R(q)‖_F, closed form
    for scale in (5e9, 1e-12, 1e200):
        np.testing.assert_allclose(chordal_distance(p * scale, q), want, rtol=1e-12)
    for scale in (5e9, 1e-12):
        got = chordal_distance((p * scale).astype(np.float32), q.astype(np.float32))
        assert got.dtype == np.float32
        np.testing.assert_allclose(got, want, rtol=1e-6)


def test_gibbs_vector_that_overflows_is_refused():
    with pytest.raises(ValueError, match=r"too close to a 180° rotation \(w = 4.94e-324"):
        sd.as_gibbs([5e-324, 1.0, 0, 0])


def test_tilt_rates_that_overflow_are_refused():
    with pytest.raises(ValueError, match=r"e is too close to upside down \(e0 = 4.94e-324\)"):
        tilt_rates([5e-324, 1.0, 0, 0], [1.0, 1.0, 1.0])


def test_tilt_from_a_huge_up_vector_is_a_unit_tilt():
    # [1, 0, 1]: 45° about -y; the norm of [1e200, 0, 1e200] used to overflow to a tilt quaternion of norm 0.707
    want = [np.cos(np.pi / 8), 0.0, -np.sin(np.pi / 8), 0.0]
    np.testing.assert_allclose(tilt_from_up([1e200, 0, 1e200]), want, atol=1e-15)
    np.testing.assert_allclose(tilt_from_up([1e-200, 0, 1e-200]), want, atol=1e-15)


def test_from_rotvec_of_a_huge_vector_does_not_warn():
    with warnings.catch_warnings(), np.errstate(over="raise"):
        warnings.simplefilter("error")
        q = sd.from_rotvec([1e78, 0, 0])
    assert abs(np.linalg.norm(q) - 1) < 1e-15


# --- integration ------------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("method", ["rk4", "coning2", "dcm", "first-order", "second-order", "cayley", "exact"])
@pytest.mark.parametrize(("rate", "dt"), [(1e200, 0.01), (1.0, 1e300)])
def test_integration_of_unrepresentable_steps_is_refused(method, rate, dt):
    # rk4, coning2 and dcm returned NaN, first-order a zero quaternion
    with pytest.raises(ValueError, match=r"gyro sample 0 turns by .* rad in one step"):
        sd.integrate(np.full((10, 3), rate), dt=dt, method=method)


def test_large_but_representable_steps_still_integrate():
    # 1e6 rad per step is far inside the limit: the exact method gives the closed-form angle mod 4π
    q = sd.integrate(np.array([[1e8, 0.0, 0.0]]), dt=0.01, method="exact")[-1]
    np.testing.assert_allclose(q, [np.cos(5e5), np.sin(5e5), 0, 0], atol=1e-9)


# --- fusion filters -----------------------------------------------------------------------------------------------
def _filters():
    from strapdown.fusion import AttitudeEstimator, Complementary, Madgwick, Mahony, TiltEstimator

    return [TiltEstimator, Mahony, Madgwick, Complementary, AttitudeEstimator]


def _still(n=60, dtype=np.float64):
    return np.zeros((n, 3), dtype), np.tile(np.array([0.0, 0.0, 9.81], dtype), (n, 1))


@pytest.mark.parametrize("cls", _filters(), ids=lambda c: c.__name__)
@pytest.mark.parametrize(
    ("what", "match"),
    [
        ("gyro", r"gyro\[10\] = \[1e\+300, .* is beyond 1e\+100"),
        ("acc", r"acc\[10\] = \[1e\+300, .* is beyond 1e\+100"),
        ("dt", r"sample 0 lasts 1e\+300 s, beyond 1e\+09 s"),
        ("step", r"gyro\[10\] turns by 1e\+13 rad in one sample"),
    ],
)
def test_filters_refuse_samples_no_sensor_gives(cls, what, match):
    # every filter returned NaN from a 1e300 gyro sample; Tilt and Attitude also from acc, Attitude from dt
    g, a = _still()
    dt = 0.01
    if what == "gyro":
        g[10] = 1e300
    elif what == "acc":
        a[10] = 1e300
    elif what == "dt":
        dt = 1e300
    else:
        g[10], dt = 1e15, 0.01
    with pytest.raises(ValueError, match=match):
        cls().update(g, a, dt=dt)


@pytest.mark.parametrize("cls", _filters(), ids=lambda c: c.__name__)
def test_filters_at_the_edge_of_the_range_stay_finite(cls):
    for change in ("gyro", "acc", "dt"):
        g, a = _still()
        dt = 0.01
        if change == "gyro":
            g[10], dt = 1e100, 1e-95  # a huge rate over a tiny step: 1e5 rad
        elif change == "acc":
            a[10] = 1e100
        else:
            dt = 1e9
        est = cls().update(g, a, dt=dt)
        assert np.isfinite(est.q).all(), change
        np.testing.assert_allclose(np.linalg.norm(est.q, axis=-1), 1, atol=1e-12)


@pytest.mark.parametrize("cls", _filters(), ids=lambda c: c.__name__)
def test_filters_keep_float32(cls):
    g, a = _still(dtype=np.float32)
    est = cls().update(g, a, dt=0.01)
    assert est.q.dtype == np.float32
    assert est.bias is None or est.bias.dtype == np.float32
    whole = cls().update(g.astype(np.float64), a.astype(np.float64), dt=0.01)
    np.testing.assert_allclose(est.q, whole.q, atol=1e-7)


def test_a_diverging_chunk_is_reported_and_the_state_kept(monkeypatch):
    from strapdown.fusion import Mahony

    g, a = _still()
    f = Mahony()
    f.update(g, a, dt=0.01)
    before = f.state
    real = Mahony._run

    def poisoned(self, *args):
        out = real(self, *args)
        out.q[7:] = np.nan  # as a kernel overflow would
        return out

    monkeypatch.setattr(Mahony, "_run", poisoned)
    with pytest.raises(ValueError, match="the filter diverged at sample 7"):
        f.update(g, a, dt=0.01)
    after = f.state
    np.testing.assert_array_equal(after["q"], before["q"])
    assert after["_t_last"] == before["_t_last"]


# --- vector observations, metrics -----------------------------------------------------------------------------------
@pytest.mark.parametrize("solver", ["quest", "davenport"])
@pytest.mark.parametrize("w", [1e200, 1e-200, 1.0])
def test_wahba_covariance_scales_with_any_weight(solver, w):
    from strapdown import wahba

    b = np.array([[1.0, 0, 0], [0, 1.0, 0]])
    # N = w [(I - x xᵀ) + (I - y yᵀ)] = w diag(1, 1, 2): P = N⁻¹ (Shuster), closed form; was inf at 1e±200
    q, cov = getattr(wahba, solver)(b, b, weights=[w, w], return_covariance=True)
    np.testing.assert_array_equal(q, [1.0, 0, 0, 0])
    np.testing.assert_allclose(cov, np.diag([1 / w, 1 / w, 0.5 / w]), rtol=1e-14, atol=0)


def test_wahba_covariance_that_overflows_is_refused():
    from strapdown.rotations.wahba import quest

    b = np.array([[1.0, 0, 0], [0, 1.0, 0]])
    with pytest.raises(ValueError, match=r"covariance overflows float64: the weights \(largest 1e-320\)"):
        quest(b, b, weights=[1e-320, 1e-320], return_covariance=True)


def test_allan_deviation_is_linear_in_x_at_any_scale():
    from strapdown.evaluate.metrics import allan_deviation

    # alternating ±c: the first cluster pair differs by 2c, so adev(1 sample) = √(4c²/2) = c√2 (closed form)
    for c in (1e200, 1e-300, 1.0, 1e308):  # 1e308: the mean of the samples alone overflowed
        _, adev = allan_deviation(np.array([c, -c] * 50), fs=10.0, taus=[0.1, 0.2])
        np.testing.assert_allclose(adev, [c * np.sqrt(2), 0.0], rtol=1e-14, atol=0)
    _, adev = allan_deviation(np.array([1.0, -1.0] * 50), fs=1e300, taus=[1e-300])
    np.testing.assert_allclose(adev, [np.sqrt(2)], rtol=1e-14)


def test_error_quaternion_of_huge_norms_and_names():
    from strapdown.evaluate.metrics import error_quaternion

    got = error_quaternion([[1e200, 0, 0, 1e199], [np.nan] * 4], [1.0, 0, 0, 0])
    np.testing.assert_allclose(got[0], unit([1.0, 0, 0, 0.1]), atol=1e-15)
    assert np.isnan(got[1]).all()  # occluded truth stays NaN
    with pytest.raises(ValueError, match=r"q_est\[0\] is a zero quaternion"):
        error_quaternion([[0.0, 0, 0, 0]], [[1.0, 0, 0, 0]])
    with pytest.raises(ValueError, match=r"q_est and q_ref do not broadcast"):
        error_quaternion(np.ones((2, 4)), np.ones((3, 4)))
