"""``strapdown report`` without a browser: its numbers against the library's own, its frames, bad input, its size.

The page's numbers are read back from the written HTML (its ``strapdown-results`` block and the error table's
cells) and compared with what ``strapdown estimate`` and ``strapdown plot --truth`` compute on the same file:
:func:`strapdown.io.estimate_file`, :func:`strapdown.io.pipelines.truth.align_truth` and
:func:`strapdown.evaluate.metrics.rmse_errors`.
"""

import html
import json
import re
import subprocess
import sys

import numpy as np
import pytest
from report_inputs import PX4_LOG, show_log, still_log

pytest.importorskip("bokeh")

from strapdown.apps.report import ReportOptions, report_file
from strapdown.apps.report.view3d import scene, view_spec
from strapdown.io import estimate_file, read_table, write_table


def page_results(path):
    text = path.read_text(encoding="utf-8")
    m = re.search(r'<script type="application/json" id="strapdown-results">(.*?)</script>', text, re.S)
    assert m, "no results block"
    return json.loads(m.group(1)), html.unescape(text)


@pytest.fixture(scope="module")
def show(tmp_path_factory):
    folder = tmp_path_factory.mktemp("show")
    log = show_log(folder, duration=30.0)
    out = folder / "show.html"
    result = report_file(log, out, truth=log, estimators=("attitude", "mahony"), points=500, frames=300)
    return log, out, result


@pytest.mark.parametrize("name", ["attitude", "mahony"])
def test_the_pages_errors_and_bias_are_those_of_estimate_and_plot(show, tmp_path, name):
    from strapdown.evaluate.metrics import rmse_errors
    from strapdown.io.pipelines.truth import align_truth

    log, page, _ = show
    results, text = page_results(page)
    row = next(r for r in results["estimators"] if r["estimator"] == name)
    est = estimate_file(log, tmp_path / f"{name}.parquet", estimator=name).output
    table = read_table(est)
    q = np.column_stack([table[c] for c in ("qw", "qx", "qy", "qz")])
    truth = align_truth(est, log)
    expected = rmse_errors(q[truth.rows], truth.q[truth.rows])
    for kind in ("total", "heading", "inclination"):
        assert row[kind] == pytest.approx(expected[kind], rel=1e-9, abs=1e-9)
        # the table a person reads shows the same number
        assert f"data-rms='{kind}'>{expected[kind]:.3f}<" in text
    bias = np.array([table[f"bias_{a}_deg_s"][-1] for a in "xyz"])
    np.testing.assert_allclose(row["bias_deg_s"], bias, rtol=0, atol=1e-9)
    assert row["mode"] == "9D" and row["north"] == "magnetic"


def test_the_bias_sigma_is_the_estimators_own(show):
    from strapdown.fusion import AttitudeEstimator
    from strapdown.io import read_imu

    log, page, _ = show
    results, _ = page_results(page)
    data = read_imu(log, optional=("acc", "mag"))
    est = AttitudeEstimator(frame="ENU").update(data.gyro, data.acc, data.mag, t=data.t)
    row = results["estimators"][0]
    np.testing.assert_allclose(row["bias_sigma_deg_s"], np.degrees(est.extra["bias_sigma"][-1]), rtol=1e-12)
    np.testing.assert_allclose(row["bias_deg_s"], np.degrees(est.bias[-1]), rtol=0, atol=1e-9)


def test_the_page_fetches_nothing(show):
    _, page, result = show
    text = page.read_text(encoding="utf-8")
    assert not re.search(r"<script[^>]*\bsrc=", text), "a script is loaded from elsewhere"
    assert not re.search(r"<link[^>]*\bhref=", text), "a style sheet is loaded from elsewhere"
    assert "Bokeh" in text and result.bytes == page.stat().st_size


def test_the_summary_says_what_was_read_and_run(show):
    _, page, _ = show
    results, _ = page_results(page)
    summary = dict((k, v) for k, v in results["summary"])
    assert summary["Format"] == "parquet"
    assert "gyro 100 Hz" in summary["Sensors"] and "mag 100 Hz" in summary["Sensors"]
    assert summary["Duration"].startswith("29.99 s, 3000 rows")
    assert "reference ENU, body FLU" in summary["Frames"]
    assert summary["Heading"] == "attitude: magnetic, mahony: magnetic"
    assert summary["Reference"] == "truth: show.parquet"
    assert summary["Gaps"] == "none over 10 sample periods"
    assert summary["Checks"].startswith("passed:")
    assert "tau_acc=3.5" in summary["Estimator attitude"]


