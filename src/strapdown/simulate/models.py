"""Datasheet-style error models of an IMU: each triad (gyro, accelerometer, magnetometer) and the sample clock.

Every field is SI: rad/s for gyros, m/s² for accelerometers, µT for magnetometers (the "sensor units" below),
seconds for time.  The classmethods :meth:`TriadModel.gyro`, :meth:`TriadModel.accelerometer` and
:meth:`TriadModel.magnetometer` take datasheet units and convert; the dataclasses store SI only.  Their
arguments say their unit in their name, and four mean the same in all three: ``scale_factor_ppm``, the
scale-factor errors in ppm (1 % = 10000 ppm), one per axis or one for all; ``misalignment_deg``, the cross-axis
coupling in degrees, a matrix with zero diagonal or a scalar δ for the fixed pattern with δ in every
off-diagonal element (no randomness: draw your own matrix for a random part); ``resolution_*``, one LSB (0 for
none); and ``range_*``, the full-scale range ± (inf for none).  What the models
do to readings is :func:`strapdown.simulate.imu.corrupt` and :func:`strapdown.simulate.imu.apply_clock` (whose
module notes hold the error equations); the models are also what :mod:`strapdown.calibrate` measures.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields

import numpy as np

from .._support import validate as _v

__all__ = ["ClockModel", "G", "ImuModel", "TriadModel"]

#: Standard gravity (m/s²), the "g" of accelerometer datasheets.
G = 9.80665


_TIMESTAMPS = ("actual", "nominal")


def _frozen(arr: np.ndarray) -> np.ndarray:
    out = np.array(arr, dtype=np.float64)  # a private copy: the caller's array may change later
    out.flags.writeable = False
    return out


def _vector3(value, name: str) -> np.ndarray:
    """A 3-vector; a scalar applies to every axis."""
    arr = _v.as_float_array(value, name, dtype=np.float64)
    if arr.ndim == 0:
        arr = np.full(3, float(arr))
    if arr.shape != (3,):
        raise ValueError(f"{name} must be a scalar or have shape (3,) (one value per axis), got shape {arr.shape}")
    _v.check_finite(arr, name)
    return arr


def _matrix3(value, name: str) -> np.ndarray:
    arr = _v.as_float_array(value, name, dtype=np.float64)
    if arr.shape != (3, 3):
        raise ValueError(f"{name} must have shape (3, 3), got shape {arr.shape}")
    _v.check_finite(arr, name)
    return arr


def _scalar(value, name: str, *, allow_inf: bool = False) -> float:
    """A non-negative real number (``+inf`` too when allowed)."""
    arr = _v.as_float_array(value, name, dtype=np.float64)
    if arr.ndim != 0:
        raise ValueError(f"{name} must be a scalar, got shape {arr.shape}")
    x = float(arr)
    if np.isnan(x) or (np.isinf(x) and not (allow_inf and x > 0)):
        raise ValueError(f"{name} is {x}; {name} must be a finite number" + (" or +inf" if allow_inf else ""))
    if x < 0:
        raise ValueError(f"{name} is {x}; {name} must be non-negative")
    return x


def _misalignment_deg(value, name: str) -> np.ndarray:
    """Cross-axis coupling in radians from degrees: a 3x3 matrix, or a scalar δ for the fixed pattern δ (1 - I)."""
    arr = _v.as_float_array(value, name, dtype=np.float64)
    if arr.ndim == 0:
        _v.check_finite(arr, name)
        arr = float(arr) * (np.ones((3, 3)) - np.eye(3))
    return np.radians(_matrix3(arr, name))


def _coupling(scale_factor_ppm, misalignment_deg) -> dict:
    """The scale factor and misalignment fields from the datasheet constructors' ppm and degrees."""
    return {
        "scale_factor": 1e-6 * _vector3(scale_factor_ppm, "scale_factor_ppm"),
        "misalignment": _misalignment_deg(misalignment_deg, "misalignment_deg"),
    }


