"""The noise model measured on a recording's rests, and the parameters it sets (issue 29).

The truth is the simulator's sensor model (its noise densities and rate random walk); a recording moves, then
stays still, and the noise is read off the still part only (found by find_rests).
"""

from dataclasses import replace

import numpy as np
import pytest

from strapdown.calibrate import Calibration, NoiseModel, allan, gyroscope, noise_model
from strapdown.fusion import AttitudeParams
from strapdown.simulate import ClockModel, ConstantRotation, ImuModel, RandomMotion, sample

FS = 100.0


def recording(imu, still_s=60.0, seed=0):
    imu = replace(imu, clock=ClockModel())
    moving = sample(RandomMotion(30.0, seed=seed), FS, imu=imu, seed=seed)
    still = sample(ConstantRotation([0.0, 0.0, 0.0], still_s), FS, imu=imu, seed=seed + 1)
    return np.concatenate([moving.gyro, still.gyro]), np.concatenate([moving.acc, still.acc])


@pytest.mark.parametrize("grade", ["consumer_mems", "tactical"])
def test_noise_densities_recovered_within_1_5(grade):
    imu = getattr(ImuModel, grade)()
    gyro, acc = recording(imu)
    model = noise_model(gyro, acc, fs=FS, allan_time=np.inf)
    assert model.source == "rests" and 50.0 <= model.seconds <= 60.0  # the still minute, not the motion
    assert 1 / 1.5 < model.gyro_noise_density / imu.gyro.noise_density < 1.5
    assert 1 / 1.5 < model.acc_noise_density / imu.acc.noise_density < 1.5


def test_rate_random_walk_from_a_long_rest():
    imu = ImuModel.consumer_mems()
    gyro, acc = recording(imu, still_s=1200.0)
    model = noise_model(gyro, acc, fs=FS)
    assert model.source == "allan"
    assert 1 / 1.5 < model.gyro_rate_random_walk / imu.gyro.bias_random_walk < 1.5
    assert 1 / 1.5 < model.gyro_noise_density / imu.gyro.noise_density < 1.5


def test_no_rest_no_model():
    imu = ImuModel.consumer_mems()
    d = sample(RandomMotion(30.0, seed=2), FS, imu=imu, seed=2)
    assert noise_model(d.gyro, d.acc, fs=FS) is None


def test_rules():
    quiet = NoiseModel(np.radians(0.007), 0.0015, None, np.radians(0.002), FS)
    p = quiet.estimator_params()
    # a good sensor keeps the default thresholds and wander (the floors) and sets the rest noise
    assert p["rest_gyro"] == AttitudeParams().rest_gyro and p["rest_acc"] == AttitudeParams().rest_acc
    assert p["bias_forgetting_time"] == AttitudeParams().bias_forgetting_time
    assert p["bias_noise_rest"] == pytest.approx(np.radians(0.007))
    noisy = NoiseModel(np.radians(0.1), 0.02, None, np.radians(0.2), 1000.0)
    q = noisy.estimator_params()
    assert q["rest_gyro"] == pytest.approx(6 * np.radians(0.1) * np.sqrt(1000.0))  # 6 σ per sample
    assert q["rest_acc"] == pytest.approx(6 * 0.02 * np.sqrt(1000.0))
    assert q["bias_forgetting_time"] == pytest.approx(AttitudeParams().bias_sigma_init ** 2 / np.radians(0.2) ** 2)
    AttitudeParams(**q)  # valid parameters
    assert set(noisy.estimator_params("tilt")) == {"rest_gyro", "rest_acc"}


def test_a_noisy_gyro_is_found_at_rest_with_the_adapted_thresholds():
    """At 1000 Hz a gyro of 0.1°/s/√Hz scatters by 3°/s per sample: never at rest under the 2°/s default."""
    from strapdown.fusion import FLAG_REST, attitude

    rng = np.random.default_rng(3)
    n, fs = 20000, 1000.0
    bias = np.radians([0.3, -0.2, 0.1])
    gyro = bias + np.radians(0.1) * np.sqrt(fs) * rng.standard_normal((n, 3))
    acc = [0.0, 0.0, 9.81] + 0.002 * np.sqrt(fs) * rng.standard_normal((n, 3))
    # find_rests's default thresholds (1.1°/s standard deviation) miss this rest too: it is given
    model = noise_model(gyro, acc, fs=fs, rests=[[0, n]], allan_time=np.inf)
    default = attitude(gyro, acc, dt=1 / fs)
    adapted = attitude(gyro, acc, dt=1 / fs, params=model.estimator_params())
    assert not (default.flags & FLAG_REST).any()
    assert (adapted.flags[-5000:] & FLAG_REST).all()
    assert np.abs(adapted.bias[-1] - bias).max() < np.abs(default.bias[-1] - bias).max()


def test_from_calibration_files():
    imu = replace(ImuModel.consumer_mems(), clock=ClockModel())
    still = sample(ConstantRotation([0.0, 0.0, 0.0], 600.0), FS, imu=imu, seed=4)
    cal = allan(still.gyro, FS).calibration()
    model = NoiseModel.from_calibration(cal, fs=FS)
    assert model.source == "calibration"
    assert model.gyro_noise_density == pytest.approx(np.sqrt(np.mean(np.square(cal.quality["arw"]))))
    assert model.gyro_rate_random_walk == pytest.approx(np.sqrt(np.mean(np.square(cal.quality["rate_random_walk"]))))
    rests = gyroscope(still.gyro, fs=FS, acc=still.acc)
    from_rests = NoiseModel.from_calibration(Calibration.from_dict(rests.to_dict()), fs=FS)
    assert from_rests.gyro_noise_density == pytest.approx(
        np.sqrt(np.mean(np.square(rests.quality["noise"]))) / np.sqrt(FS)
    )
    assert 1 / 1.5 < from_rests.gyro_noise_density / imu.gyro.noise_density < 1.5
    with pytest.raises(ValueError, match="holds no noise figures"):
        NoiseModel.from_calibration(Calibration("gyro", offset=np.zeros(3), matrix=np.eye(3)))
