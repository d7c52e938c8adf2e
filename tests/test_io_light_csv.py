"""Small CSV files read and written without pyarrow: the same values, bytes and errors as pyarrow's own paths.

The oracle is pyarrow itself: each case is run once on the light path and once with it switched off
(``LIGHT_BYTES`` / ``MAX_VALUES`` set to 0), which is the reader and writer as they were before.
"""

import io
import subprocess
import sys

import numpy as np
import pytest

pa = pytest.importorskip("pyarrow")
pc = pytest.importorskip("pyarrow.csv")

from strapdown.io import _csvtext  # noqa: E402
from strapdown.io.formats import csv as csv_format  # noqa: E402
from strapdown.io.readers import open_source  # noqa: E402
from strapdown.io.writers import table_writer  # noqa: E402


def arrow_text(columns) -> str:
    out = io.BytesIO()
    pc.write_csv(pa.table(columns), out, pc.WriteOptions(include_header=False))
    return out.getvalue().decode()


def random_floats(rng, n, dtype):
    """Every kind of value of the type: uniform bit patterns (subnormals, NaNs, infinities, both zeros)."""
    bits = rng.integers(0, 2 ** (8 * np.dtype(dtype).itemsize), n, dtype=np.uint64, endpoint=False)
    return bits.astype(f"u{np.dtype(dtype).itemsize}").view(dtype)


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_float_text_is_arrows_for_any_bit_pattern(dtype, monkeypatch):
    monkeypatch.setattr(_csvtext, "MAX_VALUES", 10**6)
    rng = np.random.default_rng(7)
    values = random_floats(rng, 20000, dtype)
    assert _csvtext.csv_rows({"x": values}) == arrow_text({"x": values})


def test_float_text_is_arrows_at_every_decade_and_its_neighbours():
    decades = 10.0 ** np.arange(-12, 23)
    values = np.concatenate(
        [decades, -decades, np.nextafter(decades, 0), np.nextafter(decades, np.inf), [0.0, -0.0, np.nan, np.inf]]
    )
    values = np.concatenate([values, [-np.inf, 5e-324, 1.7976931348623157e308, 1234567890.5, 0.1 + 0.2]])
    for dtype in (np.float64, np.float32):
        with np.errstate(over="ignore"):
            v = values.astype(dtype)
        assert _csvtext.csv_rows({"x": v}) == arrow_text({"x": v})


def test_integer_and_mixed_columns_are_arrows():
    columns = {
        "i8": np.array([-128, 127, 0], np.int8),
        "u64": np.array([0, 2**64 - 1, 12345], np.uint64),
        "i64": np.array([-(2**63), 2**63 - 1, 0]),
        "flag": np.array([True, False, True]).view(np.uint8),
        "t": np.array([0.0, 0.01, 1e10]),
    }
    assert _csvtext.csv_rows(columns) == arrow_text(columns)


def test_what_it_does_not_write_goes_to_pyarrow():
    assert _csvtext.csv_rows({"s": np.array(["a", "b"])}) is None
    assert _csvtext.csv_rows({"h": np.array([1.0], np.float16)}) is None
    big = np.zeros(_csvtext.MAX_VALUES + 1)
    assert _csvtext.csv_rows({"x": big}) is None


def write(path, columns, light: bool, monkeypatch) -> bytes:
    monkeypatch.setattr(_csvtext, "MAX_VALUES", 1 << 15 if light else 0)
    with table_writer(path, metadata={"frame": "ENU"}) as w:
        w.write(columns)
        w.write({n: v[:3] for n, v in columns.items()})  # a second chunk
    return path.read_bytes()


def test_a_small_table_is_written_to_the_same_bytes(tmp_path, monkeypatch):
    rng = np.random.default_rng(3)
    columns = {
        "t": np.arange(50) * 0.01,
        "qw": rng.normal(0, 1, 50),
        "yaw_deg": rng.uniform(0, 360, 50).astype(np.float32),
        "rest": rng.integers(0, 2, 50).astype(bool),
        "flags": rng.integers(0, 8, 50).astype(np.uint8),
    }
    as_written = {n: v.view(np.uint8) if v.dtype == bool else v for n, v in columns.items()}
    assert _csvtext.csv_rows(as_written) is not None  # written by the light path
    light = write(tmp_path / "light.csv", columns, True, monkeypatch)
    arrow = write(tmp_path / "arrow.csv", columns, False, monkeypatch)
    assert light == arrow


