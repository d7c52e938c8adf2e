"""Calibrations and declination inside file pipelines (private).

Kept here so that ``strapdown.io.estimate_file`` needs only a few lines for them.
"""

from __future__ import annotations

import numpy as np

from ._calibration import one_per_sensor


def by_sensor(calibration) -> dict:
    """Calibrations by sensor name from None, :func:`strapdown.calibrate.load`'s mapping or a sequence."""
    if calibration is None:
        return {}
    items = calibration.values() if isinstance(calibration, dict) else calibration
    return one_per_sensor(items, "calibration must hold strapdown.calibrate.Calibration objects:")


def check_axes(cal: dict, sensor: str, declared: str) -> None:
    """Refuse a calibration fitted in other named axes than the readings'.

    Its matrix and offset would act on the wrong components.  A calibration fitted in unnamed axes ("sensor")
    and readings whose axes are only assumed pass.
    """
    for c in cal.values():
        if c.frame != "sensor" and declared != "assumed" and c.frame != sensor:
            raise ValueError(
                f"the {c.sensor} calibration was fitted in {c.frame} axes, but these readings are in {sensor} axes "
                f"({declared}): fit it on readings in {sensor} axes, or give --body {c.frame} if that is what the "
                "file holds"
            )


def readings(cal: dict, gyro, acc, mag):
    """Rates (rad/s, not increments), specific force and field with each sensor's calibration applied."""
    pairs = (("gyroscope", gyro), ("accelerometer", acc), ("magnetometer", mag))
    return tuple(x if x is None or s not in cal else cal[s].apply(x) for s, x in pairs)


def heading_metadata(use_mag: bool, declination, cal: dict) -> dict:
    """What the output's heading refers to, for the file's metadata; refuses a declination without magnetometer."""
    if declination is not None and not use_mag:
        raise ValueError("a declination needs the magnetometer (9D): a 6D heading has no north to correct")
    items = {
        "heading": ("true" if declination is not None else "magnetic") if use_mag else "free",
        "declination_deg": None if declination is None else float(np.degrees(declination)),
        "calibration": ", ".join(sorted(cal)) or None,
    }
    return {k: str(v) for k, v in items.items() if v is not None}  # metadata values are text
