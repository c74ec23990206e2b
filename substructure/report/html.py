"""The report as one HTML page: plain words first, units everywhere, the technical names in small notes.

:func:`render` writes a page that opens in any browser without a server or a
network: the figures are PNG data inside it, the style sheet is inline, and
there is no script and no address outside the page (links are to its own
sections).  The markup is well-formed (every element closed, void elements
written ``<img ... />``, no named entities), so that it also parses as XML.
"""

from __future__ import annotations

import html
import re
from typing import Any

import numpy as np

from . import figures
from .shop import (_choice, _num, band_lines, band_table, cutting_lines, every_speed_line, lobes_caption,
                   provenance_note, provenance_table, provenance_warnings, readable)
from .style import STYLE
from .text import ENTRY_NAMES, EFFECT_NAMES, _number, assumptions, diagnosis_verdict, joint_findings

__all__ = ["render"]

_UNIT = {"N*m/rad": "N·m/rad", "N*s/m": "N·s/m", "N*s": "N·s", "N*s/rad": "N·s/rad", "N*m*s/rad": "N·m·s/rad",
         "kg*m^2": "kg·m²", "kg*m**2": "kg·m²", "N*m": "N·m"}
_UNITS = {"k": {"yf": "N/m", "ym": "N", "tf": "N/rad", "tm": "N·m/rad"},
          "c": {"yf": "N·s/m", "ym": "N·s", "tf": "N·s/rad", "tm": "N·m·s/rad"}}


# -- small pieces -------------------------------------------------------------------------------------


_NOT_XML = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\x7f-\x9f\ud800-\udfff\ufffe\uffff]")
"""Characters XML 1.0 forbids even as references (C0 controls but tab and line ends, lone surrogates, U+FFFE and
U+FFFF), with DEL and the C1 controls, which HTML calls errors."""


def clean(text: str) -> str:
    """Text with every character the page may not hold replaced by U+FFFD (shown, never dropped)."""
    return _NOT_XML.sub("\ufffd", text)


def esc(value: Any) -> str:
    """Text made safe for the page: markup escaped, control characters and lone surrogates as U+FFFD."""
    return html.escape(clean(str(value)), quote=True)


def unit(text: Any) -> str:
    """A unit as the page writes it (``N·m/rad``)."""
    text = str(text)
    return esc(_UNIT.get(text, text.replace("*", "·").replace("^2", "²").replace("**2", "²")))


def sci(value: Any, digits: int = 3) -> str:
    """A number with ``digits`` significant digits: plain from 0.001 to 99,999, else ``1.43 × 10<sup>7</sup>``."""
    v = _number(value)
    if v is None:
        return "–"
    if v == 0:
        return "0"
    v = float(f"{v:.{digits}g}")  # rounded to its significant digits
    exponent = int(np.floor(np.log10(abs(v))))
    if -3 <= exponent < 5:
        return esc(f"{v:,.{max(digits - 1 - exponent, 0)}f}")
    mantissa = f"{v / 10.0 ** exponent:.{digits - 1}f}"
    return f"{esc(mantissa)}&#8201;×&#8201;10<sup>{exponent}</sup>"


def quantity(value: Any, unit_text: str, digits: int = 3) -> str:
    """A value in an SI unit shown in the unit a machinist reads: kg below 1 kg in g, m below 1 m in mm."""
    v = _number(value)  # None, infinite or not a number: a dash
    if v is None:
        return f"– {unit(unit_text)}"
    if unit_text == "kg" and abs(v) < 1:
        return f"{sci(v * 1e3, digits)} g"
    if unit_text == "m" and abs(v) < 1:
        return f"{sci(v * 1e3, digits)} mm"
    return f"{sci(v, digits)} {unit(unit_text)}"


def fixed(value: Any, fmt: str, scale: float = 1.0) -> str:
    """``value * scale`` with a format (``",.0f"``), or a dash for none."""
    return _num(value, fmt, scale)  # a formatted number holds nothing to escape


def tech(text: str) -> str:
    """A technical name, in the small grey type of notes."""
    return f'<span class="tech">{esc(text)}</span>'


def note(markup: str) -> str:
    """A small note under a table or figure."""
    return f'<p class="note">{markup}</p>'


def table(headers: list[str], rows: list[list[str]], cls: str = "") -> str:
    """A table from markup cells (escaped by the caller)."""
    head = "".join(f"<th>{h}</th>" for h in headers)
    body = "".join("<tr>" + "".join(f"<td>{c}</td>" for c in row) + "</tr>" for row in rows)
    klass = f' class="{cls}"' if cls else ""
    return f"<table{klass}><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


