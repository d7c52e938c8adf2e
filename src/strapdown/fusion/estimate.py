"""What a fusion filter returns: the attitudes, the gyro bias and the flags of every sample.

The flags are one bit mask per sample, the bits documented here once; the file commands write one boolean column per
bit besides (:data:`strapdown.io.tables.FLAG_COLUMNS`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

__all__ = [
    "FLAG_ACC_REJECTED",
    "FLAG_BIAS_AT_LIMIT",
    "FLAG_INVERTED",
    "FLAG_MAG_REJECTED",
    "FLAG_REST",
    "FLAG_SATURATED",
    "Estimate",
    "PiecewiseEstimate",
]


FLAG_REST = 1  # rest detected: the gyro bias is being learnt from the raw gyro


FLAG_ACC_REJECTED = 2  # the accelerometer was left out (its magnitude too far from g, or no sample)


FLAG_MAG_REJECTED = 4  # the magnetometer was left out (disturbed field)


FLAG_INVERTED = 8  # within 1e-6 of upside down: the tilt quaternion chart is singular there (tilt.py)


FLAG_BIAS_AT_LIMIT = 16  # the gyro bias estimate lies beyond its prior's spread (bias_limit) on some axis


# a gyro or accelerometer component is pinned at its range limit (strapdown.fusion.saturation): the gyro is not
# trusted while clipped, a clipped accelerometer sample is left out
FLAG_SATURATED = 32


@dataclass
class Estimate:
    """The output of a fusion filter for N samples.

    Attributes
    ----------
    q : numpy.ndarray, shape (N, 4)
        Attitude after each sample, sensor to ``frame`` (scalar first).
    frame : str
        Reference frame of ``q``.
    bias : numpy.ndarray, shape (N, 3), or None
        Gyro bias estimate (rad/s, sensor axes), for filters that estimate one.
    flags : numpy.ndarray of uint8, shape (N,), or None
        Bit mask per sample: ``FLAG_REST``, ``FLAG_ACC_REJECTED``, ``FLAG_MAG_REJECTED``, ``FLAG_INVERTED``,
        ``FLAG_BIAS_AT_LIMIT``, ``FLAG_SATURATED`` (values 1, 2, 4, 8, 16, 32; defined in one place, this module).
    extra : dict
        Filter-specific outputs.

    The tilt quaternion, pitch and roll of ``q`` are computed when first asked for (properties below), so a
    filter's throughput is not spent on outputs nobody reads.
    """

    q: np.ndarray
    frame: str
    bias: np.ndarray | None = None
    flags: np.ndarray | None = None
    extra: dict = field(default_factory=dict)

    def __len__(self) -> int:
        return self.q.shape[0]

    @property
    def attitude(self):
        """``q`` as a :class:`strapdown.Attitude` (sensor axes, not named, to ``frame``), sharing its memory."""
        from ..rotations.attitude import Attitude

        return Attitude._wrap(self.q, self.frame, None)

    @cached_property
    def tilt(self) -> np.ndarray:
        """Tilt quaternions e of ``q = q_z(ψ) ⊗ e`` (the Rowe patent's form, e3 = 0), shape (N, 4).

        See :func:`strapdown.rotations.tilt.tilt_from_quaternion`; upside down gives the half turn (and
        ``FLAG_INVERTED`` in the flags of :class:`~strapdown.fusion.TiltEstimator`).
        """
        from ..rotations.tilt import tilt_from_quaternion

        return tilt_from_quaternion(self.q, check=False)[0]

    @cached_property
    def _ypr(self) -> np.ndarray:
        from ..rotations.euler import as_euler

        return as_euler(self.q, "ZYX") if len(self) else np.zeros((0, 3))

    @property
    def pitch(self) -> np.ndarray:
        """Pitch θ of ``q`` in the yaw-pitch-roll (ZYX) convention of ``frame``, radians, shape (N,)."""
        return self._ypr[:, 1]

    @property
    def roll(self) -> np.ndarray:
        """Roll φ of ``q`` in the yaw-pitch-roll (ZYX) convention of ``frame``, radians, shape (N,)."""
        return self._ypr[:, 2]


class PiecewiseEstimate(Estimate):
    """An Estimate whose bias and extra outputs are piecewise constant, expanded to one row per sample when read.

    A filter whose bias changes at block updates only hands over one row per block: ``segments`` is
    ``(ends, bias, extra)``, segment i covering samples ``ends[i-1]`` (0 for the first) to ``ends[i]`` with bias
    row ``bias[i]`` and the rows ``extra[key][i]``.  Writing (and faulting in) per-sample copies costs a filter a
    fifth of its throughput, and many callers never read them; to the caller this is an :class:`Estimate`.
    """

    def __init__(self, q, frame, bias=None, flags=None, extra=None, *, segments=None):
        super().__init__(q=q, frame=frame, bias=bias, flags=flags, extra={} if extra is None else extra)
        self._segments = segments

    def _expand(self) -> None:
        if self._segments is None:
            return
        ends, bias, extra = self._segments
        self._segments = None
        counts = np.diff(ends, prepend=0)
        # contiguous rows: np.repeat copies them several times faster than strided ones
        self._bias = np.repeat(np.ascontiguousarray(bias), counts, axis=0)
        self._extra.update({k: np.repeat(np.ascontiguousarray(v), counts, axis=0) for k, v in extra.items()})

    @property
    def bias(self) -> np.ndarray | None:
        """The gyro bias of every sample, expanded from the segments on first use."""
        self._expand()
        return self._bias

    @bias.setter
    def bias(self, value) -> None:
        self._bias = value

    @property
    def extra(self) -> dict:
        """The extra outputs of every sample, expanded from the segments on first use."""
        self._expand()
        return self._extra

    @extra.setter
    def extra(self, value) -> None:
        self._extra = value


def joined(parts: list, frame: str) -> PiecewiseEstimate:
    """One PiecewiseEstimate of consecutive pieces' (their segments' ends shifted to the whole chunk's samples)."""
    offsets = np.cumsum([0] + [len(x) for x in parts[:-1]])
    segs = [x._segments for x in parts]
    ends = np.concatenate([seg[0] + o for seg, o in zip(segs, offsets, strict=True)])
    bias = np.concatenate([seg[1] for seg in segs])
    sigma = np.concatenate([seg[2]["bias_sigma"] for seg in segs])
    q = np.concatenate([x.q for x in parts])
    flags = np.concatenate([x.flags for x in parts])
    return PiecewiseEstimate(q=q, frame=frame, flags=flags, segments=(ends, bias, {"bias_sigma": sigma}))