def test_the_log_s_own_estimate_is_the_reference_of_a_px4_log(tmp_path):
    from strapdown.evaluate.metrics import rmse_errors
    from strapdown.io.pipelines.truth import align_truth

    result = report_file(PX4_LOG, tmp_path / "px4.html", points=300, frames=200)
    results, _ = page_results(result.output)
    assert results["reference"] == "the log's own estimate (vehicle_attitude)"
    assert (results["frame"], results["body"]) == ("NED", "FRD")
    est = estimate_file(PX4_LOG, tmp_path / "px4.parquet").output
    table = read_table(est)
    q = np.column_stack([table[c] for c in ("qw", "qx", "qy", "qz")])
    truth = align_truth(est, PX4_LOG)
    expected = rmse_errors(q[truth.rows], truth.q[truth.rows])
    assert results["estimators"][0]["total"] == pytest.approx(expected["total"], rel=1e-9)


def test_a_gap_restarts_the_estimators_and_is_shown_or_stops_the_report(tmp_path):
    n = 600
    t = np.arange(n) * 0.01
    t[300:] += 2.0  # two seconds without a sample
    level = {"t": t, "gx": np.zeros(n), "gy": np.zeros(n), "gz": np.zeros(n)}
    level.update(ax=np.zeros(n), ay=np.zeros(n), az=np.full(n, 9.81))
    log = write_table(tmp_path / "gap.parquet", level)
    result = report_file(log, tmp_path / "gap.html", estimators=("mahony",), points=100, frames=50)
    results, _ = page_results(result.output)
    assert results["gaps"] == [[pytest.approx(2.99), pytest.approx(5.0)]]
    assert dict(results["summary"])["Gaps"].startswith("1 over 10 sample periods, every estimator started afresh")
    with pytest.raises(ValueError, match=r"a gap of 2\.01 s"):
        report_file(log, tmp_path / "stop.html", on_gap="error", estimators=("mahony",))
    assert not (tmp_path / "stop.html").exists()


def test_broken_or_empty_input_is_named_and_leaves_no_page(tmp_path):
    empty = tmp_path / "empty.csv"
    empty.write_text("t,gx,gy,gz,ax,ay,az\n")
    out = tmp_path / "page.html"
    with pytest.raises(ValueError, match=r"empty\.csv"):
        report_file(empty, out)
    broken = tmp_path / "broken.csv"
    lines = ["t,gx,gy,gz,ax,ay,az"] + [f"{k * 0.01},0,0,0,0,0,9.81" for k in range(50)]
    lines[31] = "0.30,0,nan,0,0,0,9.81"
    broken.write_text("\n".join(lines) + "\n")
    out.write_text("the page of an earlier run")
    with pytest.raises(ValueError, match=r"broken.csv.*line 32"):
        report_file(broken, out)
    assert out.read_text() == "the page of an earlier run"  # untouched
    assert sorted(p.name for p in tmp_path.iterdir()) == ["broken.csv", "empty.csv", "page.html"]  # no temp left
    with pytest.raises(ValueError, match=r"name it \.html"):
        report_file(broken, tmp_path / "page.txt")
    with pytest.raises(ValueError, match="unknown estimator 'kalman'"):
        ReportOptions(estimators=("attitude", "kalman"))


def test_the_page_does_not_grow_with_the_log(tmp_path):
    rng = np.random.default_rng(0)
    sizes = []
    for n in (20_000, 200_000):
        cols = {"t": np.arange(n) * 1e-3}
        for i, a in enumerate("xyz"):
            cols[f"g{a}"] = 0.01 * rng.standard_normal(n)
            cols[f"a{a}"] = 0.05 * rng.standard_normal(n) + (9.81 if i == 2 else 0.0)
        log = write_table(tmp_path / f"still{n}.parquet", cols)
        sizes.append(report_file(log, tmp_path / f"still{n}.html", estimators=("mahony",), points=1000).bytes)
    assert sizes[1] < 1.1 * sizes[0], sizes