def figure(uri: str, alt: str, caption: str) -> str:
    """An embedded figure with its caption (markup)."""
    return f'<figure><img src="{uri}" alt="{esc(alt)}" /><figcaption>{caption}</figcaption></figure>'


def section(ident: str, title: str, body: str) -> str:
    """A numbered section of the page."""
    return f'<section id="{ident}"><h2>{esc(title)}</h2>{body}</section>'


def mm(q: Any) -> str:
    """A length quantity in mm."""
    return fixed(q.m_as("mm"), ".4g")


def _matrix(owner: Any, kind: str, digits: int, sep: str) -> str:
    """The entries a joint or support gives of its stiffness (``kind`` "k") or damping ("c"), with units."""
    matrix = getattr(owner, kind)
    return sep.join(f"{tech(f'{kind}_{e}')} {sci(matrix.get(e), digits)} {_UNITS[kind][e]}" for e, _ in matrix.entries)


# -- the summary -------------------------------------------------------------------------------------


def _answer(report: Any) -> str:
    parts = []
    cut = report.cut
    # with joints of stated uncertainty, the answer is the speed and depth stable for all of them (shop.band_lines)
    r = report.recommendation if report.band_recommendation is None else report.band_recommendation
    if r is not None:
        until = "Until the joints are identified, run" if report.band_recommendation is not None else "Run"
        lines = [f'<p class="big">{until} at <strong>{fixed(r.spindle_speed_rpm, ",.0f")} rpm</strong> with an '
                 f"axial depth of cut of <strong>{fixed(r.depth_m, '.3g', 1e3)} mm</strong>.</p>"]
        what = f"{esc(_direction(cut))} milling, radial depth {mm(cut.radial_depth)} mm of {mm(cut.diameter)} mm, " \
               f"{cut.teeth} teeth"
        if cut.feed_per_tooth is not None:
            what += f", feed {fixed(cut.feed_per_tooth.m_as('mm'), '.3g')} mm per tooth"
        if getattr(cut, "workpiece", None) is not None:
            what += f", {esc(cut.workpiece.material or cut.workpiece.name)}"
        lines.append(f"<p>For {what}.</p>")
        lo, hi = r.window_rpm
        limit = fixed(r.limit_depth_m, ".3g", 1e3)
        lines.append(f"<p>Safety margin: the depth is {1 - r.reserve:.0%} of the chatter limit, {limit} mm, "
                     f"which is the lowest limit anywhere between {fixed(lo, ',.0f')} and {fixed(hi, ',.0f')} rpm "
                     f"(speed ±{r.speed_tolerance:.0%}){' for every variant of the joints' if until != 'Run' else ''};"
                     f" the depth is set by {esc(r.limited_by)}.</p>")
        lines += band_lines(report) + cutting_lines(report)
        if r.mrr_m3_per_s is not None:
            power = f"cutting power {fixed(r.power_w, '.2g', 1e-3)} kW"
            if np.isfinite(r.available_power_w):
                power += f" of {fixed(r.available_power_w, '.3g', 1e-3)} kW available"
            lines.append(f"<p>Removal rate {fixed(r.mrr_m3_per_s, '.3g', 6e7)} cm³/min, {power}.</p>")
        else:
            lines.append("<p>Give the feed per tooth for the removal rate and the cutting power.</p>")
        parts.append('<div class="answer">' + "".join(lines) + "</div>")
    elif cut is not None:
        parts.append(f'<div class="answer warn"><p class="big">No recommended speed and depth.</p>'
                     f"<p>{esc(report.no_recommendation)}</p></div>")
    else:
        parts.append('<div class="answer neutral"><p class="big">No cut was given.</p><p>Give the cut (radial '
                     "depth, work material or cutting coefficients) for the chatter-free speeds and depths and the "
                     "recommended operating point.</p></div>")
    facts = []
    if report.modes:
        worst = max(report.modes, key=lambda m: m.peak_m_per_n)
        facts.append(f"The tool tip is most flexible at <strong>{fixed(worst.frequency_hz, ',.0f')} Hz</strong>: "
                     f"{fixed(worst.peak_m_per_n, '.3g', 1e6)} µm per newton. That mode usually limits the cut.")
    if report.diagnosis is not None:
        kind, sentence = diagnosis_verdict(report.diagnosis.to_json())
        facts.append(f'<span class="verdict {kind}">Tap test: {esc(sentence)}</span>')
    for c in report.assembly.components:
        if "APPROXIMATE" in (getattr(c, "description", "") or ""):
            facts.append(f"The geometry of {esc(c.name)} is approximate (from the holder catalogue): check it.")
    facts += provenance_warnings(_provenances(report))
    if facts:
        parts.append("<ul class=\"facts\">" + "".join(f"<li>{f}</li>" for f in facts) + "</ul>")
    return "".join(parts)


