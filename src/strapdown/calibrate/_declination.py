"""True north: the Earth's magnetic field from position and date, and headings turned from magnetic to true.

The field comes from NOAA/BGS's World Magnetic Model through the maintained ``pygeomag`` package (the
``geomag`` extra: ``pip install 'strapdown[geomag]'``), whose coefficient files cover 2010-2030: WMM2010,
WMM2015v2, WMM2020 and WMM2025, chosen by the date.  Declination D is the angle from true north to the
horizontal field, east positive; inclination (dip) the angle below the horizontal.

An estimator that takes its heading from the magnetometer outputs attitudes in a frame whose north is
magnetic north; :func:`to_true_north` rotates them about the vertical by D into the true frame.
"""

from __future__ import annotations

import datetime as _dt
from dataclasses import dataclass

import numpy as np

from .._support import validate as _v
from ..rotations.frames import frame_matrix
from ..rotations.quaternion import multiply

__all__ = ["GeomagneticField", "declination", "field", "to_true_north"]

_MODELS: dict = {}


def _geomag(year: float):
    try:
        from pygeomag import GeoMag
    except ImportError:  # pragma: no cover - the extra is missing
        raise ImportError("the geomagnetic model needs pygeomag: pip install 'strapdown[geomag]'") from None
    if not 2010.0 <= year < 2030.0:
        raise ValueError(f"date is {year:.3f} (decimal year); the World Magnetic Model files cover 2010.0-2030.0")
    key = next(k for k in (2025, 2020, 2015, 2010) if year >= k)
    if key not in _MODELS:
        _MODELS[key] = GeoMag(base_year=key)
    return _MODELS[key]


def decimal_year(date) -> float:
    """A date as a decimal year (2025.5 is 2 July 2025 at noon).

    Accepted: a ``datetime`` or ``date``, an ISO string, a ``numpy.datetime64``, or a number (a decimal year).
    """
    if isinstance(date, (int, float, np.integer, np.floating)) and not isinstance(date, bool):
        return float(date)
    if isinstance(date, np.datetime64):
        date = date.astype("datetime64[us]").astype(_dt.datetime)
    if isinstance(date, str):
        try:
            date = _dt.datetime.fromisoformat(date)
        except ValueError:
            raise ValueError(f"date {date!r} is not an ISO date (YYYY-MM-DD) nor a decimal year") from None
    if isinstance(date, _dt.date) and not isinstance(date, _dt.datetime):
        date = _dt.datetime(date.year, date.month, date.day)
    if not isinstance(date, _dt.datetime):
        raise ValueError(f"date must be a date, datetime, ISO string or decimal year, got {type(date).__name__}")
    date = date.replace(tzinfo=None)
    start = _dt.datetime(date.year, 1, 1)
    length = (_dt.datetime(date.year + 1, 1, 1) - start).total_seconds()
    return date.year + (date - start).total_seconds() / length


@dataclass(frozen=True)
class GeomagneticField:
    """The main field at a place and time (radians unless ``degrees=True`` was asked; µT).

    Attributes
    ----------
    declination, inclination : numpy.ndarray
        East of true north; below the horizontal.
    strength : numpy.ndarray
        Total intensity, µT.
    north, east, down : numpy.ndarray
        Components, µT.
    model : str
        The World Magnetic Model used.
    """

    declination: np.ndarray
    inclination: np.ndarray
    strength: np.ndarray
    north: np.ndarray
    east: np.ndarray
    down: np.ndarray
    model: str


