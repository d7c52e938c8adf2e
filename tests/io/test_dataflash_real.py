"""A real ArduPilot DataFlash log: read as pymavlink reads it, estimated with no options, compared to its ATT.

``tests/data/ardupilot/log171.bin`` (provenance and licence in tests/data/PROVENANCE.md) is a flight of a
quadcopter with ArduCopter 3.3-dev on a Pixhawk (PX4v2), from the dronekit-la test logs: three IMUs logged at 50 Hz,
three compasses and ATT at 10 Hz, GPS at 5 Hz; on the ground for a minute, a 2 s hole in the log at arming,
two and a half minutes of flight, then a flip (the gyro saturates at 2000 deg/s) and the vehicle on its back.  It
is of the generation before ArduPilot 3.3's renaming: ``TimeMS`` (ms since boot) instead of ``TimeUS``, ``GPS``
with ``Week``/``TimeMS`` (GPS week and time of week) instead of ``GWk``/``GMS``, and ``FMT`` messages of types
without payload (``STRT``: a length of 3, the header alone).  pymavlink's DFReader is the oracle.
"""

from __future__ import annotations

import datetime as dt
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from strapdown.io import ImuColumns, read_imu, read_metadata
from strapdown.io.registry import formats

pytest.importorskip("pymavlink")

LOG = Path(__file__).resolve().parents[1] / "data" / "ardupilot" / "log171.bin"
T0_MS = 11_460  # the first IMU message's TimeMS


def _cli(*args):
    return subprocess.run(
        [sys.executable, "-m", "strapdown.cli", *map(str, args)], capture_output=True, text=True, timeout=600
    )


@pytest.fixture(scope="module")
def oracle():
    """What pymavlink reads: the IMU, MAG, ATT, GPS rows and the log's parameters."""
    from pymavlink import DFReader

    log = DFReader.DFReader_binary(str(LOG))
    rows = {k: [] for k in ("IMU", "MAG", "ATT", "GPS")}
    params = {}
    while (m := log.recv_match(type=["IMU", "MAG", "ATT", "GPS", "PARM"])) is not None:
        kind = m.get_type()
        if kind == "IMU":
            rows[kind].append((m.TimeMS, m.GyrX, m.GyrY, m.GyrZ, m.AccX, m.AccY, m.AccZ))
        elif kind == "MAG":
            rows[kind].append((m.TimeMS, m.MagX, m.MagY, m.MagZ))
        elif kind == "ATT":
            rows[kind].append((m.TimeMS, m.Roll, m.Pitch, m.Yaw))
        elif kind == "GPS":
            rows[kind].append((m.Status, m.Week, m.TimeMS, m.Lat, m.Lng, m.Alt, m.T, m.Spd, m.GCrs))
        else:
            params.setdefault(m.Name, m.Value)
    return {k: np.array(v, dtype=np.float64) for k, v in rows.items()}, params


@pytest.fixture(scope="module")
def imu():
    return read_imu(LOG, ImuColumns(max_gap=0), optional=("acc", "mag"))


def test_the_imu_and_mag_rows_are_pymavlinks(oracle, imu):
    rows, _ = oracle
    ref = rows["IMU"]
    assert imu.t.shape == (len(ref),) and ref[0, 0] == T0_MS
    np.testing.assert_allclose(imu.t, (ref[:, 0] - T0_MS) / 1e3, atol=1e-12)  # TimeMS: ms since boot
    np.testing.assert_array_equal(np.column_stack([imu.gyro, imu.acc]), ref[:, 1:])
    mag = rows["MAG"]
    present = ~np.isnan(imu.mag).any(axis=1)
    assert present.sum() == len(mag)  # every MAG message, on the IMU row nearest in time
    np.testing.assert_allclose(imu.mag[present], mag[:, 1:] * 0.1, rtol=1e-12)  # milligauss -> µT
    # the nearest IMU row (they jitter: 20 ms apart, some 10 or 30), a tie to the later one (in whole ms: exact)
    distance = np.abs(ref[::-1, 0][None, :] - mag[:, 0, None])
    nearest = len(ref) - 1 - distance.argmin(axis=1)
    np.testing.assert_array_equal(np.flatnonzero(present), nearest)