# -- the model ---------------------------------------------------------------------------------------


def _segment_rows(component: Any) -> list[list[str]]:
    rows = []
    for i, s in enumerate(component.segments, 1):
        od = mm(s.od) + (f" → {mm(s.od_tip)}" if getattr(s, "od_tip", None) is not None else "")
        inner = mm(s.id) + (f" → {mm(s.id_tip)}" if getattr(s, "id_tip", None) is not None else "")
        inner = "solid" if inner == "0" else inner
        extra = []
        if s.insert is not None:
            extra.append(f"bore filled by {esc(s.insert.material.name)} (Ø {mm(s.insert.od)} mm)")
        if s.flutes is not None:
            extra.append(f"fluted (equivalent diameter {s.flutes.diameter_ratio:g} × outer)")
        if getattr(s, "od_tip", None) is not None:
            extra.append("tapered")
        rows.append([str(i), mm(s.length), od, inner, esc(s.material.name), ", ".join(extra) or "–"])
    return rows


def _model(report: Any) -> str:
    a = report.assembly
    kind = "on supports (as modelled)" if a.supports else "free-free (no supports: nothing holds it)"
    f = report.frf.frequency
    out = [f"<p><strong>{esc(a.name)}</strong>: {len(a.components)} parts joined by {len(a.joints)} joints, "
           f"{kind}. Results on {f.n:,} frequency lines from {f.hz[0]:.4g} to {f.hz[-1]:.5g} Hz.</p>"]
    rows = []
    for c in a.components:
        kind_name = getattr(c, "kind", type(c).__name__)
        if hasattr(c, "segments"):
            rows.append([esc(c.name), esc(kind_name), mm(c.length), fixed(c.mass(), ".3g"), str(len(c.segments)),
                         esc((c.description or "").split(". ")[0].rstrip(".")) or "–"])
        else:
            rows.append([esc(c.name), esc(kind_name), "–", "–", "–", "measured or built in code"])
    out.append(table(["Part", "Kind", "Length (mm)", "Mass (kg)", "Segments", "Description"], rows))
    for c in a.components:
        if not hasattr(c, "segments"):
            continue
        title = f"<h3>{esc(c.name)}: segments from base to tip</h3>"
        extra = ""
        if hasattr(c, "teeth"):
            bits = [f"{c.teeth} teeth" if c.teeth is not None else "teeth not given",
                    f"cutting diameter {mm(c.cutting_diameter)} mm"]
            if c.flute_length is not None:
                bits.append(f"flute length {mm(c.flute_length)} mm")
            if getattr(c, "helix", None) is not None:
                bits.append(f"helix {fixed(c.helix.m_as('deg'), '.3g')}°")
            extra = f"<p>Tool: {', '.join(bits)}.</p>"
        desc = note(esc(c.description)) if c.description else ""
        out.append(title + extra + table(["#", "Length (mm)", "Outer Ø (mm)", "Inner Ø (mm)", "Material", "Notes"],
                                         _segment_rows(c)) + desc)
    materials = {}
    for c in a.components:
        for s in getattr(c, "segments", ()):
            materials.setdefault(s.material.name, s.material)
            if s.insert is not None:
                materials.setdefault(s.insert.material.name, s.insert.material)
    rows = [[esc(m.name), fixed(m.E.m_as("GPa"), ".4g"), fixed(m.nu, ".3g"), fixed(m.rho.m_as("kg/m^3"), ".5g"),
             fixed(m.loss_factor, ".3g")] for m in materials.values()]
    out.append("<h3>Materials</h3>" + table(["Material", "Young's modulus E (GPa)", "Poisson's ratio",
                                              "Density (kg/m³)", "Loss factor"], rows))
    rows = []
    for j in a.joints:
        values = (["rigid", "–"] if getattr(j, "rigid", False) or not hasattr(j, "k")
                  else [_matrix(j, "k", 4, "<br />"), _matrix(j, "c", 4, "<br />") or "none"])
        rows.append([esc(j.name), esc(f"{j.between[0]} – {j.between[1]}")] + values)
    out.append("<h3>Joints</h3>" + (table(["Joint", "Connects", "Stiffness", "Damping"], rows)
                                    + note('Their uncertainty: <a href="#joints">the joints</a>.')
                                    if rows else "<p>None.</p>"))
    if a.supports:
        rows = [[esc(s.name or "–"), esc(s.at), _matrix(s, "k", 3, ", ") or "–", _matrix(s, "c", 3, ", ") or "–"]
                for s in a.supports]
        out.append("<h3>Supports (springs to the ground)</h3>" + table(["Name", "At", "Stiffness", "Damping"], rows))
    if a.sensors:
        rows = [[esc(s.name), esc(s.at), fixed(s.mass.m_as("g"), ".3g"), sci(s.inertia.m_as("kg*m^2"))]
                for s in a.sensors]
        out.append("<h3>Sensors</h3>" + table(["Sensor", "At", "Mass (g)", "Rotary inertia (kg·m²)"], rows)
                   + note("Sensors of the model file are on the structure in every result of this report."))
    return "".join(out)


