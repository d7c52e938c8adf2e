"""The method comparison on Gajda's hammerhead + loop: the table itself is the test of conclusions 3a-3c."""

import numpy as np
import pytest

from strapdown import METHODS
from strapdown.evaluate.compare import compare
from strapdown.simulate import hammerhead_loop, sample

EXACT_FOR_THIS_DATA = ["exact", "coning1-prev", "coning2", "coning3", "coning4", "coning5", "coning6"]
BASELINES = ["euler-angles", "dcm", "euler-parameters", "rotation-vector"]
QUATERNION = [m for m in METHODS if m not in BASELINES]


@pytest.fixture(scope="module")
def comparison():
    data = sample(hammerhead_loop(), 100.0, gyro="increment")
    return compare(data, timing_repeats=1, title="hammerhead + loop")


def test_quaternion_methods_have_no_singular_points(comparison):
    """3a: through four passes of pitch ±90°, no quaternion method reports or suffers a singularity."""
    for m in QUATERNION:
        r = comparison.result(m)
        assert r.singular_steps == 0
        assert np.isfinite(r.q).all()
        assert r.norm_error <= 1e-15


def test_quaternion_errors_below_stated_bounds(comparison):
    """Ideal 100 Hz increments of rotations about body-fixed axes: exp is exact; the others within their order."""
    for m in [*EXACT_FOR_THIS_DATA, "coning3-poly", "coning4-poly"]:
        assert comparison.result(m).max_error < 1e-12, m
    assert comparison.result("rk4").max_error < 1e-9
    # first-, second-order and Cayley: per-step errors (φ)³/12, /24, /48 (math.md §7), about 6e-3° here
    assert comparison.result("first-order").max_error < np.radians(0.01)
    assert comparison.result("second-order").max_error == pytest.approx(
        comparison.result("first-order").max_error / 2, rel=0.01
    )
    assert comparison.result("cayley").max_error == pytest.approx(
        comparison.result("first-order").max_error / 4, rel=0.01
    )


def test_euler_angle_method_fails_near_vertical(comparison):
    """3a: the Euler-angle kinematics (1.6) are flagged at the first vertical climb (pitch 90° at t ≈ 4.4 s)."""
    r = comparison.result("euler-angles")
    assert r.singular_steps > 0
    assert 3.5 < r.first_singular_time < 4.5
    assert r.max_error < 1e-8  # fine until then


def test_accuracy_does_not_depend_on_attitude(comparison):
    """3b: from an oblique start the same rates fly the rotated trajectory; quaternion errors do not change,
    while the Euler-angle method, no longer passing the vertical, survives."""
    for m in QUATERNION:
        r = comparison.result(m)
        assert r.rotated_error == pytest.approx(r.max_error, rel=1e-6, abs=2e-13), m
    assert np.isfinite(comparison.result("euler-angles").rotated_error)
    assert comparison.result("euler-angles").rotated_error < 1e-5


def test_speed_is_measured_not_asserted(comparison):
    """3c: the comparison times every method; how fast is a benchmark's claim (benchmarks/), not a test's,
    because a busy machine would fail any bound on elapsed time."""
    assert np.isfinite(comparison.ns_per_loop_with_angles) and comparison.ns_per_loop_with_angles > 0
    for r in comparison.results:
        assert r.ns_per_step > 0


def test_table_and_plots(comparison, tmp_path):
    text = comparison.table()
    for m in METHODS:
        assert m in text
    assert "Gajda 3c" in text
    pytest.importorskip("matplotlib")
    paths = comparison.plot(tmp_path)
    assert [p.name for p in paths] == ["compare_angles.png", "compare_errors.png"]
    for p in paths:
        assert p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert not list(tmp_path.glob("*.tmp"))
