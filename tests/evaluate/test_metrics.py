"""Allan deviation against direct implementations written from the definition (cluster means, no running sums);
attitude errors against closed forms and scipy."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from strapdown.evaluate.metrics import allan_deviation, attitude_errors, remove_heading_offset, rmse, rmse_errors


def naive_non_overlapping(x, m):
    """½ mean of squared differences of adjacent disjoint cluster means (IEEE 952 / Allan 1966)."""
    clusters = len(x) // m
    means = x[: clusters * m].reshape(clusters, m).mean(axis=1)
    return np.sqrt(0.5 * np.mean(np.diff(means) ** 2))


def loop_overlapping(x, m):
    """Every start k: the difference of the means of x[k:k+m] and x[k+m:k+2m]."""
    total, count = 0.0, 0
    for k in range(len(x) - 2 * m + 1):
        total += (x[k + m : k + 2 * m].mean() - x[k : k + m].mean()) ** 2
        count += 1
    return np.sqrt(total / (2 * count))


@pytest.fixture
def signal(rng):
    # a random walk on top of white noise and an offset: every term of the estimator matters
    return 3.0 + rng.standard_normal(500) + 0.05 * np.cumsum(rng.standard_normal(500))


def test_non_overlapping_matches_cluster_means(signal):
    fs = 50.0
    sizes = np.array([1, 2, 3, 7, 10, 50, 100, 166, 250])
    taus, adev = allan_deviation(signal, fs, taus=sizes / fs, overlapping=False)
    np.testing.assert_allclose(taus, sizes / fs, rtol=1e-15)
    expected = [naive_non_overlapping(signal, m) for m in sizes]
    np.testing.assert_allclose(adev, expected, rtol=1e-12, atol=0)


def test_overlapping_matches_a_direct_loop(signal):
    fs = 50.0
    sizes = np.array([1, 2, 3, 7, 10, 50, 100, 166, 250])
    _, adev = allan_deviation(signal, fs, taus=sizes / fs)
    expected = [loop_overlapping(signal, m) for m in sizes]
    np.testing.assert_allclose(adev, expected, rtol=1e-12, atol=0)


def test_single_cluster_size_closed_forms():
    # alternating ±1: adjacent single samples differ by 2 (adev² = 4/2), pairs average to 0
    x = np.tile([1.0, -1.0], 20)
    _, adev = allan_deviation(x, 1.0, taus=[1.0, 2.0])
    np.testing.assert_allclose(adev, [np.sqrt(2), 0], rtol=1e-15, atol=1e-15)
    # a linear ramp x_k = a k: means of adjacent clusters of m differ by a m, so adev = a m / √2 at any offset
    a = 0.3
    ramp = 7.0 + a * np.arange(200)
    taus, adev = allan_deviation(ramp, 10.0, taus=[0.1, 0.5, 2.0])
    np.testing.assert_allclose(adev, a * taus * 10.0 / np.sqrt(2), rtol=1e-11)
    # a constant has none
    assert np.all(allan_deviation(np.full(100, 5.0), 1.0)[1] == 0)


def test_white_noise_expectation(rng):
    # E[adev²] = σ²/m for white noise; 10^5 samples, pooled over 4 columns, m ≤ 100: well under 5 % error
    sigma, fs = 0.7, 100.0
    x = sigma * rng.standard_normal((100_000, 4))
    taus, adev = allan_deviation(x, fs, taus=[0.01, 0.1, 1.0])
    ratio = np.sqrt((adev**2).mean(axis=1)) / (sigma / np.sqrt(taus * fs))
    assert np.all(np.abs(ratio - 1) < 0.05), ratio


def test_columns_are_independent_signals(rng):
    x = rng.standard_normal((1000, 3))
    taus, adev = allan_deviation(x, 20.0)
    assert adev.shape == (taus.shape[0], 3)
    for c in range(3):
        t1, a1 = allan_deviation(x[:, c], 20.0)
        np.testing.assert_array_equal(t1, taus)
        np.testing.assert_allclose(a1, adev[:, c], rtol=1e-14)


def test_default_taus():
    n, fs = 100_000, 200.0
    taus, adev = allan_deviation(np.random.default_rng(0).standard_normal(n), fs)
    sizes = taus * fs
    np.testing.assert_allclose(sizes, np.round(sizes), atol=1e-9)
    assert sizes[0] == 1 and sizes[-1] == n // 10
    assert np.all(np.diff(sizes) > 0) and 25 <= len(sizes) <= 30
    ratios = sizes[1:] / sizes[:-1]
    assert ratios[-10:].max() / ratios[-10:].min() < 1.01  # log-spaced where rounding no longer matters
    # tiny records still give the one cluster size they can
    taus, adev = allan_deviation([1.0, 2.0, 4.0], 1.0)
    np.testing.assert_array_equal(taus, [1.0])
    np.testing.assert_allclose(adev, [np.sqrt(((2 - 1) ** 2 + (4 - 2) ** 2) / (2 * 2))], rtol=1e-15)


def test_taus_are_rounded_to_whole_samples(rng):
    x = rng.standard_normal(1000)
    taus, adev = allan_deviation(x, 10.0, taus=[0.26, 1.04])
    np.testing.assert_allclose(taus, [0.3, 1.0], rtol=1e-15)
    np.testing.assert_allclose(adev, allan_deviation(x, 10.0, taus=[0.3, 1.0])[1], rtol=0)


def test_errors():
    x = np.zeros(100)
    with pytest.raises(ValueError, match=r"x\[3\] is NaN"):
        allan_deviation(np.where(np.arange(100) == 3, np.nan, 0.0), 1.0)
    with pytest.raises(ValueError, match=r"x must have shape \(N,\) or \(N, c\)"):
        allan_deviation(np.zeros((10, 2, 2)), 1.0)
    with pytest.raises(ValueError, match="at least 2"):
        allan_deviation([1.0], 1.0)
    with pytest.raises(ValueError, match="fs must be a positive scalar"):
        allan_deviation(x, 0.0)
    with pytest.raises(ValueError, match="fs must be a positive scalar"):
        allan_deviation(x, [1.0, 2.0])
    with pytest.raises(ValueError, match=r"fs is infinite"):
        allan_deviation(x, np.inf)
    with pytest.raises(ValueError, match=r"taus\[1\] is 51.0 s"):
        allan_deviation(x, 1.0, taus=[1.0, 51.0])
    with pytest.raises(ValueError, match=r"taus\[0\] is 0.1 s"):
        allan_deviation(x, 1.0, taus=[0.1])
    with pytest.raises(ValueError, match=r"taus\[0\] is NaN"):
        allan_deviation(x, 1.0, taus=[np.nan])
    with pytest.raises(ValueError, match=r"taus must be a scalar or have shape \(T,\)"):
        allan_deviation(x, 1.0, taus=[[1.0]])


# --- attitude errors on the BROAD protocol ----------------------------------------------------------------------


def _sp(q):
    """scalar-first -> scipy's scalar-last."""
    return Rotation.from_quat(np.asarray(q)[..., [1, 2, 3, 0]])


