"""IMU error models: every statistic is checked against the model parameter it should reproduce.

Tolerances come from the sample sizes: the mean of n samples of std σ has std σ/√n, a sample std has relative
std 1/√(2n), a sample variance 2/√(2n).  Bounds are 4-9 of those standard deviations, so a correct model fails
with negligible probability and the seeded generators make every run identical anyway.
"""

import numpy as np
import pytest

from strapdown.evaluate.metrics import allan_deviation
from strapdown.simulate.imu import KINDS, ClockModel, ImuModel, TriadModel, apply_clock, corrupt

G = 9.80665


@pytest.fixture
def truth(rng):
    return rng.uniform(-5, 5, (1000, 3))


# ---------------------------------------------------------------------------------------------- deterministic part


@pytest.mark.parametrize("kind", KINDS)
def test_ideal_model_returns_truth_exactly(truth, kind, rng):
    ideal = ImuModel.ideal()
    for model in (ideal.gyro, ideal.acc, ideal.mag, TriadModel()):
        out = corrupt(model, truth, 0.01, kind, rng)
        assert out.dtype == np.float64 and out.shape == truth.shape
        assert np.array_equal(out, truth)


@pytest.mark.parametrize("kind", KINDS)
def test_linear_errors_are_the_matrix_product(truth, kind, rng):
    scale = np.array([0.01, -0.02, 0.005])
    mis = np.array([[0, 1e-3, -2e-3], [3e-3, 0, 1e-3], [-1e-3, 2e-3, 0]])
    soft = np.array([[1.1, 0.05, 0.0], [0.05, 0.9, -0.02], [0.0, -0.02, 1.05]])
    out = corrupt(TriadModel(scale_factor=scale, misalignment=mis, soft_iron=soft), truth, 0.01, kind, rng)
    # reading_i = Σ_j soft_ij Σ_l ((1 + s_j) δ_jl + M_jl) truth_l, written out element by element
    inner = np.empty_like(truth)
    for j in range(3):
        inner[:, j] = (1 + scale[j]) * truth[:, j] + sum(mis[j, i] * truth[:, i] for i in range(3))
    expected = np.stack([sum(soft[i, j] * inner[:, j] for j in range(3)) for i in range(3)], axis=1)
    np.testing.assert_allclose(out, expected, rtol=1e-14, atol=1e-14)


def test_constant_bias_scales_with_the_step_for_increments(truth, rng):
    bias = np.array([0.1, -0.2, 0.3])
    h = rng.uniform(0.001, 0.02, truth.shape[0])
    model = TriadModel(bias=bias)
    np.testing.assert_allclose(corrupt(model, truth, h, "rate", rng), truth + bias, rtol=0, atol=1e-15)
    np.testing.assert_allclose(corrupt(model, truth, h, "average", rng), truth + bias, rtol=0, atol=1e-15)
    np.testing.assert_allclose(
        corrupt(model, truth, h, "increment", rng), truth + bias * h[:, None], rtol=0, atol=1e-15
    )


def test_quantisation_gives_multiples_within_half_an_lsb(truth, rng):
    res = 0.061
    out = corrupt(TriadModel(resolution=res), truth, 0.01, "rate", rng)
    counts = out / res
    assert np.abs(counts - np.round(counts)).max() < 1e-9
    assert np.abs(out - truth).max() <= res / 2 + 1e-12
    assert len(np.unique(np.round(counts))) > 100  # not all collapsed onto a few levels


def test_quantisation_of_increments_uses_the_increment_lsb(rng):
    h = 0.01
    inc = rng.uniform(-0.05, 0.05, (1000, 3))
    res = 1e-4  # an angle LSB, not a rate LSB
    out = corrupt(TriadModel(resolution=res), inc, h, "increment", rng)
    assert np.abs(out / res - np.round(out / res)).max() < 1e-9
    assert np.abs(out - inc).max() <= res / 2 + 1e-15


def test_saturation_clips(truth, rng):
    out = corrupt(TriadModel(range=2.0), truth, 0.01, "average", rng)
    np.testing.assert_array_equal(out, np.clip(truth, -2, 2))
    h = rng.uniform(0.5, 1.5, truth.shape[0])
    out = corrupt(TriadModel(range=2.0), truth, h, "increment", rng)
    lim = 2.0 * h[:, None]
    np.testing.assert_array_equal(out, np.minimum(np.maximum(truth, -lim), lim))


