"""Trajectories with exact attitude, body rate, gyro increments and specific force.

Frames: the reference frame is NED (north, east, down) and the body axes are FRD (forward, right, down), the
aviation convention of Gajda's paper; :func:`strapdown.simulate.sample` re-expresses everything in other frames.
An attitude maps body to reference.  Gravity is ``g = (0, 0, +9.80665)`` m/s² in NED; an accelerometer measures
the **specific force** ``f_b = Cᵀ (a - g)``, so at rest it reads ``(0, 0, -9.80665)`` in FRD: +g along body up.

Every trajectory provides, at any times ``t`` (seconds, array_like):

* ``attitude(t)`` (n, 4) and ``rate(t)`` (n, 3), body rate in rad/s, exact;
* ``increments(t)`` (n - 1, 3): ``∫ω dt`` over consecutive times, exact (closed form, or Gauss-Legendre
  quadrature with 8 nodes per 20 ms, exact to rounding for these smooth motions);
* ``rotation_vectors(t)`` (n - 1, 3): the rotation vector of each interval's attitude change
  ``log(q(t_k)* ⊗ q(t_k+1))``, which the ``exact`` method turns back into the attitudes to rounding;
* ``acceleration(t)`` (n, 3) in NED, ``specific_force(t)`` (n, 3) in FRD, and their interval integrals.
"""

from __future__ import annotations

import numpy as np

from .._support import validate as _v
from ..rotations.quaternion import conjugate, multiply
from ..rotations.rotvec import as_rotvec, from_rotvec

__all__ = ["GRAVITY", "Coning", "ConstantRotation", "RandomMotion", "RockingPlatform", "Trajectory"]

GRAVITY = 9.80665
_G_NED = np.array([0.0, 0.0, GRAVITY])
_GL_X, _GL_W = np.polynomial.legendre.leggauss(8)


def _times(t, duration=None) -> np.ndarray:
    arr = _v.finite(t, "t", dtype=np.float64)
    if arr.ndim != 1:
        raise ValueError(f"t must be a 1-D array of times, got shape {arr.shape}")
    if duration is not None and arr.size and (arr.min() < 0 or arr.max() > duration * (1 + 1e-12)):
        raise ValueError(f"t must lie in [0, {duration:g}] s, the trajectory's duration")
    return arr


def _quadrature(func, t: np.ndarray, max_step: float = 0.02) -> np.ndarray:
    """∫ func over [t_k, t_k+1] by 8-point Gauss-Legendre on pieces of at most `max_step` seconds.

    The motions here have no frequency above a few Hz, where 8 nodes per 20 ms are exact to rounding.
    """
    pieces = np.maximum(1, np.ceil(np.diff(t) / max_step).astype(np.int64))
    if (pieces == 1).all():
        fine = t
    else:
        # every interval cut into equal pieces; reduceat sums them back per interval
        fine = np.concatenate(
            [np.linspace(a, b, m, endpoint=False) for a, b, m in zip(t[:-1], t[1:], pieces, strict=True)] + [t[-1:]]
        )
    mid = 0.5 * (fine[1:] + fine[:-1])
    half = 0.5 * (fine[1:] - fine[:-1])
    nodes = mid[:, None] + half[:, None] * _GL_X[None, :]
    values = func(nodes.ravel()).reshape((*nodes.shape, 3))
    per_piece = np.einsum("kn,knc->kc", half[:, None] * _GL_W[None, :], values)
    if fine is t:
        return per_piece
    return np.add.reduceat(per_piece, np.concatenate([[0], np.cumsum(pieces)[:-1]]), axis=0)


class Trajectory:
    """Base class: subclasses define ``duration``, ``attitude`` and ``rate``, and may refine the rest.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.simulate import ConstantRotation
    >>> traj = ConstantRotation([0.0, 0.0, np.pi / 2], duration=2.0)    # yaw at 90 deg/s
    >>> traj.specific_force([0.0]).round(5)                            # at rest: +g along body up
    array([[ 0.     ,  0.     , -9.80665]])
    """

    duration: float

    def attitude(self, t) -> np.ndarray:
        """Body-to-NED attitude quaternions at times t, shape (n, 4)."""
        raise NotImplementedError

    def rate(self, t) -> np.ndarray:
        """Body angular rate (FRD, rad/s) at times t, shape (n, 3)."""
        raise NotImplementedError

    def acceleration(self, t) -> np.ndarray:
        """Kinematic acceleration of the body (NED, m/s²) at times t; zero unless the trajectory translates."""
        return np.zeros((_times(t).size, 3))

    def increments(self, t) -> np.ndarray:
        """``∫ω dt`` over each interval of the times t (rad), shape (n - 1, 3)."""
        t = _times(t, self.duration)
        return _quadrature(self.rate, t)

    def rotation_vectors(self, t) -> np.ndarray:
        """Rotation vector of each interval's attitude change, ``log(q_k* ⊗ q_k+1)``, shape (n - 1, 3)."""
        q = self.attitude(t)
        return as_rotvec(multiply(conjugate(q[:-1]), q[1:]))

    def specific_force(self, t) -> np.ndarray:
        """What an ideal accelerometer reads (FRD, m/s²): ``Cᵀ (a - g)``."""
        from ..rotations.quaternion import rotate

        t = _times(t, self.duration)
        return rotate(conjugate(self.attitude(t)), self.acceleration(t) - _G_NED)

    def specific_force_increments(self, t) -> np.ndarray:
        """``∫ f_b dt`` over each interval (m/s), the reading of a delta-velocity sensor."""
        t = _times(t, self.duration)
        return _quadrature(self.specific_force, t)


