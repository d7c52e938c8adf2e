"""The messages of an ArduPilot DataFlash log, binary (``.bin``) or text (``.log``), a block at a time (private).

The binary layout (ArduPilot ``libraries/AP_Logger/LogStructure.h``): every message is ``0xA3 0x95 type`` and a
payload; a ``FMT`` message (type 128, 89 bytes) declares each type's name, length, format characters and column
names before its first use.  The format characters and their C types (and the scale ArduPilot stores them at):

====  ===============  ====  =====================
a     int16[32]        c     int16 × 100
b     int8             C     uint16 × 100
B     uint8            e     int32 × 100
h     int16            E     uint32 × 100
H     uint16           L     int32 latitude/longitude × 1e7
i     int32            M     uint8 flight mode
I     uint32           n     char[4]
f     float            N     char[16]
d     double           Z     char[64]
q     int64            g     float16
Q     uint64
====  ===============  ====  =====================

so a ``c`` column divided by 100 is in its unit, and an ``L`` column divided by 1e7 in degrees (as pymavlink's
DFReader scales them).  The text form (what Mission Planner and ``mavlogdump.py --format`` write) has one message
a line, ``NAME, value, value, ...``, its ``FMT`` lines declaring the columns, the values already scaled.
"""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np

from ._walk import BATCH, Blocks, Break

HEAD = (0xA3, 0x95)
FMT_TYPE, FMT_LENGTH = 0x80, 89
# format character: (numpy type, count, scale that takes the stored integer to the unit)
_CHARS = {
    "a": ("<i2", 32, None),
    "b": ("i1", 1, None),
    "B": ("u1", 1, None),
    "g": ("<f2", 1, None),
    "h": ("<i2", 1, None),
    "H": ("<u2", 1, None),
    "i": ("<i4", 1, None),
    "I": ("<u4", 1, None),
    "f": ("<f4", 1, None),
    "d": ("<f8", 1, None),
    "n": ("S4", 1, None),
    "N": ("S16", 1, None),
    "Z": ("S64", 1, None),
    "c": ("<i2", 1, 100.0),
    "C": ("<u2", 1, 100.0),
    "e": ("<i4", 1, 100.0),
    "E": ("<u4", 1, 100.0),
    "L": ("<i4", 1, 1e7),
    "M": ("u1", 1, None),
    "q": ("<i8", 1, None),
    "Q": ("<u8", 1, None),
}
#: Longest line of a text log read (its lines are a few hundred bytes; past this it is no DataFlash text).
MAX_TEXT_LINE = 1 << 16


def layout(name: str, format: str, columns: str, where: str):
    """The numpy layout of one message type and the scale of its columns: ``(dtype, {column: divisor})``."""
    names = [c for c in columns.split(",")] if columns else []
    if len(names) != len(format) or len(set(names)) != len(names):
        raise ValueError(
            f"{where}: the FMT of {name} declares {len(format)} formats {format!r} for columns {columns!r}"
        )
    fields, divisors = [], {}
    for col, char in zip(names, format, strict=True):
        if char not in _CHARS:
            raise ValueError(f"{where}: the FMT of {name} has the format character {char!r}, which DataFlash has not")
        code, count, divisor = _CHARS[char]
        fields.append((col, code) if count == 1 else (col, code, (count,)))
        if divisor:
            divisors[col] = divisor
    return np.dtype(fields), divisors


def _text(raw) -> str:
    return raw.split(b"\0", 1)[0].decode("ascii", errors="replace").strip()


def numeric(records, divisors) -> dict:
    """The columns of decoded records: numbers as float64 scaled to their units, names (``n``, ``N``, ``Z``) as str."""
    out = {}
    for col in records.dtype.names:
        kind = records.dtype[col].kind
        if kind in "iuf" and not records.dtype[col].shape:
            v = records[col].astype(np.float64) if col != "TimeUS" else records[col].astype(np.int64)
            out[col] = v / divisors[col] if col in divisors else v
        elif kind == "S":  # a parameter's name, a text message: NUL-padded ASCII
            out[col] = np.char.strip(np.char.decode(records[col], "ascii", errors="replace"))
    return out


def boot_time(name: str, cols: dict) -> dict:
    """``cols`` with ``TimeUS`` (µs since boot): logs before ArduPilot 3.3 stamp their messages ``TimeMS`` instead.

    Not for ``GPS``, whose ``TimeMS`` in those logs is the GPS time of week (its boot time is ``T``).
    """
    if "TimeUS" not in cols and "TimeMS" in cols and not name.startswith("GPS"):
        cols["TimeUS"] = np.round(cols["TimeMS"] * 1000.0).astype(np.int64)
    return cols


