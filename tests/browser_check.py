"""Render an HTML file in a real headless browser (Debian's chromium) and find the figures on the screenshot.

Used by ``tests/test_report_browser.py`` (``make report-check``).  The browser
runs with its network cut off (a proxy that does not exist, no background
services), so a page that needed the network would render without its
figures.  Figures are found by rendering the page twice, as it is and with
its images hidden (``visibility: hidden`` keeps the layout): the pixels that
differ are the images' own, and each connected region of them is one figure.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import tempfile
from pathlib import Path

import numpy as np

BROWSERS = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable")
"""Names the browser is looked up by (``SUBSTRUCTURE_CHROMIUM`` gives a path instead)."""

INSTALL = "apt-get install -y chromium"
"""The documented command that installs it (Debian and Ubuntu)."""

HIDE_IMAGES = "<style>img { visibility: hidden !important; }</style></head>"


def browser() -> str | None:
    """The path of a Chromium-family browser, or None."""
    given = os.environ.get("SUBSTRUCTURE_CHROMIUM")
    if given:
        return given if Path(given).exists() else shutil.which(given)
    for name in BROWSERS:
        found = shutil.which(name)
        if found:
            return found
    return None


def screenshot(html: Path, png: Path, width: int = 1200, height: int = 3000, timeout: float = 180.0) -> Path:
    """Render ``html`` to ``png`` in headless chromium (window ``width`` x ``height`` CSS pixels).

    The browser gets a new, empty profile, removed afterwards.
    """
    exe = browser()
    if exe is None:
        raise FileNotFoundError(f"no chromium found; install it with: {INSTALL}")
    with tempfile.TemporaryDirectory(prefix="substructure-chromium-") as profile:
        return _run(exe, html, png, Path(profile), width, height, timeout)


def _run(exe: str, html: Path, png: Path, profile: Path, width: int, height: int, timeout: float) -> Path:
    command = [exe, "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
               "--disable-background-networking", "--disable-component-update", "--disable-sync",
               "--disable-extensions", "--disable-default-apps", "--hide-scrollbars", "--force-device-scale-factor=1",
               "--proxy-server=127.0.0.1:9", "--proxy-bypass-list=<-loopback>",  # no network: figures must be inside
               f"--user-data-dir={profile}", f"--screenshot={png}", f"--window-size={width},{height}",
               html.resolve().as_uri()]
    done = subprocess.run(command, capture_output=True, text=True, timeout=timeout)
    if done.returncode != 0 or not png.exists():
        raise RuntimeError(f"chromium failed ({done.returncode}): {done.stderr[-2000:]}")
    return png


def pixels(png: Path) -> np.ndarray:
    """The screenshot as an ``(height, width, 3)`` array of 0-255 values."""
    from PIL import Image

    with Image.open(png) as image:
        return np.asarray(image.convert("RGB"), dtype=np.int16)


def figure_regions(with_images: np.ndarray, without_images: np.ndarray, min_area: int = 40_000) -> list[tuple]:
    """Bounding boxes ``(top, left, bottom, right)`` of the regions where the two renderings differ.

    Regions smaller than ``min_area`` pixels (bounding box) are dropped: a
    broken-image icon or anti-aliasing is not a figure.
    """
    from scipy import ndimage

    differ = np.abs(with_images - without_images).sum(axis=2) > 30
    grown = ndimage.binary_dilation(differ, iterations=6)  # a figure's lines and text become one region
    labels, count = ndimage.label(grown)
    boxes = []
    for region in ndimage.find_objects(labels):
        top, bottom = region[0].start, region[0].stop
        left, right = region[1].start, region[1].stop
        if (bottom - top) * (right - left) >= min_area:
            boxes.append((top, left, bottom, right))
    return sorted(boxes)


def check_page(html: Path, work: Path, width: int = 1200, height: int = 3000) -> dict:
    """Render a page with and without its images and describe what the browser showed.

    Returns
    -------
    dict
        ``shown`` (the screenshot as an array), ``regions`` (figure boxes),
        ``ink`` (fraction of the screenshot that is not white), ``std`` (of
        the grey levels), ``colour_in_regions`` (fraction of the figure pixels
        that are coloured: plotted lines), ``png`` (the screenshot's path).
    """
    work.mkdir(parents=True, exist_ok=True)
    hidden = work / (html.stem + "_hidden.html")
    text = html.read_text(encoding="utf-8")
    assert text.count("</head>") == 1
    hidden.write_text(text.replace("</head>", HIDE_IMAGES), encoding="utf-8")
    shown_png = screenshot(html, work / (html.stem + ".png"), width, height)
    hidden_png = screenshot(hidden, work / (html.stem + "_hidden.png"), width, height)
    shown, bare = pixels(shown_png), pixels(hidden_png)
    regions = figure_regions(shown, bare)
    grey = shown.mean(axis=2)
    coloured = 0
    total = 0
    for top, left, bottom, right in regions:
        block = shown[top:bottom, left:right]
        spread = block.max(axis=2) - block.min(axis=2)
        coloured += int((spread > 60).sum())
        total += block.shape[0] * block.shape[1]
    return {"shown": shown, "regions": regions, "ink": float((grey < 245).mean()), "std": float(grey.std()),
            "colour_in_regions": coloured / total if total else 0.0, "png": shown_png}


def dump_dom(html: Path, timeout: float = 180.0) -> str:
    """The page's DOM as the browser built it (``--dump-dom``), serialised as HTML."""
    exe = browser()
    if exe is None:
        raise FileNotFoundError(f"no chromium found; install it with: {INSTALL}")
    with tempfile.TemporaryDirectory(prefix="substructure-chromium-") as profile:
        command = [exe, "--headless", "--no-sandbox", "--disable-gpu", "--no-first-run",
                   "--disable-background-networking", "--disable-component-update", "--disable-sync",
                   "--disable-extensions", "--disable-default-apps", "--proxy-server=127.0.0.1:9",
                   "--proxy-bypass-list=<-loopback>", f"--user-data-dir={profile}", "--dump-dom",
                   html.resolve().as_uri()]
        done = subprocess.run(command, capture_output=True, text=True, timeout=timeout)
    if done.returncode != 0 or "<html" not in done.stdout:
        raise RuntimeError(f"chromium failed ({done.returncode}): {done.stderr[-2000:]}")
    return done.stdout


def element_region(html: Path, shown: np.ndarray, selector: str, work: Path, width: int, height: int,
                   name: str) -> tuple[tuple, np.ndarray] | None:
    """Where the elements matching a CSS ``selector`` are drawn on the screenshot ``shown``, and their pixels.

    The page is rendered once more with those elements hidden (``visibility: hidden`` keeps the layout); the
    bounding box of the pixels that differ is the elements' visible region, saved as ``NAME.png`` in ``work``
    for a person to look at. None when nothing of them is visible.
    """
    from PIL import Image

    hidden = work / (html.stem + f"_without_{name}.html")
    text = html.read_text(encoding="utf-8")
    hidden.write_text(text.replace("</head>", f"<style>{selector} {{ visibility: hidden !important; }}</style></head>"),
                      encoding="utf-8")
    without = pixels(screenshot(hidden, work / (hidden.stem + ".png"), width, height))
    differ = np.abs(shown - without).sum(axis=2) > 30
    rows, cols = np.flatnonzero(differ.any(axis=1)), np.flatnonzero(differ.any(axis=0))
    if not rows.size:
        return None
    box = (int(rows[0]), int(cols[0]), int(rows[-1]) + 1, int(cols[-1]) + 1)
    crop = shown[box[0]:box[2], box[1]:box[3]]
    Image.fromarray(crop.astype(np.uint8)).save(work / f"{html.stem}_{name}.png")
    return box, crop
