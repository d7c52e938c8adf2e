"""The reader registry: every input format is one module that registers how to recognise and open it.

A format is chosen from, in this order: the ``format`` the user names; a folder's or zip's layout (a Sensor
Logger or phyphox export, an EuRoC ``mav0`` folder, a ROS 2 bag); the suffix (``.ulg``, ``.bag``, ``.csv``,
...); the first bytes of the file (ULog's magic, HDF5's signature).  :func:`register` adds a format; the
modules of :mod:`strapdown.io.formats` call it when imported.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

__all__ = ["Format", "choose", "formats", "register"]


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
    """

    name: str
    open: Callable
    suffixes: tuple = ()
    detect: Callable | None = None
    options: tuple = ()
    table: bool = False
    description: str = field(default="", compare=False)


_FORMATS: dict[str, Format] = {}


def register(fmt: Format) -> Format:
    """Add a format (a later registration of the same name replaces the earlier one).

    Parameters
    ----------
    fmt : Format
        The format.

    Returns
    -------
    Format
        ``fmt``.

    Examples
    --------
    >>> from strapdown.io.registry import Format, formats, register
    >>> _ = register(Format("demo_txt", open=lambda path: None, suffixes=(".demo",)))
    >>> "demo_txt" in formats()
    True
    >>> _ = formats().pop("demo_txt") and None
    """
    _FORMATS[fmt.name] = fmt
    return fmt


def formats() -> dict[str, Format]:
    """The registered formats by name (the registry itself).

    Parameters
    ----------
    None

    Returns
    -------
    dict of str to Format
        Every format, in registration order.

    Examples
    --------
    >>> from strapdown.io.registry import formats
    >>> {"csv", "ulog", "rosbag", "sensorlogger", "phyphox", "euroc"} <= set(formats())
    True
    """
    from . import formats as _modules  # noqa: F401  (importing registers the built-in formats)

    return _FORMATS


def choose(path, format: str | None = None) -> Format:
    """The format of an input path: named, from the layout of a folder or zip, the suffix, or the content.

    Parameters
    ----------
    path : path-like
        A file, folder or zip.
    format : str, optional
        A format name, which overrides everything.

    Returns
    -------
    Format
        The format.

    Examples
    --------
    >>> from strapdown.io.registry import choose
    >>> choose("flight.ulg").name, choose("imu.CSV").name, choose("x.dat", "csv").name
    ('ulog', 'csv', 'csv')
    """
    known = formats()
    if format is not None:
        if format not in known:
            raise ValueError(f"unknown format {format!r}; use one of {', '.join(known)}")
        return known[format]
    path = Path(path)
    suffix = path.suffix.lower()
    container = path.is_dir() or suffix == ".zip"
    if container:
        for fmt in known.values():
            if fmt.detect is not None and _safe(fmt.detect, path):
                return fmt
    for fmt in known.values():
        if suffix in fmt.suffixes:
            return fmt
    if path.is_file():
        for fmt in known.values():
            if fmt.detect is not None and _safe(fmt.detect, path):
                return fmt
    what = "folder" if path.is_dir() else "zip" if suffix == ".zip" else "file"
    suffixes = sorted({s for f in known.values() for s in f.suffixes})
    raise ValueError(
        f"cannot tell the format of {path.name!r} ({what}): its layout or suffix matches none of "
        f"{', '.join(known)} (suffixes {' '.join(suffixes)}); name it with --in-format"
    )


def _safe(detect, path: Path) -> bool:
    """A detector's answer; one that cannot read the path says no instead of failing the choice."""
    try:
        return bool(detect(path))
    except (OSError, ValueError):
        return False
