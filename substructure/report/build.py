"""The results a report presents, computed by the library's workflows: :func:`report` and :class:`Report`.

:func:`report` runs what the commands run, in the same way: the tool point
receptance of the model and the part of it stability may use
(:func:`~substructure.stability.assembly_structure`), its modes
(:class:`~substructure.stability.ModalFitter`), the lobes of a cut and the
recommended speed and depth (:func:`~substructure.stability.zoa` or
:func:`~substructure.stability.sdm`, :func:`~substructure.stability.recommend`),
and, with a measurement set, the diagnosis
(:func:`~substructure.diagnose.diagnose`) and the identification of the joints
(:func:`~substructure.identify.identify_joint`).  :class:`Report` keeps the
results; it computes nothing more, it only presents them
(:meth:`Report.to_html`, :meth:`Report.to_json`).
"""

from __future__ import annotations

import datetime
import os
import warnings
from pathlib import Path
from typing import Any, Callable, Sequence

import attrs
import numpy as np

from ..errors import InvalidValueError, SubstructureError, SubstructureWarning
from ._variants import _cutting, _joint_band, _lobes, _structure
from .text import _number

__all__ = ["Report", "ToolMode", "report", "tool_point", "SUMMARY_KEYS", "DEFAULT_SPEEDS"]

#: The keys of :meth:`Report.to_json` (the object ``substructure report --json`` prints, with ``file``
#: and ``bytes`` added).
SUMMARY_KEYS = ("title", "created", "version", "sources", "assembly", "tool_point", "frequency_hz",
                "structure_band", "modes", "cut", "workpiece", "machine", "method", "absolute_limit_m",
                "recommended", "no_recommendation", "diagnosis", "joints", "assumptions", "notes",
                "stability_band", "cutting_data")

DEFAULT_SPEEDS = ("2000 rpm", "24000 rpm", "50 rpm")
"""The spindle speeds of the lobes when none are given (as ``substructure lobes``)."""


@attrs.frozen
class ToolMode:
    """One mode of the tool point receptance, as the report lists it.

    Parameters
    ----------
    frequency_hz : float
        Natural frequency [Hz].
    peak_m_per_n : float
        The largest ``|H|`` of the receptance near it (within 2 % in frequency) [m/N].
    damping_ratio : float or None
        Fitted damping ratio (fraction of critical), or None when no fit was made.
    stiffness_n_per_m : float or None
        Fitted modal stiffness [N/m], or None.
    """

    frequency_hz: float
    peak_m_per_n: float
    damping_ratio: float | None = None
    stiffness_n_per_m: float | None = None

    def to_json(self) -> dict:
        """The mode as in ``substructure report --json``.

        Returns
        -------
        dict
            ``frequency_hz``, ``peak_m_per_n``, ``damping_ratio``, ``stiffness_n_per_m`` (SI).
        """
        return attrs.asdict(self)


