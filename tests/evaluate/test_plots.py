"""Figures: every line told apart, the truth under the estimate, unwrapped yaw, and all-or-nothing output."""

import itertools

import numpy as np
import pytest

import strapdown as sd

pytest.importorskip("matplotlib")
pytest.importorskip("pyarrow")

from strapdown.evaluate import figures
from strapdown.io import write_table
from strapdown.io.pipelines import plot as plots
from strapdown.rotations.values import Angles


def test_seventeen_methods_get_seventeen_styles():
    styles = figures.line_styles(len(sd.METHODS))
    assert len(sd.METHODS) == 17
    assert len({(s["color"], s["linestyle"]) for s in styles}) == 17
    # neighbours in a legend never share a colour
    assert all(a["color"] != b["color"] for a, b in itertools.pairwise(styles))
    with pytest.raises(ValueError, match="n must be"):
        figures.line_styles(-1)


def test_yaw_is_unwrapped_and_blanked_near_the_vertical():
    # closed form: a steady turn, ψ = 100°/s · t from 0, pitch climbing through 85° in the middle
    t = np.linspace(0, 10, 1001)
    psi, theta = 100.0 * t, 85.0 * np.sin(np.pi * t / 10)
    q = sd.from_euler(np.c_[psi, theta, 0 * t], "ZYX", degrees=True)
    values, blanked = figures.angles_for_display(q)
    np.testing.assert_array_equal(blanked, theta > 80.0)
    shown = ~blanked
    np.testing.assert_allclose(values[shown, 1], theta[shown], atol=1e-9)
    first = np.flatnonzero(blanked)[0]
    np.testing.assert_allclose(values[:first, 0], psi[:first], atol=1e-9)  # 0 .. 360 .. no jump
    after = np.flatnonzero(blanked)[-1] + 1
    # after the blanked stretch yaw restarts in range and runs on continuously
    assert np.all(np.abs(np.diff(values[after:, 0])) < 1.5)
    np.testing.assert_allclose((values[after:, 0] - psi[after:] + 180) % 360 - 180, 0, atol=1e-9)
    assert np.isnan(values[blanked, 0]).all() and np.isnan(values[blanked, 2]).all()


def test_proper_euler_sequences_are_blanked_at_zero_and_half_turn():
    q = sd.from_euler(np.array([[10.0, 3.0, 20.0], [10.0, 90.0, 20.0], [10.0, 178.0, 20.0]]), "ZXZ", degrees=True)
    _, blanked = figures.angles_for_display(q, Angles("ZXZ"))
    assert blanked.tolist() == [True, False, True]


@pytest.fixture
def files(tmp_path):
    t = np.linspace(0.0, 4.0, 201)
    truth = sd.from_euler(np.c_[90.0 * t, 5 * np.sin(t), 0 * t], "ZYX", degrees=True)
    est = sd.from_euler(np.c_[90.0 * t + 1.0, 5 * np.sin(t), 0 * t], "ZYX", degrees=True)
    cols = {"t": t, **{f"q{c}": est[:, i] for i, c in enumerate("wxyz")}, "bias_x_rad_s": 0 * t}
    write_table(tmp_path / "est.csv", cols)
    write_table(tmp_path / "sim.csv", {"t": t, **{f"q{c}_true": truth[:, i] for i, c in enumerate("wxyz")}})
    write_table(tmp_path / "short.csv", {"t": t[:-1], **{f"q{c}_true": truth[:-1, i] for i, c in enumerate("wxyz")}})
    return tmp_path


def test_the_angles_figure_draws_the_truth_under_the_estimate(files):
    import matplotlib.pyplot as plt

    figs = plots._file_figures(files / "est.csv", files / "sim.csv", Angles(), 10_000, None)
    try:
        assert sorted(figs) == ["angles", "bias", "errors"]
        yaw_axes = figs["angles"].axes[0]
        lines = {line.get_label(): line for line in yaw_axes.get_lines()}
        assert set(lines) == {"truth", "est"}
        assert lines["truth"].get_zorder() < lines["est"].get_zorder()
        assert lines["truth"].get_linewidth() > lines["est"].get_linewidth()
        # yaw unwrapped: 90°/s for 4 s reaches 360° without a jump; estimate 1° above the truth
        yaw_truth, yaw_est = lines["truth"].get_ydata(), lines["est"].get_ydata()
        assert np.nanmax(yaw_truth) == pytest.approx(360.0)
        np.testing.assert_allclose(yaw_est - yaw_truth, 1.0, atol=1e-6)
        styles = {(ln.get_color(), ln.get_linestyle()) for ln in figs["errors"].axes[0].get_lines()}
        assert len(styles) == 3  # total, heading, inclination each its own
    finally:
        for f in figs.values():
            plt.close(f)


def test_a_failed_plot_run_leaves_no_figure(files):
    out = files / "figs"
    with pytest.raises(ValueError, match="rows"):
        plots.plot_file(files / "est.csv", files / "short.csv", out)
    assert not out.exists() or list(out.iterdir()) == []


def test_a_failure_while_writing_leaves_no_figure(files, monkeypatch):
    from matplotlib.figure import Figure

    real, calls = Figure.savefig, []

    def failing(self, *args, **kwargs):
        calls.append(1)
        if len(calls) == 2:  # the first figure is already on disk (as a temporary file) by now
            raise OSError("disk full")
        return real(self, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", failing)
    out = files / "figs"
    with pytest.raises(OSError, match="disk full"):
        plots.plot_file(files / "est.csv", files / "sim.csv", out)
    assert list(out.iterdir()) == []  # neither a PNG nor a temporary file
    monkeypatch.setattr(Figure, "savefig", real)
    written = plots.plot_file(files / "est.csv", files / "sim.csv", out)
    assert sorted(p.name for p in out.iterdir()) == ["est_angles.png", "est_bias.png", "est_errors.png"]
    assert all(p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" for p in written)
