"""The parts of the report a machinist checks before trusting a number: cutting data, the stability band, where the
joint values come from, and the diagnosis's further results as readable text.

Each function returns HTML for :mod:`substructure.report.html` to place; like
it, they compute nothing and only present what :func:`~substructure.report.report`
returned.
"""

from __future__ import annotations

import html
import math
from typing import Any

from ..errors import InvalidValueError

__all__ = ["cutting_lines", "band_lines", "band_table", "depth_order", "every_speed_line", "lobes_caption",
           "provenance_note", "provenance_table", "provenance_warnings", "readable"]


def _esc(value: Any) -> str:
    return html.escape(str(value), quote=True)


def _num(value: Any, fmt: str, scale: float = 1.0) -> str:
    try:
        v = float(value) * scale
    except (TypeError, ValueError, OverflowError):
        return "–"
    return format(v, fmt) if math.isfinite(v) else "–"


def _choice(label: str, r: Any) -> list[str]:
    """A recommendation's first cells: the label, speed (rpm), depth and chatter limit (mm), speed window (rpm)."""
    lo, hi = r.window_rpm
    return [label, _num(r.spindle_speed_rpm, ",.0f"), _num(r.depth_m, ".3g", 1e3), _num(r.limit_depth_m, ".3g", 1e3),
            f"{_num(lo, ',.0f')}–{_num(hi, ',.0f')}"]


def cutting_lines(report: Any) -> list[str]:
    """Paragraphs for the answer: cutting speed (m/min, SFM), feed per tooth and feed rate, checked against the
    usual range; the milling direction in the shop's words.

    Parameters
    ----------
    report : Report
        The report.

    Returns
    -------
    list of str
        HTML paragraphs (none without a recommendation), for the answer's speed: the stability band's when
        there is one, else the nominal one.
    """
    r, c = report.recommendation, report.cutting
    if report.band_recommendation is not None:
        r, c = report.band_recommendation, report.band_cutting
    if r is None or r.cutting_speed_m_per_min is None:
        return []
    vc = r.cutting_speed_m_per_min
    text = (f"Cutting speed <strong>{_num(vc, ',.0f')} m/min</strong> ({_num(vc / 0.3048, ',.0f')} SFM)")
    if r.feed_per_tooth_m is not None:
        text += (f", feed <strong>{_num(r.feed_per_tooth_m, '.3g', 1e3)} mm per tooth</strong>, feed rate "
                 f"{_num(r.feed_rate_m_per_min, ',.0f', 1e3)} mm/min")
    out = [f'<p class="cutting-data">{text}.</p>']
    if c is not None and c.get("range") is not None:
        row = c["range"]
        lo, hi = row["cutting_speed_m_per_min"]
        flo, fhi = row["feed_per_tooth_m"]
        usual = (f"The usual range for {_esc(row['workpiece'])} with a {_esc(row['tool_material'])} tool: "
                 f"{_num(lo, ',.0f')} to {_num(hi, ',.0f')} m/min, {_num(flo, '.3g', 1e3)} to {_num(fhi, '.3g', 1e3)} "
                 f"mm per tooth ({_esc(row['source'].split(';')[0])}).")
        if c.get("warnings"):
            out.append('<p class="verdict unexplained">Outside the usual cutting data: '
                       + "; ".join(_esc(w) for w in c["warnings"]) + ". " + usual
                       + " Check with your tool maker's data before you run it.</p>")
        else:
            out.append(f"<p>{usual}</p>")
    return out


def band_lines(report: Any) -> list[str]:
    """Paragraphs for the answer: the depth stable across the joints' uncertainty next to the nominal one.

    Parameters
    ----------
    report : Report
        The report.

    Returns
    -------
    list of str
        HTML paragraphs (none without a band).
    """
    if report.band is None or report.recommendation is None:
        return []
    n = len(report.band.members)
    robust = report.band_recommendation
    if robust is None:
        return [f'<p class="verdict unexplained">Across the uncertainty of the joints ({n} variants) no speed and '
                f"depth is stable with the margin: {_esc(report.band_no_recommendation)}</p>"]
    r = report.recommendation
    return [f'<p class="band">Stability band: with every joint anywhere within its stated uncertainty ({n} '
            f"variants), <strong>{_num(robust.spindle_speed_rpm, ',.0f')} rpm at "
            f"{_num(robust.depth_m, '.3g', 1e3)} mm</strong> stays stable with the same margin. The nominal joint "
            f"values alone give {_num(r.spindle_speed_rpm, ',.0f')} rpm at {_num(r.depth_m, '.3g', 1e3)} mm, which "
            "holds only if the joints are exactly as the model says: identify them (tap test) before you run "
            "deeper than the band's depth.</p>"] + _open_lines(report)