@attrs.frozen(eq=False)  # a container of results: compared by identity, never hashed by its arrays
class Report:
    """What :func:`report` computed: the model, its tool point FRF, the diagnosis, the lobes, the joints.

    Parameters
    ----------
    title : str
        The report's title.
    assembly : Assembly
        The model as given.
    at : str
        The tool point with its DOF (``"tool.tip:y"``).
    frf : FRF
        The tool point receptance [m/N] on the model's whole grid.
    structure_band : FlexibleBand
        The lines stability uses, and why (rigid-body and suspension lines left out).
    modes : tuple of ToolMode
        The modes of the tool point receptance in the band.
    modal_fit_error : float or None
        Relative error of the modes alone against the receptance in the band (None without a fit).
    cut : MillingCut or TurningCut or None
        The cut (None: no lobes).
    limits : MachineLimits or None
        The machine's limits used for the recommendation.
    lobes : Lobes or None
        The stability lobes of the cut.
    recommendation : Recommendation or None
        The recommended speed and depth with its margin and runners-up.
    no_recommendation : str or None
        Why there is no recommendation, when a cut was given.
    measurements : MeasurementSet or None
        The tap tests.
    diagnosis : Diagnosis or None
        The model diagnosed against the tap tests.
    identifications : tuple of IdentificationReport
        The joints identified from the tap tests.
    identification_errors : tuple of (str, str)
        Joints that could not be identified, with the reason.
    notes : tuple of str
        What was taken from where (teeth, diameter, workpiece, largest depth, ...).
    sources : tuple of (str, str)
        The input files: ``("assembly", path)``, ``("measurements", path)``.
    created : str
        When the report was made (ISO 8601, UTC).
    version : str
        The version of substructure that made it.
    command : str or None
        The command line that made it, shown in the report.
    band : LobesBand or None
        The lobes over the joints' stated uncertainty
        (:func:`~substructure.joint_priors.joint_variants`), the nominal among
        them; None when no joint states one.
    band_recommendation : Recommendation or None
        The speed and depth stable for every member of ``band``.
    band_no_recommendation : str or None
        Why there is none over the band, when there is a band.
    band_depths_m : tuple of float or None
        Each member's own recommended depth (m), as if its joints were
        known (None where it has none); empty without a band. Their range
        (:attr:`depth_range_m`) is what the joints' uncertainty leaves open.
    cutting : dict or None
        The recommendation's cutting speed and feed against the usual range
        (:func:`~substructure.stability.cutting_conditions`, with
        ``warnings``); None without a recommendation.
    band_cutting : dict or None
        The same for the band's recommendation (None without one).
    """

    title: str
    assembly: Any
    at: str
    frf: Any
    structure_band: Any
    modes: tuple = attrs.field(default=(), converter=tuple)
    modal_fit_error: float | None = None
    cut: Any = None
    limits: Any = None
    lobes: Any = None
    recommendation: Any = None
    no_recommendation: str | None = None
    measurements: Any = None
    diagnosis: Any = None
    identifications: tuple = attrs.field(default=(), converter=tuple)
    identification_errors: tuple = attrs.field(default=(), converter=tuple)
    notes: tuple = attrs.field(default=(), converter=tuple)
    sources: tuple = attrs.field(default=(), converter=tuple)
    created: str = ""
    version: str = ""
    command: str | None = None
    band: Any = None
    band_recommendation: Any = None
    band_no_recommendation: str | None = None
    band_depths_m: tuple = attrs.field(default=(), converter=tuple)
    cutting: dict | None = None
    band_cutting: dict | None = None

    @property
    def depth_range_m(self) -> tuple[float, float] | None:
        """The lowest and highest recommended depth (m) over the joints' uncertainty, the nominal among them
        (the nominal depth twice without a band; None without a recommendation)."""
        if self.recommendation is None:
            return None
        depths = [d for d in self.band_depths_m if d is not None] + [self.recommendation.depth_m]
        return float(min(depths)), float(max(depths))

    @property
    def tool(self):
        """The :class:`~substructure.components.Tool` that holds the tool point, or None."""
        return _tool_of(self.assembly, self.at)

    def assumptions(self) -> list[str]:
        """The assumptions behind the results, in plain words (also in the report's last section).

        Returns
        -------
        list of str
            One sentence or two per assumption.
        """
        from .text import assumptions

        return assumptions(self)

    def to_json(self) -> dict:
        """A summary of the report: the keys of :data:`SUMMARY_KEYS` (SI units, rpm, Hz).

        Returns
        -------
        dict
            The model, the tool point, the band, the modes, the cut, the recommendation (the object
            of ``substructure lobes --json``), the diagnosis (the object of ``substructure diagnose
            --json``), the joints with their uncertainty, the assumptions and notes.
        """
        from .text import joints_json

        cut = self.cut
        milling = cut is not None and hasattr(cut, "radial_depth")
        workpiece = getattr(cut, "workpiece", None)
        f = self.frf.frequency.hz
        return {
            "title": self.title,
            "created": self.created,
            "version": self.version,
            "sources": {kind: os.fspath(path) for kind, path in self.sources},
            "assembly": {"name": self.assembly.name,
                         "components": [c.name for c in self.assembly.components],
                         "joints": [j.name for j in self.assembly.joints],
                         "supports": len(self.assembly.supports),
                         "sensors": [s.name for s in self.assembly.sensors]},
            "tool_point": self.at,
            "frequency_hz": [float(f[0]), float(f[-1])],
            "structure_band": None if self.structure_band is None else self.structure_band.to_json(),
            "modes": [m.to_json() for m in self.modes],
            "cut": cut.to_json() if milling else (None if cut is None else {"describe": cut.describe()}),
            "workpiece": None if workpiece is None else workpiece.to_json(),
            "machine": None if self.limits is None else self.limits.to_json(),
            "method": None if self.lobes is None else self.lobes.method,
            "absolute_limit_m": None if self.lobes is None else self.lobes.absolute_limit_m,
            "recommended": None if self.recommendation is None else self.recommendation.to_json(),
            "no_recommendation": self.no_recommendation,
            "diagnosis": None if self.diagnosis is None else self.diagnosis.to_json(),
            "joints": joints_json(self),
            "assumptions": self.assumptions(),
            "notes": list(self.notes),
            "stability_band": None if self.band is None else {
                "members": len(self.band.members),
                "recommended": None if self.band_recommendation is None else self.band_recommendation.to_json(),
                "no_recommendation": self.band_no_recommendation,
                "depth_range_m": None if self.depth_range_m is None else list(self.depth_range_m),
                "cutting_data": self.band_cutting},
            "cutting_data": self.cutting,
        }

    def to_html(self) -> str:
        """The report as one self-contained HTML page (figures embedded, CSS inline, nothing fetched).

        Returns
        -------
        str
            The page (UTF-8 text, well-formed: it parses as XML too).
        """
        from .html import render

        return render(self)

    def save(self, path: Any, overwrite: bool = False) -> Path:
        """Write :meth:`to_html` to a file, atomically.

        Parameters
        ----------
        path : str or os.PathLike
            The file, usually ``*.html``.
        overwrite : bool, default False
            Whether an existing file may be replaced.

        Returns
        -------
        pathlib.Path
            The file written.
        """
        from ..io import check_writable, write_text

        check_writable(path, overwrite)  # before the figures are drawn
        write_text(path, self.to_html(), overwrite)
        return Path(path)