def test_saturated_and_quantised_readings_stay_inside_the_range(rng):
    # 2000 deg/s is not a whole number of 0.061 deg/s LSBs (32786.9), and exactly 32800 LSBs of 1/16.4 in
    # decimal but not in binary: either way the reading must not exceed the range
    top = 2000.0
    truth = np.array([[2500.0, -2500.0, 1999.99], [1e6, -1e6, 0.0]])
    for res, counts in ((0.061, 32786), (1 / 16.4, 32800)):
        out = corrupt(TriadModel(resolution=res, range=top), truth, 0.01, "rate", rng)
        assert np.abs(out).max() <= top
        np.testing.assert_allclose(np.abs(out[:, :2]), counts * res, rtol=1e-15)
        assert np.abs(out / res - np.round(out / res)).max() < 1e-9


def test_same_rng_state_same_result(truth):
    model = ImuModel.consumer_mems().gyro
    a = corrupt(model, truth, 0.01, "rate", np.random.default_rng(7))
    b = corrupt(model, truth, 0.01, "rate", np.random.default_rng(7))
    c = corrupt(model, truth, 0.01, "rate", np.random.default_rng(8))
    assert np.array_equal(a, b) and not np.array_equal(a, c)


# ------------------------------------------------------------------------------------------------ statistics


def test_constant_bias_is_the_mean_error(rng):
    n, sigma_rate, fs = 100_000, 0.02, 100.0
    bias = np.array([0.01, -0.004, 0.002])
    model = TriadModel(bias=bias, noise_density=sigma_rate / np.sqrt(fs))
    truth = rng.uniform(-1, 1, (n, 3))
    err = corrupt(model, truth, 1 / fs, "rate", rng) - truth
    # the sample mean has std σ/√n
    assert np.all(np.abs(err.mean(axis=0) - bias) < 5 * sigma_rate / np.sqrt(n))


@pytest.mark.parametrize("kind", ["rate", "average"])
def test_white_noise_std_is_density_times_sqrt_fs(kind, rng):
    n, fs, density = 100_000, 200.0, 3e-3
    err = corrupt(TriadModel(noise_density=density), np.zeros((n, 3)), 1 / fs, kind, rng)
    ratio = err.std(axis=0) / (density * np.sqrt(fs))
    # relative std of a sample std: 1/√(2n) = 0.22 %
    assert np.all(np.abs(ratio - 1) < 0.02), ratio
    assert np.all(np.abs(err.mean(axis=0)) < 5 * density * np.sqrt(fs) / np.sqrt(n))


def test_white_noise_follows_each_step(rng):
    n, density = 100_000, 1e-3
    h = rng.uniform(0.001, 0.1, n)
    zeros = np.zeros((n, 3))
    rate = corrupt(TriadModel(noise_density=density), zeros, h, "average", rng)
    inc = corrupt(TriadModel(noise_density=density), zeros, h, "increment", rng)
    rate_ratio = (rate / (density / np.sqrt(h))[:, None]).std(axis=0)
    inc_ratio = (inc / (density * np.sqrt(h))[:, None]).std(axis=0)
    assert np.all(np.abs(rate_ratio - 1) < 0.02), rate_ratio
    assert np.all(np.abs(inc_ratio - 1) < 0.02), inc_ratio


def test_allan_deviation_of_white_noise(rng):
    n, fs, density = 200_000, 100.0, 2e-3
    x = corrupt(TriadModel(noise_density=density), np.zeros((n, 3)), 1 / fs, "rate", rng)
    taus, adev = allan_deviation(x, fs, taus=np.array([1, 2, 5, 10, 20, 50, 100]) / fs)
    avar = (adev**2).mean(axis=1)  # pooled over the axes
    slope = np.polyfit(np.log(taus), 0.5 * np.log(avar), 1)[0]
    assert abs(slope + 0.5) < 0.05, slope
    # white noise of density D: adev(τ) = D/√τ, so D at τ = 1 s (a seed sweep: 1.3 % relative std per axis,
    # 0.75 % pooled; slope std 0.0014)
    _, at_1s = allan_deviation(x, fs, taus=[1.0])
    assert abs(np.sqrt((at_1s**2).mean()) / density - 1) < 0.05