def test_the_model_is_drawn_where_the_attitude_puts_it():
    """Seen from straight above (east to the right, north up), the model's nose and right wing tip lie where
    scipy's rotation of them, re-expressed in east-north-up, puts them."""
    from scipy.spatial.transform import Rotation

    above = {"az": np.pi, "el": np.pi / 2}
    rng = np.random.default_rng(4)
    enu = {"NED": np.array([[0, 1, 0], [1, 0, 0], [0, 0, -1.0]]), "ENU": np.eye(3)}
    for frame, body in (("NED", "FRD"), ("ENU", "FLU"), ("ENU", "RFU")):
        spec = view_spec(frame, body)
        for q in rng.standard_normal((5, 4)):
            q /= np.linalg.norm(q)
            s = scene(spec, q, above)
            tips = np.array(spec["vertices"])[[0, 8]]  # nose, right wing tip (body axes)
            turned = Rotation.from_quat(q, scalar_first=True).apply(tips) @ enu[frame].T
            drawn = {
                (round(x, 9), round(y, 9))
                for xs, ys in zip(s["model"]["xs"], s["model"]["ys"], strict=True)
                for x, y in zip(xs, ys, strict=True)
            }
            for e, n_, _ in turned:
                assert (round(e, 9), round(n_, 9)) in drawn
    # level and facing north in NED: the nose is north, the right wing east, body z down
    s = scene(view_spec("NED", "FRD"), [1.0, 0, 0, 0], above)
    assert s["axes"]["text"][3:] == ["x F", "y R", "z D"]
    np.testing.assert_allclose([s["axes"]["x1"][3], s["axes"]["y1"][3]], [0.0, 1.5], atol=1e-12)
    np.testing.assert_allclose([s["axes"]["x1"][4], s["axes"]["y1"][4]], [1.5, 0.0], atol=1e-12)


def test_the_plates_show_their_top_colour_from_above():
    from strapdown.apps.report import view3d

    spec = view_spec("NED", "FRD")
    s = scene(spec, [1.0, 0, 0, 0], {"az": 0.3, "el": 1.2})  # from above
    right_wing = spec["faces"].index([6, 7, 9, 8])
    assert spec["front"][right_wing] == view3d._RIGHT
    s_below = scene(spec, [1.0, 0, 0, 0], {"az": 0.3, "el": -1.2})
    assert set(s["model"]["color"]) != set(s_below["model"]["color"])


def run_cli(*args):
    return subprocess.run(
        [sys.executable, "-m", "strapdown.cli", "report", *args], capture_output=True, text=True, timeout=600
    )


def test_the_command_writes_the_page_and_says_where(tmp_path):
    out = tmp_path / "flight.html"
    res = run_cli(str(PX4_LOG), "-o", str(out), "-e", "attitude,mahony", "--points", "300", "--frames", "100")
    assert res.returncode == 0, res.stderr
    assert f"written: {out}" in res.stdout
    assert "mahony runs 6D: the magnetometer comes at a lower rate than the gyro" in res.stderr
    results, _ = page_results(out)
    assert [r["estimator"] for r in results["estimators"]] == ["attitude", "mahony"]
    assert [r["mode"] for r in results["estimators"]] == ["9D", "6D"]


def test_the_command_refuses_what_it_cannot_do(tmp_path):
    res = run_cli(str(PX4_LOG), "-e", "attitude,kalman")
    assert res.returncode == 2 and "unknown estimator 'kalman'" in res.stderr
    res = run_cli(str(PX4_LOG), "--on-gap", "split")
    assert res.returncode == 2 and "a report is one page" in res.stderr
    res = run_cli(str(PX4_LOG), "-o", str(tmp_path / "x.txt"))
    assert res.returncode == 1 and "name it .html" in res.stderr
    assert not list(tmp_path.iterdir())


def test_the_allan_terms_are_those_of_calibrate_allan_and_find_the_noise(tmp_path):
    from strapdown.calibrate import allan
    from strapdown.io import read_imu

    still = still_log(tmp_path)
    result = report_file(still, tmp_path / "still.html", allan=still, estimators=("mahony",), points=200)
    shown, _ = page_results(result.output)
    data = read_imu(still)
    expected = allan(data.gyro, 100.0)
    for key in ("arw", "bias_instability", "rate_random_walk"):
        np.testing.assert_allclose(shown["allan"][key], getattr(expected, key), rtol=1e-12)
    # the white noise written into the file: 0.3 deg/sqrt(h), found within 10 %
    np.testing.assert_allclose(shown["allan"]["arw"], np.radians(0.3) / 60.0, rtol=0.1)
    assert "gyro Allan deviation (900 s at 100 Hz)" in result.output.read_text(encoding="utf-8")  # its figure