def scan_binary(path: Path, wanted, sink) -> tuple[list, list]:
    """Walk a binary log; ``sink(name, columns)`` gets the wanted types' numeric columns a block at a time.

    Returns the names of the log's message types and its :class:`~._walk.Break` list (``counts`` by name).
    """
    from . import _logs_numba as k

    length = np.zeros(256, dtype=np.int64)
    length[FMT_TYPE] = FMT_LENGTH
    want = np.full(256, -1, dtype=np.int64)
    kinds, names, breaks, counts = [], [], [], {}
    offs, ids = np.empty(BATCH, dtype=np.int64), np.empty(BATCH, dtype=np.int64)
    with open(path, "rb") as f:
        head = f.read(3)
        if tuple(head[:2]) != HEAD:
            raise ValueError(f"{path} is not a DataFlash log (its first bytes are not 0xA3 0x95)")
        blocks = Blocks(f, 0)
        pos = 0
        while True:
            pos, n, status = k.dataflash_walk(blocks.buf, pos, blocks.end, length, want, offs, ids, *HEAD)
            for j, (name, dtype, divisors) in enumerate(kinds):
                o = offs[:n][ids[:n] == j]
                if o.size:
                    rows = blocks.buf[o[:, None] + np.arange(dtype.itemsize)]
                    counts[name] = counts.get(name, 0) + o.size
                    sink(name, boot_time(name, numeric(rows.view(dtype).ravel(), divisors)))
            if status == k.FULL:
                continue
            if status == k.STOP:
                body = blocks.buf[pos + 3 : pos + FMT_LENGTH].tobytes()
                typ, size, name, fmt, cols = struct.unpack("<BB4s16s64s", body)
                name, fmt, cols = _text(name), _text(fmt), _text(cols)
                if size < 3 or (typ == FMT_TYPE and size != FMT_LENGTH):
                    raise ValueError(f"{path}: the FMT at byte {blocks.base + pos} gives {name} a length of {size}")
                length[typ] = size
                names.append(name)
                if wanted(name):
                    dtype, divisors = layout(name, fmt, cols, f"{path} (byte {blocks.base + pos})")
                    if dtype.itemsize != size - 3:
                        raise ValueError(
                            f"{path}: the FMT of {name} at byte {blocks.base + pos} declares {size} bytes, but its "
                            f"format {fmt!r} takes {dtype.itemsize + 3}"
                        )
                    kinds.append((name, dtype, divisors))
                    want[typ] = len(kinds) - 1
                pos += FMT_LENGTH
                continue
            if status == k.NEED:
                if not blocks.eof:
                    pos = blocks.fill(pos)
                    continue
                rest = blocks.buf[pos : blocks.end]
                # a log is written in pages: the end of the last one is padding (0xFF or 0x00), not a cut message
                if rest.size and not (np.all(rest == 0xFF) or np.all(rest == 0)):
                    breaks.append(
                        Break(
                            blocks.base + pos,
                            None,
                            f"the log is cut inside a message ({rest.size} bytes)",
                            dict(getattr(sink, "counts", counts)),
                        )
                    )
                break
            where = blocks.base + pos
            typ = int(blocks.buf[pos + 2]) if pos + 3 <= blocks.end else -1
            head_ok = tuple(blocks.buf[pos : pos + 2]) == HEAD
            what = f"a message of type {typ}, which no FMT declares" if head_ok else "bytes that start no message"
            while True:
                found = k.dataflash_resync(blocks.buf, pos, blocks.end, blocks.eof, length, *HEAD)
                if found >= 0 or blocks.eof:
                    break
                pos = blocks.fill(max(pos, blocks.end - 4096))
            if found < 0 and _padding(blocks.buf[pos : blocks.end]):
                break
            breaks.append(
                Break(where, None if found < 0 else blocks.base + found, what, dict(getattr(sink, "counts", counts)))
            )
            if found < 0:
                break
            pos = found
    return names, breaks


def _padding(rest) -> bool:
    return bool(rest.size) and bool(np.all(rest == 0xFF) or np.all(rest == 0))


def scan_text(path: Path, wanted, sink) -> tuple[list, list]:
    """Read a text log line by line; ``sink(name, columns)`` gets the wanted types' numeric columns in blocks."""
    formats: dict[str, list] = {}
    rows: dict[str, list] = {}
    names: list[str] = []

    def flush(name):
        cols = formats[name]
        table = rows.pop(name, [])
        if not table:
            return
        out = {}
        for i, col in enumerate(cols):
            values = [r[i] for r in table]
            try:
                out[col] = np.array(values, dtype=np.int64 if col == "TimeUS" else np.float64)
            except ValueError:
                out[col] = np.array(values, dtype=str)  # a text column (a parameter's name, a message)
        sink(name, boot_time(name, out))

    breaks = []
    with open(path, "rb") as f:
        for number, line in enumerate(iter(lambda: f.readline(MAX_TEXT_LINE + 1), b""), start=1):
            if not line.endswith(b"\n") and len(line) <= MAX_TEXT_LINE:  # the last line, cut short
                counts = dict(getattr(sink, "counts", {}))
                breaks.append(Break(f.tell() - len(line), None, f"the log is cut inside line {number}", counts))
                break
            if len(line) > MAX_TEXT_LINE:
                raise ValueError(f"{path}: line {number} is longer than {MAX_TEXT_LINE} bytes: no DataFlash text log")
            parts = [p.strip() for p in line.decode("utf-8", errors="replace").split(",")]
            if len(parts) < 2:
                continue
            name = parts[0]
            if name == "FMT" and len(parts) >= 6:
                declared = parts[3]
                columns = [c for c in parts[5:] if c]
                if declared != "FMT":
                    formats[declared] = columns
                    names.append(declared)
                continue
            if name in formats and wanted(name):
                if len(parts) - 1 != len(formats[name]):
                    raise ValueError(
                        f"{path}: line {number} has {len(parts) - 1} values for {name}, whose FMT names "
                        f"{len(formats[name])} columns"
                    )
                rows.setdefault(name, []).append(parts[1:])
                if len(rows[name]) >= 1 << 16:
                    flush(name)
        for name in list(rows):
            flush(name)
    return names, breaks


def is_text_log(path: Path) -> bool:
    """A text DataFlash log starts with ``FMT,`` lines."""
    with open(path, "rb") as f:
        return f.read(4) == b"FMT,"
