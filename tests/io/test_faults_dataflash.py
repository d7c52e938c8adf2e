"""A real DataFlash log corrupted: cut at several offsets, bits flipped, 4 KiB blocks zeroed (issue 28).

The same cases as the ULog ones of tests/io/test_faults.py, on tests/data/ardupilot/log171.bin (a real ArduCopter
3.3 flight, tests/data/PROVENANCE.md).  DataFlash has no checksum, so a break shows only as bytes that start no
message: the reader either refuses by the file's name and the byte where the log broke, writing nothing, or reads
on and warns with the samples lost and their time span; never a silent loss, never a traceback.  The messages'
offsets are found here with a walk of the file's own FMTs (ArduPilot's LogStructure.h), and pymavlink's DFReader
reads the cut logs as the oracle of what is left in them.
"""

from __future__ import annotations

import re
import struct
import subprocess
import sys
from pathlib import Path

import pytest

LOG = Path(__file__).resolve().parents[1] / "data" / "ardupilot" / "log171.bin"
ROWS = 11_916  # the log's IMU messages (pymavlink counts them too: tests/io/test_dataflash_real.py)


def _estimate(log, out):
    res = subprocess.run(
        [sys.executable, "-m", "strapdown.cli", "estimate", str(log), "-o", str(out)],
        capture_output=True,
        text=True,
        timeout=600,
    )
    text = res.stdout + res.stderr
    assert "Traceback" not in text, text
    return res.returncode, text


def _damaged(tmp_path, data, name):
    """Write ``data`` as ``name``.bin and estimate it: (log, output, returncode, text)."""
    log, out = tmp_path / f"{name}.bin", tmp_path / f"{name}.csv"
    log.write_bytes(data)
    code, text = _estimate(log, out)
    return log, out, code, text


def _lost(text, log, what):
    """The warning's groups: where the skipped bytes start and stop, the samples lost, and their time span."""
    said = re.search(
        rf"warning: {re.escape(str(log))}: {what} at bytes (\d+) to (\d+), skipped: about (\d+) gyro \(IMU:0\) "
        r"samples lost \(t = ([\d.]+) s to ([\d.]+) s\)",
        text,
    )
    assert said, text
    return int(said.group(1)), int(said.group(2)), int(said.group(3)), float(said.group(4)), float(said.group(5))


def _rows(path):
    from strapdown.io import read_table

    return len(read_table(path)["t"])


def _messages(data: bytes, name: str) -> list[int]:
    """Offsets of one message type: ``0xA3 0x95 type`` and the length its FMT (type 128, 89 bytes) declares."""
    length, names, pos, found = {128: 89}, {128: "FMT"}, 0, []
    while pos + 3 <= len(data) and data[pos : pos + 2] == b"\xa3\x95" and data[pos + 2] in length:
        typ = data[pos + 2]
        if typ == 128:
            declared, size, label = struct.unpack_from("<BB4s", data, pos + 3)
            length[declared], names[declared] = size, label.rstrip(b"\0").decode()
        if names[typ] == name:
            found.append(pos)
        pos += length[typ]
    return found


def _pymavlink_imu(path) -> list:
    from pymavlink import DFReader

    log = DFReader.DFReader_binary(str(path))
    times = []
    while (m := log.recv_match(type="IMU")) is not None:
        times.append(m.TimeMS)
    return times


DATA = LOG.read_bytes()
IMU = _messages(DATA, "IMU")


def test_the_walk_here_finds_every_imu_message():
    assert len(IMU) == ROWS


@pytest.mark.parametrize("fraction", [0.001, 0.002, 0.01, 0.3, 0.77, 0.999])
def test_a_real_dataflash_log_cut_anywhere_warns_where_it_ends_or_refuses_by_name(tmp_path, fraction):
    pytest.importorskip("pymavlink")
    cut = DATA[: int(len(DATA) * fraction)]
    (tmp_path / "cut.bin").write_bytes(cut)
    left = _pymavlink_imu(tmp_path / "cut.bin")
    log, out, code, text = _damaged(tmp_path, cut, "cut")
    if not left:  # cut among the FMTs at the start: nothing to estimate from, refused with where it ends
        assert code == 1 and not out.exists(), text
        assert re.search(rf"{re.escape(str(log))}: no IMU messages .*(at byte \d+|its {len(cut)} bytes)", text), text
        return
    assert code == 0, text
    said = re.search(
        rf"warning: {re.escape(str(log))}: the log is cut inside a message \((\d+) bytes\) at bytes (\d+) to the "
        r"end, skipped: the gyro \(IMU:0\) readings end there, at t = ([\d.]+) s",
        text,
    )
    assert said, text
    assert int(said.group(1)) + int(said.group(2)) == len(cut)  # the broken message is the file's last bytes
    assert _rows(out) == len(left)  # every IMU message before the cut, as pymavlink reads them
    assert float(said.group(3)) == pytest.approx((left[-1] - left[0]) / 1e3, abs=5e-4)


@pytest.mark.parametrize("bit", [0, 7, 8, 15, 16, 17, 23])
def test_a_flipped_bit_in_an_imu_messages_header_is_warned_with_the_sample_lost(tmp_path, bit):
    data = bytearray(DATA)
    at = IMU[len(IMU) // 2 + bit]
    data[at + bit // 8] ^= 1 << (bit % 8)  # 0xA3, 0x95 or the type byte of one IMU message
    log, out, code, text = _damaged(tmp_path, data, "flip")
    assert code == 0, text
    start, stop, lost, since, until = _lost(text, log, ".*")
    # where the walk lost the thread: the flipped message, or (a type byte turned into another type's) the bytes
    # that follow it, within one message (DataFlash messages are at most 255 bytes)
    assert at <= start <= at + 255 and stop > at
    assert ROWS - _rows(out) == lost == 1 and since < until


@pytest.mark.parametrize("block", [186, 297, 601, 700])
def test_a_zeroed_4_kib_block_is_warned_with_the_samples_lost_and_when(tmp_path, block):
    data = bytearray(DATA)
    start = block * 4096
    data[start : start + 4096] = bytes(4096)
    log, out, code, text = _damaged(tmp_path, data, "zeroed")
    assert code == 0, text
    begin, stop, said, since, until = _lost(text, log, "bytes that start no message")
    assert start <= begin < start + 256 and start + 4096 <= stop < start + 4096 + 256
    lost = sum(start - 42 < o < start + 4096 for o in IMU)  # an IMU message is 43 bytes: any byte zeroed loses it
    assert ROWS - _rows(out) == said == lost
    assert until - since == pytest.approx(0.02 * (lost + 1), abs=0.025)


@pytest.mark.parametrize(("field", "bit"), [(3, 20), (3, 31), (7, 30)])  # TimeMS (bytes 3-6), GyrX (7-10)
def test_a_flipped_bit_in_an_imu_time_or_reading_is_refused_by_name_and_row(tmp_path, field, bit):
    data = bytearray(DATA)
    at = IMU[len(IMU) // 2]
    data[at + field + bit // 8] ^= 1 << (bit % 8)  # a time 17 min or 596 h later, a rate of 1e37 rad/s
    log, out, code, text = _damaged(tmp_path, data, "value")
    assert code == 1 and not out.exists(), text
    row = len(IMU) // 2  # the flipped one; a time check names the row after it, where the time goes back
    assert re.search(rf"{re.escape(str(log))}: .*row ({row}|{row + 1})\b", text), text
