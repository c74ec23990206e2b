"""The check of the examples' figures (docs/_ext/figure_checks.py): no panel without data in sight.

The docs build runs every example with it (docs/_ext/gallery_support.py);
here it is tried on figures whose answer is known, including the mistake of
lesson 01 (a limit in m/N on an axis drawn in um/N).
"""

from __future__ import annotations

import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from substructure import FRF, Frequency  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "docs" / "_ext"))
import figure_checks  # noqa: E402


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close("all")


def free_free_beam_like():
    """A point receptance with a mass line, an antiresonance and two modes, in m/N."""
    grid = Frequency.from_range("20 Hz", "5000 Hz", "2 Hz")
    w = 2 * np.pi * grid.hz
    h = -1 / (2.0 * w**2)
    for f, m in ((1500.0, 0.5), (3200.0, 0.8)):
        wn = 2 * np.pi * f
        h = h + 1 / (m * (wn**2 - w**2 + 2j * 0.02 * wn * w))
    return FRF(grid, h[:, None, None], ["tool.tip:y"], ["tool.tip:y"])


def test_the_lesson_01_mistake_is_an_empty_panel():
    frf = free_free_beam_like()
    fig = frf.plot()
    assert figure_checks.empty_axes(fig) == []
    peak = np.abs(frf.data).max() * 1e6
    fig.axes[0].set_ylim(top=1e-3)   # meant as 1e-3 m/N; the axis is in um/N
    problems = figure_checks.empty_axes(fig)
    assert len(problems) == 1 and problems[0].startswith("panel 1 of 2 (receptance |H| (µm/N))")
    assert "shows no data within its limits" in problems[0] and f"{peak:.3g}" in problems[0]
    # the same limit with its unit is what the author meant
    fig = frf.plot(limits=(None, "1e-3 m/N"))
    assert figure_checks.empty_axes(fig) == []


def test_all_outside_and_a_sliver_count_as_empty_a_zoom_does_not():
    x = np.linspace(0.0, 100.0, 1001)
    fig, ax = plt.subplots()
    ax.plot(x, np.exp(-((x - 50.0) / 2.0) ** 2))  # one narrow resonance-like spike
    ax.set_ylim(2.0, 3.0)                         # every point above the limits
    assert "shows no data" in figure_checks.empty_axes(fig)[0]
    ax.set_ylim(0.5, 1.5)                         # only the spike's tip peeps in: a sliver
    assert figure_checks.empty_axes(fig) != []
    ax.set_ylim(0.99, 1.5)
    ax.plot(x, 0.5 + 0 * x)                       # a flat line below does not help
    assert figure_checks.empty_axes(fig) != []
    ax.set_ylim(0.0, 1.5)                         # all of it
    assert figure_checks.empty_axes(fig) == []
    ax.set_ylim(-1.5, 1.5)
    ax.set_xlim(10.0, 11.0)                       # a zoom: 1 % of the points, but the whole width
    assert figure_checks.empty_axes(fig) == []
    fig, ax = plt.subplots()
    ax.plot([0.0, 10.0], [0.0, 10.0])             # a segment crossing the axes, no vertex inside
    ax.set_xlim(4.0, 6.0)
    ax.set_ylim(4.0, 6.0)
    assert figure_checks.empty_axes(fig) == []
    ax.set_ylim(7.0, 8.0)                         # the segment passes beside the axes
    assert figure_checks.empty_axes(fig) != []


def test_decorations_do_not_count_as_data():
    fig, (a, b) = plt.subplots(2)
    a.axvspan(0.0, 1.0, alpha=0.2)
    a.axhline(0.5)
    b.plot([1, 2], [np.nan, np.nan])
    problems = figure_checks.empty_axes(fig)
    assert len(problems) == 2 and "panel 1 of 2 draws nothing" in problems[0]
    assert "panel 2 of 2" in problems[1]


def test_other_kinds_of_data_and_text_panels_pass():
    rng = np.random.default_rng(0)
    fig, axes = plt.subplots(2, 3)
    axes[0, 0].scatter([1.0], [2.0])
    axes[0, 1].bar([1, 2], [3, 4])
    axes[0, 2].imshow(rng.random((4, 4)))
    mesh = axes[1, 0].pcolormesh(rng.random((4, 4)))
    fig.colorbar(mesh, ax=axes[1, 0])
    axes[1, 1].fill_between([0, 1, 2], [0, 1, 0], [1, 2, 1])
    axes[1, 2].axis("off")
    axes[1, 2].text(0.5, 0.5, "a text panel")
    assert figure_checks.empty_axes(fig) == []
    axes[0, 1].set_ylim(10, 20)                   # the bars below the limits
    axes[1, 1].set_xlim(5, 6)
    problems = figure_checks.empty_axes(fig)
    assert [p.split(" shows")[0] for p in problems] == ["panel 2 of 7", "panel 5 of 7"]


def test_installed_it_fails_savefig_with_the_file_name(tmp_path):
    fig, ax = plt.subplots()
    ax.plot([1, 2], [1, 2])
    ax.set_ylim(5, 6)
    figure_checks.install()
    try:
        with pytest.raises(figure_checks.EmptyAxesError, match=r"empty\.png: panel 1 of 1"):
            fig.savefig(tmp_path / "empty.png")
        ax.set_ylim(0, 3)
        fig.savefig(tmp_path / "fine.png")
    finally:
        figure_checks.uninstall()
    ax.set_ylim(5, 6)
    fig.savefig(tmp_path / "unchecked.png")       # uninstalled: saved as before
    assert (tmp_path / "fine.png").exists() and (tmp_path / "unchecked.png").exists()