# -- computing ---------------------------------------------------------------------------------------


def _fraction(value: Any, field: str, hi: float) -> float:
    v = _number(value)
    if v is None or not 0.0 <= v < hi:
        raise InvalidValueError(f"{field}: got {value!r}; expected a number in [0, {hi:g})")
    return v


def tool_point(assembly: Any, at: Any = None) -> str:
    """The tool point of a report: ``at`` with the DOF ``y``, or the tip of the assembly's one tool.

    Parameters
    ----------
    assembly : Assembly
        The model.
    at : str, optional
        A point (``"tool.tip"``, ``"tool.tip:y"``); default the tip of the one
        :class:`~substructure.components.Tool` component of the assembly.

    Returns
    -------
    str
        The point with its DOF, ``"tool.tip:y"``.

    Raises
    ------
    substructure.errors.InvalidValueError
        When ``at`` is not given and the assembly has no tool or several, or ``at`` is a
        rotation (``:theta``).
    """
    from ..components import Tool
    from ..points import parse_point

    if at is None:
        tools = [c for c in assembly.components if isinstance(c, Tool)]
        if len(tools) != 1:
            names = ", ".join(c.name for c in tools) or "none"
            raise InvalidValueError(f"at: the assembly has {len(tools)} tool components ({names}); give the tool "
                                    "point, e.g. at='tool.tip' (--at tool.tip)")
        at = f"{tools[0].name}.tip"
    ref = parse_point(str(at))
    dof = ref.dof or "y"
    if dof != "y":
        raise InvalidValueError(f"at: got {at!r}; the tool point needs a translational receptance (':y'), "
                                f"not ':{dof}'")
    component = assembly.component(ref.component)  # an unknown component: the error names the ones there are
    if hasattr(component, "position"):
        component.position(ref.point)  # a point outside the component: the error says its length
    return f"{ref.point}:y"


def _tool_of(assembly: Any, at: str):
    from ..components import Tool
    from ..points import parse_point

    name = parse_point(at).component
    return next((c for c in assembly.components if isinstance(c, Tool) and c.name == name), None)


