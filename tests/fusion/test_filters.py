"""The classic filters: Madgwick (against the gradient of its own cost, written here from the paper), Mahony and
the quaternion complementary filter (against simulated truth), and what every filter shares (frames, chunking,
state, errors)."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from strapdown import change_frame
from strapdown.evaluate.metrics import attitude_errors
from strapdown.fusion import (
    FLAG_ACC_REJECTED,
    AttitudeEstimator,
    Complementary,
    ComplementaryParams,
    Madgwick,
    MadgwickParams,
    Mahony,
    MahonyParams,
    TiltEstimator,
    initial_attitude,
)
from strapdown.simulate import RandomMotion, sample

G = 9.80665
FILTERS = [Complementary, Mahony, Madgwick]


def wxyz(r):
    return r.as_quat()[..., [3, 0, 1, 2]]


DIP = np.radians(66.0)  # magnetic dip, as in central Europe


def still(q_true, n, dip=DIP):
    """n samples of a sensor at rest with attitude q_true (sensor to ENU): gyro, acc, mag."""
    r = Rotation.from_quat(np.asarray(q_true)[[1, 2, 3, 0]])
    up = r.inv().apply([0.0, 0.0, G])
    field = r.inv().apply([0.0, 48.0 * np.cos(dip), -48.0 * np.sin(dip)])  # north and down, µT
    return np.zeros((n, 3)), np.tile(up, (n, 1)), np.tile(field, (n, 1))


def error_deg(q, q_true):
    return {k: float(np.degrees(v)) for k, v in attitude_errors(q, q_true).items()}


# --- Madgwick: one step is the normalised gradient step of the paper's cost -------------------------------------


def madgwick_residual(q, a, m, b, half_field):
    """The paper's f_g and f_b (Madgwick 2010, eqs. (25), (29)) as polynomials in q, NWU earth frame."""
    q0, q1, q2, q3 = q
    k = 1.0 if half_field else 2.0  # the C code's _2bx holds b_x: its predicted field has half the length
    bx, bz = b
    return np.array(
        [
            2 * (q1 * q3 - q0 * q2) - a[0],
            2 * (q0 * q1 + q2 * q3) - a[1],
            2 * (0.5 - q1**2 - q2**2) - a[2],
            k * bx * (0.5 - q2**2 - q3**2) + k * bz * (q1 * q3 - q0 * q2) - m[0],
            k * bx * (q1 * q2 - q0 * q3) + k * bz * (q0 * q1 + q2 * q3) - m[1],
            k * bx * (q0 * q2 + q1 * q3) + k * bz * (0.5 - q1**2 - q2**2) - m[2],
        ]
    )


@pytest.mark.parametrize("variant", ["corrected", "reference"])
def test_madgwick_step_is_the_normalised_gradient(variant, rng):
    beta, dt = 0.3, 0.01
    for _ in range(20):
        q = wxyz(Rotation.random(random_state=int(rng.integers(1 << 30))))
        a = rng.standard_normal(3)
        a /= np.linalg.norm(a)
        m = rng.standard_normal(3)
        m /= np.linalg.norm(m)
        h = Rotation.from_quat(q[[1, 2, 3, 0]]).apply(m)  # the measured field in the earth frame
        b = (np.hypot(h[0], h[1]), h[2])

        def cost(x, a=a, m=m, b=b):
            return 0.5 * np.sum(madgwick_residual(x, a, m, b, variant == "reference") ** 2)

        step = 1e-6
        grad = np.array([(cost(q + step * e) - cost(q - step * e)) / (2 * step) for e in np.eye(4)])
        expected = q - beta * dt * grad / np.linalg.norm(grad)
        expected /= np.linalg.norm(expected)
        f = Madgwick(MadgwickParams(beta=beta, variant=variant), q0=q, frame="NWU")
        out = f.update(np.zeros((1, 3)), a[None] * G, m[None] * 50.0, dt=dt).q[0]
        np.testing.assert_allclose(out, expected, atol=1e-9)