class ConstantRotation(Trajectory):
    """Rotation at a constant body rate from ``q0``: ``q(t) = q0 ⊗ exp(ω t / 2)``.

    Parameters
    ----------
    rate : array_like, shape (3,)
        Body rate, rad/s.
    duration : float
        Seconds.
    q0 : array_like, shape (4,), optional
        Initial attitude (identity).

    Examples
    --------
    >>> from strapdown.simulate import ConstantRotation
    >>> ConstantRotation([1.0, 0.0, 0.0], duration=1.0).increments([0.0, 0.5]).round(12)
    array([[0.5, 0. , 0. ]])
    """

    def __init__(self, rate, duration: float, q0=None):
        self._rate = _v.vectors(rate, "rate", dtype=np.float64).reshape(3)
        self.duration = _positive(duration, "duration")
        self._q0 = np.array([1.0, 0, 0, 0]) if q0 is None else _unit(q0, "q0")

    def attitude(self, t):
        """See :meth:`Trajectory.attitude`."""
        t = _times(t, self.duration)
        return multiply(self._q0, from_rotvec(np.outer(t, self._rate)))

    def rate(self, t):
        """See :meth:`Trajectory.rate`."""
        return np.tile(self._rate, (_times(t).size, 1))

    def increments(self, t):
        """See :meth:`Trajectory.increments` (here in closed form)."""
        return np.outer(np.diff(_times(t, self.duration)), self._rate)


class Coning(Trajectory):
    """Coning motion, the standard strapdown benchmark (math.md §6.1), closed form throughout.

    ``q(t) = [cos(α/2), 0, sin(α/2) cos Ωt, sin(α/2) sin Ωt]``: the body rotates by the half-cone angle α about an
    axis that spins at Ω = 2π f in the y-z plane; its x gyro reads the constant ``-2Ω sin²(α/2)``.

    Parameters
    ----------
    half_angle : float
        α in radians.
    frequency : float
        f in Hz.
    duration : float
        Seconds.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.simulate import Coning
    >>> cone = Coning(np.radians(1.0), 10.0, duration=1.0)
    >>> bool(cone.rate([0.3])[0, 0] == -2 * 2 * np.pi * 10 * np.sin(np.radians(0.5)) ** 2)   # -2Ω sin²(α/2)
    True
    """

    def __init__(self, half_angle: float, frequency: float, duration: float):
        self.alpha = float(half_angle)
        if not (np.isfinite(self.alpha) and 0 < abs(self.alpha) < np.pi):
            raise ValueError(f"half_angle must be in (0, π) radians, got {half_angle!r}")
        self.omega = 2 * np.pi * _positive(frequency, "frequency")
        self.duration = _positive(duration, "duration")

    def attitude(self, t):
        """See :meth:`Trajectory.attitude`."""
        t = _times(t, self.duration)
        s = np.sin(self.alpha / 2)
        return np.stack(
            [
                np.full_like(t, np.cos(self.alpha / 2)),
                np.zeros_like(t),
                s * np.cos(self.omega * t),
                s * np.sin(self.omega * t),
            ],
            axis=-1,
        )

    def rate(self, t):
        """See :meth:`Trajectory.rate`."""
        t = _times(t)
        w, a = self.omega, self.alpha
        return np.stack(
            [
                np.full_like(t, -2 * w * np.sin(a / 2) ** 2),
                -w * np.sin(a) * np.sin(w * t),
                w * np.sin(a) * np.cos(w * t),
            ],
            axis=-1,
        )

    def increments(self, t):
        """See :meth:`Trajectory.increments` (here in closed form)."""
        t = _times(t, self.duration)
        t1, t2 = t[:-1], t[1:]
        w, a = self.omega, self.alpha
        return np.stack(
            [
                -2 * w * np.sin(a / 2) ** 2 * (t2 - t1),
                np.sin(a) * (np.cos(w * t2) - np.cos(w * t1)),
                np.sin(a) * (np.sin(w * t2) - np.sin(w * t1)),
            ],
            axis=-1,
        )