def test_allan_deviation_of_rate_random_walk(rng):
    # fs = 10 Hz and 2e5 samples: 20000 s, so even τ = 200 s averages 100 intervals; a seed sweep of this setup
    # gives relative std 1.1 % (τ = 20 s) to 3.6 % (τ = 200 s) for the axis-pooled deviation, 0.012 in slope
    n, fs, k = 200_000, 10.0, 1e-3
    x = corrupt(TriadModel(bias_random_walk=k), np.zeros((n, 3)), 1 / fs, "average", rng)
    taus, adev = allan_deviation(x, fs, taus=[10.0, 20.0, 50.0, 100.0, 200.0])
    avar = (adev**2).mean(axis=1)
    slope = np.polyfit(np.log(taus), 0.5 * np.log(avar), 1)[0]
    assert abs(slope - 0.5) < 0.1, slope
    ratio = np.sqrt(avar[:4]) / (k * np.sqrt(taus[:4] / 3))
    assert np.all(np.abs(ratio - 1) < 0.10), ratio


def test_bias_random_walk_variance_grows_linearly(rng):
    runs, n, h, k = 400, 1001, 0.05, 2e-3
    model = TriadModel(bias=[1.0, 2.0, 3.0], bias_random_walk=k)
    end = np.array([corrupt(model, np.zeros((n, 3)), h, "rate", rng)[-1] for _ in range(runs)])
    walk = end - model.bias
    t_end = (n - 1) * h  # the last instant sample is taken at the start of the last step
    # 1200 values: the sample variance has relative std √(2/1200) = 4 %
    ratio = walk.var() / (k**2 * t_end)
    assert abs(ratio - 1) < 0.15, ratio


def test_bias_walk_over_a_step_is_the_exact_wiener_average(rng):
    # Means over [0, h] and [h, 2h] of a Wiener process from 0 have variances K² h/3 and K² (h + h/3); the
    # instant samples at 0 and h have 0 and K² h.  6000 values each: relative std 1.8 %.
    runs, h, k = 2000, 0.5, 0.1
    model = TriadModel(bias_random_walk=k)
    zeros = np.zeros((2, 3))
    avg = np.array([corrupt(model, zeros, h, "average", rng) for _ in range(runs)])
    inst = np.array([corrupt(model, zeros, h, "rate", rng) for _ in range(runs)])
    inc = np.array([corrupt(model, zeros, h, "increment", rng) for _ in range(runs)])
    var_avg = avg.reshape(runs, 2, 3).transpose(1, 0, 2).reshape(2, -1).var(axis=1)
    var_inc = inc.reshape(runs, 2, 3).transpose(1, 0, 2).reshape(2, -1).var(axis=1)
    np.testing.assert_allclose(var_avg / (k**2 * h), [1 / 3, 4 / 3], rtol=0.08)
    np.testing.assert_allclose(var_inc / (k**2 * h**3), [1 / 3, 4 / 3], rtol=0.08)
    assert np.all(inst[:, 0] == 0)
    assert abs(inst[:, 1].var() / (k**2 * h) - 1) < 0.08


def test_same_rng_state_gives_the_same_bias_path_for_every_kind():
    model = TriadModel(bias_random_walk=0.1)
    zeros = np.zeros((50, 3))
    inst = corrupt(model, zeros, 0.1, "rate", np.random.default_rng(3))
    avg = corrupt(model, zeros, 0.1, "average", np.random.default_rng(3))
    inc = corrupt(model, zeros, 0.1, "increment", np.random.default_rng(3))
    np.testing.assert_allclose(inc, 0.1 * avg, rtol=1e-14)
    # the mean over a step lies near the midpoint of the walk: its bridge part has std K √(h/12) = 0.009
    mid = 0.5 * (inst[:-1] + inst[1:])
    assert np.abs(avg[:-1] - mid).max() < 6 * 0.1 * np.sqrt(0.1 / 12)


# ---------------------------------------------------------------------------------------------------- clock


def test_clock_jitter_std(rng):
    n, h, jitter = 100_000, 0.01, 5e-4  # h/20: the truncation at ±h/2 = ±10σ never acts
    t = np.arange(n + 1) * h
    t_actual, t_recorded, keep = apply_clock(ClockModel(jitter=jitter), t, rng)
    offset = t_actual - t
    assert offset[0] == 0 and offset[-1] == 0
    ratio = offset[1:-1].std() / jitter
    assert abs(ratio - 1) < 0.05, ratio  # relative std 0.22 %
    assert np.array_equal(t_recorded, t_actual) and keep.all()