def test_the_two_madgwick_variants_differ_only_with_a_magnetometer():
    data = sample(RandomMotion(duration=20.0, seed=4), 100.0, gyro="rate", reference="ENU", body="FLU")
    runs = {v: Madgwick(MadgwickParams(variant=v)) for v in ("corrected", "reference")}
    six = [f.update(data.gyro, data.acc, dt=0.01).q for f in runs.values()]
    np.testing.assert_array_equal(six[0], six[1])
    nine = [Madgwick(MadgwickParams(variant=v)).update(data.gyro, data.acc, data.mag, dt=0.01).q for v in runs]
    assert np.max(np.abs(nine[0] - nine[1])) > 1e-3


# --- convergence on exact data ----------------------------------------------------------------------------------


@pytest.mark.parametrize("cls", FILTERS)
def test_filters_converge_from_a_wrong_start(cls):
    q_true = wxyz(Rotation.from_euler("ZYX", [0.7, 0.3, -0.4]))
    g, a, m = still(q_true, 60000)  # 600 s from 44° off: Mahony's integral winds up and needs 400 s
    nine = cls(q0=[1.0, 0, 0, 0]).update(g, a, m, dt=0.01)
    six = cls(q0=[1.0, 0, 0, 0]).update(g, a, dt=0.01)
    e9, e6 = error_deg(nine.q[-1], q_true), error_deg(six.q[-1], q_true)
    # Madgwick's step has the fixed length β dt, so it chatters about the optimum by up to 2 β dt (0.115°);
    # the others settle exponentially (complementary: 12 time constants of the heading)
    tol = np.degrees(2 * 0.1 * 0.01) if cls is Madgwick else 1e-3
    assert e9["total"] < tol
    assert e6["inclination"] < tol
    assert abs(e6["heading"] - error_deg([1.0, 0, 0, 0], q_true)["heading"]) < 0.5  # 6D: heading stays put


@pytest.mark.parametrize("cls", FILTERS)
def test_start_from_the_first_sample_is_exact(cls):
    q_true = wxyz(Rotation.from_euler("ZYX", [2.0, -0.6, 1.1]))
    g, a, m = still(q_true, 200)
    est = cls().update(g, a, m, dt=0.01)
    assert error_deg(est.q[0], q_true)["total"] < 1e-9
    tol = 0.1 if cls is Madgwick else 1e-9
    assert error_deg(est.q[-1], q_true)["total"] < tol
    np.testing.assert_allclose(initial_attitude(a[0], m[0]), q_true * np.sign(q_true[0]), atol=1e-14)


def test_mahony_learns_the_bias_in_9d():
    q_true = wxyz(Rotation.from_euler("ZYX", [0.3, 0.2, 0.1]))
    bias = np.radians([0.5, -0.4, 0.3])
    g, a, m = still(q_true, 60000)  # 600 s: twelve bias time constants kp/ki
    est = Mahony().update(g + bias, a, m, dt=0.01)
    np.testing.assert_allclose(est.bias[-1], bias, rtol=1e-3)
    assert error_deg(est.q[-1], q_true)["total"] < 1e-3


def test_complementary_gate_and_time_constant():
    # from a 10° roll error the correction decays as exp(-t/τ_acc): after 2 τ it is e^-2 of the start
    q_true = np.array([1.0, 0, 0, 0])
    g, a, _ = still(q_true, 400)
    q0 = wxyz(Rotation.from_euler("x", 10.0, degrees=True))
    est = Complementary(ComplementaryParams(tau_acc=2.0), q0=q0).update(g, a, dt=0.01)
    assert error_deg(est.q[399], q_true)["inclination"] == pytest.approx(10.0 * np.exp(-2.0), rel=1e-3)
    a[100:110] *= 2.0  # 2 g shocks are left out with a 1 m/s² gate
    est = Complementary(ComplementaryParams(acc_gate=1.0)).update(g, a, dt=0.01)
    np.testing.assert_array_equal(np.flatnonzero(est.flags & FLAG_ACC_REJECTED), np.arange(100, 110))


# --- what every filter shares -----------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def motion():
    return sample(RandomMotion(duration=20.0, seed=9), 100.0, gyro="rate", reference="ENU", body="FLU")


@pytest.mark.parametrize("cls", [*FILTERS, TiltEstimator])
def test_output_frame_is_a_change_of_frame(cls, motion):
    mag = None if cls is TiltEstimator else motion.mag
    enu = cls().update(motion.gyro, motion.acc, mag, dt=0.01)
    ned = cls(frame="NED").update(motion.gyro, motion.acc, mag, dt=0.01)
    np.testing.assert_allclose(change_frame(enu.q, ref_from="ENU", ref_to="NED"), ned.q, atol=1e-12)