def _modes(structure: Any, notes: list[str]) -> tuple[tuple[ToolMode, ...], float | None]:
    """The modes of the band: fitted (damping, stiffness), or the peaks alone when the fit fails."""
    from ..stability import ModalFitter, ModalFitWarning

    f = structure.frequency.hz
    mag = np.abs(structure.data[:, 0, 0])

    def peak(fn: float) -> float:
        near = (f >= fn * 0.98) & (f <= fn * 1.02)
        return float(mag[near].max()) if near.any() else float(np.interp(fn, f, mag))

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ModalFitWarning)
            fit = ModalFitter().fit(structure)
        modes = tuple(ToolMode(float(m.frequency.m_as("Hz")), peak(float(m.frequency.m_as("Hz"))),
                               float(m.damping_ratio), float(m.stiffness.m_as("N/m"))) for m in fit.modes_)
        return modes, float(fit.modal_error_)
    except (SubstructureError, ValueError, np.linalg.LinAlgError) as exc:
        notes.append(f"modes: no modal fit ({exc}); the peaks of the receptance are listed instead")
        return tuple(ToolMode(float(p), peak(float(p))) for p in structure.peaks(prominence=0.05)), None


def _cut_notes(cut: Any, tool: Any, notes: list[str]) -> None:
    if tool is None or not hasattr(cut, "radial_depth"):
        return
    if tool.teeth is not None and tool.teeth != cut.teeth:
        notes.append(f"teeth: the cut has {cut.teeth} teeth, the tool {tool.name!r} of the assembly {tool.teeth}")
    d = tool.cutting_diameter
    if abs(d.m_as("m") - cut.diameter.m_as("m")) > 1e-9:
        notes.append(f"diameter: the cut's {cut.diameter:~P} differs from the tool's {d:~P}")


def _joints_to_identify(assembly: Any, identify: Any) -> list[str]:
    if identify is None or identify is False:
        return []
    if isinstance(identify, str) and identify == "auto":
        return [j.name for j in assembly.joints if not j.rigid]
    names = [identify] if isinstance(identify, str) else list(identify)
    for name in names:
        if assembly.joint(name).rigid:  # an unknown name raises here, with the joints there are
            raise InvalidValueError(f"identify: joint {name!r} is rigid; only elastic joints are identified")
    return names


def _tests_outside_the_grid(tests: Any, grid: Any, notes: list[str]) -> None:
    """Say (a warning and a note) when the tap tests' lines and the model's grid do not overlap at all.

    The tool point receptance, its modes and the lobes are on the model's grid, the diagnosis and the
    identification on the tests' lines: without a line in common the page shows the two on different bands,
    most often a frequency unit mistaken (kHz for Hz) or a grid or file that is not the one meant.
    """
    lo, hi = float(tests.hz[0]), float(tests.hz[-1])
    first, last = float(grid.hz[0]), float(grid.hz[-1])
    if lo <= last and hi >= first:
        return
    text = (f"the tap tests ({lo:.6g} to {hi:.6g} Hz) lie outside the model's frequency grid ({first:.6g} to "
            f"{last:.6g} Hz, the assembly file's [frequency]): the tool point receptance, its modes and the lobes "
            "are on the model's grid, the diagnosis and the joints on the tests' lines; check the tests' frequency "
            "unit, or the grid")
    warnings.warn(text, SubstructureWarning, stacklevel=3)
    notes.append(text)