def _one_density(a, b, name_a: str, name_b: str) -> tuple[float, float]:
    """Two alternative white-noise figures, validated; at most one may be non-zero."""
    a, b = _scalar(a, name_a), _scalar(b, name_b)
    if a != 0 and b != 0:
        raise ValueError(f"give either {name_a} or {name_b}, not both: they describe the same white noise")
    return a, b


@dataclass(frozen=True, eq=False)
class TriadModel:
    """Errors of a 3-axis sensor, in SI units (module notes: conventions).

    A reading is ``quantise(saturate(soft_iron (I + diag(scale_factor) + misalignment) truth + b(t) + noise))``,
    see :func:`corrupt`.  "units" below are the sensor's: rad/s (gyro), m/s² (accelerometer), µT (magnetometer).
    Arrays are stored as read-only float64 copies; two models are equal when every field is.

    Parameters
    ----------
    bias : array_like, shape (3,) or scalar
        Constant bias (units); for a magnetometer the hard-iron offset.  A scalar applies to every axis.
    bias_random_walk : float
        Rate random walk K (units/√s): the bias is a Wiener process whose standard deviation after T seconds is
        ``K √T``; its Allan deviation is ``K √(τ/3)``.
    noise_density : float
        White-noise density (units/√Hz); a gyro's angle random walk, an accelerometer's velocity random walk.
    scale_factor : array_like, shape (3,) or scalar
        Dimensionless scale errors s: axis i reads ``(1 + s_i)`` times its true value.
    misalignment : array_like, shape (3, 3)
        Small cross-axis coupling M (rad), zero diagonal: ``M[i, j]`` is how much of true axis j axis i reads.
    soft_iron : array_like, shape (3, 3)
        Matrix applied after scale and misalignment (identity: none).  Meant for magnetometers, available to all.
    resolution : float
        Quantisation step, one LSB (units; integrated units for increments), 0 for none.
    range : float
        Saturation limit: readings are clipped to ±range (±range·h for increments); ``inf`` for none.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.simulate.models import TriadModel
    >>> gyro = TriadModel(bias=[0.01, 0.0, -0.02], noise_density=1e-4)
    >>> gyro.bias
    array([ 0.01,  0.  , -0.02])
    >>> gyro.matrix
    array([[1., 0., 0.],
           [0., 1., 0.],
           [0., 0., 1.]])
    """

    bias: np.ndarray = field(default_factory=lambda: np.zeros(3))  # units
    bias_random_walk: float = 0.0  # units/√s
    noise_density: float = 0.0  # units/√Hz
    scale_factor: np.ndarray = field(default_factory=lambda: np.zeros(3))  # dimensionless
    misalignment: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))  # rad, zero diagonal
    soft_iron: np.ndarray = field(default_factory=lambda: np.eye(3))  # dimensionless
    resolution: float = 0.0  # units per LSB, 0 = no quantisation
    range: float = np.inf  # units, inf = no saturation

    def __post_init__(self):
        misalignment = _matrix3(self.misalignment, "misalignment")
        diagonal = np.diag(misalignment) != 0
        if diagonal.any():
            i = int(np.flatnonzero(diagonal)[0])
            raise ValueError(
                f"misalignment[{i}, {i}] is {misalignment[i, i]}; the misalignment diagonal must be zero "
                "(a gain error on an axis belongs in scale_factor)"
            )
        values = {
            "bias": _frozen(_vector3(self.bias, "bias")),
            "bias_random_walk": _scalar(self.bias_random_walk, "bias_random_walk"),
            "noise_density": _scalar(self.noise_density, "noise_density"),
            "scale_factor": _frozen(_vector3(self.scale_factor, "scale_factor")),
            "misalignment": _frozen(misalignment),
            "soft_iron": _frozen(_matrix3(self.soft_iron, "soft_iron")),
            "resolution": _scalar(self.resolution, "resolution"),
            "range": _scalar(self.range, "range", allow_inf=True),
        }
        if values["range"] == 0:
            raise ValueError("range is 0; range must be positive (inf for no saturation)")
        for name, value in values.items():
            object.__setattr__(self, name, value)

    def __eq__(self, other):
        if type(other) is not type(self):
            return NotImplemented
        return all(np.array_equal(getattr(self, f.name), getattr(other, f.name)) for f in fields(self))

    def __hash__(self):
        return hash(tuple(np.asarray(getattr(self, f.name)).tobytes() for f in fields(self)))

    @property
    def matrix(self) -> np.ndarray:
        """The linear part ``soft_iron @ (I + diag(scale_factor) + misalignment)`` of the model.

        Examples
        --------
        >>> from strapdown.simulate.models import TriadModel
        >>> TriadModel(scale_factor=[0.1, 0.0, 0.0], misalignment=[[0, 0.01, 0], [0, 0, 0], [0, 0, 0]]).matrix
        array([[1.1 , 0.01, 0.  ],
               [0.  , 1.  , 0.  ],
               [0.  , 0.  , 1.  ]])
        """
        return self.soft_iron @ (np.eye(3) + np.diag(self.scale_factor) + self.misalignment)

    @classmethod
    def gyro(
        cls,
        *,
        bias_deg_s=0.0,
        rate_random_walk_deg_s_sqrt_s: float = 0.0,
        arw_deg_sqrt_h: float = 0.0,
        noise_density_deg_s_sqrt_hz: float = 0.0,
        scale_factor_ppm=0.0,
        misalignment_deg=0.0,
        resolution_deg_s: float = 0.0,
        range_deg_s: float = np.inf,
    ) -> TriadModel:
        """A gyro model (rad/s) from datasheet units.

        Parameters
        ----------
        bias_deg_s : float or array_like, shape (3,)
            Constant bias (deg/s); divide a figure in deg/h by 3600.
        rate_random_walk_deg_s_sqrt_s : float
            Rate random walk (deg/s/√s); divide a figure in deg/h/√h by 216000.
        arw_deg_sqrt_h : float
            Angle random walk (deg/√h); it is 60 times the noise density in deg/s/√Hz.
        noise_density_deg_s_sqrt_hz : float
            The same white noise as a rate noise density (deg/s/√Hz); give this or ``arw_deg_sqrt_h``.

        Returns
        -------
        TriadModel
            The model in rad/s.

        Examples
        --------
        >>> from strapdown.simulate.models import TriadModel
        >>> g = TriadModel.gyro(arw_deg_sqrt_h=0.3, bias_deg_s=0.5, range_deg_s=2000)
        >>> g.noise_density        # rad/s/√Hz = radians(0.3 / 60)
        8.726646259971648e-05
        >>> g.bias                 # rad/s
        array([0.00872665, 0.00872665, 0.00872665])
        """
        arw, density = _one_density(
            arw_deg_sqrt_h, noise_density_deg_s_sqrt_hz, "arw_deg_sqrt_h", "noise_density_deg_s_sqrt_hz"
        )
        # ARW in deg/√h is 60 × the density in deg/s/√Hz = deg/√s, because √h = 60 √s.
        density += arw / 60
        return cls(
            bias=np.radians(_vector3(bias_deg_s, "bias_deg_s")),
            bias_random_walk=np.radians(_scalar(rate_random_walk_deg_s_sqrt_s, "rate_random_walk_deg_s_sqrt_s")),
            noise_density=np.radians(density),
            **_coupling(scale_factor_ppm, misalignment_deg),
            resolution=np.radians(_scalar(resolution_deg_s, "resolution_deg_s")),
            range=np.radians(_scalar(range_deg_s, "range_deg_s", allow_inf=True)),
        )

    @classmethod
    def accelerometer(
        cls,
        *,
        bias_mg=0.0,
        rate_random_walk_mg_sqrt_s: float = 0.0,
        vrw_m_s_sqrt_h: float = 0.0,
        noise_density_ug_sqrt_hz: float = 0.0,
        scale_factor_ppm=0.0,
        misalignment_deg=0.0,
        resolution_mg: float = 0.0,
        range_g: float = np.inf,
    ) -> TriadModel:
        """An accelerometer model (m/s²) from datasheet units, with g = 9.80665 m/s².

        Parameters
        ----------
        bias_mg : float or array_like, shape (3,)
            Constant bias (mg).
        rate_random_walk_mg_sqrt_s : float
            Random walk of the bias (mg/√s).
        vrw_m_s_sqrt_h : float
            Velocity random walk (m/s/√h); the noise density in m/s²/√Hz is this over 60.
        noise_density_ug_sqrt_hz : float
            The same white noise as a density (µg/√Hz); give this or ``vrw_m_s_sqrt_h``.

        Returns
        -------
        TriadModel
            The model in m/s².

        Examples
        --------
        >>> from strapdown.simulate.models import TriadModel
        >>> a = TriadModel.accelerometer(noise_density_ug_sqrt_hz=150, range_g=16)
        >>> a.noise_density, a.range      # m/s²/√Hz and m/s²
        (0.0014709975, 156.9064)
        >>> TriadModel.accelerometer(vrw_m_s_sqrt_h=0.06).noise_density
        0.001
        """
        vrw, density_ug = _one_density(
            vrw_m_s_sqrt_h, noise_density_ug_sqrt_hz, "vrw_m_s_sqrt_h", "noise_density_ug_sqrt_hz"
        )
        density = vrw / 60 + 1e-6 * G * density_ug  # one of the two terms is zero
        return cls(
            bias=1e-3 * G * _vector3(bias_mg, "bias_mg"),
            bias_random_walk=1e-3 * G * _scalar(rate_random_walk_mg_sqrt_s, "rate_random_walk_mg_sqrt_s"),
            noise_density=density,
            **_coupling(scale_factor_ppm, misalignment_deg),
            resolution=1e-3 * G * _scalar(resolution_mg, "resolution_mg"),
            range=G * _scalar(range_g, "range_g", allow_inf=True),
        )

    @classmethod
    def magnetometer(
        cls,
        *,
        bias_uT=0.0,
        rate_random_walk_uT_sqrt_s: float = 0.0,
        noise_density_uT_sqrt_hz: float = 0.0,
        soft_iron=None,
        scale_factor_ppm=0.0,
        misalignment_deg=0.0,
        resolution_uT: float = 0.0,
        range_uT: float = np.inf,
    ) -> TriadModel:
        """A magnetometer model (µT): hard iron is the bias, soft iron a 3x3 matrix.

        Parameters
        ----------
        bias_uT : float or array_like, shape (3,)
            Hard-iron offset plus sensor offset (µT).
        rate_random_walk_uT_sqrt_s : float
            Random walk of the offset (µT/√s).
        noise_density_uT_sqrt_hz : float
            White-noise density (µT/√Hz); an rms noise σ per sample at a rate fs is ``σ / √fs``.
        soft_iron : array_like, shape (3, 3), optional
            Soft-iron matrix, identity by default.

        Returns
        -------
        TriadModel
            The model in µT.

        Examples
        --------
        >>> from strapdown.simulate.models import TriadModel
        >>> m = TriadModel.magnetometer(bias_uT=[10, -5, 20], noise_density_uT_sqrt_hz=0.03, resolution_uT=0.3)
        >>> m.bias, m.resolution
        (array([10., -5., 20.]), 0.3)
        """
        return cls(
            bias=_vector3(bias_uT, "bias_uT"),
            bias_random_walk=_scalar(rate_random_walk_uT_sqrt_s, "rate_random_walk_uT_sqrt_s"),
            noise_density=_scalar(noise_density_uT_sqrt_hz, "noise_density_uT_sqrt_hz"),
            **_coupling(scale_factor_ppm, misalignment_deg),
            soft_iron=np.eye(3) if soft_iron is None else _matrix3(soft_iron, "soft_iron"),
            resolution=_scalar(resolution_uT, "resolution_uT"),
            range=_scalar(range_uT, "range_uT", allow_inf=True),
        )