def _skew(v: np.ndarray) -> np.ndarray:
    out = np.zeros((*v.shape[:-1], 3, 3))
    out[..., 0, 1], out[..., 0, 2] = -v[..., 2], v[..., 1]
    out[..., 1, 0], out[..., 1, 2] = v[..., 2], -v[..., 0]
    out[..., 2, 0], out[..., 2, 1] = -v[..., 1], v[..., 0]
    return out


def _right_jacobian(r: np.ndarray) -> np.ndarray:
    """J_r(r) with ω_body = J_r(r) ṙ for q = exp(r/2): I - (1 - cos θ)/θ² [r×] + (θ - sin θ)/θ³ [r×]²."""
    theta = np.linalg.norm(r, axis=-1)
    small = theta < 1e-4
    th = np.where(small, 1.0, theta)
    a = np.where(small, 0.5 - theta**2 / 24, (1 - np.cos(th)) / th**2)
    b = np.where(small, 1 / 6 - theta**2 / 120, (th - np.sin(th)) / th**3)
    k = _skew(r)
    return np.eye(3) - a[..., None, None] * k + b[..., None, None] * (k @ k)


class RandomMotion(Trajectory):
    """A random smooth motion in all three axes, with translation, any attitude reachable.

    ``q(t) = q0 ⊗ exp(r(t)/2)`` with ``r(t)`` a sum of random sinusoids plus a random drift per axis; the body
    rate is ``J_r(r) ṙ`` (the right Jacobian of SO(3)), exact.  The position is a sum of random sinusoids, so the
    acceleration is exact too.

    Parameters
    ----------
    duration : float
        Seconds.
    seed : int
        Seeds the random coefficients (reproducible).
    rate_scale : float
        Typical body rate, rad/s.
    bandwidth : float
        Highest frequency of the motion, Hz.
    acceleration_scale : float
        Typical kinematic acceleration, m/s².

    Examples
    --------
    >>> from strapdown.simulate import RandomMotion
    >>> motion = RandomMotion(duration=10.0, seed=3)
    >>> motion.attitude([0.0, 5.0]).shape
    (2, 4)
    """

    def __init__(
        self,
        duration: float,
        seed: int = 0,
        rate_scale: float = 1.0,
        bandwidth: float = 1.0,
        acceleration_scale: float = 2.0,
        components: int = 4,
    ):
        self.duration = _positive(duration, "duration")
        rng = np.random.default_rng(_seed(seed))
        self._w = 2 * np.pi * rng.uniform(0.05, bandwidth, (components, 3))
        self._phase = rng.uniform(0, 2 * np.pi, (components, 3))
        # amplitude a with a·w ~ rate_scale / sqrt(components): each component contributes comparable rate
        self._amp = rate_scale / np.sqrt(components) / self._w * rng.uniform(0.5, 1.0, (components, 3))
        self._drift = rate_scale * rng.uniform(-0.3, 0.3, 3)
        self._q0 = from_rotvec(rng.uniform(-np.pi, np.pi, 3) * 0.5)
        self._pw = 2 * np.pi * rng.uniform(0.05, bandwidth, (components, 3))
        self._pphase = rng.uniform(0, 2 * np.pi, (components, 3))
        self._pamp = acceleration_scale / np.sqrt(components) / self._pw**2 * rng.uniform(0.5, 1.0, (components, 3))

    def _r(self, t):
        arg = self._w[None] * t[:, None, None] + self._phase[None]
        r = (self._amp[None] * np.sin(arg)).sum(axis=1) + t[:, None] * self._drift
        dr = (self._amp[None] * self._w[None] * np.cos(arg)).sum(axis=1) + self._drift
        return r, dr

    def attitude(self, t):
        """See :meth:`Trajectory.attitude`."""
        r, _ = self._r(_times(t, self.duration))
        return multiply(self._q0, from_rotvec(r))

    def rate(self, t):
        """See :meth:`Trajectory.rate`."""
        r, dr = self._r(_times(t))
        return np.einsum("nij,nj->ni", _right_jacobian(r), dr)

    def acceleration(self, t):
        """See :meth:`Trajectory.acceleration`."""
        t = _times(t)
        arg = self._pw[None] * t[:, None, None] + self._pphase[None]
        return -(self._pamp[None] * self._pw[None] ** 2 * np.sin(arg)).sum(axis=1)


