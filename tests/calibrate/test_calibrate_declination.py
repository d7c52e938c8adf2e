"""Declination, inclination and field strength against the World Magnetic Model's published test values, and a
heading test in simulation where true and magnetic north differ."""

import datetime

import numpy as np
import pytest

from strapdown.calibrate import declination, field, to_true_north
from strapdown.evaluate.metrics import rmse_errors
from strapdown.fusion import attitude
from strapdown.simulate import MagneticField, RandomMotion, sample

pytest.importorskip("pygeomag")

# NOAA/BGS, "The US/UK World Magnetic Model for 2025-2030", test values (WMM2025testvalues.pdf, also in
# WMM2025COF.zip): decimal year, height km, latitude, longitude, X, Y, Z (nT), declination (deg).
WMM2025 = [
    (2025.0, 0, 80, 0, 6521.6, 145.9, 54791.5, 1.28),
    (2025.0, 0, 0, 120, 39677.8, -109.6, -10580.2, -0.16),
    (2025.0, 0, -80, 240, 6117.5, 15751.9, -52022.5, 68.78),
    (2025.0, 100, 80, 0, 6216.0, 92.4, 52598.8, 0.85),
    (2025.0, 100, 0, 120, 37688.6, -96.2, -10152.1, -0.15),
    (2025.0, 100, -80, 240, 5907.6, 14780.3, -49540.7, 68.21),
    (2027.5, 0, 80, 0, 6500.8, 294.5, 54869.4, 2.59),
    (2027.5, 0, 0, 120, 39701.6, -167.4, -10381.8, -0.24),
    (2027.5, 0, -80, 240, 6200.7, 15730.3, -51783.7, 68.49),
    (2027.5, 100, 80, 0, 6196.7, 233.8, 52670.5, 2.16),
    (2027.5, 100, 0, 120, 37711.5, -148.7, -9969.8, -0.23),
    (2027.5, 100, -80, 240, 5984.0, 14760.1, -49317.7, 67.93),
]
# NOAA, WMM2020 test values (WMM2020testvalues.pdf): year, height km, lat, lon, X, Y, Z, declination.
WMM2020 = [
    (2020.0, 0, 80, 0, 6570.4, -146.3, 54606.0, -1.28),
    (2020.0, 0, -80, 240, 5940.6, 15772.1, -52480.8, 69.36),
    (2022.5, 100, 0, 120, 37694.0, -35.3, -10362.0, -0.05),
]


@pytest.mark.parametrize("row", WMM2025 + WMM2020)
def test_published_test_values(row):
    year, height_km, lat, lon, x, y, z, dec = row
    f = field(latitude=lat, longitude=lon, date=year, altitude=height_km * 1000.0, degrees=True)
    assert float(f.declination) == pytest.approx(dec, abs=0.006)  # published to 0.01°
    # inclination from the published components (0.1 nT): I = atan2(Z, H)
    assert float(f.inclination) == pytest.approx(np.degrees(np.arctan2(z, np.hypot(x, y))), abs=1e-3)
    np.testing.assert_allclose([f.north, f.east, f.down], np.array([x, y, z]) / 1000.0, atol=0.06e-3)
    assert float(f.strength) == pytest.approx(np.sqrt(x * x + y * y + z * z) / 1000.0, abs=0.1e-3)


def test_radians_dates_and_broadcasting():
    rad = declination(latitude=np.radians(-80.0), longitude=np.radians(240.0), date=2025.0)
    assert float(rad) == pytest.approx(np.radians(68.78), abs=np.radians(0.006))
    d = declination(latitude=np.radians([80.0, 0.0]), longitude=np.radians([0.0, 120.0]), date="2025-01-01")
    assert d.shape == (2,)
    np.testing.assert_allclose(np.degrees(d), [1.28, -0.16], atol=0.006)
    same = declination(latitude=0.5, longitude=0.2, date=datetime.date(2026, 7, 2))
    assert float(same) == float(declination(latitude=0.5, longitude=0.2, date=np.datetime64("2026-07-02")))
    assert declination(latitude=np.float32(0.5), longitude=np.float32(0.2), date=2026.0).dtype == np.float32
    with pytest.raises(ValueError, match="latitude"):
        declination(latitude=100.0, longitude=0.0, date=2025.0, degrees=True)
    with pytest.raises(ValueError, match=r"2010\.0-2030\.0"):
        declination(latitude=0.0, longitude=0.0, date=1999.0)
    with pytest.raises(ValueError, match="ISO date"):
        declination(latitude=0.0, longitude=0.0, date="yesterday")


def heading_rmse(q, q_true):
    return rmse_errors(q, q_true, np.ones(len(q), dtype=bool))["heading"]


def test_true_north_in_simulation():
    """The estimator's heading follows magnetic north; turned by the declination it follows true north."""
    dec = 12.0
    data = sample(
        RandomMotion(duration=120.0, seed=4),
        100.0,
        magnetic_field=MagneticField(50.0, 60.0, dec),
        reference="ENU",
        body="FLU",
    )
    est = attitude(data.gyro, data.acc, data.mag, dt=0.01, frame="ENU").q
    truth = data.q_true[1:]
    late = slice(6000, None)  # after the heading has settled
    magnetic = heading_rmse(est[late], truth[late])
    true = heading_rmse(to_true_north(est, dec, frame="ENU", degrees=True)[late], truth[late])
    assert magnetic == pytest.approx(dec, abs=1.0)
    assert true < 1.0
    # the same correction in NED: the frame's up axis is its -z
    ned = to_true_north([1.0, 0, 0, 0], np.radians(dec), frame="NED")
    enu = to_true_north([1.0, 0, 0, 0], np.radians(dec), frame="ENU")
    np.testing.assert_allclose(ned, [np.cos(np.radians(dec / 2)), 0, 0, np.sin(np.radians(dec / 2))], atol=1e-12)
    np.testing.assert_allclose(enu, [np.cos(np.radians(dec / 2)), 0, 0, -np.sin(np.radians(dec / 2))], atol=1e-12)