@dataclass(frozen=True)
class ClockModel:
    """Timing errors of a sampled sensor (see :func:`apply_clock`).

    Parameters
    ----------
    jitter : float
        Standard deviation (s) of the actual sampling instants around the nominal ones; it must be below a
        quarter of the shortest nominal step (checked by :func:`apply_clock`).
    drop_probability : float
        Probability, in [0, 1], that a sample is lost (each independently; the first sample is always kept).
    timestamps : {"actual", "nominal"}
        What the logger records: the jittered instants at which the sensor sampled (``"actual"``), or the nominal
        instants although the sensor sampled at the jittered ones (``"nominal"``).

    Examples
    --------
    >>> from strapdown.simulate.models import ClockModel
    >>> ClockModel(jitter=20e-6, timestamps="nominal")
    ClockModel(jitter=2e-05, drop_probability=0.0, timestamps='nominal')
    """

    jitter: float = 0.0
    drop_probability: float = 0.0
    timestamps: str = "actual"

    def __post_init__(self):
        object.__setattr__(self, "jitter", _scalar(self.jitter, "jitter"))
        p = _scalar(self.drop_probability, "drop_probability")
        if p > 1:
            raise ValueError(f"drop_probability is {p}; drop_probability must lie in [0, 1]")
        object.__setattr__(self, "drop_probability", p)
        _v.choice(self.timestamps, "timestamps", _TIMESTAMPS)


