"""The screenshots of ``strapdown report`` in the docs: three pages opened in headless Chromium.

    python benchmarks/report_gallery.py            # writes docs/images/report/{px4,phone,show}.png

The three pages of the issue: a PX4 log against its own ``vehicle_attitude`` (tests/data/px4), a phone export (an
Android Sensor Logger folder, simulated by tests/sim_exports.py, its magnetometer fitted with ``--fit-mag``) and
the simulated aerobatic show against its truth with two estimators.  Each page is opened as a person opens it
(from the file, no network), the time slider moved to a chosen instant and a tab shown; the screenshot is the
browser's.  It needs /usr/bin/chromium and Playwright for Python (the ``test`` extra).
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT / "tests" / "apps"), str(ROOT / "tests")]

from report_inputs import PX4_LOG, browser, have_chromium, open_page, phone_export, show_log, show_tab  # noqa: E402

from strapdown.apps.report import report_file  # noqa: E402

OUT = ROOT / "docs" / "images" / "report"

_SLIDE = """(fraction) => {
  const s = [...Bokeh.documents[0].all_models].find((m) => (m.tags || []).includes("time-slider"));
  s.value = s.start + fraction * (s.end - s.start);
}"""


def main() -> int:
    if not have_chromium():
        print("needs /usr/bin/chromium (apt-get install chromium) and Playwright for Python", file=sys.stderr)
        return 1
    OUT.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        show = show_log(folder)
        pages = [
            ("px4", report_file(PX4_LOG, folder / "px4.html"), 0.55, "Attitude"),
            ("phone", report_file(phone_export(folder, 40.0), folder / "phone.html", fit_mag=True), 0.4, "Sensors"),
            (
                "show",
                report_file(show, folder / "show.html", truth=show, estimators=("attitude", "mahony")),
                0.3,
                "Attitude",
            ),
        ]
        with browser(1500, 1000) as ctx:
            for name, result, fraction, tab in pages:
                page = open_page(ctx, result.output)
                show_tab(page, tab)
                page.evaluate(_SLIDE, fraction)
                page.wait_for_function("() => Bokeh.documents[0].is_idle")
                page.wait_for_timeout(500)
                if page.problems:
                    raise RuntimeError(f"{name}: {page.problems}")
                path = OUT / f"{name}.png"
                page.screenshot(path=str(path))
                print(
                    f"{path.relative_to(ROOT)}: {result.output.name}, {result.bytes / 1e6:.2f} MB, {result.rows} rows"
                )
                page.close()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
