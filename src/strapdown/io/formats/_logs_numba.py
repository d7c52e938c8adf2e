"""Numba kernels of the log readers (private): walk the messages of a ULog or DataFlash block, find the next good one.

Both formats are sequences of messages whose length is known from a header: ULog's ``uint16 size, uint8 type``
(PX4 ULog file format, "Message Header"), DataFlash's ``0xA3 0x95 type`` with the length its FMT message declared
(ArduPilot AP_Logger, LogStructure.h).  Walking them is a sequential loop over tens of millions of messages, which
is why it is compiled; the payloads are then decoded with numpy from the offsets the walk returns.
"""

from __future__ import annotations

import numba

from ..._support import kernel_cache  # noqa: F401  (strapdown's own numba cache, before any kernel: its notes)

NEED, STOP, FULL, CORRUPT = 0, 1, 2, 3  # the walk's statuses: more bytes, a message for Python, output full, bad
_CHAIN = 4  # messages in a row that must be valid for a resynchronisation point

# ULog message types (ASCII): those of the data section, and what the walk does with them
_D, _A, _R, _S, _O = 68, 65, 82, 83, 79
_SKIPPED = (73, 77, 80, 81, 76, 67, 70, 66)  # I M P Q L C F B: skipped by their size


@numba.njit(cache=True)
def _ulog_check(buf, pos, end, item, top):
    """0: a valid message header at ``pos`` (its size), -1: invalid, -2: too few bytes to tell."""
    if pos + 3 > end:
        return -2
    size = buf[pos] | (numba.int64(buf[pos + 1]) << 8)
    typ = buf[pos + 2]
    if typ == _D:
        if size < 2:
            return -1
        if pos + 5 > end:
            return -2
        msg_id = buf[pos + 3] | (numba.int64(buf[pos + 4]) << 8)
        if top[msg_id] < 0 or size - 2 < item[msg_id] or size - 2 > top[msg_id]:
            return -1
        return size
    if typ == _S:
        return size if size == 8 else -1
    if typ == _O:
        return size if size == 2 else -1
    if typ == _A:
        return size if size >= 4 else -1
    if typ == _R:
        return size if size == 2 else -1
    for t in _SKIPPED:
        if typ == t:
            return size
    return -1


@numba.njit(cache=True)
def ulog_walk(buf, pos, end, item, top, want, offs, ids):
    """Walk ULog data messages from ``pos``; record the payload offset and topic of every wanted data message.

    ``item[msg_id]``/``top[msg_id]``: the smallest and largest payload a subscribed id may have (-1: none);
    ``want[msg_id]``: the topic index to record, or -1.  Returns ``(pos, n, status)``: where it stopped, how many
    were recorded in ``offs``/``ids``, and why (NEED, STOP at an add/remove message, FULL, CORRUPT at ``pos``).
    """
    n = 0
    cap = offs.shape[0]
    while True:
        size = _ulog_check(buf, pos, end, item, top)
        if size == -2:
            return pos, n, NEED
        if size == -1:
            return pos, n, CORRUPT
        if pos + 3 + size > end:
            return pos, n, NEED
        typ = buf[pos + 2]
        if typ == _A or typ == _R:
            return pos, n, STOP
        if typ == _D:
            msg_id = buf[pos + 3] | (numba.int64(buf[pos + 4]) << 8)
            k = want[msg_id]
            if k >= 0:
                if n == cap:
                    return pos, n, FULL
                offs[n] = pos + 5
                ids[n] = k
                n += 1
        pos += 3 + size


@numba.njit(cache=True)
def ulog_resync(buf, pos, end, at_eof, item, top):
    """The first offset after ``pos`` where _CHAIN valid messages follow one another (or that reach the end), or -1."""
    for p in range(pos + 1, end - 2):
        q = p
        good = 0
        while good < _CHAIN:
            size = _ulog_check(buf, q, end, item, top)
            if size < 0:
                break
            q += 3 + size
            good += 1
            if q >= end:
                break
        if good == _CHAIN or (good > 0 and q == end and at_eof):
            return p
    return -1


@numba.njit(cache=True)
def dataflash_walk(buf, pos, end, length, want, offs, ids, head1, head2):
    """Walk DataFlash messages from ``pos``; record the offset and kind of every wanted one.

    ``length[type]``: the message length its FMT declared (header included, so 3 for a message without payload;
    0: no FMT yet); ``want[type]``: the
    index to record, or -1; the FMT type (0x80) always stops for Python.  Returns ``(pos, n, status)`` as
    :func:`ulog_walk`.
    """
    n = 0
    cap = offs.shape[0]
    while True:
        if pos + 3 > end:
            return pos, n, NEED
        if buf[pos] != head1 or buf[pos + 1] != head2:
            return pos, n, CORRUPT
        typ = buf[pos + 2]
        size = length[typ]
        if size < 3:  # no FMT has declared the type (a message of only its header, 3 bytes, is legitimate)
            return pos, n, CORRUPT
        if pos + size > end:
            return pos, n, NEED
        if typ == 0x80:
            return pos, n, STOP
        k = want[typ]
        if k >= 0:
            if n == cap:
                return pos, n, FULL
            offs[n] = pos + 3
            ids[n] = k
            n += 1
        pos += size


@numba.njit(cache=True)
def dataflash_resync(buf, pos, end, at_eof, length, head1, head2):
    """The first offset after ``pos`` where _CHAIN known messages follow one another (or reach the end), or -1."""
    for p in range(pos + 1, end - 2):
        q = p
        good = 0
        while good < _CHAIN and q + 3 <= end:
            if buf[q] != head1 or buf[q + 1] != head2 or length[buf[q + 2]] < 3:
                break
            q += length[buf[q + 2]]
            good += 1
        if good == _CHAIN or (good > 0 and q >= end and at_eof):
            return p
    return -1
