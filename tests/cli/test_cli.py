"""The command line and the package as a newcomer meets them: run as subprocesses."""

import subprocess
import sys

import numpy as np
import pytest


def run(*args):
    return subprocess.run([sys.executable, "-m", "strapdown.cli", *args], capture_output=True, text=True, timeout=120)


@pytest.fixture(scope="module")
def demo(tmp_path_factory):
    out = tmp_path_factory.mktemp("demo")
    res = run("demo", "--out", str(out))
    assert res.returncode == 0, res.stderr
    return res.stdout, out


def test_demo_prints_gajda_roll_every_45_degrees(demo):
    stdout, _ = demo
    rows = [line.split() for line in stdout.splitlines() if line[:6].strip().replace(".", "").isdigit()]
    assert len(rows) == 9
    table = np.array([[float(x) for x in row] for row in rows])
    t, q, ypr, err = table[:, 0], table[:, 1:5], table[:, 5:8], table[:, 9]
    # closed form of a roll at 90°/s from yaw 30°, pitch 10°: yaw and pitch stay, roll steps by 45°
    np.testing.assert_allclose(t, np.arange(9) * 0.5)
    np.testing.assert_allclose(ypr[:, 0], 30.0)
    np.testing.assert_allclose(ypr[:, 1], 10.0)
    np.testing.assert_allclose(ypr[:, 2], [0, 45, 90, 135, 180, -135, -90, -45, 0])
    np.testing.assert_allclose(np.linalg.norm(q, axis=-1), 1, atol=1e-6)
    np.testing.assert_allclose(q[-1], -q[0], atol=1e-7)  # 360° flips the quaternion's sign
    assert err.max() < 1e-12


