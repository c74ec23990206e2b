"""The report in a real browser: headless chromium renders it, offline, with every figure visible.

Skipped where chromium is not installed (install it with ``apt-get install -y
chromium``); ``make report-check`` runs this file alone and keeps the
screenshots in ``out/report-check`` (``SUBSTRUCTURE_REPORT_CHECK_OUT``) for a
person to look at.  See docs/report.md, "Checking it in a browser".
"""

from __future__ import annotations

import base64
import functools
import io
import os
import re
from pathlib import Path

import attrs
import numpy as np
import pytest

from browser_check import INSTALL, browser, check_page, dump_dom, element_region, pixels, screenshot
from substructure import Holder, Sensor, default_assembly
from substructure.joint_priors import with_joint_priors
from substructure.measurements import MeasurementSet
from substructure.report import report
from substructure.stability import MachineLimits, MillingCut
from substructure.synthetic import simulate

pytestmark = pytest.mark.skipif(browser() is None, reason=f"chromium is not installed ({INSTALL})")

BORDER = 1  # the figures' CSS border, in pixels
GROWTH = 6  # browser_check.figure_regions grows the differing pixels by this much


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    import matplotlib.pyplot as plt

    plt.close("all")


@pytest.fixture
def out(tmp_path):
    folder = os.environ.get("SUBSTRUCTURE_REPORT_CHECK_OUT")
    if not folder:
        return tmp_path
    Path(folder).mkdir(parents=True, exist_ok=True)
    return Path(folder)


@functools.cache
def _page():
    """A catalogue holder with the priors of its type (so the page shows where the joint values come from and the
    stability band), tap-tested with a 2 g accelerometer, with a cut and a machine."""
    model = with_joint_priors(default_assembly().with_component(
        Holder.from_catalog("BT40 shrink-fit", bore="12 mm", gauge_length="80 mm")))
    rig = model.attach(Sensor("accelerometer", "tool.tip", "2 g"))
    taps = simulate(rig, ["tool.tip"], frequency=model.frequency, noise=0.015, seed=7, sensors=["accelerometer"],
                    name="tap test")
    taps = MeasurementSet(taps.name, tuple(attrs.evolve(m, sensors=()) for m in taps))
    tool = model.component("tool")
    cut = MillingCut.for_workpiece(tool.teeth, tool.cutting_diameter, "aluminium-7075", radial_depth="3 mm",
                                   feed_per_tooth="0.05 mm", milling="down")
    limits = MachineLimits(max_speed="20000 rpm", power="11 kW", max_depth=tool.flute_length)
    return report(model, taps, cut, limits)


def _embedded(page: str) -> list[np.ndarray]:
    from PIL import Image

    images = []
    for src in re.findall(r'<img src="data:image/png;base64,([^"]+)"', page):
        with Image.open(io.BytesIO(base64.b64decode(src))) as image:
            images.append(np.asarray(image.convert("RGB"), dtype=np.int16))
    return images


def test_chromium_shows_the_report_with_every_figure(out):
    result = _page()
    html = result.save(out / "report.html", overwrite=True)
    page = html.read_text(encoding="utf-8")
    images = _embedded(page)
    assert len(images) == 6
    seen = check_page(html, out, width=1200, height=16000)
    shown = seen["shown"]
    grey = shown.mean(axis=2)
    ink_rows = np.flatnonzero((grey < 245).any(axis=1))
    assert ink_rows.size and ink_rows[-1] < shown.shape[0] - 50, "the page is longer than the screenshot"
    assert seen["ink"] > 0.02 and seen["std"] > 15  # not blank: text, tables, figures
    # one region per figure, in the order of the page, each the embedded PNG itself, pixel for pixel
    assert len(seen["regions"]) == len(images), seen["regions"]
    for (top, left, bottom, right), image in zip(seen["regions"], images):
        h, w, _ = image.shape
        assert (bottom - top, right - left) == (h + 2 * (BORDER + GROWTH), w + 2 * (BORDER + GROWTH))
        at = GROWTH + BORDER
        crop = shown[top + at: top + at + h, left + at: left + at + w]
        assert np.abs(crop - image).mean() < 1.0
    assert seen["colour_in_regions"] > 0.002  # the curves are drawn in colour
    # the answer is at the top, in the first screen a person sees
    first = grey[:900]
    assert (first < 128).mean() > 0.01
    assert seen["regions"][0][0] > 600  # the first figure comes after the answer's text


def test_a_bare_report_renders_too(out):
    html = report(default_assembly()).save(out / "bare.html", overwrite=True)
    seen = check_page(html, out, width=1000, height=5000)
    assert len(seen["regions"]) == 1 and seen["ink"] > 0.02


def test_chromium_shows_the_joint_provenance_and_the_band(out):
    """The browser's DOM holds the table of where the joint values come from and the stability band, and both are
    drawn, legible, inside the screenshot (each found by rendering the page again with it hidden)."""
    result = _page()
    html = result.save(out / "report.html", overwrite=True)
    text = " ".join(re.sub(r"<[^>]+>", " ", dump_dom(html)).split())
    assert "Where the joint values come from" in text
    assert "holder-tool holder – tool Prior" in text and "spindle-holder spindle – holder Prior" in text  # two rows
    assert "Prior for this type of holder, assumed (no measurement of this type)" in text  # the shrink-fit joint
    assert "Prior for this type of holder, measured on a similar holder" in text  # the steep taper
    assert text.count("from 1/4 to 4 times the values") == 2
    lo, hi = result.depth_range_m
    robust, nominal = result.band_recommendation, result.recommendation
    assert (f"Stability band: with every joint anywhere within its stated uncertainty (9 variants), "
            f"{robust.spindle_speed_rpm:,.0f} rpm at {robust.depth_m * 1e3:.3g} mm") in text
    assert (f"The nominal joint values alone give {nominal.spindle_speed_rpm:,.0f} rpm at {nominal.depth_m * 1e3:.3g} "
            "mm, which holds only if the joints are exactly as the model says") in text
    # the answer's headline is the band's speed and depth, the one to use until the joints are identified
    assert (f"Until the joints are identified, run at {robust.spindle_speed_rpm:,.0f} rpm with an axial depth of cut "
            f"of {robust.depth_m * 1e3:.3g} mm") in text
    assert f"would recommend from {lo * 1e3:.3g} to {hi * 1e3:.3g} mm" in text and "not decided by the data" in text
    width, height = 1200, 16000
    shown = pixels(screenshot(html, out / "report_visible.png", width, height))
    for selector, name in (("table.provenance", "provenance"), (".band", "band")):
        found = element_region(html, shown, selector, out, width, height, name)
        assert found is not None, f"{selector} is not drawn"
        (top, left, bottom, right), crop = found
        assert bottom < height - 50 and right <= width  # inside the screenshot, not cut off
        assert bottom - top > 30 and right - left > 300  # a table or paragraph, not a speck
        grey = crop.mean(axis=2)
        assert (grey < 128).mean() > 0.01  # dark text on a light ground: legible
    assert element_region(html, shown, "table.nothing-of-the-kind", out, width, height, "none") is None
