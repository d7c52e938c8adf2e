"""``strapdown report`` on long logs: the page's size, its build time, and how the page behaves in a browser.

    nice -n 10 python benchmarks/bench_report.py                 # 10^6 rows (1000 s at 1 kHz) and one hour at 1 kHz
    python benchmarks/bench_report.py --rows 1e6

For each length a simulated log (a random smooth motion, a consumer MEMS IMU at 1 kHz, Parquet, with its truth
and frames, as ``strapdown simulate`` writes it) is written, then the report of it (``--truth`` the same file:
the estimate, the reference and the error on the page) is built once.  Figures:

* the page's size in MB (the issue's bound: a one-hour 1 kHz log under 15 MB);
* its build time, and as a ratio to ``strapdown estimate`` on the same file in the same run (the estimate is
  the part of the report a plain command does too; the rest is reading the truth, the errors, the
  decimation and Bokeh);
* where /usr/bin/chromium and Playwright are present: the time until the page is drawn in headless Chromium,
  and the time from a move of the time slider until every figure has redrawn, each as a ratio to the same
  figure for the page of a 60-s log measured in the same run (a page that stays responsive does not grow
  with the log).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "apps"))

from report_inputs import browser, have_chromium, open_page  # noqa: E402

from strapdown.apps.report import report_file  # noqa: E402
from strapdown.io import estimate_file, write_table  # noqa: E402

_MOVE = """async (value) => {
  const slider = [...Bokeh.documents[0].all_models].find((m) => (m.tags || []).includes("time-slider"));
  const t0 = performance.now();
  slider.value = value;
  await new Promise((done) => requestAnimationFrame(() => requestAnimationFrame(done)));
  return performance.now() - t0;
}"""


def _log(folder: Path, rows: int) -> Path:
    """A random smooth motion of ``rows`` samples at 1 kHz, consumer MEMS IMU, with its truth (as ``simulate``)."""
    from strapdown.simulate import ImuModel, RandomMotion, sample

    model = ImuModel.consumer_mems()
    data = sample(
        RandomMotion(rows / 1000.0, seed=0), 1000.0, gyro="average", imu=model, seed=1, reference="ENU", body="FLU"
    )
    n = data.gyro.shape[0]
    cols = {"t": data.t[:n]}
    for prefix, values in (("g", data.gyro), ("a", data.acc), ("m", data.mag)):
        cols.update({f"{prefix}{a}": values[:n, i] for i, a in enumerate("xyz")})
    cols.update({f"{c}_true": data.q_true[:n, i] for i, c in enumerate(("qw", "qx", "qy", "qz"))})
    meta = {
        "frame": "ENU",
        "reference": "ENU",
        "body": "FLU",
        "gyro_input": data.gyro_input,
        "time_unit": "s",
        "gyro_unit": "rad/s",
    }
    meta.update(acc_unit="m/s2", mag_unit="uT", time_origin="0", time_origin_unit="s", time_origin_kind="file")
    return write_table(folder / f"random{rows}.parquet", cols, None, meta)


def _in_browser(context, page_path: Path) -> tuple[float, float]:
    """Seconds until the page is drawn, and milliseconds a slider move takes to redraw (median of five)."""
    t0 = time.perf_counter()
    page = open_page(context, page_path)
    load = time.perf_counter() - t0
    end = page.evaluate("[...Bokeh.documents[0].all_models].find((m) => (m.tags || []).includes('time-slider')).end")
    moves = sorted(page.evaluate(_MOVE, end * k / 6) for k in range(1, 6))
    if page.problems:
        raise RuntimeError(f"{page_path.name}: {page.problems}")
    page.close()
    return load, moves[2]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rows", default="1e6,3.6e6", help="Log lengths, rows at 1 kHz (comma-separated).")
    args = ap.parse_args(argv)
    lengths = [int(float(x)) for x in args.rows.split(",")]
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        short = _log(folder, 60_000)
        short_page = report_file(short, folder / "short.html", truth=short)
        print(f"reference: a 60-s log at 1 kHz: page {short_page.bytes / 1e6:.2f} MB in {short_page.seconds:.1f} s")
        browse = have_chromium()
        if browse:
            with browser() as ctx:
                ref_load, ref_move = _in_browser(ctx, short_page.output)
            print(f"  in Chromium: drawn in {ref_load:.2f} s, a slider move redrawn in {ref_move:.0f} ms")
        else:
            print("  (no /usr/bin/chromium or no Playwright: the browser figures are left out)")
        print(f"{'rows':>10} {'log':>8} {'page MB':>8} {'build s':>8} {'estimate s':>10} {'ratio':>6}", end="")
        print(f" {'load s':>7} {'× 60 s':>7} {'move ms':>8} {'× 60 s':>7}" if browse else "")
        for rows in lengths:
            log = _log(folder, rows)
            t0 = time.perf_counter()
            estimate_file(log, folder / "estimate.parquet")
            estimate = time.perf_counter() - t0
            page = report_file(log, folder / f"report{rows}.html", truth=log)
            line = f"{page.rows:>10} {page.rows / 1000:>7.0f}s {page.bytes / 1e6:>8.2f} {page.seconds:>8.1f}"
            line += f" {estimate:>10.1f} {page.seconds / estimate:>6.2f}"
            if browse:
                with browser() as ctx:
                    load, move = _in_browser(ctx, page.output)
                line += f" {load:>7.2f} {load / ref_load:>7.2f} {move:>8.0f} {move / ref_move:>7.2f}"
            print(line, flush=True)
            for p in (log, page.output):
                p.unlink()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