CASES = {
    "plain": "t,gx,gy\n0,0.5,-1\n0.01,1e-3,2E+2\n0.02,.5,5.\n",
    "crlf and blank lines": "t,gx,gy\r\n0,1,2\r\n\r\n0.01,3,4\r\n0.02,-0,00012\r\n",
    "empty cells": "t,gx,gy\n0,,2\n0.01,3,\n0.02,5,6",
    "long digits": "t,gx,gy\n0,0.30000000000000004,2.4703282292062328e-324\n1,1e400,-1e-400\n",
    "integer time": "t,gx,gy\n1700000000000000,1,2\n1700000000010000,3,4\n1700000000020000,5,6\n",
    # past 2**53 the time is read as int64 (exact before the first is subtracted): pyarrow's part
    "integer time ns": "t,gx,gy\n1700000000000000000,1,2\n1700000000010000000,3,4\n1700000000020000000,5,6\n",
    "semicolons": "t;gx;gy\n0;1.5;2\n1;3;4\n",
    "unused bad column": "t,gx,gy,note\n0,1,2,hello\n1,3,4,world\n",
}


def read(path, light: bool, monkeypatch, names=None, expect_light=True, **kwargs):
    monkeypatch.setattr(csv_format, "LIGHT_BYTES", 1 << 17 if light else 0)
    src = open_source(path)
    names = names or [h for h in src.header if h != "note"]
    parts = list(src.chunks(names, kwargs.pop("chunk_rows", 4096), **kwargs))
    if light and expect_light:  # the case is one the light path reads itself (not one it hands to pyarrow)
        assert src._light_rows is not None and src._light_rows[1] is not None
    return {n: np.concatenate([c[n] for _, c in parts]) for n in names}, [row for row, _ in parts], src.origins


@pytest.mark.parametrize("case", list(CASES))
@pytest.mark.parametrize("window", [{}, {"start": 1}, {"start": 1, "stop": 2}, {"chunk_rows": 1}])
def test_light_reading_gives_arrows_values(case, window, tmp_path, monkeypatch):
    path = tmp_path / "log.csv"
    path.write_text(CASES[case], newline="")
    relative = {"relative": ("t",)} if case.startswith("integer time") else {}
    light = read(path, True, monkeypatch, expect_light=case != "integer time ns", **window, **relative)
    arrow = read(path, False, monkeypatch, **window, **relative)
    for name in arrow[0]:
        np.testing.assert_array_equal(light[0][name], arrow[0][name])  # NaN where Arrow has a null
    assert light[2] == arrow[2]  # the integer time's origin
    if "chunk_rows" not in window:
        assert light[1] == arrow[1]  # the rows each chunk starts at


BAD = {
    "a word": "t,gx\n0,1\n1,abc\n",
    "a row too long": "t,gx\n0,1\n1,2,3\n",
    "a row too short": "t,gx\n0,1\n1\n",
    "quoted": 't,gx\n0,"1"\n1,"x"\n',
    "NA marker": "t,gx\n0,1\n1,NA\n",
    "spaces": "t,gx\n0, 1\n1,2 \n",
    "decimal comma": "t;gx\n0;1,5\n1;2,5\n",
    "latin-1": "t,gx\n" + "".join(f"{i},1\n" for i in range(3000)) + "3000,2\xb5\n",  # past what opening reads
}


@pytest.mark.parametrize("case", list(BAD))
def test_anything_else_is_read_and_reported_by_pyarrow_as_before(case, tmp_path, monkeypatch):
    path = tmp_path / "log.csv"
    path.write_bytes(BAD[case].encode("latin-1" if case == "latin-1" else "utf-8"))

    def outcome(light):
        monkeypatch.setattr(csv_format, "LIGHT_BYTES", 1 << 17 if light else 0)
        try:
            src = open_source(path)
            values = {n: np.concatenate([c[n] for _, c in src.chunks(src.header, 4096)]) for n in src.header}
        except ValueError as exc:
            return str(exc)
        return {n: [repr(x) for x in v.tolist()] for n, v in values.items()}  # NaN compares equal as text

    assert outcome(True) == outcome(False)


def test_a_small_estimate_imports_no_pyarrow(tmp_path):
    n = 200
    t = np.arange(n) * 0.01
    cols = np.column_stack([t, np.zeros((n, 3)), np.tile([0.0, 0.0, 9.81], (n, 1))])
    np.savetxt(tmp_path / "log.csv", cols, delimiter=",", header="t,gx,gy,gz,ax,ay,az", comments="", fmt="%.9g")
    code = (
        "import sys\nfrom strapdown.cli import main\n"
        f"try:\n    main(['estimate', {str(tmp_path / 'log.csv')!r}, '-q'])\nexcept SystemExit as e:\n"
        "    assert not e.code, e.code\n"
        "assert 'pyarrow' not in sys.modules, 'pyarrow imported'\n"
    )
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stderr
    assert (tmp_path / "log.estimate.csv").exists()