def test_the_units_are_right_by_the_logs_own_numbers(imu):
    from strapdown.calibrate import field

    rest = (imu.t > 20) & (imu.t < 55)  # on the ground, disarmed (the gyro's spread is its noise)
    assert np.degrees(np.linalg.norm(imu.gyro[rest], axis=1)).max() < 0.5  # rad/s: deg/s would read 57x more
    g = np.median(np.linalg.norm(imu.acc[rest], axis=1))
    assert abs(g - 9.797) < 0.3  # m/s², against normal gravity at 35.4 deg S and 590 m (9.797)
    m = np.nanmedian(np.linalg.norm(imu.mag[rest], axis=1))
    wmm = float(field(latitude=-35.36237, longitude=149.16585, date="2015-11-21", degrees=True).strength)  # µT
    assert abs(m / wmm - 1) < 0.15  # µT; milligauss taken as µT would read 10x


def test_att_is_pymavlinks_and_the_trim_is_undone(oracle, imu):
    from strapdown import from_euler
    from strapdown.evaluate.metrics import attitude_errors
    from strapdown.io.formats.dataflash import read_attitude

    rows, params = oracle
    att = rows["ATT"]
    t, q, origin = read_attitude(LOG, trim=False)
    assert origin.value == T0_MS * 1000
    np.testing.assert_allclose(t, (att[:, 0] - T0_MS) / 1e3, atol=1e-12)
    # the same rotations (ATT's roll runs past 180 deg, to -181.16, on the vehicle's back: angles would not match)
    theirs = from_euler(att[:, [3, 2, 1]], "ZYX", degrees=True)
    assert np.degrees(attitude_errors(q, theirs)["total"]).max() < 1e-9
    trim = (params["AHRS_TRIM_X"], params["AHRS_TRIM_Y"])  # radians: 1.18 and 0.30 deg
    ref = formats()["dataflash"].reference(LOG)
    assert "AHRS_TRIM_X 1.176 deg" in ref["source"]
    # undone: at rest, the accelerometer's gravity gives the tilt of the IMU's own axes, which is ATT turned by the
    # trim; before the trim is undone, the tilts differ by about the trim itself
    rest = (imu.t > 20) & (imu.t < 55)
    f = imu.acc[rest].mean(axis=0)
    tilt = from_euler(np.array([0.0, np.arctan2(f[0], np.hypot(f[1], f[2])), np.arctan2(-f[1], -f[2])]), "ZYX")
    at = (ref["t"] > 20) & (ref["t"] < 55)
    undone = np.degrees(attitude_errors(ref["q"][at], tilt)["inclination"])
    kept = np.degrees(attitude_errors(q[at], tilt)["inclination"])
    assert np.sqrt(np.mean(undone**2)) < 0.25 < np.degrees(np.hypot(*trim)) - 0.5 < np.sqrt(np.mean(kept**2))


def test_the_position_is_pymavlinks_first_3d_fix(oracle):
    from strapdown.io.reference import log_position

    gps = oracle[0]["GPS"]
    first = gps[np.argmax((gps[:, 0] >= 3) & (gps[:, 1] > 0))]
    place = log_position(LOG)
    assert abs(place.latitude_deg - first[3]) < 1e-9 and abs(place.longitude_deg - first[4]) < 1e-9
    assert abs(place.altitude_m - first[5]) < 1e-9
    # GPS week 1871 began on Sunday 2015-11-15 at 00:00 GPS time; UTC ran 17 s behind GPS time from 2015-07-01 to
    # 2016-12-31 (IERS Bulletin C 49 and 52)
    when = dt.datetime(2015, 11, 15, tzinfo=dt.UTC) + dt.timedelta(milliseconds=first[2] - 17_000)
    assert first[1] == 1871 and place.date == when.date() == dt.date(2015, 11, 21)
    assert when.replace(tzinfo=None).isoformat(timespec="seconds") in place.source  # 23:44:25 UTC