def test_clock_keeps_order_at_the_largest_jitter(rng):
    h = rng.uniform(0.005, 0.015, 100_000)
    t = np.concatenate([[0.0], np.cumsum(h)])
    t_actual, _, _ = apply_clock(ClockModel(jitter=0.999 * h.min() / 4), t, rng)
    assert np.all(np.diff(t_actual) > 0)


def test_clock_nominal_timestamps(rng):
    t = np.arange(1001) * 0.01
    t_actual, t_recorded, _ = apply_clock(ClockModel(jitter=1e-3, timestamps="nominal"), t, rng)
    assert np.array_equal(t_recorded, t)
    assert not np.array_equal(t_actual, t)


def test_clock_drops(rng):
    n, p = 100_000, 0.05
    t = np.arange(n + 1) * 0.01
    _, t_recorded, keep = apply_clock(ClockModel(drop_probability=p), t, rng)
    assert keep.shape == (n,) and keep[0]
    dropped = 1 - keep[1:].mean()
    assert abs(dropped - p) < 4 * np.sqrt(p * (1 - p) / (n - 1)), dropped
    times = t_recorded[np.append(keep, True)]
    assert times.shape == (keep.sum() + 1,) and np.all(np.diff(times) > 0)
    assert times[0] == t[0] and times[-1] == t[-1]
    assert np.array_equal(apply_clock(ClockModel(drop_probability=1.0), t[:5], rng)[2], [True, False, False, False])


# ---------------------------------------------------------------------------------------- datasheet conversions


def test_gyro_conversions():
    g = TriadModel.gyro(
        bias_deg_s=[0.3, -0.4, 0.2],
        rate_random_walk_deg_s_sqrt_s=0.002,
        arw_deg_sqrt_h=0.3,
        scale_factor_ppm=500,
        misalignment_deg=0.1,
        resolution_deg_s=0.061,
        range_deg_s=2000,
    )
    assert g.noise_density == pytest.approx(np.radians(0.3 / 60), rel=1e-15)
    np.testing.assert_allclose(g.bias, np.array([0.3, -0.4, 0.2]) * np.pi / 180, rtol=1e-15)
    assert g.bias_random_walk == pytest.approx(0.002 * np.pi / 180, rel=1e-15)
    np.testing.assert_allclose(g.scale_factor, [5e-4] * 3, rtol=1e-15)
    np.testing.assert_allclose(g.misalignment, 0.1 * np.pi / 180 * (1 - np.eye(3)), rtol=1e-15)
    assert g.resolution == pytest.approx(0.061 * np.pi / 180, rel=1e-15)
    assert g.range == pytest.approx(2000 * np.pi / 180, rel=1e-15)
    # ARW 0.42 deg/√h is the density 0.007 deg/s/√Hz
    a = TriadModel.gyro(noise_density_deg_s_sqrt_hz=0.007).noise_density
    assert a == pytest.approx(TriadModel.gyro(arw_deg_sqrt_h=0.42).noise_density, rel=1e-14)
    m = np.array([[0, 0.1, -0.2], [0.05, 0, 0.0], [0.0, 0.3, 0]])
    np.testing.assert_allclose(TriadModel.gyro(misalignment_deg=m).misalignment, np.radians(m), rtol=1e-15)


def test_accelerometer_conversions():
    a = TriadModel.accelerometer(
        bias_mg=20, rate_random_walk_mg_sqrt_s=0.03, vrw_m_s_sqrt_h=0.06, resolution_mg=0.488, range_g=16
    )
    assert a.noise_density == pytest.approx(0.06 / 60, rel=1e-15)
    np.testing.assert_allclose(a.bias, [0.02 * G] * 3, rtol=1e-15)
    assert a.bias_random_walk == pytest.approx(0.03e-3 * G, rel=1e-15)
    assert a.resolution == pytest.approx(0.488e-3 * G, rel=1e-15)
    assert a.range == pytest.approx(16 * G, rel=1e-15)
    b = TriadModel.accelerometer(noise_density_ug_sqrt_hz=150)
    assert b.noise_density == pytest.approx(150e-6 * G, rel=1e-15)
    with pytest.raises(ValueError, match="vrw_m_s_sqrt_h or noise_density_ug_sqrt_hz"):
        TriadModel.accelerometer(vrw_m_s_sqrt_h=0.06, noise_density_ug_sqrt_hz=150)
    with pytest.raises(ValueError, match="arw_deg_sqrt_h or noise_density_deg_s_sqrt_hz"):
        TriadModel.gyro(arw_deg_sqrt_h=0.1, noise_density_deg_s_sqrt_hz=0.007)


