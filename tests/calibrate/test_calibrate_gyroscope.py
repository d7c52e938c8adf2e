"""Gyro calibration (bias from rests, scale and coupling against a reference) and the Allan analysis, on
simulated gyros with exact truth."""

import numpy as np
import pytest
import scipy.signal

from strapdown.calibrate import InsufficientMotionError, allan, gyroscope, rates_from_attitude
from strapdown.fusion import AttitudeParams
from strapdown.simulate import ImuModel, RandomMotion, sample
from strapdown.simulate.imu import TriadModel, corrupt


def gyro_model():
    mis = np.array([[0, 0.002, -0.001], [0.003, 0, 0.0015], [-0.002, 0.001, 0]])
    return TriadModel(
        bias=np.radians([0.3, -0.4, 0.2]),
        noise_density=np.radians(0.007),
        scale_factor=[0.005, -0.003, 0.004],
        misalignment=mis,
    )


def test_bias_from_rests():
    rng = np.random.default_rng(0)
    model = gyro_model()
    fs = 100.0
    truth = np.zeros((3000, 3))
    truth[1000:2000] = 2.0 * np.sin(np.linspace(0, 20, 1000))[:, None]  # 10 s of turning between two rests
    gyro = corrupt(model, truth, 1 / fs, "average", rng)
    cal = gyroscope(gyro, fs=fs)
    assert len(cal.quality["rests"]) == 2
    assert np.all(np.abs(cal.offset - model.bias) < 4 * cal.offset_sigma)
    # white noise: the reported sigma is the noise density over √(rest seconds)
    rest_seconds = cal.quality["samples"] / fs
    np.testing.assert_allclose(cal.offset_sigma, model.noise_density / np.sqrt(rest_seconds), rtol=0.15)
    with pytest.raises(InsufficientMotionError, match="no rest found"):
        gyroscope(gyro[1000:2000], fs=fs)


def test_scale_and_coupling_against_a_reference_attitude():
    data = sample(RandomMotion(duration=60.0, seed=3, rate_scale=2.0), 200.0, imu=ImuModel(gyro=gyro_model()))
    model = gyro_model()
    cal = gyroscope(data.gyro, fs=200.0, reference_attitude=data.q_true)
    q = cal.quality
    assert np.all(np.abs(cal.offset - model.bias) < 4.5 * cal.offset_sigma)
    assert np.all(np.abs(np.array(q["scale_factor"]) - model.scale_factor) < 4.5 * np.array(q["scale_factor_sigma"]))
    off = ~np.eye(3, dtype=bool)
    err = np.abs(np.array(q["misalignment"])[off] - model.misalignment[off])
    assert np.all(err < 4.5 * np.array(q["misalignment_sigma"])[off])
    # the rates of the true attitude are the steps' rotation vectors over their duration
    ideal = sample(RandomMotion(duration=2.0, seed=3, rate_scale=2.0), 200.0, gyro="rotvec")
    np.testing.assert_allclose(rates_from_attitude(ideal.q_true, 200.0), ideal.gyro * 200.0, atol=1e-9)


def test_reference_turning_about_one_axis_is_refused():
    rng = np.random.default_rng(1)
    w = np.zeros((2000, 3))
    w[:, 2] = np.radians(90) * np.sin(np.linspace(0, 30, 2000))  # a turntable about z only
    gyro = corrupt(gyro_model(), w, 0.01, "average", rng)
    with pytest.raises(InsufficientMotionError, match=r"hardly turns about sensor axis .*\(≈ [xy]\)"):
        gyroscope(gyro, reference_rate=w)


def flicker(n, fs, b, rng, axes=3):
    """Bias-instability noise: rate PSD B²/(2π f) (two-sided, IEEE Std 952 Table C.1) by spectral shaping of
    white noise; generated 4x longer and cut, so the circular FFT's period does not shorten the slow part."""
    big = 4 * n
    f = np.fft.rfftfreq(big, 1 / fs)
    psd = np.zeros_like(f)
    psd[1:] = b**2 / (2 * np.pi * f[1:])
    spec = np.sqrt(big * fs * psd)[:, None] * (
        rng.standard_normal((len(f), axes)) + 1j * rng.standard_normal((len(f), axes))
    )
    return np.fft.irfft(spec / np.sqrt(2), big, axis=0)[:n]