def _open_lines(report: Any) -> list[str]:
    span = report.depth_range_m
    if not report.band_depths_m or span is None:
        return []
    return [f'<p class="band">Each variant alone, its joints taken as known, would recommend from '
            f"<strong>{_num(span[0], '.3g', 1e3)} to {_num(span[1], '.3g', 1e3)} mm</strong>: the data leave the "
            "depth that open (each at its own best speed: the band's depth is smaller because one speed must suit "
            "every variant). Against another holder or tool whose range overlaps this one, the order of the "
            "recommended depths is <strong>not decided by the data</strong>; tap-test both to rank them.</p>"]


def every_speed_line(report: Any, technical: str = "") -> str:
    """The depth stable at every speed: the nominal lobes' and, with a band, the lowest over its variants.

    Parameters
    ----------
    report : Report
        The report (with lobes).
    technical : str
        HTML of the technical name, appended.

    Returns
    -------
    str
        An HTML paragraph (empty when the lobes have no finite limit).
    """
    lobes = report.lobes
    if lobes.absolute_limit_m is None or not math.isfinite(lobes.absolute_limit_m):
        return ""
    nominal = "With the nominal joints, stable" if report.band is not None else "Stable"
    lowest = [v for v in (report.band.lower_m if report.band is not None else ()) if math.isfinite(v)]
    across = (f" With every variant of the joints, stable at every computed speed up to "
              f"{_num(min(lowest), '.3g', 1e3)} mm." if lowest else "")
    return (f"<p>{nominal} at every speed up to {_num(lobes.absolute_limit_m, '.3g', 1e3)} mm axial depth (chatter "
            f"there at {_num(lobes.absolute_limit_frequency_hz, ',.0f')} Hz).{across} {technical}</p>")


def lobes_caption(report: Any) -> str:
    """The first sentence of the lobe figure's caption: which curve is stable for which joints.

    Parameters
    ----------
    report : Report
        The report.

    Returns
    -------
    str
        Plain text.
    """
    if report.band is not None:
        return ("Below the blue curve the cut is stable with the nominal joints, below the purple line with every "
                "variant of the joints; above, it may chatter.")
    return "Below the curve the cut is stable, above it chatters."


def depth_order(first: Any, second: Any, names: tuple[str, str] = ("the first", "the second")) -> dict:
    """Whether the joints' uncertainty decides which of two assemblies (two holders for one tool) allows the
    larger recommended depth.

    Each report's range of recommended depths (``Report.depth_range_m``:
    every variant of its joints within their stated uncertainty, each taken
    as known) is compared: when the ranges overlap, the order is not decided
    by the data; when they do not, every variant of one lies above every
    variant of the other.

    Parameters
    ----------
    first, second : Report
        Reports of the same cut, each with a recommendation (a report
        without a stability band counts as its nominal depth alone).
    names : (str, str)
        How the two are called in the sentence (the holders' names).

    Returns
    -------
    dict
        ``order`` (``"first"`` or ``"second"``, the one with the larger
        depth, or None when the data do not decide), ``ranges_m`` (the two
        ranges of depth, m) and ``text`` (one sentence).
    """
    ranges = [r.depth_range_m for r in (first, second)]
    if any(span is None for span in ranges):
        raise InvalidValueError("depth_order: both reports need a recommended depth (a milling cut and a "
                                "recommendation)")
    (lo1, hi1), (lo2, hi2) = ranges
    shown = [f"{_num(lo, '.3g', 1e3)} to {_num(hi, '.3g', 1e3)} mm" for lo, hi in ranges]
    if lo1 > hi2 or lo2 > hi1:
        order = "first" if lo1 > hi2 else "second"
        big, small = names if order == "first" else names[::-1]
        text = (f"{big} allows a larger depth than {small} for every variant of the joints within their stated "
                f"uncertainty ({shown[0]} against {shown[1]}).")
        text = text[0].upper() + text[1:]
    else:
        order = None
        text = (f"The order of the recommended depths of {names[0]} ({shown[0]}) and {names[1]} ({shown[1]}) is not "
                "decided by the data: their ranges over the joints' uncertainty overlap; identify the joints (tap "
                "test) to rank them.")
    return {"order": order, "ranges_m": [[float(lo), float(hi)] for lo, hi in ranges], "text": text}


