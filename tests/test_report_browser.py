"""The report in a real browser: headless chromium renders it, offline, with every figure visible.

Skipped where chromium is not installed (install it with ``apt-get install -y
chromium``); ``make report-check`` runs this file alone and keeps the
screenshots in ``out/report-check`` (``SUBSTRUCTURE_REPORT_CHECK_OUT``) for a
person to look at.  See docs/report.md, "Checking it in a browser".
"""

from __future__ import annotations

import base64
import io
import os
import re
from pathlib import Path

import attrs
import numpy as np
import pytest

from browser_check import INSTALL, browser, check_page
from substructure import Sensor, default_assembly
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


def _page():
    model = default_assembly()
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