@dataclass(frozen=True)
class ImuModel:
    """Error models of a whole IMU: gyro (rad/s), accelerometer (m/s²), magnetometer (µT) and sample clock.

    Every part defaults to an ideal sensor.  The presets are typical figures, not any part's guarantee.

    Parameters
    ----------
    gyro, acc, mag : TriadModel
        Error models of the three triads (``accel``, release 0.1's name of ``acc``, still reads it).
    clock : ClockModel
        Timing errors shared by the triads.

    Examples
    --------
    >>> from strapdown.simulate.models import ImuModel, TriadModel
    >>> imu = ImuModel(gyro=TriadModel.gyro(arw_deg_sqrt_h=0.2))
    >>> imu.acc == TriadModel()
    True
    """

    gyro: TriadModel = field(default_factory=TriadModel)
    acc: TriadModel = field(default_factory=TriadModel)
    mag: TriadModel = field(default_factory=TriadModel)
    clock: ClockModel = field(default_factory=ClockModel)

    def __post_init__(self):
        for name, kind in (("gyro", TriadModel), ("acc", TriadModel), ("mag", TriadModel), ("clock", ClockModel)):
            value = getattr(self, name)
            if not isinstance(value, kind):
                raise ValueError(f"{name} must be a {kind.__name__}, got {type(value).__name__}")

    @property
    def accel(self) -> TriadModel:
        """``acc`` by its name of release 0.1."""
        return self.acc

    @classmethod
    def ideal(cls) -> ImuModel:
        """An error-free IMU: readings equal the truth, samples come on time.

        Returns
        -------
        ImuModel
            All fields zero (soft iron identity, no range limit).

        Examples
        --------
        >>> from strapdown.simulate.models import ImuModel
        >>> ImuModel.ideal().gyro.noise_density
        0.0
        """
        return cls()

    @classmethod
    def consumer_mems(cls) -> ImuModel:
        """A smartphone/drone-class MEMS IMU (BMI160 / MPU-6500 / BMM150 class parts).

        Returns
        -------
        ImuModel
            Gyro: noise 0.007 deg/s/√Hz (ARW 0.42 deg/√h), bias [0.3, -0.4, 0.2] deg/s, rate random walk
            0.002 deg/s/√s, scale errors of 0.3-0.5 %, 0.1° cross-axis, ±2000 deg/s at 16.4 LSB/(deg/s).
            Accelerometer: 150 µg/√Hz, bias [20, -15, 10] mg, 0.03 mg/√s, 0.3-0.5 % scale, 0.1° cross-axis,
            ±16 g at 2048 LSB/g.  Magnetometer: 0.3 µT rms per sample at 100 Hz (0.03 µT/√Hz), hard iron
            [10, -5, 20] µT, mild soft iron (±3 %), 0.3 µT LSB, ±1300 µT.  Clock jitter 20 µs, no drops.

        Examples
        --------
        >>> import numpy as np
        >>> from strapdown.simulate.models import ImuModel
        >>> imu = ImuModel.consumer_mems()
        >>> float(np.degrees(imu.gyro.range)), imu.clock.jitter
        (2000.0, 2e-05)
        """
        # Typical datasheet figures of this class of parts (rounded); the sign patterns are fixed, not random.
        gyro = TriadModel.gyro(
            bias_deg_s=[0.3, -0.4, 0.2],
            rate_random_walk_deg_s_sqrt_s=0.002,
            noise_density_deg_s_sqrt_hz=0.007,
            scale_factor_ppm=[5000, -3000, 4000],
            misalignment_deg=0.1,
            resolution_deg_s=1 / 16.4,
            range_deg_s=2000,
        )
        acc = TriadModel.accelerometer(
            bias_mg=[20, -15, 10],
            rate_random_walk_mg_sqrt_s=0.03,
            noise_density_ug_sqrt_hz=150,
            scale_factor_ppm=[-4000, 5000, 3000],
            misalignment_deg=0.1,
            resolution_mg=1 / 2.048,
            range_g=16,
        )
        mag = TriadModel.magnetometer(
            bias_uT=[10, -5, 20],
            noise_density_uT_sqrt_hz=0.3 / np.sqrt(100.0),
            soft_iron=[[1.03, 0.02, -0.01], [0.02, 0.97, 0.015], [-0.01, 0.015, 1.01]],
            resolution_uT=0.3,
            range_uT=1300,
        )
        return cls(gyro=gyro, acc=acc, mag=mag, clock=ClockModel(jitter=20e-6))

    @classmethod
    def tactical(cls) -> ImuModel:
        """A tactical-grade IMU (HG1700 / STIM300 class) with a calibrated magnetometer.

        Returns
        -------
        ImuModel
            Gyro: ARW 0.1 deg/√h, bias [1, -0.7, 0.5] deg/h, a rate random walk that wanders by the 1 deg/h bias
            instability in about 20 minutes, 150 ppm scale, 0.01° cross-axis, ±1000 deg/s, no quantisation.
            Accelerometer: VRW 0.03 m/s/√h, bias [1, -0.8, 0.6] mg, wander 0.05 mg in 20 minutes, 300 ppm,
            0.01°, ±50 g.  Magnetometer: 0.003 µT/√Hz, residual hard iron of a few tenths of a µT, 0.01 µT LSB,
            ±200 µT.  Clock jitter 1 µs.

        Examples
        --------
        >>> import numpy as np
        >>> from strapdown.simulate.models import ImuModel
        >>> round(float(np.degrees(ImuModel.tactical().gyro.noise_density)) * 60, 12)    # ARW, deg/√h
        0.1
        """
        # Typical datasheet figures of this class (rounded).  Flicker noise is not modelled: the bias instability
        # is approximated by a rate random walk K with K √(1200 s) equal to it.
        wander = np.sqrt(1200.0)
        gyro = TriadModel.gyro(
            bias_deg_s=np.array([1.0, -0.7, 0.5]) / 3600,
            rate_random_walk_deg_s_sqrt_s=1.0 / 3600 / wander,
            arw_deg_sqrt_h=0.1,
            scale_factor_ppm=150,
            misalignment_deg=0.01,
            range_deg_s=1000,
        )
        acc = TriadModel.accelerometer(
            bias_mg=[1.0, -0.8, 0.6],
            rate_random_walk_mg_sqrt_s=0.05 / wander,
            vrw_m_s_sqrt_h=0.03,
            scale_factor_ppm=300,
            misalignment_deg=0.01,
            range_g=50,
        )
        mag = TriadModel.magnetometer(
            bias_uT=[0.2, -0.1, 0.15],
            noise_density_uT_sqrt_hz=0.003,
            resolution_uT=0.01,
            range_uT=200,
        )
        return cls(gyro=gyro, acc=acc, mag=mag, clock=ClockModel(jitter=1e-6))