def field(*, latitude, longitude, date, altitude=0.0, degrees: bool = False) -> GeomagneticField:
    """The Earth's main magnetic field at a position and date (World Magnetic Model).

    Parameters
    ----------
    latitude, longitude : float or array_like
        Geodetic position (WGS 84), radians (degrees with ``degrees=True``), north and east positive.
    date : date, datetime, str or float
        When (ISO string or decimal year accepted); 2010-2030.
    altitude : float or array_like
        Height above the WGS 84 ellipsoid, metres.
    degrees : bool
        Positions in and angles out in degrees.

    Returns
    -------
    GeomagneticField
        Declination, inclination (radians, or degrees), strength and NED components (µT), broadcast over the
        inputs; float32 for float32 input.

    Examples
    --------
    >>> from strapdown.calibrate import field
    >>> f = field(latitude=80.0, longitude=0.0, date=2025.0, degrees=True)    # a WMM2025 test point
    >>> round(float(f.declination), 2), round(float(f.inclination), 2), round(float(f.strength), 2)
    (1.28, 83.21, 55.18)
    """
    lat = _v.finite(latitude, "latitude")
    lon = _v.finite(longitude, "longitude")
    alt = _v.finite(altitude, "altitude")
    # Python numbers do not decide the result's precision (the library's rule): the arrays among the inputs do
    arrays = [a for a, raw in ((lat, latitude), (lon, longitude), (alt, altitude)) if not isinstance(raw, (int, float))]
    dtype = _v.result_dtype(*arrays) if arrays else np.dtype(np.float64)
    lat, lon, alt = np.broadcast_arrays(lat, lon, alt)
    lat_deg = lat.astype(np.float64) if degrees else np.degrees(lat.astype(np.float64))
    lon_deg = lon.astype(np.float64) if degrees else np.degrees(lon.astype(np.float64))
    if np.any(np.abs(lat_deg) > 90):
        bad = np.abs(lat_deg) > 90
        raise ValueError(f"latitude{_v.first_index(bad)} is {lat[bad][0]}; it must be within ±90° (±π/2 rad)")
    lon_deg = (lon_deg + 180.0) % 360.0 - 180.0
    year = decimal_year(date)
    model = _geomag(year)
    out = np.empty((6, *lat.shape))
    for idx in np.ndindex(lat.shape):
        r = model.calculate(glat=float(lat_deg[idx]), glon=float(lon_deg[idx]), alt=float(alt[idx]) / 1000.0, time=year)
        out[(slice(None), *idx)] = (r.d, r.i, r.f / 1000.0, r.x / 1000.0, r.y / 1000.0, r.z / 1000.0)
    angles = out[:2] if degrees else np.radians(out[:2])
    values = [a.astype(dtype) for a in (*angles, *out[2:])]
    return GeomagneticField(*values, model=model.model)


def declination(*, latitude, longitude, date, altitude=0.0, degrees: bool = False) -> np.ndarray:
    """Magnetic declination (east positive) at a position and date, radians (World Magnetic Model).

    Parameters are those of :func:`field`.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.calibrate import declination
    >>> round(float(declination(latitude=-80.0, longitude=240.0, date=2025.0, degrees=True)), 2)   # WMM2025 test
    68.78
    """
    return field(latitude=latitude, longitude=longitude, date=date, altitude=altitude, degrees=degrees).declination


def to_true_north(q, declination, *, frame: str = "ENU", degrees: bool = False) -> np.ndarray:
    """Attitudes whose reference north is magnetic north re-expressed with true north.

    The magnetic frame is turned about the vertical by the declination D: ``q_true = r(up, -D) ⊗ q_mag``,
    so that a sensor pointing to magnetic north has true azimuth D.

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Attitudes (sensor to ``frame`` with magnetic north).
    declination : float or array_like, shape (...)
        Declination, east positive, radians (degrees with ``degrees=True``).
    frame : str
        Reference frame of q (``"ENU"``, ``"NED"``, ``"NWU"`` ...).
    degrees : bool
        Declination in degrees.

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        Attitudes in ``frame`` with true north.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.calibrate import to_true_north
    >>> from strapdown.rotations.quaternion import rotate
    >>> q = to_true_north([1.0, 0.0, 0.0, 0.0], 10.0, frame="NED", degrees=True)
    >>> np.degrees(np.arctan2(*rotate(q, [1.0, 0.0, 0.0])[[1, 0]])).round(6)     # azimuth of the nose
    np.float64(10.0)
    """
    q = _v.quaternions(q, "q")
    d = _v.finite(declination, "declination")
    d = np.radians(d) if degrees else d
    up = frame_matrix("NED", frame) @ np.array([0.0, 0.0, -1.0])
    half = -0.5 * np.asarray(d, dtype=np.float64)
    r = np.concatenate([np.cos(half)[..., None], np.sin(half)[..., None] * up], axis=-1)
    return multiply(r, q).astype(q.dtype, copy=False)
