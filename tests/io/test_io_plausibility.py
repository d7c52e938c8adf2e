"""Readings no sensor makes in any unit (issue 14): named by file, line and column in every chunk, without overflow.

A single 1e300 used to pass the unit check as "inf rad/s ... the values look like deg/s", with numpy's overflow
warning on stderr and no line.  The limits (io.units.LIMITS) are physical: 1e4 rad/s, 1e7 m/s², 1e7 µT.
"""

import math
import sys
import warnings

import numpy as np
import pytest
import scipy.io
from hypothesis import given
from hypothesis import strategies as st

from conftest import strapdown_cli
from strapdown.io import ImuColumns, ImuFile, write_table
from strapdown.io.plausibility import LIMITS, check_gyro_at_rest, check_magnitude, check_plausible, row_norms


def still(n=200):
    """A level IMU at rest, 100 Hz: gyro zero, gravity up, a 50 µT field (the Earth's, 25-65 µT)."""
    cols = {"t": np.arange(n) * 0.01}
    cols.update(gx=np.zeros(n), gy=np.zeros(n), gz=np.zeros(n), ax=np.zeros(n), ay=np.zeros(n))
    cols.update(az=np.full(n, 9.81), mx=np.full(n, 20.0), my=np.zeros(n), mz=np.full(n, 45.0))
    return cols


def read_all(path, chunk_rows=1 << 18, **spec):
    # every RuntimeWarning (overflow) is an error here too, whatever the pytest configuration says
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with ImuFile(path, ImuColumns(**spec), optional=("acc", "mag")) as imu:
            return [len(c) for c in imu.chunks(chunk_rows)]


@pytest.mark.parametrize("unit_check", [True, False])
@pytest.mark.parametrize(("column", "quantity"), [("gx", "gyro"), ("az", "accelerometer"), ("my", "magnetometer")])
def test_one_1e300_reading_on_line_100_is_named_by_file_line_column_and_value(tmp_path, column, quantity, unit_check):
    cols = still()
    cols[column][98] = 1e300  # row 98: line 100 after the header line
    path = write_table(tmp_path / "huge.csv", cols)
    with pytest.raises(ValueError) as err:
        read_all(path, unit_check=unit_check)
    message = str(err.value)
    assert message.startswith(f"{path}: line 100, column '{column}': the {quantity} reads 1e+300 ")
    assert "not plausible in any unit" in message
    assert "inf" not in message and "deg/s: pass" not in message  # 1e300 reads as 1e300, and no unit is guessed


@pytest.mark.parametrize("chunk_rows", [1 << 18, 3000])
def test_a_huge_reading_late_in_a_big_file_is_caught(tmp_path, chunk_rows):
    # row 15001: past the 4096 rows the first checks read, in the 6th chunk of 3000 rows, and not one of the rows
    # the unit check samples (every 5th of 20000); a third of the limit per axis is no component past it alone
    cols = still(20000)
    value = 0.7 * LIMITS["acc"]  # |a| = 0.7 * sqrt(3) = 1.21 times the limit
    cols["ax"][15001] = cols["ay"][15001] = cols["az"][15001] = value
    path = write_table(tmp_path / "big.csv", cols)
    with pytest.raises(ValueError, match=r"big\.csv: line 15003, column 'ax': the accelerometer reads 7e\+06 m/s2"):
        read_all(path, chunk_rows=chunk_rows)
    cols["ax"][15001] = cols["ay"][15001] = cols["az"][15001] = 0.5 * LIMITS["acc"]  # |a| = 0.87 times the limit
    write_table(path, cols)
    assert sum(read_all(path, chunk_rows=chunk_rows, unit_check=False)) == 20000