def report(assembly: Any, measurements: Any = None, cut: Any = None, limits: Any = None, *, at: str | None = None,
           speeds: Any = None, band: Any = "auto", method: str = "zoa", intervals: int | None = None,
           margin: float = 0.2, speed_tolerance: float = 0.03, identify: Any = "auto", title: str | None = None,
           notes: Sequence[str] = (), command: str | None = None,
           progress: bool | Callable[[str], None] = False, tool_material: str | None = None,
           cutting_table: Any = None) -> Report:
    """Compute everything a report shows, with the library's workflows.

    Parameters
    ----------
    assembly : Assembly or str or os.PathLike
        The model, or its assembly file; it needs a frequency grid.
    measurements : MeasurementSet or str or os.PathLike, optional
        Tap tests of the assembly (or their measurement file): the diagnosis and the
        identification of the joints are added.
    cut : MillingCut or TurningCut, optional
        The cut: the lobes (and, for milling, the recommended speed and depth) are added.
    limits : MachineLimits, optional
        The machine's speed range, power, torque and largest depth; default: only the largest
        depth, the flute length of the tool where it is known.
    at : str, optional
        The tool point (``"tool.tip"``); default the tip of the assembly's one tool component.
    speeds : pint.Quantity, optional
        Spindle speeds of the lobes [rpm] (:func:`~substructure.stability.spindle_speeds`);
        default 2,000 to 24,000 rpm in 50 rpm steps.
    band : "auto", "all" or (float, float), default "auto"
        The receptance lines stability uses: ``"auto"`` leaves out rigid-body and suspension
        lines (:func:`~substructure.stability.assembly_structure`), or a band in Hz.
    method : {"zoa", "sdm"}, default "zoa"
        Zero-order approximation, or semi-discretization on modes fitted to the receptance.
    intervals : int, optional
        Semi-discretization only: intervals in the cut per delay period (default: chosen per speed).
    margin : float, default 0.2
        Fraction of the stability limit kept in reserve (:func:`~substructure.stability.recommend`).
    speed_tolerance : float, default 0.03
        The recommended speed stays stable within ``n (1 +- speed_tolerance)``.
    identify : "auto", None or sequence of str, default "auto"
        Joints to identify from the measurements: ``"auto"`` every elastic joint, None none.
    title : str, optional
        The title; default ``"Tool report: <assembly name>"``.
    notes : sequence of str, optional
        Lines saying what was taken from where, shown in the report (the command's).
    command : str, optional
        The command line that made the report, shown in it.
    progress : bool or callable, default False
        Report the steps (to standard error when True).
    tool_material : {"carbide", "hss"}, optional
        For the check of the cutting speed and feed; default the material of
        the assembly's tool when it is carbide or HSS, else carbide (said so).
    cutting_table : str or os.PathLike, optional
        A user's table of cutting-speed and feed ranges, searched first
        (:func:`~substructure.stability.load_cutting_data`).

    Returns
    -------
    Report
        The results; :meth:`Report.to_html` and :meth:`Report.save` present them.

    Raises
    ------
    substructure.errors.InvalidValueError
        For a model without a frequency grid, a tool point that is not translational, a margin
        or tolerance out of range, a method other than zoa or sdm, or a power or torque limit
        without the cut's feed per tooth.
    """
    import substructure

    from ..assembly import Assembly
    from ..measurements import MeasurementSet
    from ..stability import MachineLimits, MillingCut, TurningCut, recommend, spindle_speeds

    if progress is True:
        import sys

        def progress(text: str) -> None:  # noqa: F811 - a printer when asked for
            print(f"report: {text}", file=sys.stderr, flush=True)
    say = progress if callable(progress) else (lambda text: None)
    sources: list[tuple[str, str]] = []
    if isinstance(assembly, (str, os.PathLike)):
        from ..io.assembly_toml import load_assembly

        sources.append(("assembly", os.fspath(assembly)))
        assembly = load_assembly(assembly)
    elif not isinstance(assembly, Assembly):
        raise InvalidValueError(f"assembly: got {type(assembly).__name__}; expected an Assembly or the path of an "
                                "assembly file")
    if isinstance(measurements, (str, os.PathLike)):
        from ..io.measurements import load_measurements

        sources.append(("measurements", os.fspath(measurements)))
        measurements = load_measurements(measurements)
    elif measurements is not None and not isinstance(measurements, MeasurementSet):
        raise InvalidValueError(f"measurements: got {type(measurements).__name__}; expected a MeasurementSet or "
                                "the path of a measurement file")
    if not isinstance(method, str) or method not in ("zoa", "sdm"):
        raise InvalidValueError(f"method: got {method!r}; expected 'zoa' or 'sdm'")
    if title is not None and not isinstance(title, str):
        raise InvalidValueError(f"title: got {title!r}; expected a text or None (the default title)")
    if isinstance(notes, str) or not isinstance(notes, (list, tuple)) or not all(isinstance(n, str) for n in notes):
        raise InvalidValueError(f"notes: got {notes!r}; expected a list of texts (each a note of the report)")
    if cut is not None and not isinstance(cut, (MillingCut, TurningCut)):
        raise InvalidValueError(f"cut: got {type(cut).__name__}; expected a MillingCut or a TurningCut")
    if intervals is not None and method != "sdm":
        raise InvalidValueError("intervals: they set the semi-discretization; use them with method='sdm'")
    margin = _fraction(margin, "margin", 1.0)
    speed_tolerance = _fraction(speed_tolerance, "speed_tolerance", 0.5)
    if assembly.frequency is None:
        raise InvalidValueError(f"assembly {assembly.name!r} has no frequency grid ([frequency] in its file); the "
                                "report computes the tool point receptance on it")
    at = tool_point(assembly, at)
    joints = _joints_to_identify(assembly, identify) if measurements is not None else []
    if measurements is not None:
        measurements.validate(assembly)  # every point, sensor and component it names: before any work
    notes = list(notes)
    if measurements is not None:
        _tests_outside_the_grid(measurements.frequency, assembly.frequency, notes)
    say(f"tool point receptance at {at}")
    frf = assembly.receptance(at, frequency=assembly.frequency)
    structure, chosen = _structure(assembly, at, band, frf)
    modes, fit_error = _modes(structure, notes)
    tool = _tool_of(assembly, at)
    lobes = best = why = spread = robust = robust_why = shop = band_shop = None
    own = ()
    if cut is not None:
        milling = hasattr(cut, "radial_depth")
        if milling:
            if limits is None:
                depth = tool.flute_length if tool is not None else None
                limits = MachineLimits(max_depth=depth)
                if depth is not None:
                    notes.append(f"largest depth: the flute length {depth:~P} of the tool {tool.name!r}")
            elif not isinstance(limits, MachineLimits):
                raise InvalidValueError(f"limits: got {type(limits).__name__}; expected MachineLimits")
            if (limits.power is not None or limits.torque is not None) and cut.feed_per_tooth is None:
                raise InvalidValueError("feed_per_tooth: checking the spindle's power or torque needs the cut's feed "
                                        "per tooth (MillingCut(..., feed_per_tooth='0.1 mm'), --feed-per-tooth)")
            _cut_notes(cut, tool, notes)
        elif limits is not None:
            raise InvalidValueError("limits: the machine's limits are for the recommendation of a milling cut")
        speeds = spindle_speeds(*DEFAULT_SPEEDS) if speeds is None else speeds
        lobes = _lobes(structure, chosen, cut, speeds, method, intervals, say)
        if milling:
            say("recommendation")
            try:
                best = recommend(lobes, cut, limits, margin=margin, speed_tolerance=speed_tolerance)
            except InvalidValueError as exc:  # the lobes leave nothing to recommend: the report says why
                why = str(exc)
            spread, robust, robust_why, own = _joint_band(assembly, at, band, lobes, cut, limits, speeds, method,
                                                          intervals, margin, speed_tolerance, say)
            shop = _cutting(cut, best, tool, cutting_table, tool_material)
            band_shop = _cutting(cut, robust, tool, cutting_table, tool_material)
        else:
            why = "the recommendation of a speed and depth is for milling cuts; the lobes are shown"
    diagnosis = None
    identified, failed = [], []
    if measurements is not None:
        from ..diagnose import diagnose
        from ..identify import identify_joint

        say(f"diagnosis against {len(measurements)} measured FRF(s)")
        diagnosis = diagnose(assembly, measurements, progress=progress if callable(progress) else False)
        for name in joints:
            say(f"identification of joint {name!r}")
            try:
                identified.append(identify_joint(assembly, measurements, name))
            except SubstructureError as exc:
                failed.append((name, " ".join(str(exc).split())))
    created = datetime.datetime.now(datetime.timezone.utc).replace(microsecond=0).isoformat()
    return Report(
        title=title or f"Tool report: {assembly.name}", assembly=assembly, at=at, frf=frf, structure_band=chosen,
        modes=modes, modal_fit_error=fit_error, cut=cut, limits=limits if cut is not None else None, lobes=lobes,
        recommendation=best, no_recommendation=why, measurements=measurements, diagnosis=diagnosis,
        identifications=identified, identification_errors=failed, notes=notes, sources=sources, created=created,
        version=substructure.__version__, command=command, band=spread, band_recommendation=robust,
        band_no_recommendation=robust_why, band_depths_m=own, cutting=shop, band_cutting=band_shop)
