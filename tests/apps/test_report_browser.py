"""``strapdown report`` in a real browser: Debian's Chromium, headless, driven by Playwright.

Three pages (a PX4 log against its own estimate, a phone export with its magnetometer fitted, a simulated show
against its truth) are opened as a person would open them, from the file, with the network closed.  Each loads
with no console error or warning, every figure draws its data (the figure painted with and without its data
differs), the slider turns the 3D model exactly as :func:`strapdown.apps.report.view3d.scene` computes and moves
every cursor, the play button and a click on a time figure move the slider, and a screenshot is not blank.

The tests skip where /usr/bin/chromium or Playwright is missing (``apt-get install chromium``), unless
``STRAPDOWN_REQUIRE_BROWSER`` is set: ``.ci/run`` installs the browser and sets it, so there they must run.
Playwright drives the system's browser: ``playwright install`` is never needed.
"""

import io
import os

import numpy as np
import pytest
from report_inputs import PX4_LOG, browser, have_chromium, open_page, phone_export, show_log, show_tab, still_log

pytest.importorskip("bokeh")
if not have_chromium():
    why = "no Chromium at /usr/bin/chromium (apt-get install chromium), or no Playwright for Python (the test extra)"
    if os.environ.get("STRAPDOWN_REQUIRE_BROWSER"):  # .ci/run: the browser tests must run there
        raise RuntimeError(f"STRAPDOWN_REQUIRE_BROWSER is set but {why}")
    pytest.skip(why, allow_module_level=True)

from strapdown.apps.report import report_file
from strapdown.apps.report.view3d import CAMERA, scene, view_spec

# The page's models by type or tag, and each figure's painted pixels with and without its data (the figure's
# own export, so that a figure of a hidden tab is painted too).
_MODELS_JS = """
window.__sd = {
  models: () => [...Bokeh.documents[0].all_models],
  tagged: (tag) => __sd.models().find((m) => m.tags && m.tags.includes(tag)),
  slider: () => __sd.tagged("time-slider"),
  data: (tag) => { const d = __sd.tagged(tag).data; const o = {};
                   for (const k in d) o[k] = Array.from(d[k], (v) => (Array.isArray(v) || ArrayBuffer.isView(v))
                                                          ? Array.from(v) : v);
                   return o; },
  pixels(view) {
    const c = view.export("png").canvas;
    const f = view.frame.bbox, r = window.devicePixelRatio || 1;
    return c.getContext("2d").getImageData(f.left * r, f.top * r, f.width * r, f.height * r).data;
  },
  figures() {
    return [...Bokeh.index.all_views()].filter((v) => v.model.type === "Figure").map((view) => {
      const glyphs = view.model.renderers.filter((r) => r.type === "GlyphRenderer" && !(r.tags || []).length);
      const full = __sd.pixels(view);
      const shown = glyphs.map((r) => r.visible);
      glyphs.forEach((r) => { r.visible = false; });
      const bare = __sd.pixels(view);
      glyphs.forEach((r, i) => { r.visible = shown[i]; });
      let changed = 0;
      for (let i = 0; i < full.length; i += 4)
        if (full[i] !== bare[i] || full[i + 1] !== bare[i + 1] || full[i + 2] !== bare[i + 2]) changed++;
      return {name: view.model.name, glyphs: glyphs.length, inked: changed / (full.length / 4),
              width: view.frame.bbox.width, height: view.frame.bbox.height};
    });
  },
};
"""


@pytest.fixture(scope="module")
def pages(tmp_path_factory):
    folder = tmp_path_factory.mktemp("pages")
    show = show_log(folder, duration=30.0)
    return {
        "px4": report_file(PX4_LOG, folder / "px4.html", points=600, frames=300),
        "phone": report_file(
            phone_export(folder, 40.0), folder / "phone.html", fit_mag=True, allan=still_log(folder), points=600
        ),
        "show": report_file(show, folder / "show.html", truth=show, estimators=("attitude", "mahony"), points=600),
    }


@pytest.fixture(scope="module")
def context():
    with browser() as ctx:
        yield ctx


def opened(context, result):
    page = open_page(context, result.output)
    page.evaluate(_MODELS_JS)
    return page