def test_errors_of_a_heading_then_tilt_error_are_closed_form(rng):
    # q_err = q_z(ψ) ⊗ (rotation θ about a horizontal axis): heading ψ, inclination θ, total 2 acos(cos ψ/2 cos θ/2)
    n = 500
    psi = rng.uniform(0, np.pi, n)
    theta = rng.uniform(0, np.pi, n)
    az = rng.uniform(0, 2 * np.pi, n)
    horizontal = np.column_stack([np.cos(az), np.sin(az), np.zeros(n)])
    err = _sp(np.column_stack([np.cos(psi / 2), 0 * psi, 0 * psi, np.sin(psi / 2)])) * Rotation.from_rotvec(
        horizontal * theta[:, None]
    )
    ref = Rotation.random(n, random_state=1)
    est = (err * ref).as_quat()[:, [3, 0, 1, 2]]
    e = attitude_errors(est, ref.as_quat()[:, [3, 0, 1, 2]])
    np.testing.assert_allclose(e["heading"], psi, atol=1e-7)
    np.testing.assert_allclose(e["inclination"], theta, atol=1e-7)
    np.testing.assert_allclose(e["total"], 2 * np.arccos(np.cos(psi / 2) * np.cos(theta / 2)), atol=1e-7)
    # the total error is the angle of est ⊗ ref⁻¹ (scipy), whatever the signs of the inputs
    signs = rng.choice([-1.0, 1.0], (n, 1))
    e2 = attitude_errors(est * signs, ref.as_quat()[:, [3, 0, 1, 2]])
    np.testing.assert_allclose(e2["total"], (err).magnitude(), atol=1e-7)


def test_nan_truth_is_ignored_and_the_mask_selects():
    est = np.tile([np.cos(0.01), np.sin(0.01), 0, 0], (6, 1))  # 0.02 rad of roll everywhere
    ref = np.tile([1.0, 0, 0, 0], (6, 1))
    ref[1] = np.nan
    est[5] = [np.cos(0.1), np.sin(0.1), 0, 0]  # 0.2 rad, masked out below
    r = rmse_errors(est, ref, mask=[True, True, True, True, True, False], degrees=False)
    assert r["inclination"] == pytest.approx(0.02, rel=1e-9)
    assert r["heading"] == pytest.approx(0.0, abs=1e-12)
    assert rmse([np.nan, np.nan]) != rmse([np.nan, np.nan])  # NaN when nothing is finite
    with pytest.raises(ValueError, match="mask"):
        rmse(np.ones(3), mask=[True, False])
    with pytest.raises(ValueError, match="q_est and q_ref"):
        rmse_errors(est, ref[:3])


def test_heading_offset_removal(rng):
    # a constant heading offset plus a tilt error: removal leaves the tilt, and the inclination never changes
    n = 400
    ref = Rotation.random(n, random_state=2)
    tilt = Rotation.from_rotvec(np.column_stack([0.03 * np.ones(n), np.zeros(n), np.zeros(n)]))
    est = (Rotation.from_euler("z", 2.5) * tilt * ref).as_quat()[:, [3, 0, 1, 2]]
    refq = ref.as_quat()[:, [3, 0, 1, 2]]
    fixed = remove_heading_offset(est, refq)
    e_before, e_after = attitude_errors(est, refq), attitude_errors(fixed, refq)
    np.testing.assert_allclose(e_after["inclination"], e_before["inclination"], atol=1e-12)
    np.testing.assert_allclose(e_after["heading"], 0, atol=1e-9)
    np.testing.assert_allclose(e_after["total"], 0.03, atol=1e-9)
    r6 = rmse_errors(est, refq, heading_offset=True)
    assert r6["total"] == pytest.approx(np.degrees(0.03), rel=1e-7)