def band_table(report: Any) -> str:
    """A table of the nominal recommendation and the one across the stability band.

    Parameters
    ----------
    report : Report
        The report.

    Returns
    -------
    str
        HTML (empty without a band).
    """
    if report.band is None or report.recommendation is None:
        return ""
    rows = [("nominal joints", report.recommendation), ("across the stability band", report.band_recommendation)]
    body = ""
    for label, r in rows:
        if r is None:
            body += f"<tr><td>{label}</td><td colspan=\"4\">{_esc(report.band_no_recommendation or 'none')}</td></tr>"
        else:
            body += "<tr>" + "".join(f"<td>{cell}</td>" for cell in _choice(label, r)) + "</tr>"
    head = ("<tr><th>Joints</th><th>Speed (rpm)</th><th>Axial depth (mm)</th><th>Chatter limit in the window (mm)"
            "</th><th>Speed window (rpm)</th></tr>")
    lower = report.band.lower_m
    finite = lower[[math.isfinite(v) for v in lower]]
    low = f" The lowest limit over the band is {_num(min(finite), '.3g', 1e3)} mm." if finite.size else ""
    span = report.depth_range_m
    own = (f" Each variant's own recommendation (its joints taken as known) lies between {_num(span[0], '.3g', 1e3)} "
           f"and {_num(span[1], '.3g', 1e3)} mm." if report.band_depths_m and span is not None else "")
    return ("<h3>The stability band: the joints within their uncertainty</h3>"
            f'<table class="wide"><thead>{head}</thead><tbody>{body}</tbody></table>'
            f'<p class="note">The lobes were computed for {len(report.band.members)} variants of the model, each joint '
            "with a stated uncertainty at its lower end, nominal value and upper end (stiffness and damping "
            f"together); the band's recommendation holds its margin for every one of them.{low}{own}</p>")


def provenance_note(joint: Any, rows: list[dict]) -> str:
    """Where a joint's values come from, one paragraph.

    Parameters
    ----------
    joint : Joint
        The joint.
    rows : list of dict
        :func:`~substructure.joint_priors.joint_provenances` of the report's assembly.

    Returns
    -------
    str
        HTML.
    """
    row = next((r for r in rows if r["name"] == joint.name), None)
    if row is None:
        return ""
    kind = row["kind"]
    plain = {"identified": "identified from a tap test", "predicted": "predicted from a joint table",
             "borrowed": "borrowed from another holder", "prior": "a prior for this type of holder",
             "not stated": "not stated"}.get(kind, kind)
    spread = (f"; within a factor {row['uncertainty']:g} either way" if row["uncertainty"] is not None else
              "; no uncertainty stated")
    text = f'<p class="provenance">Where the values come from: <strong>{_esc(plain)}</strong>{spread}'
    text += " (the source in the table above).</p>" if row["source"] else ".</p>"
    if row["warning"]:
        text += f'<p class="verdict unexplained">{_esc(row["warning"])}.</p>'
    return text


_PLAIN = {"identified": "Measured: identified from a tap test of this assembly",
          "predicted": "Predicted from a joint table", "borrowed": "Borrowed from another holder or tool",
          "not stated": "Not stated"}
_ROLES = {"holder-tool": "holder – tool", "spindle-holder": "spindle – holder"}