def tab_titles(page) -> list[str]:
    return [t.strip() for t in page.locator(".bk-tab").all_inner_texts()]


@pytest.mark.parametrize("name", ["px4", "phone", "show"])
def test_the_page_loads_cleanly_and_every_figure_draws_its_data(pages, context, name):
    page = opened(context, pages[name])
    titles = tab_titles(page)
    expected = ["Summary", "Attitude", "Quaternion", "Sensors", "Bias", "Estimators"]
    assert titles[:6] == expected
    assert ("Calibration" in titles) == (name == "phone")  # the fitted magnetometer on its sphere, Allan
    for title in titles:  # every tab drawn once, as a click shows it
        show_tab(page, title)
    figures = page.evaluate("__sd.figures()")
    names = [f["name"] for f in figures]
    assert "view3d" in names and "time:flags" in names and "time:gyro (body axes)" in names
    if name != "px4":
        assert "time:magnetic dip (below the horizontal, by attitude's attitude)" in names
    if name == "phone":
        assert "mag-sphere" in names and "allan" in names, names
    for f in figures:
        assert f["width"] > 100 and f["height"] >= 40, f
        # lanes and bars are few pixels; a line over the whole time axis is more than 0.1 % of its frame
        assert f["glyphs"] > 0 and f["inked"] > 0.001, f
    assert page.problems == []
    page.close()


@pytest.mark.parametrize("name", ["px4", "show"])
def test_the_slider_turns_the_model_as_the_library_does_and_moves_every_cursor(pages, context, name):
    result = pages[name]
    rec = result.recording
    page = opened(context, result)
    spec = view_spec(rec.axes.frame, rec.axes.body)
    view = page.locator(".bk-Figure").first  # the 3D view comes first on the page
    before = view.screenshot()
    model0 = page.evaluate("__sd.data('view-model')")
    # a drag of the slider's handle with the mouse, two thirds along its track
    handle = page.locator(".noUi-handle").first.bounding_box()
    track = page.locator(".noUi-base").first.bounding_box()
    page.mouse.move(handle["x"] + handle["width"] / 2, handle["y"] + handle["height"] / 2)
    page.mouse.down()
    page.mouse.move(track["x"] + 2 * track["width"] / 3, handle["y"] + handle["height"] / 2, steps=8)
    page.mouse.up()
    page.wait_for_function("() => Bokeh.documents[0].is_idle")
    value = page.evaluate("__sd.slider().value")
    t = rec.t
    assert abs(value - (t[0] + 2 * (t[-1] - t[0]) / 3)) < 0.05 * (t[-1] - t[0])
    cursors = page.evaluate("__sd.models().filter((m) => (m.tags || []).includes('cursor')).map((m) => m.location)")
    assert len(cursors) >= 10 and np.allclose(cursors, value, rtol=0, atol=1e-12)
    # the model drawn is scene() of the attitude the page holds at that instant, which is the estimate's
    frames = page.evaluate("__sd.data('view-frames')")
    k = int(np.searchsorted(frames["t"], value, side="right") - 1)
    q = [frames[c][k] for c in ("qw", "qx", "qy", "qz")]
    row = int(np.searchsorted(t, frames["t"][k]))
    np.testing.assert_allclose(q, rec.main.q[row], rtol=0, atol=1e-12)
    drawn = page.evaluate("__sd.data('view-model')")
    want = scene(spec, q, CAMERA)["model"]
    assert drawn["color"] == want["color"]
    for key in ("xs", "ys"):
        assert len(drawn[key]) == len(want[key])
        for a, b in zip(drawn[key], want[key], strict=True):
            np.testing.assert_allclose(a, b, rtol=0, atol=1e-9)
    assert drawn["xs"] != model0["xs"]
    assert view.screenshot() != before  # and the picture changed
    # the readout in the view: that instant, and its angles as the library's as_euler gives them
    from strapdown.rotations.euler import as_euler

    yaw, pitch, roll = as_euler(rec.main.q[row], "ZYX", degrees=True)
    readout = page.evaluate("__sd.models().find((m) => m.name === 'view-readout').text")
    assert readout == f"t = {frames['t'][k]:.3f} s   yaw {yaw:.1f}°, pitch {pitch:.1f}°, roll {roll:.1f}°"
    assert page.problems == []
    page.close()