# -- the tool point ------------------------------------------------------------------------------------


def _tool_point(report: Any) -> str:
    out = [figure(figures.tool_point_figure(report), "tool point receptance",
                  "How far the tool tip moves per newton of force, against frequency (top: size in µm/N, "
                  "bottom: phase). Peaks are modes: there the tool vibrates easily. "
                  + tech(f"Receptance H = y/F at {report.at}, the driving point FRF of the model."))]
    band = report.structure_band
    if report.modes:
        worst = max(report.modes, key=lambda m: m.peak_m_per_n)
        rows = [[("<strong>" if m is worst else "") + fixed(m.frequency_hz, ",.0f")
                 + ("</strong>" if m is worst else ""),
                 fixed(m.peak_m_per_n, ".3g", 1e6), fixed(m.damping_ratio, ".2g", 100.0),
                 fixed(m.stiffness_n_per_m, ".3g", 1e-6)]
                for m in report.modes]
        out.append("<h3>Modes</h3>" + table(["Frequency (Hz)", "Peak (µm/N)", "Damping (% of critical)",
                                             "Modal stiffness (N/µm)"], rows))
        where = f" between {band.lo_hz:.4g} and {band.hi_hz:.5g} Hz" if band is not None else ""
        fit = (f"; the modes alone miss the receptance by {report.modal_fit_error:.1%}"
               if report.modal_fit_error is not None else "")
        out.append(note(f"Modes fitted to the receptance{where}{fit}. The strongest is in bold. "
                        + tech("single-degree-of-freedom modes with residual terms, ModalFitter")))
    else:
        out.append("<p>No mode stands out of the receptance in the band used.</p>")
    if band is not None:
        out.append(note(f"Band used for stability: {band.lo_hz:.5g} to {band.hi_hz:.5g} Hz. {esc(band.reason)}. "
                        + tech(f"structure band, kind {band.kind}")))
    return "".join(out)


# -- the diagnosis -------------------------------------------------------------------------------------


def _params(parameters: Any) -> str:
    bits = []
    for name, spec in (parameters or {}).items():
        spec = spec if isinstance(spec, dict) else {"value": spec}
        u = str(spec.get("unit", ""))
        text = f"{tech(name)} {quantity(spec.get('value'), u, 4)}"
        if spec.get("std") is not None:
            text += f" ± {quantity(spec.get('std'), u, 2)}"
        if spec.get("nominal") is not None:
            text += f" (model: {quantity(spec.get('nominal'), u, 4)})"
        bits.append(text)
    return "<br />".join(bits) or "–"


# "settings" (every threshold and grid the diagnosis ran with) is there to reproduce it, not for the reader
_SHOWN = {"metric", "baseline_error", "noise_floor", "missing_effect", "ambiguous_with", "candidates", "refinement",
          "missing_where", "suggestion", "band_hz", "final_error", "final_effects", "modes", "error_bands_hz",
          "explained", "settings", "equivalents"}


