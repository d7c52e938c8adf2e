r"""Where an MCAP file breaks (private): a walk over its records, for the bag reader's messages.

MCAP (https://mcap.dev/spec): the magic ``\x89MCAP0\r\n``, then records, each an opcode (uint8), a length
(uint64, little-endian) and that many bytes, up to a Footer record (opcode 0x02) and the magic again.  A Chunk
record (0x06) holds ``message_start_time``, ``message_end_time`` (uint64 ns), ``uncompressed_size``,
``uncompressed_crc`` (uint32, 0: not computed), ``compression`` (a uint32-prefixed string: ``""``, ``"zstd"`` or
``"lz4"``) and its records, compressed.  rosbags reads a file through the summary at its end, so a cut file
cannot be opened and a damaged chunk ends the reading early; neither says where.  The walk reads the record
headers only, seeking over their contents, and, when asked, each chunk whole (one at a time: memory bounded by the
largest chunk), checking its CRC or, without one, that its own records follow one another.
"""

from __future__ import annotations

import struct
import zlib
from pathlib import Path

MAGIC = b"\x89MCAP0\r\n"
_NAMES = {
    1: "Header",
    2: "Footer",
    3: "Schema",
    4: "Channel",
    5: "Message",
    6: "Chunk",
    7: "Message Index",
    8: "Chunk Index",
    9: "Attachment",
    10: "Attachment Index",
    11: "Statistics",
    12: "Metadata",
    13: "Metadata Index",
    14: "Summary Offset",
    15: "Data End",
}
_CHUNK_FIXED = 8 + 8 + 8 + 4  # the times, the uncompressed size and CRC before the compression's name
#: Chunks larger than this are not read whole to be checked (writers make them of a few MiB).
MAX_CHECKED_CHUNK = 256 << 20


def _opcode_name(op: int) -> str | None:
    return _NAMES.get(op) or (f"user record 0x{op:02x}" if op >= 0x80 else None)


def mcap_break(path, chunks: bool = False) -> str | None:
    """What breaks an MCAP file and at which byte, or None when its records run whole from magic to magic.

    Parameters
    ----------
    path : path-like
        The ``.mcap`` file.
    chunks : bool
        Also read every chunk and check its CRC, or that its records follow one another.

    Returns
    -------
    str or None
        ``"the file is cut inside a Chunk record that starts at byte 43 (it declares 211877 bytes; the file ends
        at byte 113471)"`` and the like.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> from strapdown.io.formats._mcap import MAGIC, mcap_break
    >>> cut = pathlib.Path(tempfile.mkdtemp()) / "cut.mcap"
    >>> _ = cut.write_bytes(MAGIC + bytes([1]) + (26).to_bytes(8, "little") + bytes(10))
    >>> mcap_break(cut)
    'the file is cut inside a Header record that starts at byte 8 (it declares 26 bytes; the file ends at byte 27)'
    """
    path = Path(path)
    size = path.stat().st_size
    with open(path, "rb") as f:
        if f.read(8) != MAGIC:
            return "it does not start with the MCAP magic (byte 0)"
        pos, first_ns = 8, None
        while True:
            head = f.read(9)
            if not head:
                return f"the file ends at byte {pos} without its Footer: it is cut there"
            if len(head) < 9:
                return f"the file is cut inside the header of a record at byte {pos}"
            op, length = struct.unpack("<BQ", head)
            name = _opcode_name(op)
            if name is None:
                return f"bytes that start no MCAP record (opcode 0x{op:02x}) at byte {pos}"
            end = pos + 9 + length
            if end > size:
                return (
                    f"the file is cut inside a {name} record that starts at byte {pos} (it declares {length} bytes; "
                    f"the file ends at byte {size})"
                )
            if op == 2:
                f.seek(end)
                return None if f.read(8) == MAGIC else f"no MCAP magic after the Footer at byte {pos}"
            if op == 6 and chunks and length <= MAX_CHECKED_CHUNK:
                content = f.read(length)
                first_ns = first_ns or struct.unpack_from("<Q", content)[0]
                problem = _chunk_problem(content, pos)
                if problem:
                    start, stop = struct.unpack_from("<QQ", content)
                    span = f"{(start - first_ns) / 1e9:.6g} s to {(stop - first_ns) / 1e9:.6g} s"
                    return f"the Chunk at bytes {pos} to {end}, messages of {span}, is damaged: {problem}"
            f.seek(end)
            pos = end


def _chunk_problem(content: bytes, pos: int) -> str | None:
    """Why a chunk's records cannot be right (a CRC that does not match, a record that runs past it), or None."""
    try:
        _, _, usize, crc, clen = struct.unpack_from("<QQQII", content)
        compression = content[_CHUNK_FIXED + 4 : _CHUNK_FIXED + 4 + clen].decode("ascii")
        rlen = struct.unpack_from("<Q", content, _CHUNK_FIXED + 4 + clen)[0]
        start = _CHUNK_FIXED + 4 + clen + 8
        records = _decompress(content[start : start + rlen], compression, usize)
    except (struct.error, UnicodeDecodeError, ValueError) as exc:
        return f"its header or compressed records cannot be read ({exc})"
    if records is None:
        return None  # a compression this installation cannot undo: rosbags could not either
    if len(records) != usize:
        return f"its records are {len(records)} bytes where it declares {usize}"
    if crc:
        return None if zlib.crc32(records) == crc else "its records do not match its CRC"
    inner = 0
    while inner < len(records):
        where = "" if compression else f", byte {pos + 9 + start + inner} of the file"
        if inner + 9 > len(records):
            return f"a record header is cut at byte {inner} of its records{where}"
        op, length = struct.unpack_from("<BQ", records, inner)
        if _opcode_name(op) is None or inner + 9 + length > len(records):
            return f"no record can start at byte {inner} of its records{where}"
        inner += 9 + length
    return None


def _decompress(data: bytes, compression: str, size: int) -> bytes | None:
    if not compression:
        return data
    try:
        if compression == "zstd":
            try:
                from compression import zstd  # Python 3.14
            except ImportError:
                from backports import zstd
            return zstd.decompress(data)
        if compression == "lz4":
            import lz4.frame

            return lz4.frame.decompress(data)
    except ImportError:
        return None
    except Exception as exc:  # the libraries' own errors: the data is not what it claims
        raise ValueError(f"{compression} cannot decompress them: {exc}") from None
    raise ValueError(f"the compression {compression!r} is not MCAP's")
