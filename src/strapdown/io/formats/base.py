"""What a reader module declares about its format: how to recognise it and how to open it."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

__all__ = ["Format"]


@dataclass(frozen=True)
class Format:
    """How to recognise and open one input format.

    Attributes
    ----------
    name : str
        The name users give (``--in-format``).
    open : callable
        ``open(path, **options) -> Source``.
    suffixes : tuple of str
        File suffixes (lower case, with the dot) that mean this format.
    detect : callable, optional
        ``detect(path) -> bool`` for folders, zips and files whose suffix says nothing; tried before suffixes
        for folders and zips, after them for files.
    options : tuple of str
        The options ``open`` accepts besides the path (``"topic"``).
    table : bool
        A plain table that :func:`strapdown.io.write_table` also writes (csv, parquet, hdf5, mat).
    reference : callable, optional
        ``reference(path, topic=None) -> dict`` for a log that records its own attitude estimate (PX4
        ``vehicle_attitude``, ArduPilot ATT, a ROS ``Imu`` orientation): the keys ``t`` (s, the IMU's time
        origin), ``q`` (n, 4, body to ``frame``), ``frame``, ``body``, ``time_origin`` and ``source`` (what was
        read), the fields of :class:`strapdown.io.reference.Reference`; None when the format records none.
    position : callable, optional
        ``position(path) -> dict or None`` for a log that records where and when it was made (GPS): the keys
        ``latitude_deg``, ``longitude_deg``, ``altitude_m`` and ``date`` (a ``datetime.date``, UTC), and
        ``source``; None when this log holds no fix.
    """

    name: str
    open: Callable
    suffixes: tuple = ()
    detect: Callable | None = None
    options: tuple = ()
    table: bool = False
    description: str = field(default="", compare=False)
    reference: Callable | None = field(default=None, compare=False)
    position: Callable | None = field(default=None, compare=False)


def named_failure(path, name: str, open_: Callable):
    """``open_()``, a failure to read ``path`` as a ``name`` file named as :func:`strapdown.io.open_source` names it.

    ImportError (a missing extra) and FileNotFoundError pass as they are; any other error becomes a ValueError
    that names the path (``<path> is not a readable csv file: <the reader's reason>``).
    """
    try:
        return open_()
    except (ImportError, FileNotFoundError):
        raise
    except ValueError as exc:
        text = str(exc)
        raise ValueError(text if str(path) in text else f"{path} is not a readable {name} file: {text}") from None
    except Exception as exc:  # a corrupt file, or one without a header: named, with the reader's reason
        raise ValueError(f"{path} is not a readable {name} file: {exc}") from None
