"""A log's own place and date (its GPS) for ``--declination auto``, read through the format registry."""

from __future__ import annotations

import datetime as dt
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from strapdown.io import read_metadata, read_table
from strapdown.io.position import export_position
from strapdown.io.reference import log_position

pytest.importorskip("pyulog")
pytest.importorskip("pygeomag")

PX4 = Path(__file__).resolve().parents[1] / "data" / "px4"
LOGS = sorted(PX4.glob("*.ulg"))


def _gps(path):
    """The log's first 3D fix with a UTC time, read here with pyulog directly: its place and UTC date."""
    from pyulog import ULog

    d = ULog(str(path), ["vehicle_gps_position"]).data_list[0].data
    i = int(np.argmax((d["fix_type"] >= 3) & (d["time_utc_usec"] > 0)))
    utc = d["time_utc_usec"][i] / 1e6
    return d["lat"][i] * 1e-7, d["lon"][i] * 1e-7, dt.datetime.fromtimestamp(utc, dt.UTC)


@pytest.mark.parametrize("log", LOGS, ids=lambda p: p.stem)
def test_a_px4_log_gives_its_gps_place_and_utc_date(log):
    lat, lon, when = _gps(log)
    place = log_position(log)
    assert abs(place.latitude_deg - lat) < 1e-9 and abs(place.longitude_deg - lon) < 1e-9
    assert place.date == when.date() and "vehicle_gps_position" in place.source


@pytest.mark.parametrize("log", LOGS, ids=lambda p: p.stem)
def test_declination_auto_is_the_world_magnetic_models_at_the_logs_place_and_date(tmp_path, log):
    from pygeomag import GeoMag

    lat, lon, when = _gps(log)
    start = dt.datetime(when.year, 1, 1, tzinfo=dt.UTC)
    year = when.year + (when - start).total_seconds() / (365.25 * 86400)
    # the model's own package, directly: the coefficients of the model year that covers the date
    expected = GeoMag(base_year=2020 if year < 2025 else 2025).calculate(glat=lat, glon=lon, alt=0, time=year).d
    out, magnetic = tmp_path / "true.parquet", tmp_path / "magnetic.parquet"
    cli = [sys.executable, "-m", "strapdown.cli", "estimate", str(log)]
    res = subprocess.run([*cli, "-o", str(out), "--declination", "auto"], capture_output=True, text=True)
    assert res.returncode == 0, res.stderr
    said = float(res.stderr.split("declination ")[1].split("°")[0])
    assert abs(said - expected) < 0.01  # the report's 3 decimals
    assert "World Magnetic Model at" in res.stderr and when.date().isoformat() in res.stderr
    meta = read_metadata(out)
    assert (
        abs(float(meta["declination_deg"]) - expected) < 0.01 and when.date().isoformat() in meta["declination_place"]
    )
    # and the headings are turned by it: true = magnetic + D (NED, yaw clockwise from north)
    assert subprocess.run([*cli, "-o", str(magnetic)], capture_output=True).returncode == 0
    turned = np.asarray(read_table(out)["yaw_deg"]) - np.asarray(read_table(magnetic)["yaw_deg"])
    np.testing.assert_allclose(np.mod(turned + 180.0, 360.0) - 180.0, expected, atol=0.01)


def test_declination_auto_asks_for_the_place_only_where_the_log_has_none(tmp_path):
    path = tmp_path / "log.csv"
    t = np.arange(200) * 0.01
    rows = np.column_stack([t, 0 * t, 0 * t, 0 * t, 0 * t, 0 * t, 9.81 + 0 * t, 20 + 0 * t, 0 * t, -40 + 0 * t])
    np.savetxt(path, rows, delimiter=",", header="t,gx,gy,gz,ax,ay,az,mx,my,mz", comments="", fmt="%.6g")
    cli = [sys.executable, "-m", "strapdown.cli", "estimate", str(path), "-o", str(tmp_path / "a.csv")]
    res = subprocess.run([*cli, "--declination", "auto"], capture_output=True, text=True)
    assert res.returncode == 1 and "records no GPS position" in res.stderr and "--lat, --lon and --date" in res.stderr
    res = subprocess.run([*cli, "--declination", "auto", "--lat", "52.5", "--lon", "13.4", "--date", "2025-06-01"])
    assert res.returncode == 0


def test_a_phone_exports_location_file_gives_its_place_and_date(tmp_path):
    stamp = int(dt.datetime(2024, 3, 1, 12, tzinfo=dt.UTC).timestamp() * 1e9)
    rows = [f"{stamp + i * 10**9},{i},{52.5 + i * 1e-5},{13.4},{35}" for i in range(5)]
    (tmp_path / "Location.csv").write_text("time,seconds_elapsed,latitude,longitude,altitude\n" + "\n".join(rows))
    place = export_position(tmp_path)
    assert place.date == dt.date(2024, 3, 1) and abs(place.latitude_deg - 52.50002) < 1e-9 and place.altitude_m == 35
    (tmp_path / "Location.csv").write_text("time,seconds_elapsed,latitude,longitude,altitude\n0,0,0,0,0\n")
    assert export_position(tmp_path) is None  # no fix: zeros and no UTC time


@pytest.mark.parametrize("semicolon", [False, True])
def test_a_phyphox_exports_location_file_gives_the_place_and_meta_time_the_date(tmp_path, semicolon):
    # SIMULATED: a phone at rest written in phyphox's own layout by tests/sim_exports.py (Location.csv as the app's
    # "Location (GPS)" sensor exports it, seconds from the start; meta/time.csv's START event in epoch seconds)
    from pygeomag import GeoMag

    import sim_exports as sim

    aachen = (50.77640, 6.08342, 173.0)
    start = dt.datetime(2024, 6, 10, 14, 45, 36, 500_000, tzinfo=dt.UTC)
    data = sim.phone_at_rest(duration=20.0)
    folder = sim.phyphox(tmp_path / "p", data, semicolon=semicolon, start_epoch=start.timestamp(), location=aachen)
    place = log_position(folder)
    # the median of 19 fixes with 2e-5 deg (2 m) of noise each
    assert abs(place.latitude_deg - aachen[0]) < 2e-5 and abs(place.longitude_deg - aachen[1]) < 2e-5
    assert abs(place.altitude_m - aachen[2]) < 1.0 and place.date == start.date()
    assert "Location.csv" in place.source and "meta/time.csv" in place.source
    year = 2024 + (start - dt.datetime(2024, 1, 1, tzinfo=dt.UTC)).total_seconds() / (366 * 86400)
    expected = GeoMag(base_year=2020).calculate(glat=aachen[0], glon=aachen[1], alt=0, time=year).d  # WMM2020
    out = tmp_path / "out.csv"
    cli = [sys.executable, "-m", "strapdown.cli", "estimate", str(folder), "-o", str(out), "--declination", "auto"]
    res = subprocess.run(cli, capture_output=True, text=True)
    assert res.returncode == 0, res.stderr
    assert abs(float(res.stderr.split("declination ")[1].split("°")[0]) - expected) < 0.01
    said = re.search(r"World Magnetic Model at ([\d.]+) N, ([\d.]+) E on 2024-06-10 \(Location\.csv", res.stderr)
    assert said, res.stderr  # the place and date it used, said
    assert abs(float(said.group(1)) - aachen[0]) < 2e-5 and abs(float(said.group(2)) - aachen[1]) < 2e-5
    (folder / "meta" / "time.csv").unlink()  # no start time: no date, none made up
    assert log_position(folder) is None
    res = subprocess.run(cli, capture_output=True, text=True)
    assert res.returncode == 1 and "--lat, --lon and --date" in res.stderr
