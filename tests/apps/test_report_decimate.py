"""Min-max decimation for the report (strapdown.apps.report.decimate): every bucket's extremes are kept."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from strapdown.apps.report.decimate import break_lines, minmax_indices


def buckets_of(t, buckets):
    """Each sample's bucket, computed here from the definition: equal spans of time from t[0] to t[-1]."""
    span = t[-1] - t[0]
    return np.minimum(np.floor((t - t[0]) / span * buckets), buckets - 1).astype(int)


@given(
    n=st.integers(50, 3000),
    buckets=st.integers(1, 40),
    channels=st.integers(1, 3),
    seed=st.integers(0, 2**31 - 1),
    jitter=st.booleans(),
)
def test_every_bucket_keeps_its_minimum_and_maximum(n, buckets, channels, seed, jitter):
    rng = np.random.default_rng(seed)
    steps = rng.uniform(0.5, 1.5, n) if jitter else np.ones(n)
    t = np.cumsum(steps)
    y = rng.standard_normal((n, channels)).cumsum(axis=0)
    y[rng.integers(0, n, 3), 0] += rng.choice([-50.0, 50.0], 3)  # spikes of one sample
    keep = minmax_indices(t, y, buckets)
    assert np.all(np.diff(keep) > 0) and keep[0] == 0 and keep[-1] == n - 1
    if n <= 2 * buckets:
        assert keep.size == n
        return
    assert keep.size <= 2 * buckets * channels + 2
    b = buckets_of(t, buckets)
    for j in range(channels):
        for k in np.unique(b):
            rows = b == k
            kept = np.intersect1d(np.flatnonzero(rows), keep)
            assert y[kept, j].max() == y[rows, j].max()
            assert y[kept, j].min() == y[rows, j].min()
    # hence every peak of the whole signal survives
    assert np.isin(np.argmax(y, axis=0), keep).all() and np.isin(np.argmin(y, axis=0), keep).all()


def test_a_spike_that_taking_every_kth_sample_drops_is_kept():
    t = np.arange(1_000_000) * 1e-3  # 1000 s at 1 kHz
    y = np.sin(t)
    y[123_457] = 40.0  # one sample
    keep = minmax_indices(t, y, 500)
    assert 123_457 in keep
    assert keep.size <= 1002
    stride = np.arange(0, t.size, t.size // keep.size)  # what plain thinning would keep: no spike
    assert y[stride].max() < 1.01


def test_nan_samples_are_never_chosen_and_all_nan_buckets_give_nothing():
    t = np.arange(100.0)
    y = np.arange(100.0)
    y[10:30] = np.nan
    keep = minmax_indices(t, y, 10)
    inner = keep[(keep > 0) & (keep < 99)]
    assert np.isfinite(y[inner]).all()
    assert not np.isin(np.arange(10, 30), keep).any()


def test_bad_arguments_are_named():
    with pytest.raises(ValueError, match="values have 3 rows for 4 times"):
        minmax_indices(np.arange(4.0), np.zeros(3), 2)
    with pytest.raises(ValueError, match="buckets must be a positive integer, got 0"):
        minmax_indices(np.arange(4.0), np.zeros(4), 0)


def test_lines_break_where_the_label_changes():
    rows = break_lines(np.array([0, 4, 5, 9, 12]), np.array([0, 0, 1, 1, 2]))
    assert rows.tolist() == [0, 4, -1, 5, 9, -1, 12]