def test_play_steps_the_slider_and_a_click_on_a_time_figure_sets_it(pages, context):
    result = pages["show"]
    page = opened(context, result)
    play = page.get_by_role("button", name="▶ Play")
    play.click()
    page.wait_for_function("() => __sd.slider().value > __sd.slider().start + 0.5", timeout=30_000)
    page.get_by_role("button", name="❚❚ Pause").click()
    paused = page.evaluate("__sd.slider().value")
    page.wait_for_timeout(400)
    assert page.evaluate("__sd.slider().value") == paused  # it stopped
    first = page.evaluate("__sd.data('view-model')")
    # a click in the middle of the yaw figure's frame: the slider, the cursors and the model go there
    show_tab(page, "Attitude")
    box = page.evaluate(
        "(() => { const v = [...Bokeh.index.all_views()].find((v) => v.model.name === 'time:yaw (Z)');"
        " const r = v.el.getBoundingClientRect(), f = v.frame.bbox;"
        " return {x: r.left + f.left + f.width / 2, y: r.top + f.top + f.height / 2}; })()"
    )
    page.mouse.click(box["x"], box["y"])
    page.wait_for_function("() => Bokeh.documents[0].is_idle")
    t = result.recording.t
    value = page.evaluate("__sd.slider().value")
    assert abs(value - (t[0] + t[-1]) / 2) < 0.02 * (t[-1] - t[0])
    assert page.evaluate("__sd.data('view-model')")["xs"] != first["xs"]
    assert page.problems == []
    page.close()


def test_a_drag_on_the_view_turns_the_camera_not_the_body(pages, context):
    result = pages["px4"]
    page = opened(context, result)
    ring0 = page.evaluate("__sd.data('view-ring')")
    frames0 = page.evaluate("__sd.data('view-frames')")
    box = page.locator(".bk-Figure").first.bounding_box()
    page.mouse.move(box["x"] + box["width"] / 2, box["y"] + box["height"] / 2)
    page.mouse.down()
    page.mouse.move(box["x"] + box["width"] / 2 + 80, box["y"] + box["height"] / 2 + 40, steps=6)
    page.mouse.up()
    page.wait_for_function("() => Bokeh.documents[0].is_idle")
    assert page.evaluate("__sd.data('view-ring')") != ring0  # the horizon is seen from elsewhere
    assert page.evaluate("__sd.data('view-frames')") == frames0  # the attitudes are the same
    assert page.evaluate("__sd.slider().value") == pytest.approx(float(result.recording.t[0]))
    assert page.problems == []
    page.close()


@pytest.mark.parametrize("name", ["px4", "show"])
def test_a_screenshot_is_not_blank_and_shows_the_library_s_numbers(pages, context, name):
    from PIL import Image

    result = pages[name]
    page = opened(context, result)
    shot = np.asarray(Image.open(io.BytesIO(page.screenshot(full_page=True))).convert("RGB"))
    ink = (shot < 235).any(axis=2)
    assert shot.shape[0] >= 600 and shot.shape[1] >= 1000
    assert 0.02 < ink.mean() < 0.6, ink.mean()  # drawn on, not filled
    assert np.unique(shot.reshape(-1, 3), axis=0).shape[0] > 50  # the model's faces, lines, text
    # the 3D view's square holds the model: its grey and its green and red wings
    left = shot[: shot.shape[0] // 2, : shot.shape[1] // 3].reshape(-1, 3).astype(int)
    assert ((left[:, 1] - left[:, 0] > 60) & (left[:, 1] - left[:, 2] > 30)).sum() > 200  # green right wing
    # the error table as rendered shows the library's numbers
    shown = [s for s in page.locator("td[data-rms='total']").all_inner_texts() if s]
    main = result.recording.runs
    if result.recording.reference is not None:
        assert shown == [f"{r.rmse['total']:.3f}" for r in main]
    bias = next(s for s in page.locator("td[data-bias='1']").all_inner_texts() if s)
    assert bias.startswith(f"{np.degrees(main[0].bias[-1, 0]):.4f}")
    assert page.problems == []
    page.close()