def _diagnosis(report: Any) -> str:
    d = report.diagnosis
    data = d.to_json()
    kind, sentence = diagnosis_verdict(data)
    floor = data.get("noise_floor")
    out = [f'<p class="verdict {kind}">{esc(sentence)}</p>']
    n = len(report.measurements) if report.measurements is not None else 0
    band = data.get("band_hz") or [None, None]
    out.append(f"<p>{n} measured FRF(s), compared from {fixed(band[0], '.6g')} to {fixed(band[1], '.6g')} Hz. "
               f"The model as given is off by {sci(data.get('baseline_error'))}; the test's own scatter (noise floor) "
               f"is {sci(floor)}; with what the diagnosis added, the model is off by {sci(data.get('final_error'))}"
               + (f" ({float(data['final_error']) / float(floor):.2g} × the noise floor)"
                  if isinstance(floor, (int, float)) and floor and data.get("final_error") is not None else "")
               + ". " + tech(f"{data.get('metric', 'rms_log_ratio')}: RMS of |ln(H_model / H_measured)| over "
                             "the lines; 0.01 is about 1 %") + "</p>")
    where, fall = figures.diagnosis_figures(d)
    out.append("<h3>Where the model fails</h3>"
               + figure(where, "model against measurement", "The first measurement (grey) and the model as given "
                        "(blue); the bottom panel shows the difference, and the shaded bands carry most of it. "
                        + tech("log-ratio residual, error bands, paired modes with their shift")))
    modes = [m for m in data.get("modes") or [] if isinstance(m, dict)]
    if modes:
        rows = [[fixed(m.get("measured_hz"), ",.0f"), fixed(m.get("model_hz"), ",.0f"),
                 fixed(m.get("shift_hz"), "+,.0f"), fixed(m.get("amplitude_ratio"), ".2f")] for m in modes]
        out.append(table(["Measured (Hz)", "Model (Hz)", "Model − measured (Hz)", "Model peak / measured peak"], rows))
    bands = data.get("error_bands_hz") or []
    if bands:
        out.append(note("Most of the difference lies in " + ", ".join(
            f"{fixed(b[0], ',.0f')}–{fixed(b[1], ',.0f')} Hz ({fixed(b[2], '.0%')})" for b in bands if len(b) == 3)
            + "."))
    effects = [e for e in data.get("final_effects") or [] if isinstance(e, dict)]
    explanations = {(c.get("effect"), c.get("where")): c.get("explanation") for c in data.get("candidates") or []
                    if isinstance(c, dict)}
    if effects:
        rows = [[esc(EFFECT_NAMES.get(str(e.get("effect")), e.get("effect"))) + "<br />" + tech(str(e.get("effect"))),
                 esc(e.get("where")), _params(e.get("parameters")),
                 esc(explanations.get((e.get("effect"), e.get("where"))) or "–")] for e in effects]
        out.append("<h3>What the model misses</h3>" + table(["Effect", "Where", "Values (± 1 standard deviation "
                                                             "where given)", "Why it fits"], rows))
    if data.get("ambiguous_with"):
        out.append(f"<p>Equally possible: {esc(', '.join(map(str, data['ambiguous_with'])))}. To tell them apart: "
                   f"{esc(data.get('suggestion') or '')}</p>")
    for q in [q for q in data.get("equivalents") or [] if isinstance(q, dict)]:
        of = q.get("of")
        kept = effects[of] if isinstance(of, int) and 0 <= of < len(effects) else {}
        out.append(f"<p>As well as {esc(kept.get('effect', '?'))} at {esc(kept.get('where', '?'))}, the data allow "
                   f"{esc(q.get('effect'))} at {esc(q.get('where'))} ({_params(q.get('parameters'))}): the same part "
                   "changed another way, which this test cannot tell apart.</p>")
    steps = [s for s in data.get("refinement") or [] if isinstance(s, dict)]
    out.append("<h3>The error falling as effects are added</h3>"
               + figure(fall, "error fall", "The model's error after each step, against the noise floor (the "
                        "closest any model can come to this test)."))
    if steps:
        rows = [[str(s.get("step")), "model as given" if s.get("added") is None
                 else f"+ {esc(s.get('added'))} at {esc(s.get('where'))}", sci(s.get("error"), 3),
                 _params(s.get("parameters")) if s.get("parameters") else "–"] for s in steps]
        out.append(table(["Step", "Added", "Error", "Values at that step"], rows))
    cands = [c for c in data.get("candidates") or [] if isinstance(c, dict)][:6]
    if cands:
        rows = [[esc(c.get("effect")), esc(c.get("where")), sci(c.get("error"), 3), _params(c.get("parameters"))]
                for c in cands]
        out.append("<h3>The best candidates</h3>" + table(["Effect", "Where", "Error after the fit", "Values"], rows)
                   + note("Every effect the diagnosis knows, fitted at every place it can act; the best first."))
    other = {k: v for k, v in data.items() if k not in _SHOWN}
    if other:
        rows = [[esc(str(k).replace("_", " ")) + " " + tech(k), readable(v)] for k, v in other.items()]
        out.append("<h3>More from the diagnosis</h3>" + table(["Key", "Value"], rows, cls="small"))
    return "".join(out)


