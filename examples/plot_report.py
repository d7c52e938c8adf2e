"""
An interactive report of a log: ``strapdown report``
=====================================================

:func:`strapdown.apps.report.report_file` (the command ``strapdown report``) writes one HTML page per recording,
with every script inline: the summary, yaw/pitch/roll over the truth with the errors and the flags' lanes, the
sensors, the bias, the estimators side by side and a 3D view of the body driven by a time slider.  Here it makes
the page of a simulated aerobatic show flown with a consumer MEMS IMU, against its truth, for two estimators;
the page's numbers are the library's own (``result.recording``).

The page itself is interactive and lives in a browser; below are the browser's screenshots of the three pages of
the :doc:`report guide <../guide/report>` (``benchmarks/report_gallery.py`` makes them in headless Chromium).
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt

from strapdown.apps.report import report_file
from strapdown.io import simulate_file

folder = Path(tempfile.mkdtemp())
log = simulate_file(folder / "show.parquet", scenario="aerobatic-show", imu="consumer", rate=100.0).output
result = report_file(log, folder / "show.html", truth=log, estimators=("attitude", "mahony"))
print(f"{result.output.name}: {result.bytes / 1e6:.2f} MB, {result.rows} rows, {result.seconds:.1f} s")
for key, value in result.recording.summary:
    print(f"{key:>22}: {value[:90]}")
for run in result.recording.runs:
    print(
        f"{run.name:>10} ({run.mode}): RMS total {run.rmse['total']:.2f}°, inclination {run.rmse['inclination']:.2f}°"
    )

# %%
# Both estimators are far off here, and the page says why: through the loops and turns of the show the
# accelerometer reads the manoeuvre as much as gravity (on the sensors tab ``|acc|`` leaves g for seconds at a time),
# every filter that takes it for gravity is pulled off (the lesson of ``strapdown demo``), and the flags' lanes
# show the AttitudeEstimator rejecting the accelerometer and its bias estimate running into its limit.
#
# The three pages as a browser shows them: a PX4 log against its own ``vehicle_attitude``, a phone export on the
# sensors tab (``|acc|`` against g, ``|mag|`` and the magnetic dip), and the show above against its truth.
try:
    here = Path(__file__).resolve().parent
except NameError:  # run by hand in a console
    here = Path.cwd()
shots = here.parent / "docs" / "images" / "report"
for name, caption in (
    ("show", "a simulated aerobatic show against its truth, two estimators"),
    ("px4", "a PX4 log against its own estimate (NED, FRD)"),
    ("phone", "a phone export, sensors tab"),
):
    fig, ax = plt.subplots(figsize=(12, 8), constrained_layout=True)
    ax.imshow(plt.imread(shots / f"{name}.png"))
    ax.set_axis_off()
    ax.set_title(f"strapdown report: {caption}")
plt.show()
