"""The Estimate a filter returns, and its piecewise-constant form (fusion/estimate.py)."""

import dataclasses
import pickle

import numpy as np

from strapdown.fusion import AttitudeParams, Estimate, attitude
from strapdown.fusion._base import float32_if
from strapdown.fusion.estimate import PiecewiseEstimate


def _piecewise():
    ends = np.array([2, 5, 6])
    bias = np.array([[1.0, 2.0, 3.0], [4.0, 5.0, 6.0], [7.0, 8.0, 9.0]])
    sigma = -bias
    q = np.tile([1.0, 0.0, 0.0, 0.0], (6, 1))
    est = PiecewiseEstimate(q=q, frame="ENU", flags=np.zeros(6, np.uint8), segments=(ends, bias, {"s": sigma}))
    # the rows written out by hand: segment i covers samples ends[i-1]..ends[i]-1
    rows = np.array([bias[0], bias[0], bias[1], bias[1], bias[1], bias[2]])
    return est, rows


def test_piecewise_rows_expand_to_one_per_sample():
    est, rows = _piecewise()
    assert isinstance(est, Estimate)
    np.testing.assert_array_equal(est.bias, rows)
    np.testing.assert_array_equal(est.extra["s"], -rows)
    assert list(est.extra) == ["s"]
    assert est.bias.flags.c_contiguous


def test_piecewise_estimate_behaves_as_an_estimate():
    est, rows = _piecewise()
    # pickled before anything was read (a Dask worker returns it so), then expanded on the other side
    back = pickle.loads(pickle.dumps(est))
    np.testing.assert_array_equal(back.bias, rows)
    np.testing.assert_array_equal(back.extra["s"], -rows)
    copy = dataclasses.replace(est, frame="NED")
    assert copy.frame == "NED"
    np.testing.assert_array_equal(copy.bias, rows)
    assert "bias=array" in repr(est)
    est.bias = None  # outputs can still be replaced, as on an Estimate
    assert est.bias is None
    small = float32_if(_piecewise()[0], np.zeros((6, 3), np.float32))
    assert small.bias.dtype == np.float32 and small.extra["s"].dtype == np.float32
    np.testing.assert_array_equal(small.bias, rows.astype(np.float32))


def test_attitude_bias_changes_at_block_updates_only():
    # 25 Hz and the default block rate: a block ends where its intervals reach 1/update_rate (9 samples at 3 Hz),
    # after the first sample (the start, no interval); a 2 °/s bias on z is being learnt
    n = 400
    gyro = np.zeros((n, 3))
    gyro[:, 2] = np.deg2rad(2.0)
    acc = np.tile([0.0, 0.0, 9.81], (n, 1))
    est = attitude(gyro, acc, dt=0.04)
    change = np.flatnonzero(np.any(np.diff(est.bias, axis=0) != 0, axis=1)) + 1
    assert len(change) > 10
    block = int(np.ceil(25.0 / AttitudeParams().update_rate))
    assert np.all(change % block == 1)
    sigma = est.extra["bias_sigma"]
    assert sigma.shape == (n, 3) and np.all(sigma > 0)
    change = np.flatnonzero(np.any(np.diff(sigma, axis=0) != 0, axis=1)) + 1
    assert len(change) > 10
    assert np.all(change % block == 1)


def test_a_bad_sample_deep_in_a_chunk_is_named_and_the_state_kept():
    # the AttitudeEstimator checks its input from sums its kernel forms (checks_in_kernel): a bad sample far from
    # the start must still be refused by name, and the chunk's work undone
    from strapdown.fusion import AttitudeEstimator

    n = 1000
    gyro = np.zeros((n, 3))
    acc = np.tile([0.0, 0.0, 9.81], (n, 1))
    mag = np.tile([0.0, 20.0, -40.0], (n, 1))
    f = AttitudeEstimator()
    f.update(gyro, acc, mag, dt=0.01)
    before = f.state
    cases = [
        ("gyro", 700, [0.0, np.inf, 0.0], "gyro[700, 1] is infinite"),
        ("acc", 500, [1e101, 0.0, 9.81], "acc[500] = [1e+101, 0.0, 9.81] is beyond 1e+100"),
        ("mag", 900, [np.nan, 20.0, -40.0], "mag[900] is partly NaN"),
        ("gyro", 800, [0.0, 0.0, 1e15], "gyro[800] turns by 1e+13 rad"),
    ]
    for name, k, row, message in cases:
        data = {"gyro": gyro.copy(), "acc": acc.copy(), "mag": mag.copy()}
        data[name][k] = row
        try:
            f.update(data["gyro"], data["acc"], data["mag"], dt=0.01)
        except ValueError as e:
            assert message in str(e), str(e)
        else:
            raise AssertionError(f"{name}[{k}] = {row} was accepted")
        after = f.state
        for key, v in before.items():
            np.testing.assert_array_equal(after[key], v, err_msg=key)
    # rows without a sample (all NaN) are not bad samples
    data = acc.copy()
    data[::7] = np.nan
    est = f.update(gyro, data, mag, dt=0.01)
    assert np.all(np.isfinite(est.q)) and np.all(est.flags[::7] & 2)