def test_flicker_generator_has_the_stated_spectrum():
    rng = np.random.default_rng(2)
    fs, b = 50.0, 3e-5
    x = flicker(2**18, fs, b, rng, axes=1)[:, 0]
    f, pxx = scipy.signal.welch(x, fs, nperseg=2**12, return_onesided=True)
    band = (f > 0.1) & (f < 10)
    # welch's one-sided density is twice the two-sided B²/(2πf)
    ratio = pxx[band] / (2 * b**2 / (2 * np.pi * f[band]))
    assert np.median(ratio) == pytest.approx(1.0, abs=0.1)


def test_allan_reads_back_arw_bias_instability_and_rrw():
    """Known N, B and K, each dominating a decade of τ: all three within their 95 % intervals on all axes."""
    n_true, b_true, k_true, fs = 1e-4, 3e-5, 3e-6, 50.0
    n = int(3 * 3600 * fs)
    rng = np.random.default_rng(7)
    x = n_true * np.sqrt(fs) * rng.standard_normal((n, 3)) + flicker(n, fs, b_true, rng)
    x += np.cumsum(k_true / np.sqrt(fs) * rng.standard_normal((n, 3)), axis=0)
    r = allan(x, fs)
    for value, interval, truth in (
        (r.arw, r.arw_interval, n_true),
        (r.bias_instability, r.bias_instability_interval, b_true),
        (r.rate_random_walk, r.rate_random_walk_interval, k_true),
    ):
        assert np.all((interval[:, 0] <= truth) & (truth <= interval[:, 1])), (value, interval, truth)
        assert np.all(interval[:, 0] < value) and np.all(value < interval[:, 1])
    # the measured curve follows the closed form N²/τ + (2 ln 2/π) B² + K² τ/3 of IEEE Std 952 (Table C.1)
    closed = np.sqrt(n_true**2 / r.taus + 2 * np.log(2) / np.pi * b_true**2 + k_true**2 * r.taus / 3)
    # from 1 s (the flicker's Nyquist cut-off no longer shows) to 30 s (over 1000 clusters: a few per cent)
    short = (r.taus > 1) & (r.taus < 30)
    np.testing.assert_allclose(r.adev[short], np.broadcast_to(closed[short, None], r.adev[short].shape), rtol=0.06)
    model = r.triad_model()
    assert model.noise_density == pytest.approx(n_true, rel=0.01)
    params = AttitudeParams(**r.estimator_params())
    assert params.bias_noise_rest == pytest.approx(n_true, rel=0.01)


def test_allan_of_the_simulator_gyro_matches_its_model():
    """The simulator's white noise and rate random walk (exact by construction) are read back."""
    imu = ImuModel(gyro=TriadModel(noise_density=2e-4, bias_random_walk=2e-5))
    rng = np.random.default_rng(3)
    fs = 20.0
    gyro = corrupt(imu.gyro, np.zeros((int(4000 * fs), 3)), 1 / fs, "average", rng)
    r = allan(gyro, fs)
    assert np.all((r.arw_interval[:, 0] <= 2e-4) & (2e-4 <= r.arw_interval[:, 1]))
    assert np.all((r.rate_random_walk_interval[:, 0] <= 2e-5) & (2e-5 <= r.rate_random_walk_interval[:, 1]))
    assert np.all(r.bias_instability_interval[:, 0] == 0)  # no flicker simulated: B's interval reaches 0
    assert np.all(r.bias_instability_interval[:, 1] < 1e-4)  # and stays below the curve's floor / 0.664


def test_allan_rejects_short_input():
    with pytest.raises(ValueError, match="at least 64"):
        allan(np.zeros((10, 3)), 100.0)


def test_allan_bias_calibration():
    rng = np.random.default_rng(4)
    fs, n_true, bias = 20.0, 2e-4, np.array([0.01, -0.02, 0.003])
    gyro = bias + n_true * np.sqrt(fs) * rng.standard_normal((int(2000 * fs), 3))
    r = allan(gyro, fs)
    cal = r.calibration()
    # white noise only: the mean of T seconds scatters by N/√T
    np.testing.assert_allclose(cal.offset_sigma, n_true / np.sqrt(2000.0), rtol=0.1)
    assert np.all(np.abs(cal.offset - bias) < 4 * cal.offset_sigma)
    np.testing.assert_allclose(r.apply(gyro).mean(axis=0), 0.0, atol=1e-12)