def test_magnetometer_conversions():
    soft = [[1.03, 0.02, 0], [0.02, 0.97, 0], [0, 0, 1]]
    m = TriadModel.magnetometer(
        bias_uT=[10, -5, 20], noise_density_uT_sqrt_hz=0.03, soft_iron=soft, resolution_uT=0.3, range_uT=1300
    )
    np.testing.assert_array_equal(m.bias, [10, -5, 20])
    np.testing.assert_array_equal(m.soft_iron, soft)
    assert (m.noise_density, m.resolution, m.range) == (0.03, 0.3, 1300)
    np.testing.assert_array_equal(TriadModel.magnetometer().soft_iron, np.eye(3))


@pytest.mark.parametrize("preset", [ImuModel.ideal, ImuModel.consumer_mems, ImuModel.tactical])
def test_presets(preset, rng):
    imu = preset()
    assert isinstance(imu, ImuModel)
    t_actual, _, _ = apply_clock(imu.clock, np.arange(1001) * 0.01, rng)
    for part in (imu.gyro, imu.acc, imu.mag):
        assert np.all(np.diag(part.misalignment) == 0)
        out = corrupt(part, np.zeros((1000, 3)), np.diff(t_actual), "rate", rng)
        assert out.shape == (1000, 3) and np.isfinite(out).all()


def test_consumer_preset_figures():
    imu = ImuModel.consumer_mems()
    assert np.degrees(imu.gyro.noise_density) == pytest.approx(0.007, rel=1e-12)
    assert imu.acc.noise_density == pytest.approx(150e-6 * G, rel=1e-12)
    assert imu.mag.noise_density * np.sqrt(100) == pytest.approx(0.3, rel=1e-12)  # 0.3 µT rms at 100 Hz
    assert imu.acc.range == pytest.approx(16 * G) and np.degrees(imu.gyro.range) == pytest.approx(2000)
    tactical = ImuModel.tactical()
    assert np.degrees(tactical.gyro.noise_density) * 60 == pytest.approx(0.1, rel=1e-12)
    assert tactical.acc.noise_density * 60 == pytest.approx(0.03, rel=1e-12)


def test_models_are_frozen_and_compare_by_value():
    model = TriadModel(bias=[1, 2, 3])
    with pytest.raises(ValueError, match="read-only"):
        model.bias[0] = 5.0
    with pytest.raises(AttributeError):
        model.noise_density = 1.0
    assert model == TriadModel(bias=[1.0, 2.0, 3.0]) and hash(model) == hash(TriadModel(bias=[1.0, 2.0, 3.0]))
    assert model != TriadModel(bias=[1, 2, 4])
    source = np.array([1.0, 2.0, 3.0])
    copy = TriadModel(bias=source)
    source[0] = 9.0
    assert copy.bias[0] == 1.0


# ---------------------------------------------------------------------------------------------------- bad input


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"noise_density": -1.0}, "noise_density is -1.0; noise_density must be non-negative"),
        ({"noise_density": np.nan}, "noise_density"),
        ({"bias_random_walk": -1e-3}, "bias_random_walk"),
        ({"bias_random_walk": np.inf}, "bias_random_walk"),
        ({"bias": [1.0, 2.0]}, r"bias must be a scalar or have shape \(3,\)"),
        ({"bias": [1.0, np.nan, 2.0]}, r"bias\[1\] is NaN"),
        ({"scale_factor": np.zeros((3, 3))}, "scale_factor"),
        ({"misalignment": np.zeros(3)}, r"misalignment must have shape \(3, 3\)"),
        ({"misalignment": np.diag([0.0, 1e-3, 0.0])}, r"misalignment\[1, 1\] is 0.001"),
        ({"soft_iron": np.eye(2)}, "soft_iron"),
        ({"soft_iron": [[1, 0, 0], [0, np.inf, 0], [0, 0, 1]]}, r"soft_iron\[1, 1\] is infinite"),
        ({"resolution": -0.1}, "resolution"),
        ({"range": 0.0}, "range is 0"),
        ({"range": -np.inf}, "range"),
    ],
)
def test_triad_model_rejects(kwargs, match):
    with pytest.raises(ValueError, match=match):
        TriadModel(**kwargs)