# -- stability -------------------------------------------------------------------------------------------


def _row(label: str, r: Any) -> list[str]:
    return _choice(label, r) + [esc(r.limited_by), fixed(r.mrr_m3_per_s, ".3g", 6e7), fixed(r.power_w, ".2g", 1e-3),
                                fixed(r.torque_n_m, ".3g"), fixed(r.chatter_frequency_hz, ",.0f")]


def _stability(report: Any) -> str:
    lobes, r, cut = report.lobes, report.recommendation, report.cut
    banded = report.band_recommendation is not None  # then the answer is the band's (see _answer)
    r = report.band_recommendation if banded else r
    out = []
    if r is not None:
        head = "<strong>recommended</strong>" + (" for every variant of the joints" if banded else "")
        rows = [_row(head, r)] + [_row(f"runner-up {k}", o) for k, o in enumerate(r.runners_up, 1)]
        out.append(table(["Choice", "Speed (rpm)", "Axial depth (mm)", "Chatter limit in the window (mm)",
                          "Speed window (rpm)", "Depth set by", "Removal rate (cm³/min)", "Power (kW)",
                          "Torque (N·m)", "Chatter at (Hz)"], rows, cls="wide"))
        out.append(note(f"The depth is at most {1 - r.margin:.0%} of the lowest chatter limit over the speed window "
                        f"(±{r.speed_tolerance:.0%}){' of every variant' if banded else ''}; the limit at the "
                        f"recommended speed itself is {fixed(r.limit_at_speed_m, '.3g', 1e3)} mm"
                        f"{' with the nominal joints' if banded else ''}. Runners-up are the best of other pockets of "
                        "the diagram. " + tech(f"margin {r.margin:g}, speed_tolerance {r.speed_tolerance:g}, "
                                               f"reserve {r.reserve:.3f}, "
                                               f"limiting speed {r.limiting_speed_rpm:.0f} rpm")))
    elif report.no_recommendation:
        out.append(f'<p class="verdict unexplained">No recommendation: {esc(report.no_recommendation)}</p>')
    out.append(band_table(report))
    out.append(figure(figures.lobes_figure(report), "stability lobes",
                      f"{lobes_caption(report)} The star is the recommended speed and "
                      "depth, the green box its safe window, the dashed line the limit it keeps its margin from. "
                      + tech("stability lobe diagram; " + ("zero-order approximation (Altintas & Budak 1995)"
                                                           if lobes.method == "zoa" else
                                                           "semi-discretization (Insperger & Stépán 2004)"))))
    if hasattr(cut, "radial_depth"):
        wp = getattr(cut, "workpiece", None)
        rows = [["Teeth", str(cut.teeth)], ["Tool diameter", f"{mm(cut.diameter)} mm"],
                ["Radial depth of cut", f"{mm(cut.radial_depth)} mm ({cut.immersion:.0%} of the diameter)"],
                ["Direction", f"{esc(_direction(cut))} milling"],
                ["Feed per tooth", "not given" if cut.feed_per_tooth is None
                 else f"{fixed(cut.feed_per_tooth.m_as('mm'), '.3g')} mm"],
                ["Work material", "not named (coefficients given)" if wp is None
                 else esc(f"{wp.material or wp.name} ({wp.name})")],
                ["Cutting coefficients", f"tangential {fixed(cut.kt_pa, '.4g', 1e-6)} MPa, radial "
                 f"{fixed(cut.kn_pa, '.4g', 1e-6)} MPa " + tech("Kt, Kn (Kn/Kt = " + f"{cut.kr:.3g})")]]
        out.append("<h3>The cut</h3>" + table(["", ""], rows, cls="keyvalue"))
        if wp is not None:
            out.append(note("Source: " + esc(wp.source)))
    else:
        out.append(f"<h3>The cut</h3><p>{esc(cut.describe())}</p>")
    if report.limits is not None:
        m = report.limits.to_json()

        def show(value: Any, scale: float, fmt: str, name: str) -> str:
            if value is None:
                return "no limit given"
            if isinstance(value, dict):
                pts = zip(value.get("spindle_speed_rpm", []), value.get("values", []))
                return "curve: " + ", ".join(f"{fixed(n, ',.0f')} rpm: {fixed(v, fmt, scale)} {name}" for n, v in pts)
            return f"{fixed(value, fmt, scale)} {name}"

        rows = [["Highest speed", show(m.get("max_speed_rpm"), 1, ",.0f", "rpm")],
                ["Lowest speed", show(m.get("min_speed_rpm"), 1, ",.0f", "rpm")],
                ["Spindle power", show(m.get("power_w"), 1e-3, ".3g", "kW")],
                ["Spindle torque", show(m.get("torque_n_m"), 1, ".3g", "N·m")],
                ["Largest axial depth", show(m.get("max_depth_m"), 1e3, ".3g", "mm")]]
        out.append("<h3>The machine</h3>" + table(["", ""], rows, cls="keyvalue"))
    tips = lobes.best_speeds(3)
    if tips:
        speeds = lobes.spindle_speed_rpm
        rows = [[fixed(n, ",.0f"), fixed(a, ".3g", 1e3),
                 fixed(lobes.chatter_frequency_hz[int(np.argmin(np.abs(speeds - n)))], ",.0f")] for n, a in tips]
        heading = "The tips of the lobes" + (" (nominal joints)" if report.band is not None else "")
        out.append(f"<h3>{heading}</h3>" + table(["Speed (rpm)", "Chatter limit (mm)", "Chatter at (Hz)"], rows)
                   + note("The limit itself, with no margin: a speed at the sharp tip of a lobe is stable only "
                          "right there. Use the recommendation above."))
    out.append(every_speed_line(report, tech("absolute limit of the zero-order lobes")))
    s = lobes.spindle_speed_rpm
    out.append(note(f"Spindle speeds {fixed(s[0], ',.0f')} to {fixed(s[-1], ',.0f')} rpm, {s.size:,} speeds."))
    return "".join(out)