class RockingPlatform(Trajectory):
    """The patent's tiltable body: a wheelchair driving, turning, and rocking in pitch and roll over bumps.

    Yaw ψ(t) turns smoothly, pitch θ(t) and roll φ(t) rock sinusoidally (ZYX Euler angles, NED/FRD); the body
    rate follows from the Euler-angle kinematics.  The platform drives forward along its heading at a speed
    that oscillates, and bumps up and down: its acceleration is exact.

    Parameters
    ----------
    duration : float
        Seconds.
    speed : float
        Mean forward speed, m/s.
    pitch_amplitude, roll_amplitude : float
        Rocking amplitudes, radians.
    rocking_frequency : float
        Hz.
    turn_rate : float
        Peak yaw rate, rad/s.
    bump_amplitude : float
        Vertical oscillation, m.

    Examples
    --------
    >>> from strapdown.simulate import RockingPlatform
    >>> chair = RockingPlatform(duration=60.0)
    >>> chair.specific_force([0.0]).shape
    (1, 3)
    """

    def __init__(
        self,
        duration: float,
        speed: float = 1.0,
        pitch_amplitude: float = np.radians(8.0),
        roll_amplitude: float = np.radians(5.0),
        rocking_frequency: float = 0.3,
        turn_rate: float = 0.4,
        bump_amplitude: float = 0.02,
    ):
        self.duration = _positive(duration, "duration")
        self.v0 = float(speed)
        self.ap = float(pitch_amplitude)
        self.ar = float(roll_amplitude)
        self.wr = 2 * np.pi * _positive(rocking_frequency, "rocking_frequency")
        self.turn = float(turn_rate)
        self.bump = float(bump_amplitude)

    def _angles(self, t):
        wt = 0.05 * 2 * np.pi  # turns come and go every 20 s
        psi = self.turn / wt * (1 - np.cos(wt * t))
        dpsi = self.turn * np.sin(wt * t)
        ddpsi = self.turn * wt * np.cos(wt * t)
        th = self.ap * np.sin(self.wr * t)
        dth = self.ap * self.wr * np.cos(self.wr * t)
        ph = self.ar * np.sin(0.7 * self.wr * t + 1.0)
        dph = self.ar * 0.7 * self.wr * np.cos(0.7 * self.wr * t + 1.0)
        return (psi, th, ph), (dpsi, dth, dph), ddpsi

    def attitude(self, t):
        """See :meth:`Trajectory.attitude`."""
        from ..rotations.euler import from_euler

        (psi, th, ph), _, _ = self._angles(_times(t, self.duration))
        return from_euler(np.stack([psi, th, ph], axis=-1), "ZYX")

    def rate(self, t):
        """See :meth:`Trajectory.rate`."""
        (_, th, ph), (dpsi, dth, dph), _ = self._angles(_times(t))
        return np.stack(
            [
                dph - dpsi * np.sin(th),
                dth * np.cos(ph) + dpsi * np.cos(th) * np.sin(ph),
                -dth * np.sin(ph) + dpsi * np.cos(th) * np.cos(ph),
            ],
            axis=-1,
        )

    def acceleration(self, t):
        """See :meth:`Trajectory.acceleration`."""
        t = _times(t)
        (psi, _, _), (dpsi, _, _), _ = self._angles(t)
        ws = 2 * np.pi * 0.1
        v = self.v0 * (1 + 0.3 * np.sin(ws * t))
        dv = self.v0 * 0.3 * ws * np.cos(ws * t)
        wb = 2 * np.pi * 1.5
        # velocity v (cos ψ, sin ψ, 0) along the heading, plus a bump z = b sin(ω_b t) (down positive)
        ax = dv * np.cos(psi) - v * dpsi * np.sin(psi)
        ay = dv * np.sin(psi) + v * dpsi * np.cos(psi)
        az = -self.bump * wb**2 * np.sin(wb * t)
        return np.stack([ax, ay, az], axis=-1)


def _positive(x, name: str) -> float:
    try:
        value = float(x)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a positive number, got {x!r}") from None
    if not (np.isfinite(value) and value > 0):
        raise ValueError(f"{name} must be a positive number, got {x!r}")
    return value


def _seed(seed, name: str = "seed") -> int:
    """A seed for numpy's generators: a non-negative integer (numpy's own errors do not name the argument)."""
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or seed < 0:
        raise ValueError(f"{name} must be a non-negative integer, got {seed!r}")
    return int(seed)


def _unit(q, name: str) -> np.ndarray:
    q = _v.quaternions(q, name, dtype=np.float64).reshape(4)
    return q / np.linalg.norm(q)
