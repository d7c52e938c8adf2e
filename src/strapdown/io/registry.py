"""The reader registry: every input format is one module that registers how to recognise and open it.

A format is chosen from, in this order: the ``format`` the user names; a folder's or zip's layout (a Sensor
Logger or phyphox export, an EuRoC ``mav0`` folder, a ROS 2 bag); the suffix (``.ulg``, ``.bag``, ``.csv``,
...); the first bytes of the file (ULog's magic, HDF5's signature).  Each module of :mod:`strapdown.io.formats`
declares its :class:`Format`, and this registry holds them in :data:`strapdown.io.formats.BUILT_IN`'s order;
:func:`register` adds another.
"""

from __future__ import annotations

from pathlib import Path

from .formats import BUILT_IN
from .formats.base import Format
from .formats.multi import open_files

__all__ = ["Format", "choose", "formats", "register"]


def _open_member(path, **options):
    """One file of several, by its own format (the "files" format below; readers.open_source for the user's list)."""
    return choose(path).open(path, **options)


#: Several files of one recording (one per sensor), as one table: formats.multi with each member by its format.
FILES = Format(
    "files",
    lambda path, **o: open_files([Path(path)], opener=_open_member, **o),
    options=("time_unit",),
    description="several files",
)

_FORMATS: dict[str, Format] = {f.name: f for f in (*BUILT_IN[:4], FILES, *BUILT_IN[4:])}


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
        The registered format that opens ``path`` (:func:`formats`).

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