@pytest.fixture(scope="module")
def estimate(tmp_path_factory):
    out = tmp_path_factory.mktemp("df") / "log171.csv"
    res = _cli("estimate", LOG, "-o", out)
    return res, out


def test_estimate_with_no_options_and_compare_against_att(estimate, oracle):
    res, out = estimate
    assert res.returncode == 0, res.stderr
    text = res.stdout + res.stderr
    assert "frames: NED/FRD (dataflash)" in text and "mag: MAG/MagX,MAG/MagY,MAG/MagZ (uT)" in text
    assert re.search(r"1 gap\(s\) .* 61\.146 s -> 63\.168 s", text), text  # the 2 s hole at arming, said
    cmp = _cli("compare", out, LOG)
    assert cmp.returncode == 0, cmp.stderr
    inclination = float(re.search(r"inclination +([\d.]+) deg RMS", cmp.stdout).group(1))
    offset = float(re.search(r"a constant offset of ([-+\d.]+) deg", cmp.stdout).group(1))
    # Measured (ArduCopter 3.3-dev, 11911 instants, the whole log): inclination 4.63 deg RMS; heading 19.56 deg RMS,
    # a constant offset of -16.56 deg of which the declination (+12.39 deg east) explains -12.39 deg, 10.60 deg RMS
    # about it (the compass is not compensated for the motors' current: COMPASS_MOT_* = 0).  On the ground the
    # inclination is 0.6 deg RMS; in flight 5 deg: an estimator that takes gravity from the accelerometer errs by up
    # to atan(a/g) while the vehicle accelerates horizontally by a, which ATT (an EKF with GPS) does not.
    # The bound is that physics: the RMS of atan(a/g) over the flight, a from the log's own GPS velocity (11.3 deg,
    # over twice what is measured), since a filter of the accelerometer's tilt (its gain at most 1) errs by no
    # more in RMS than the tilt it filters.
    gps = oracle[0]["GPS"]
    fixed = gps[gps[:, 0] >= 3]
    t = fixed[:, 6] / 1e3
    v = fixed[:, 7, None] * np.column_stack([np.cos(np.radians(fixed[:, 8])), np.sin(np.radians(fixed[:, 8]))])
    a = np.linalg.norm(np.gradient(v, t, axis=0), axis=1)
    bound = np.degrees(np.sqrt(np.mean(np.arctan(a / 9.797) ** 2)))
    assert 2 * inclination < bound
    assert "the offset matches the declination" in cmp.stdout
    assert -20 < offset < -12  # magnetic against ATT's true north: -D (-12.4 deg) and the uncompensated compass


def test_declination_auto_is_the_world_magnetic_models_at_the_gps_place_and_date(tmp_path, oracle):
    pytest.importorskip("pygeomag")
    from pygeomag import GeoMag

    gps = oracle[0]["GPS"]
    first = gps[np.argmax((gps[:, 0] >= 3) & (gps[:, 1] > 0))]
    when = dt.datetime(1980, 1, 6) + dt.timedelta(weeks=first[1], milliseconds=first[2] - 17_000)  # UTC
    year = when.year + (when - dt.datetime(when.year, 1, 1)).total_seconds() / (365 * 86400)
    expected = GeoMag(base_year=2015).calculate(glat=first[3], glon=first[4], alt=0, time=year).d  # WMM2015
    out = tmp_path / "true.csv"
    res = _cli("estimate", LOG, "-o", out, "--declination", "auto")
    assert res.returncode == 0, res.stderr
    said = float(res.stderr.split("declination ")[1].split("°")[0])
    assert abs(said - expected) < 0.01
    assert "35.36237 S, 149.16585 E on 2015-11-21" in res.stderr  # the place and date it used, said
    meta = read_metadata(out)
    assert abs(float(meta["declination_deg"]) - expected) < 0.01 and "2015-11-21" in meta["declination_place"]