# -- joints --------------------------------------------------------------------------------------------------


def _entry(value: Any, std: Any, units: str) -> str:
    text = sci(value, 4)
    if std is not None and float(std) > 0:
        text += f" ± {sci(std, 2)}"
        if value:
            text += f' <span class="tech">({abs(float(std) / float(value)) * 100:.2g} %)</span>'
    return f"{text} {units}"


def _joints(report: Any) -> str:
    data = None if report.diagnosis is None else report.diagnosis.to_json()
    identified = {r.joint: r for r in report.identifications}
    failed = dict(report.identification_errors)
    out = ["<p>A joint is where two parts meet (spindle and holder, holder and tool); its stiffness and damping "
           "often decide the tool's modes. The model file gives one value per entry, and may say where it comes "
           "from and how uncertain it is (the table below); the tap test gives values with a standard deviation "
           "(68 % of repeated tests fall within ± 1).</p>",
           provenance_table(_provenances(report))]
    if report.identifications and data is not None and diagnosis_verdict(data)[0] != "agrees":
        out.append('<p class="verdict unexplained">Caution: the diagnosis found that the model as given does not '
                   "agree with the tap test. The identified values absorb what the model misses, and their standard "
                   "deviations do not include it: read them with care.</p>")
    for j in report.assembly.joints:
        if getattr(j, "rigid", False) or not hasattr(j, "k"):
            out.append(f"<h3>{esc(j.name)}: rigid</h3><p>{esc(j.between[0])} – {esc(j.between[1])}: modelled as "
                       "rigid (no values).</p>")
            continue
        ident = identified.get(j.name)
        found = {f["parameter"]: f for f in joint_findings(data, j.name)}
        tapped = ident is not None or j.name in failed
        headers = ["Entry", "In the model"]
        if tapped:
            headers.append("Identified from the tap test")
        if found:
            headers.append("Found by the diagnosis")
        rows = []
        for kind, units in _UNITS.items():
            for e, plain in ENTRY_NAMES.items():
                model = getattr(j, kind).get(e)
                fitted = ident is not None and (f"{kind}_{e}" in ident.fitted
                                                or (e == "tf" and f"{kind}_ym" in ident.fitted))
                if model == 0 and not fitted and f"{kind}_{e}" not in found:
                    continue
                what = "stiffness" if kind == "k" else "damping"
                row = [f"{what}, {plain} {tech(f'{kind}_{e}')}", f"{sci(model, 4)} {units[e]}"]
                if tapped:
                    if ident is None:
                        row.append("–")
                    elif fitted:
                        name = f"{kind}_ym" if e == "tf" else f"{kind}_{e}"
                        side = getattr(ident, "at_bound", {}).get(name)
                        row.append(_entry(getattr(ident, kind)[e], getattr(ident, f"{kind}_std")[e], units[e])
                                   + ("" if side is None else f" (on the {side} bound of its search: not a "
                                                              "measurement)"))
                    else:
                        row.append("kept from the model")
                if found:
                    f = found.get(f"{kind}_{e}")
                    row.append("–" if f is None else _entry(f["value"], f["std"], unit(f["unit"])))
                rows.append(row)
        out.append(f"<h3>{esc(j.name)}</h3><p>{esc(j.between[0])} – {esc(j.between[1])}.</p>" + table(headers, rows))
        out.append(provenance_note(j, _provenances(report)))
        if ident is not None:
            lo, hi = ident.band
            out.append(note(f"Identified over {lo:.6g}–{hi:.6g} Hz from every FRF measured with the joint in place; "
                            f"relative residual {ident.residual_rms:.3g}. "
                            + tech("band fit of constant k and c, standard deviations from the Jacobian")))
            for w in ident.warnings:
                out.append(note("Note: " + esc(w)))
            out.append(figure(figures.identification_figure(ident), f"identification of {j.name}",
                              f"Joint {esc(j.name)}: the measured FRF with the model before and after the fit."))
        elif j.name in failed:
            out.append(note("Not identified: " + esc(failed[j.name])))
    return "".join(out)


