"""Figures of the chapter pages, drawn from the library at every docs build.

The pages (concepts, identify, diagnose, stability) show figures made by
the functions below, with the code the pages print, from the package being
documented: a figure cannot go stale, and none is committed.  They are
written to ``docs/figures/`` (not committed) before Sphinx reads the pages,
which include them with ``{figure}`` directives; a page that names a figure
no function here draws fails the build (a missing image is a warning, and
warnings are errors).  Each figure passes the same check as the examples'
(docs/_ext/figure_checks.py: no empty panel).

They are drawn again only when this file or the package's source changed
(a digest of both is kept beside the figures).  ``python
docs/_ext/chapter_figures.py [DIR]`` draws them without Sphinx.
"""

from __future__ import annotations

import hashlib
import sys
from pathlib import Path

import figure_checks

HERE = Path(__file__).resolve().parent
FIGURES = HERE.parent / "figures"
PACKAGE = HERE.parent.parent / "substructure"


def concepts_coupling(path: Path) -> None:
    """Free-free tip receptances of the spindle, holder and tool, and the coupled tool point FRF."""
    import matplotlib.pyplot as plt
    import numpy as np

    from substructure import Frequency, default_assembly

    assembly = default_assembly()
    grid = Frequency.from_range("20 Hz", "5000 Hz", "2 Hz")
    fig, ax = plt.subplots(figsize=(7.5, 4.2), layout="constrained")
    for part, color in zip(assembly.components, ("tab:gray", "tab:olive", "tab:cyan")):
        tip = f"{part.name}.tip:y"
        h = part.receptance(grid, ["tip"])[tip, tip]
        ax.semilogy(grid.hz, np.abs(h.data[:, 0, 0]) * 1e6, color=color, lw=1.0,
                    label=f"{part.name}, free-free, at its tip")
    h = assembly.receptance("tool.tip:y", frequency=grid)
    ax.semilogy(grid.hz, np.abs(h.data[:, 0, 0]) * 1e6, color="tab:blue", lw=2.0,
                label="tool point of the coupled assembly (eq. 2.1, 2.2)")
    ax.set_ylim(1e-3, 1e3)  # um/N, as the axis says
    ax.set_xlabel("frequency (Hz)")
    ax.set_ylabel("receptance |H| (µm/N)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize="small", loc="upper right")
    ax.set_title("Substructures and the assembly they make: receptance H = y/f")
    fig.savefig(path, dpi=100)
    plt.close(fig)


def identify_closed_form(path: Path) -> None:
    """The closed form (eq. 2.3) of the holder-tool joint on 1 % polluted receptances, with the truth."""
    import matplotlib.pyplot as plt
    import numpy as np

    from substructure import FRF, Frequency, default_assembly
    from substructure.identify import closed_form, joint_sides

    assembly = default_assembly()
    grid = Frequency.from_range("200 Hz", "5000 Hz", "2 Hz")
    side_a, side_b, at_a, at_b = joint_sides(assembly, "holder-tool")
    rng = np.random.default_rng(5)

    def measured(frf):
        return FRF(frf.frequency, frf.data * rng.normal(1.0, 0.01, frf.data.shape), frf.outputs, frf.inputs)

    SH11 = measured(side_a.receptance(at_a, frequency=grid))
    SHT11 = measured(assembly.receptance("tool.tip", frequency=grid))
    T = side_b.frf(["tool.tip", at_b], frequency=grid)
    result = closed_form(SHT11, SH11, T, at="tool.tip", at_a=at_a, at_b=at_b)
    joint = next(j for j in assembly.joints if j.name == "holder-tool")
    bad = result.ill_conditioned()
    fig, axes = plt.subplots(2, 1, sharex=True, figsize=(7.5, 5.4), layout="constrained")
    for ax, name, unit in zip(axes, ("k_yf", "k_tm"), ("N/m", "N m/rad")):
        truth, values = joint.k.get(name[2:]), result.parameter(name)
        ax.plot(grid.hz, values, lw=0.8, color="0.3", label="closed form, eq. 2.3, at every line")
        if bad.any():
            ax.plot(grid.hz[bad], values[bad], ".", ms=2, color="tab:red", label="ill-conditioned lines")
        ax.axhline(truth, color="tab:blue", lw=1.5, label="the value in the model")
        ax.set_ylim(0.0, 2.0 * truth)
        ax.set_ylabel(f"{name} ({unit})")
        ax.grid(True, alpha=0.3)
    axes[-1].set_xlabel("frequency (Hz)")
    fig.legend(*axes[0].get_legend_handles_labels(), loc="outside lower center", ncols=3, fontsize="small")
    fig.suptitle("Holder-tool joint by eq. 2.3 from receptances with 1 % noise")
    fig.savefig(path, dpi=100)
    plt.close(fig)


def diagnose_where_it_fails(path: Path) -> None:
    """The built-in model against a tap test with a 2 g accelerometer the record forgot (diagnose.md)."""
    import matplotlib.pyplot as plt

    from substructure import Sensor, default_assembly
    from substructure.diagnose import compare
    from substructure.synthetic import simulate

    model = default_assembly()
    rig = model.attach(Sensor("accelerometer", "tool.tip", "2 g"))
    taps = simulate(rig, ["tool.tip"], frequency=model.frequency, noise=0.015, seed=4,
                    sensors=["accelerometer"], name="tap test, tool tip")
    measured = taps.measurements[0].frf
    H = model.frf(list(measured.outputs), list(measured.inputs), measured.frequency)
    fig = compare(H, measured).plot()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def stability_lobes(path: Path) -> None:
    """The first diagram of stability.md: lobes with and without a 2 g accelerometer."""
    import matplotlib.pyplot as plt

    from substructure import Frequency, Sensor, default_assembly
    from substructure.stability import MillingCut, spindle_speeds, xy_frf, zoa

    cut = MillingCut(4, "12 mm", "3 mm", kt="625 MPa", kn="100 MPa", milling="up")
    speeds = spindle_speeds("3000 rpm", "24000 rpm", "10 rpm")
    assembly = default_assembly()
    grid = Frequency.from_range("500 Hz", "5000 Hz", "2 Hz")
    H = assembly.receptance("tool.tip:y", frequency=grid)
    lobes = zoa(xy_frf(H), cut, speeds, label="no sensor")
    tapped = assembly.attach(Sensor("accelerometer", "tool.tip", "2 g")).receptance("tool.tip:y", frequency=grid)
    fig = lobes.plot(lobes=True)
    zoa(xy_frf(tapped), cut, speeds, label="2 g accelerometer").plot(ax=fig.axes[0])
    fig.savefig(path, dpi=100)
    plt.close(fig)


#: The figures by file name, and the function that draws each.
DRAW = {
    "concepts-coupling.png": concepts_coupling,
    "identify-closed-form.png": identify_closed_form,
    "diagnose-where-it-fails.png": diagnose_where_it_fails,
    "stability-lobes.png": stability_lobes,
}


def _digest() -> str:
    h = hashlib.sha256(Path(__file__).read_bytes())
    h.update(Path(figure_checks.__file__).read_bytes())
    for source in sorted(PACKAGE.rglob("*.py")) + sorted(p for p in (PACKAGE / "data").glob("*") if p.is_file()):
        h.update(str(source.relative_to(PACKAGE)).encode() + source.read_bytes())
    return h.hexdigest()


def draw_all(target: Path = FIGURES) -> list[str]:
    """Draw every figure into ``target`` unless they are up to date; return the names drawn."""
    import matplotlib

    matplotlib.use("Agg")
    target.mkdir(parents=True, exist_ok=True)
    stamp, digest = target / ".digest", _digest()
    if stamp.exists() and stamp.read_text() == digest and all((target / n).exists() for n in DRAW):
        return []
    stamp.unlink(missing_ok=True)
    figure_checks.install()
    try:
        for name, draw in DRAW.items():
            draw(target / name)
    finally:
        figure_checks.uninstall()
    stamp.write_text(digest)
    return list(DRAW)


def _builder_inited(app):
    from sphinx.util import logging

    drawn = draw_all()
    if drawn:
        logging.getLogger(__name__).info(f"chapter figures drawn: {', '.join(drawn)}")


def setup(app):
    app.connect("builder-inited", _builder_inited)
    return {"parallel_read_safe": True, "parallel_write_safe": True}


if __name__ == "__main__":
    print(draw_all(Path(sys.argv[1]) if len(sys.argv) > 1 else FIGURES) or "up to date")
