"""The report's three kinds of input (a PX4 log, a phone export, a simulated show with its truth), and a browser.

Shared by the report's tests and by ``benchmarks/report_gallery.py``, which makes the docs' screenshots.
"""

import shutil
import tempfile
from contextlib import contextmanager
from pathlib import Path

PX4_LOG = Path(__file__).resolve().parents[1] / "data" / "px4" / "sample_logging_tagged_and_default_params.ulg"
CHROMIUM = "/usr/bin/chromium"
# As the machine's notes say: a fresh profile, and no background connections (the network is closed)
CHROMIUM_ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]


def show_log(folder: Path, duration: float | None = None) -> Path:
    """The aerobatic show flown with a consumer MEMS IMU at 100 Hz: readings and the exact truth (ENU/FLU)."""
    from strapdown.io import simulate_file

    return simulate_file(
        Path(folder) / "show.parquet", scenario="aerobatic-show", imu="consumer", rate=100.0, duration=duration
    ).output


def phone_export(folder: Path, duration: float = 60.0) -> Path:
    """An Android Sensor Logger export of a phone turned by hand (simulated: RFU axes, ENU, magnetometer at 50 Hz)."""
    from sim_exports import sensor_logger
    from strapdown.simulate import ImuModel, RandomMotion, sample

    data = sample(
        RandomMotion(duration=duration, seed=5, rate_scale=1.2),
        100.0,
        gyro="rate",
        imu=ImuModel.consumer_mems(),
        reference="ENU",
        body="RFU",
        seed=2,
    )
    return sensor_logger(Path(folder) / "phone", data)


def still_log(folder: Path, seconds: float = 900.0, rate: float = 100.0) -> Path:
    """A gyro at rest: white rate noise (0.3 deg/√h) on a constant bias, with a level accelerometer (ENU/FLU)."""
    import numpy as np

    from strapdown.io import write_table

    rng = np.random.default_rng(7)
    n = int(seconds * rate)
    arw = np.radians(0.3) / 60.0  # rad/√s
    cols = {"t": np.arange(n) / rate}
    for i, a in enumerate("xyz"):
        cols[f"g{a}"] = 1e-3 * (i + 1) + arw * np.sqrt(rate) * rng.standard_normal(n)
    cols.update(ax=np.zeros(n), ay=np.zeros(n), az=np.full(n, 9.81))
    return write_table(Path(folder) / "still.parquet", cols, None, {"frame": "ENU", "body": "FLU"})


def have_chromium() -> bool:
    if not Path(CHROMIUM).exists():
        return False
    try:
        import playwright.sync_api  # noqa: F401
    except ImportError:
        return False
    return True


@contextmanager
def browser(width: int = 1500, height: int = 1000):
    """A headless Chromium context (Playwright driving the system's browser), a fresh profile each time."""
    from playwright.sync_api import sync_playwright

    profile = tempfile.mkdtemp(prefix="strapdown-chromium-")
    try:
        with sync_playwright() as pw:
            context = pw.chromium.launch_persistent_context(
                profile,
                executable_path=CHROMIUM,
                args=CHROMIUM_ARGS,
                headless=True,
                viewport={"width": width, "height": height},
            )
            try:
                yield context
            finally:
                context.close()
    finally:
        shutil.rmtree(profile, ignore_errors=True)


def open_page(context, path: Path):
    """The page loaded and Bokeh idle (every view drawn); its console messages and page errors in ``page.problems``."""
    page = context.new_page()
    page.problems = []
    page.on("console", lambda m: m.type in ("error", "warning") and page.problems.append(f"{m.type}: {m.text}"))
    page.on("pageerror", lambda e: page.problems.append(f"pageerror: {e}"))
    page.goto(Path(path).resolve().as_uri())
    page.wait_for_function(
        "() => window.Bokeh && Bokeh.documents.length > 0 && Bokeh.documents[0].is_idle", timeout=120_000
    )
    return page


def show_tab(page, title: str) -> None:
    """Click a tab by its title and wait until Bokeh has drawn it."""
    page.locator(".bk-tab", has_text=title).first.click()
    page.wait_for_function("() => Bokeh.documents[0].is_idle")
    page.wait_for_timeout(300)