@pytest.mark.parametrize("cls", FILTERS)
@pytest.mark.parametrize("nine", [False, True])
def test_chunks_and_state_give_the_same_result(cls, nine, motion):
    mag = motion.mag if nine else None
    whole = cls().update(motion.gyro, motion.acc, mag, dt=0.01)
    f = cls()
    parts, start = [], 0
    for size in (1, 0, 13, 700):
        sl = slice(start, start + size)
        parts.append(f.update(motion.gyro[sl], motion.acc[sl], None if mag is None else mag[sl], dt=0.01).q)
        start += size
    g = cls()
    g.state = f.state
    parts.append(g.update(motion.gyro[start:], motion.acc[start:], None if mag is None else mag[start:], dt=0.01).q)
    np.testing.assert_array_equal(np.concatenate(parts), whole.q)
    np.testing.assert_array_equal(g.attitude, whole.q[-1])


@pytest.mark.parametrize("cls", [*FILTERS, TiltEstimator, AttitudeEstimator])
def test_an_empty_chunk_has_the_fields_of_a_full_one(cls, motion):
    # before the first sample and after it, so that streaming callers need no special case
    full = cls().update(motion.gyro[:5], motion.acc[:5], dt=0.01)
    f = cls()
    for _ in range(2):
        empty = f.update(motion.gyro[:0], motion.acc[:0], dt=0.01)
        for name in ("bias", "flags"):
            got, want = getattr(empty, name), getattr(full, name)
            assert (got is None) == (want is None), name
            if want is not None:
                assert got.shape == (0, *want.shape[1:]) and got.dtype == want.dtype, name
        assert empty.q.shape == (0, 4)
        f.update(motion.gyro[:5], motion.acc[:5], dt=0.01)


@pytest.mark.parametrize("cls", FILTERS)
def test_bad_input_is_named(cls):
    g, a, m = still(np.array([1.0, 0, 0, 0]), 5)
    with pytest.raises(ValueError, match="acc has 4 samples but gyro has 5"):
        cls().update(g, a[:4], dt=0.01)
    with pytest.raises(ValueError, match="mag has 3 samples"):
        cls().update(g, a, m[:3], dt=0.01)
    f = cls()
    f.update(g, a, dt=0.01)
    with pytest.raises(ValueError, match="started without magnetometer"):
        f.update(g, a, m, dt=0.01)
    f = cls()
    f.update(g, a, m, dt=0.01)
    with pytest.raises(ValueError, match="created for magnetometer data"):
        f.update(g, a, dt=0.01)
    bad = a.copy()
    bad[2, 2] = np.inf
    with pytest.raises(ValueError, match=r"acc\[2, 2\] is infinite"):
        cls().update(g, bad, dt=0.01)
    with pytest.raises(ValueError, match="dt must be a scalar or have one entry per sample"):
        cls().update(g, a, dt=[0.01, 0.01])
    with pytest.raises(ValueError, match="q0"):
        cls(q0=[0.0, 0, 0, 0])
    with pytest.raises(ValueError, match="state must be a dict"):
        cls().state = {"x": 1}
    # a state from another kind of filter, or a damaged one, is refused rather than failing later
    other = (Mahony if cls is not Mahony else Madgwick)()
    other.update(g, a, dt=0.01)
    with pytest.raises(ValueError, match=f"taken from the .state of a {cls.__name__}"):
        cls().state = other.state
    f = cls()
    f.update(g, a, dt=0.01)
    damaged = f.state
    damaged["q"] = np.zeros(4)
    with pytest.raises(ValueError, match="state\\['q'\\]"):
        cls().state = damaged


def test_parameter_objects_reject_bad_values():
    with pytest.raises(ValueError, match="beta"):
        MadgwickParams(beta=-0.1)
    with pytest.raises(ValueError, match="variant"):
        MadgwickParams(variant="original")
    with pytest.raises(ValueError, match="ki"):
        MahonyParams(ki=float("nan"))
    with pytest.raises(ValueError, match="bias0"):
        MahonyParams(bias0=(0.0, 0.0))
    with pytest.raises(ValueError, match="tau_mag"):
        ComplementaryParams(tau_mag=-1.0)