def test_demo_compares_every_method_and_writes_its_files(demo):
    stdout, out = demo
    from strapdown import METHODS

    assert stdout.count("Gajda 3c") == 2
    for method in METHODS:
        assert f"\n{method} " in stdout
    names = sorted(p.name for p in out.iterdir())
    assert names == [
        "aerobatic_show.csv",
        "aerobatic_show.parquet",
        "aerobatic_show.report.html",
        "aerobatic_show_angles.png",
        "aerobatic_show_errors.png",
        "aerobatic_show_fusion.png",
        "hammerhead_loop_angles.png",
        "hammerhead_loop_errors.png",
        "turns_and_rests_fusion.png",
    ]
    for name in names[3:]:
        assert (out / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # the report: the page a person opens, and where it is said
    assert f"the interactive report: {(out / 'aerobatic_show.report.html').resolve()}" in stdout
    assert (out / "aerobatic_show.report.html").read_text(encoding="utf-8").startswith("<!DOCTYPE html>")
    table = np.loadtxt(out / "aerobatic_show.csv", delimiter=",", skiprows=1)
    assert table.shape == (15201, 21)
    # the CSV's error columns are the angles between its true and integrated (fused) quaternions
    from strapdown import angle_between

    np.testing.assert_allclose(np.radians(table[:, 15]), angle_between(table[:, 1:5], table[:, 8:12]), atol=1e-8)
    assert np.isnan(table[0, 16:]).all()
    np.testing.assert_allclose(np.radians(table[1:, 20]), angle_between(table[1:, 1:5], table[1:, 16:20]), atol=1e-8)


def test_demo_fuses_the_flight(demo):
    stdout, _ = demo
    rows = {}
    for line in stdout.splitlines():
        labels = ("gyro only (exact)", "Attitude 9D, known acc.", "TiltEstimator, known acc.", "TiltEstimator 6D")
        for label in (*labels, "Madgwick 9D"):
            if line.startswith(label):
                rows[label] = [float(x) for x in line[len(label) :].split()[:2]]
    assert len(rows) == 5
    # with the kinematic acceleration the tilt beats the gyro alone; without it, lift is taken for gravity
    assert rows["TiltEstimator, known acc."][0] < 0.5 * rows["gyro only (exact)"][0]
    assert rows["Attitude 9D, known acc."][0] < 0.5 * rows["gyro only (exact)"][0]
    assert rows["TiltEstimator 6D"][0] > rows["TiltEstimator, known acc."][0]
    # the failure without the known acceleration is shown as a lesson, labelled as one
    lesson = stdout.index("LESSON")
    assert stdout.index("\nTiltEstimator 6D") > lesson > stdout.index("\nTiltEstimator, known acc.")


def test_demo_shows_the_9d_estimator_where_it_is_meant_to_work(demo):
    stdout, _ = demo
    part = stdout[stdout.index("where it is meant to work (1)") : stdout.index("where it is meant to work (2)")]
    rows = {line[:22].strip(): line[22:].split() for line in part.splitlines() if line[:1].isalpha() or line[:1] == "("}
    total = {label: float(rows[label][0]) for label in ("AttitudeEstimator 9D", "Madgwick 9D", "Mahony 9D")}
    # turns and rests with a calibrated magnetometer and a passing magnet: the flagship is best, by a margin
    assert total["AttitudeEstimator 9D"] < 0.5 * min(total["Madgwick 9D"], total["Mahony 9D"])
    bias, true = np.array(rows["AttitudeEstimator 9D"][3:6], float), np.array(rows["(true gyro bias)"], float)
    assert np.abs(bias - true).max() < 0.1  # °/s, learnt at the rests
    assert float(rows["AttitudeEstimator 9D"][-1].rstrip("%")) > 90  # the magnet is flagged nearly throughout


def _table_rows(stdout):
    return {line.split()[0]: line.split() for line in stdout.splitlines() if line and line.split()[0] in _methods()}


def _methods():
    from strapdown import METHODS

    return METHODS


def test_compare_command(tmp_path):
    res = run(
        "compare",
        "--scenario",
        "hammerhead-loop",
        "--rate",
        "50",
        "--methods",
        "exact,euler-angles",
        "--out",
        str(tmp_path),
    )
    assert res.returncode == 0, res.stderr
    rows = _table_rows(res.stdout)
    assert set(rows) == {"exact", "euler-angles"}
    assert float(rows["exact"][2]) < 1e-10  # max error, degrees
    assert rows["exact"][4] == "-"  # no singular step
    assert int(rows["euler-angles"][4]) > 0  # singular steps
    assert sorted(p.name for p in tmp_path.iterdir()) == ["hammerhead_loop_angles.png", "hammerhead_loop_errors.png"]


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--methods", "exact,rk5"], "unknown rk5"),
        (["--rate", "-3"], "--rate"),
        (["--scenario", "moon-landing"], "moon-landing"),
    ],
)
def test_compare_rejects_bad_options(args, message):
    res = run("compare", *args)
    assert res.returncode != 0
    assert message in res.stderr


def test_version_and_help():
    from strapdown import __version__

    res = run("--version")
    assert res.returncode == 0 and __version__ in res.stdout
    res = run("demo", "--help")
    assert res.returncode == 0 and "Examples" in res.stdout


def test_import_is_fast_and_compiles_nothing():
    code = "import sys, strapdown; assert 'numba' not in sys.modules, 'numba imported at package import'"
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert res.returncode == 0, res.stderr


@pytest.mark.parametrize(
    "module", ["quaternion", "euler", "matrix", "rotvec", "compressed", "frames", "cayley_klein", "interop", "demo"]
)
def test_public_functions_have_examples(module):
    import importlib

    mod = importlib.import_module(f"strapdown.{module}")
    for name in getattr(mod, "__all__", ["gajda_roll", "format_roll_demo"]):
        obj = getattr(mod, name)
        if callable(obj):
            doc = obj.__doc__ or ""
            assert "Examples" in doc and ">>>" in doc, f"{module}.{name} has no example"
            assert "Parameters" in doc and "Returns" in doc, f"{module}.{name} lacks numpy-style sections"


@pytest.mark.parametrize(("estimator", "name"), [("madgwick", "beta"), ("mahony", "kp"), ("tilt", "tau_acc")])
def test_text_for_a_numeric_parameter_is_named(estimator, name):
    from strapdown.fusion import make_params

    with pytest.raises(ValueError, match=f"{estimator} parameter {name} must be a number, got 'abc'"):
        make_params(estimator, {name: "abc"})
    assert make_params("madgwick", {"variant": "reference"}).variant == "reference"  # text where text belongs