def _provenances(report: Any) -> list[dict]:
    from ..joint_priors import joint_provenances

    return joint_provenances(report.assembly)


def _direction(cut: Any) -> str:
    return f"{cut.milling} ({'conventional' if cut.milling == 'up' else 'climb'})"


# -- the page ----------------------------------------------------------------------------------------------


def render(report: Any) -> str:
    """The whole page.

    Parameters
    ----------
    report : Report
        The results.

    Returns
    -------
    str
        The HTML document.
    """
    sections = [("answer", "At a glance", _answer(report))]
    if report.lobes is not None:
        sections.append(("stability", "Chatter-free cutting: speed and depth", _stability(report)))
    sections.append(("tool-point", "The tool point: how the tool vibrates", _tool_point(report)))
    if report.diagnosis is not None:
        sections.append(("diagnosis", "The tap test: does the model agree?", _diagnosis(report)))
    sections.append(("joints", "The joints and their uncertainty", _joints(report)))
    sections.append(("model", "The model", _model(report)))
    items = "".join(f"<li>{esc(a)}</li>" for a in assumptions(report))
    sections.append(("assumptions", "Assumptions and limits", f"<ul>{items}</ul>"))
    made = [f"substructure {esc(report.version)}, {esc(report.created)}"]
    made += [f"{esc(kind)}: {esc(path)}" for kind, path in report.sources]
    if report.command:
        made.append(f"command: <code>{esc(report.command)}</code>")
    notes = "".join(f"<li>{esc(n)}</li>" for n in report.notes)
    sections.append(("made", "How this report was made",
                     "<ul>" + "".join(f"<li>{m}</li>" for m in made) + "</ul>"
                     + (f"<h3>Taken from the inputs</h3><ul>{notes}</ul>" if notes else "")))
    toc = "".join(f'<li><a href="#{i}">{esc(t)}</a></li>' for i, t, _ in sections)
    body = "".join(section(i, t, b) for i, t, b in sections)
    page = ("<!DOCTYPE html>\n"
            '<html lang="en"><head><meta charset="utf-8" />'
            '<meta name="viewport" content="width=device-width, initial-scale=1" />'
            f"<title>{esc(report.title)}</title><style>{STYLE}</style></head>"
            f'<body><header><h1>{esc(report.title)}</h1><p class="meta">Made by substructure {esc(report.version)} on '
            f"{esc(report.created)}. This page holds everything in itself: it opens in any browser, offline.</p>"
            f'<nav><ol>{toc}</ol></nav></header><main>{body}</main></body></html>\n')
    return clean(page)  # a name with a control character or a lone surrogate: U+FFFD, the page stays XML