def test_datasheet_constructors_reject_by_their_argument_names():
    with pytest.raises(ValueError, match="arw_deg_sqrt_h"):
        TriadModel.gyro(arw_deg_sqrt_h=-0.1)
    with pytest.raises(ValueError, match="bias_mg"):
        TriadModel.accelerometer(bias_mg=[1, 2])
    with pytest.raises(ValueError, match=r"misalignment_deg\[0, 1\] is NaN"):
        TriadModel.gyro(misalignment_deg=[[0, np.nan, 0], [0, 0, 0], [0, 0, 0]])
    with pytest.raises(ValueError, match="soft_iron"):
        TriadModel.magnetometer(soft_iron=np.eye(4))


def test_corrupt_rejects(rng):
    model, good = TriadModel(), np.zeros((4, 3))
    with pytest.raises(ValueError, match=r"truth must have shape \(N, 3\)"):
        corrupt(model, np.zeros((4, 2)), 0.01, "rate", rng)
    with pytest.raises(ValueError, match=r"truth must have shape \(N, 3\)"):
        corrupt(model, np.zeros(3), 0.01, "rate", rng)
    bad = good.copy()
    bad[2, 1] = np.nan
    with pytest.raises(ValueError, match=r"truth\[2, 1\] is NaN"):
        corrupt(model, bad, 0.01, "rate", rng)
    with pytest.raises(ValueError, match=r"h\[2\] is 0.0; step durations must be positive"):
        corrupt(model, good, [0.01, 0.01, 0.0, 0.01], "rate", rng)
    with pytest.raises(ValueError, match=r"h is -0.01; step durations must be positive"):
        corrupt(model, good, -0.01, "rate", rng)
    with pytest.raises(ValueError, match=r"h must be a scalar or have shape \(N,\)"):
        corrupt(model, good, [0.01, 0.01], "rate", rng)
    with pytest.raises(ValueError, match=r"h\[0\] is NaN"):
        corrupt(model, good, [np.nan, 0.01, 0.01, 0.01], "rate", rng)
    with pytest.raises(ValueError, match="kind must be one of"):
        corrupt(model, good, 0.01, "instantaneous", rng)
    # "instant" is release 0.1's name of "rate": the same readings
    np.testing.assert_array_equal(
        corrupt(model, good, 0.01, "instant", np.random.default_rng(5)),
        corrupt(model, good, 0.01, "rate", np.random.default_rng(5)),
    )
    with pytest.raises(ValueError, match=r"rng must be a numpy\.random\.Generator"):
        corrupt(model, good, 0.01, "rate", 42)
    with pytest.raises(ValueError, match="model must be a TriadModel"):
        corrupt(ClockModel(), good, 0.01, "rate", rng)


def test_clock_rejects(rng):
    t = np.arange(11) * 0.01
    with pytest.raises(ValueError, match=r"jitter is 0\.0025 s; it must be below a quarter"):
        apply_clock(ClockModel(jitter=0.0025), t, rng)
    with pytest.raises(ValueError, match=r"jitter is -1\.0; jitter must be non-negative"):
        ClockModel(jitter=-1.0)
    with pytest.raises(ValueError, match=r"drop_probability is 1\.5"):
        ClockModel(drop_probability=1.5)
    with pytest.raises(ValueError, match="timestamps must be one of"):
        ClockModel(timestamps="sensor")
    with pytest.raises(ValueError, match=r"t_nominal\[3\] is not after t_nominal\[2\]"):
        apply_clock(ClockModel(), [0.0, 0.1, 0.2, 0.2, 0.3], rng)
    with pytest.raises(ValueError, match=r"t_nominal must have shape \(N \+ 1,\)"):
        apply_clock(ClockModel(), [0.0], rng)
    with pytest.raises(ValueError, match=r"t_nominal\[1\] is NaN"):
        apply_clock(ClockModel(), [0.0, np.nan, 1.0], rng)
    with pytest.raises(ValueError, match="rng must be"):
        apply_clock(ClockModel(), t, None)


def test_imu_model_rejects_wrong_parts():
    with pytest.raises(ValueError, match="gyro must be a TriadModel"):
        ImuModel(gyro=ClockModel())
    with pytest.raises(ValueError, match="clock must be a ClockModel"):
        ImuModel(clock=TriadModel())