def provenance_table(rows: list[dict]) -> str:
    """A table of where every joint's values come from: measured, predicted or assumed, how uncertain, the source.

    Parameters
    ----------
    rows : list of dict
        :func:`~substructure.joint_priors.joint_provenances` of the report's assembly.

    Returns
    -------
    str
        HTML (empty when the assembly has no elastic joint).
    """
    if not rows:
        return ""
    body = ""
    for row in rows:
        kind, basis = row["kind"], row.get("basis")
        if kind == "prior":
            plain = {"measured": "Prior for this type of holder, measured on a similar holder",
                     "assumed": "Prior for this type of holder, assumed (no measurement of this type)"}.get(
                         basis, "Prior for this type of holder")
        else:
            plain = _PLAIN.get(kind, kind)
        spread = (f"from 1/{row['uncertainty']:g} to {row['uncertainty']:g} times the values"
                  if row["uncertainty"] is not None and row["uncertainty"] > 1 else "none stated")
        where = _ROLES.get(row["role"], "–")
        flag = ' class="flag"' if row["warning"] else ""
        body += (f"<tr{flag}><td>{_esc(row['name'])}</td><td>{where}</td><td><strong>{_esc(plain)}</strong></td>"
                 f"<td>{spread}</td><td class=\"source\">{_esc(row['source']) or '–'}</td></tr>")
    head = ("<tr><th>Joint</th><th>Between</th><th>Where the values come from</th><th>Uncertainty</th>"
            "<th>Source</th></tr>")
    return ('<h3>Where the joint values come from</h3><table class="wide provenance">'
            f"<thead>{head}</thead><tbody>{body}</tbody></table>")


def provenance_warnings(rows: list[dict]) -> list[str]:
    """The answer's facts about joint values that cannot be trusted for this holder.

    Parameters
    ----------
    rows : list of dict
        :func:`~substructure.joint_priors.joint_provenances`.

    Returns
    -------
    list of str
        HTML fragments, one per joint with a warning or a prior.
    """
    out = []
    for row in rows:
        if row["warning"]:
            out.append(_esc(row["warning"]) + ".")
        elif row["kind"] == "prior":
            out.append(f"The joint {_esc(row['name'])} uses a prior for its holder type (a wide uncertainty, "
                       "not a measurement): see the stability band.")
    return out


def readable(value: Any, depth: int = 0) -> str:
    """A value of a JSON object as readable HTML: numbers rounded, mappings as definition lists, lists of
    mappings as tables, never raw JSON.

    Parameters
    ----------
    value : object
        A JSON value.
    depth : int
        Nesting depth (deeper values are summarised).

    Returns
    -------
    str
        HTML.
    """
    if value is None:
        return "–"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, (int, float)):
        v = float(value)
        if not math.isfinite(v):
            return "–"
        return f"{int(value):,}" if isinstance(value, int) else format(v, ".4g")
    if isinstance(value, str):
        return _esc(value)
    if depth >= 3:
        return f"({len(value)} items)"
    if isinstance(value, dict):
        if not value:
            return "none"
        items = "".join(f"<li>{_esc(str(k).replace('_', ' '))}: {readable(v, depth + 1)}</li>"
                        for k, v in value.items())
        return f"<ul>{items}</ul>"
    if isinstance(value, (list, tuple)):
        if not value:
            return "none"
        if all(isinstance(v, dict) for v in value):
            keys = list(dict.fromkeys(k for v in value for k in v))[:8]
            head = "".join(f"<th>{_esc(str(k).replace('_', ' '))}</th>" for k in keys)
            body = "".join("<tr>" + "".join(f"<td>{readable(v.get(k), depth + 1)}</td>" for k in keys) + "</tr>"
                           for v in value[:12])
            more = f"<p class=\"note\">and {len(value) - 12} more</p>" if len(value) > 12 else ""
            return f'<table class="small"><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>{more}'
        if all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value):
            shown = ", ".join(readable(v) for v in value[:8])
            return shown + (f", … ({len(value)} values)" if len(value) > 8 else "")
        return "<ul>" + "".join(f"<li>{readable(v, depth + 1)}</li>" for v in value[:12]) + "</ul>"
    return _esc(value)
