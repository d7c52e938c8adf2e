"""The first good GPS fix of a log (private): what the ULog, DataFlash and bag readers' ``position`` hooks return.

Each format says in its own words whether a fix is good (PX4's ``fix_type`` >= 3, ArduPilot's ``Status`` >= 3,
a ``NavSatFix`` status >= 0) and when it was taken; what a receiver writes before it has a fix is the same in all
of them: zeros, or numbers off the globe.  The first fix that is good and on the globe gives the place and the
date (the declination at the take-off point is the one an attitude needs; a flight moves it by nothing).
"""

from __future__ import annotations

import datetime

import numpy as np

GPS_EPOCH = datetime.datetime(1980, 1, 6, tzinfo=datetime.UTC)
#: How far GPS time runs ahead of UTC (s) from each date on: the leap seconds since the GPS epoch (IERS Bulletin C).
LEAP_SECONDS = (
    (datetime.datetime(2006, 1, 1, tzinfo=datetime.UTC), 14),
    (datetime.datetime(2009, 1, 1, tzinfo=datetime.UTC), 15),
    (datetime.datetime(2012, 7, 1, tzinfo=datetime.UTC), 16),
    (datetime.datetime(2015, 7, 1, tzinfo=datetime.UTC), 17),
    (datetime.datetime(2017, 1, 1, tzinfo=datetime.UTC), 18),
)


def gps_time(week, ms) -> datetime.datetime:
    """The UTC instant of a GPS week and millisecond of the week (less the leap seconds of that date).

    Examples
    --------
    >>> from strapdown.io.formats._gps import gps_time
    >>> gps_time(2048, 18_000).isoformat(), gps_time(1871, 603_882_400).isoformat()
    ('2019-04-07T00:00:00+00:00', '2015-11-21T23:44:25.400000+00:00')
    """
    gps = GPS_EPOCH + datetime.timedelta(weeks=int(week), milliseconds=int(ms))
    leap = 13  # from 1999-01-01; earlier logs have no GPS week of ArduPilot's or PX4's
    for start, seconds in LEAP_SECONDS:
        if gps - datetime.timedelta(seconds=seconds) >= start:
            leap = seconds
    return gps - datetime.timedelta(seconds=leap)


def first_fix(lat, lon, alt, good, when, source: str, what: str = "first 3D fix") -> dict | None:
    """The first fix that the receiver calls good and that lies on the globe, as a ``position`` hook's dict.

    Parameters
    ----------
    lat, lon : array_like
        Degrees.
    alt : array_like or None
        Metres (None: not recorded, NaN).
    good : array_like of bool
        The receiver's own verdict on each fix (its fix type or status, a time it knows).
    when : callable
        ``when(i)``: the UTC :class:`datetime.datetime` of fix ``i``, or None when its clock gives no date.
    source, what : str
        The message or topic read, and what was taken from it, for the ``source`` field.

    Returns
    -------
    dict or None
        ``latitude_deg``, ``longitude_deg``, ``altitude_m``, ``date``, ``source``; None without such a fix or
        when its time is no date.

    Examples
    --------
    >>> import datetime
    >>> from strapdown.io.formats._gps import first_fix
    >>> fix = first_fix([0.0, 47.4], [0.0, 8.5], None, [True, True],
    ...                 lambda i: datetime.datetime(2024, 5, 1, tzinfo=datetime.UTC), "GPS")
    >>> fix["latitude_deg"], str(fix["date"]), fix["source"]
    (47.4, '2024-05-01', 'GPS (first 3D fix, 2024-05-01T00:00:00+00:00)')
    """
    lat, lon = np.asarray(lat, dtype=np.float64), np.asarray(lon, dtype=np.float64)
    ok = np.asarray(good, dtype=bool) & np.isfinite(lat) & np.isfinite(lon)
    ok &= (np.abs(lat) <= 90) & (np.abs(lon) <= 180) & ((lat != 0) | (lon != 0))  # (0, 0): no fix yet
    if not ok.any():
        return None
    i = int(np.argmax(ok))
    moment = when(i)
    if moment is None:
        return None
    return {
        "latitude_deg": float(lat[i]),
        "longitude_deg": float(lon[i]),
        "altitude_m": float("nan") if alt is None else float(np.asarray(alt, dtype=np.float64)[i]),
        "date": moment.date(),
        "source": f"{source} ({what}, {moment.isoformat(timespec='seconds')})",
    }