def test_a_number_plausible_in_a_smaller_unit_names_that_unit(tmp_path):
    cols = still()
    cols["gx"][:] = 3e4  # 3e4 "rad/s" is past any gyro; 3e4 deg/s is 524 rad/s, a spinning projectile's rate
    path = write_table(tmp_path / "spin.csv", cols)
    with pytest.raises(ValueError) as err:
        read_all(path, unit_check=False)
    assert "line 2, column 'gx'" in str(err.value)
    assert f"as deg/s it would be {math.radians(3e4):.3g} rad/s" in str(err.value)
    assert "--gyro-unit deg/s" in str(err.value)
    assert sum(read_all(path, gyro_unit="deg/s", unit_check=False)) == 200


def test_gyro_increments_are_judged_as_rates(tmp_path):
    # 150 rad in one 10 ms step is 1.5e4 rad/s, past the limit; 50 rad (5e3 rad/s) is absurd but under it
    cols = still()
    cols["gz"][150] = 150.0
    path = write_table(tmp_path / "inc.csv", cols)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with ImuFile(path, ImuColumns(unit_check=False), increments=True) as imu:
            with pytest.raises(ValueError, match=r"line 152, column 'gz': the gyro increment reads 150 rad, at 100 Hz"):
                list(imu.chunks())
        cols["gz"][150] = 50.0
        write_table(path, cols)
        with ImuFile(path, ImuColumns(unit_check=False), increments=True) as imu:
            assert sum(len(c) for c in imu.chunks()) == 200


def test_an_array_field_names_its_component(tmp_path):
    # BROAD's .mat layout: (N, 3) arrays and a sampling rate; rows, not lines
    gyro, acc = np.zeros((500, 3)), np.tile([0.0, 0.0, 9.81], (500, 1))
    gyro[321, 2] = -1e300
    path = tmp_path / "trial.mat"
    scipy.io.savemat(path, {"imu_gyr": gyro, "imu_acc": acc, "sampling_rate": 100.0})
    with pytest.raises(ValueError, match=r"trial\.mat: row 321, column 'imu_gyr\[2\]': the gyro reads -1e\+300 rad/s"):
        read_all(path)


@given(
    st.lists(st.floats(-1e3, 1e3, allow_nan=False), min_size=3, max_size=3),
    st.integers(-300, 300),
)
def test_row_norms_agree_with_math_hypot_at_any_scale(v, exponent):
    # math.hypot scales internally too (CPython since 3.8), an independent implementation
    x = np.array(v) * 10.0**exponent
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        got = float(row_norms(x[None])[0])
    assert got == pytest.approx(math.hypot(*x), rel=1e-14, abs=sys.float_info.min)


def test_row_norms_of_zero_nan_inf_and_past_the_largest_float():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        got = row_norms([[0.0, 0.0, 0.0], [np.nan, 1.0, 0.0], [np.inf, 1.0, 0.0], [1.5e308, 1.5e308, 0.0]])
    assert got[0] == 0.0 and np.isnan(got[1]) and got[2] == np.inf and got[3] == np.inf  # 2.1e308: past 1.8e308


def test_the_unit_checks_do_not_call_1e300_deg_s():
    gyro = np.zeros((500, 3))
    gyro[77, 0] = 1e300
    acc = np.tile([0.0, 0.0, 9.81], (500, 1))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        at_rest = check_gyro_at_rest(gyro, acc, 5.0, "rad/s")
        plausible = check_plausible("gyro", gyro, "rad/s")
    for message in (at_rest, plausible):
        assert "1e+300 rad/s" in message and "not plausible in any unit" in message
        assert "row 77, component x" in message and "look like deg/s" not in message
    # the same check on a 1e300 accelerometer: gravity is not where it should be, so no complaint about the gyro
    acc[77, 2] = 1e300
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert check_gyro_at_rest(np.zeros((500, 3)), acc, 5.0, "rad/s") is None
        assert "not plausible in any unit" in check_plausible("acc", acc, "m/s2")


def test_check_magnitude_uses_the_vector_norm_and_the_declared_unit():
    limit = LIMITS["gyro"]
    row = np.full((1, 3), 0.6 * limit)  # each component under the limit, |w| = 1.04 times it
    assert check_magnitude("gyro", row, "rad/s")[:2] == (0, 0)
    assert check_magnitude("gyro", row * 0.9, "rad/s") is None
    # in deg/s the same numbers are 57 times smaller: no problem; converted values are judged as given
    assert check_magnitude("gyro", row, "deg/s") is None
    assert check_magnitude("gyro", row, "deg/s", converted=True) is not None


def test_estimate_refuses_a_1e300_magnetometer_value_with_its_line(tmp_path):
    # h-rel: it went through mahony with exit 0 and numpy's overflow warning on stderr
    cols = still()
    cols["mx"][98] = 1e300
    path = write_table(tmp_path / "mag.csv", cols)
    res = strapdown_cli("estimate", path, "-e", "mahony", "-o", tmp_path / "out.csv")
    assert res.returncode != 0 and "Traceback" not in res.stderr and "RuntimeWarning" not in res.stderr
    assert "mag.csv: line 100, column 'mx': the magnetometer reads 1e+300 uT" in res.stderr
    assert not (tmp_path / "out.csv").exists()


def _rolling(amplitude_deg=10.0, hz=0.1, seconds=40.0, rate=100.0):
    """A body rolling back and forth about x in FLU axes: the rate and the specific force, in closed form."""
    t = np.arange(int(seconds * rate)) / rate
    roll = np.radians(amplitude_deg) * np.sin(2 * np.pi * hz * t)
    rate_x = np.radians(amplitude_deg) * 2 * np.pi * hz * np.cos(2 * np.pi * hz * t)
    acc = 9.81 * np.column_stack([0 * t, np.sin(roll), np.cos(roll)])  # gravity's up, in the body
    return t, np.column_stack([rate_x, 0 * t, 0 * t]), acc


def test_the_gyro_tilt_check_takes_deg_s_read_as_rad_s_in_motion():
    from strapdown.io.plausibility import check_gyro_tilt

    t, gyro, acc = _rolling()
    assert check_gyro_tilt(gyro, acc, t, "rad/s") is None
    noisy = acc + np.random.default_rng(1).normal(0.0, 1.0, acc.shape)  # linear acceleration adds to what is seen
    assert check_gyro_tilt(gyro, noisy, t, "rad/s") is None
    # peak 6.3 deg/s: as rad/s under the 35 rad/s of the range check, so only the tilt tells
    assert np.degrees(gyro).max() < 35.0 and check_plausible("gyro", np.degrees(gyro), "rad/s") is None
    message = check_gyro_tilt(np.degrees(gyro), acc, t, "rad/s")
    assert "--gyro-unit deg/s" in message
    ratio = float(message.split(", ")[1].split(" times")[0])
    assert 50 < ratio < 60  # 180/pi


def test_the_gyro_tilt_check_leaves_a_coordinated_turn_alone():
    """Banked at 20 deg and turning, the apparent gravity stays on the body's z while the gyro tilts it."""
    from strapdown.io.plausibility import check_gyro_tilt

    t = np.arange(4000) / 100.0
    bank, turn = np.radians(20.0), 0.3  # rad/s about the vertical
    gyro = np.tile([0.0, turn * np.sin(bank), turn * np.cos(bank)], (t.size, 1))
    acc = np.tile([0.0, 0.0, 9.81 / np.cos(bank)], (t.size, 1))
    assert check_gyro_tilt(gyro, acc, t, "rad/s") is None


def test_flipped_body_reads_gravity_the_other_way():
    from strapdown.io.plausibility import check_gravity_sign, flipped_body
    from strapdown.rotations.frames import frame_matrix

    for body in ("FRD", "FLU", "RFU", "LBU"):
        other = flipped_body(body)
        m = frame_matrix(body, other)  # a rotation between right-handed axes
        np.testing.assert_allclose(m @ m.T, np.eye(3), atol=1e-12)
        assert np.isclose(np.linalg.det(m), 1.0)
        down = np.tile([0.0, 0.0, 9.81 if body[2] == "D" else -9.81], (20, 1))  # gravity downward in body
        assert check_gravity_sign(down, body) is not None
        assert check_gravity_sign(down, other) is None  # the same numbers, taken in the other axes
