"""The words of a report: the assumptions, the verdict of a diagnosis and the joints' values, from the results.

Shared by the HTML page (:mod:`~substructure.report.html`) and the JSON
summary (:meth:`~substructure.report.Report.to_json`), so that both say the
same.  A diagnosis is read through its ``to_json()`` only, key by key, with
defaults: keys added in later versions (``explained``, standard deviations
``std`` of the fitted values) are used when present.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["ENTRY_NAMES", "EFFECT_NAMES", "AS_GOOD_AS_DATA", "assumptions", "diagnosis_verdict", "joints_json",
           "joint_findings"]

#: Plain names of the joint matrix entries (``k_yf``: force per deflection, ...), for the tables.
ENTRY_NAMES = {
    "yf": "force per deflection",
    "ym": "force per rotation",
    "tf": "moment per deflection",
    "tm": "moment per rotation",
}

#: Plain names of the diagnosis's effects (others are shown by their own name).
EFFECT_NAMES = {
    "sensor-mass": "a mass on the structure (a sensor the model does not have)",
    "joint-stiffness": "a joint stiffer or softer than in the model",
    "joint-damping": "a joint with more or less damping than in the model",
    "joint-cross-coupling": "a joint whose deflection and rotation are coupled",
    "rigid-joint-flexibility": "a connection modelled as rigid that gives",
    "fluted-section": "flutes the tool model lacks",
    "tapered-tool": "a taper the tool model lacks",
    "support-springs": "springs to the ground (suspension bands, a fixture)",
    "model-parameter": "a value of the model file that is off",
    "added-mass": "a mass the model lacks (a nut, a ring, a sensor)",
}

AS_GOOD_AS_DATA = 1.5
"""A model is as good as the data allow when its error is within this many times the noise floor."""


def _number(value: Any) -> float | None:
    try:
        v = float(value)
    except (TypeError, ValueError, OverflowError):
        return None
    return v if np.isfinite(v) else None


def diagnosis_verdict(data: dict) -> tuple[str, str]:
    """The diagnosis in one word and one plain sentence, from ``Diagnosis.to_json()``.

    Parameters
    ----------
    data : dict
        The diagnosis's JSON object.

    Returns
    -------
    (str, str)
        ``"agrees"`` (the model as given is as good as the data), ``"explained"`` (with the
        effects found it is), ``"unexplained"`` (it is not), and the sentence.  The key
        ``explained`` of the object decides where it is present; otherwise the final error
        against :data:`AS_GOOD_AS_DATA` times the noise floor.
    """
    floor = _number(data.get("noise_floor"))
    base = _number(data.get("baseline_error"))
    final = _number(data.get("final_error"))
    if final is None:
        final = base
    explained = data.get("explained")
    if not isinstance(explained, bool):
        explained = floor is not None and final is not None and final <= AS_GOOD_AS_DATA * floor
    effects = data.get("final_effects") or []
    named = "; ".join(f"{_effect_name(e.get('effect'))} at {e.get('where')} ({_values(e.get('parameters'))})"
                      for e in effects if isinstance(e, dict))
    assumed = data.get("assumed_windows")
    taus = [_number(w.get("window_tau_s")) for w in assumed if isinstance(w, dict)] if isinstance(assumed, list) else []
    through = "" if not explained or not taus else (
        " That is with the tap test read through an exponential window (tau = "
        + ", ".join("?" if t is None else f"{t:.3g} s" for t in taus)
        + ") that its noise shows and its file does not declare: check the analyser's window.")
    if explained and not effects:
        return "agrees", "The model agrees with the tap test as closely as the test's own scatter allows." + through
    if explained:
        return "explained", (f"The model misses {named}. With it, the model agrees with the tap test as closely "
                             "as the test's own scatter allows." + through)
    if effects:
        return "unexplained", (f"Not explained: the model does not agree with the tap test, and what the diagnosis "
                               f"found explains it only in part ({named}; partial). Something else is missing.")
    return "unexplained", ("Not explained: the model does not agree with the tap test, and no effect the "
                           "diagnosis knows explains the difference.")


def _values(parameters: Any) -> str:
    """``name value +- std unit, ...`` with masses below 1 kg in g and lengths below 1 m in mm."""
    bits = []
    for name, spec in (parameters or {}).items():
        spec = spec if isinstance(spec, dict) else {"value": spec}
        v, u, scale = _number(spec.get("value")), str(spec.get("unit", "")), 1.0
        if v is None:
            continue
        if u in ("kg", "m") and abs(v) < 1:
            u, scale = ("g" if u == "kg" else "mm"), 1e3
        std = _number(spec.get("std"))
        u = u.replace("**2", "²").replace("^2", "²").replace("*", "·")
        bits.append(f"{name} {v * scale:.3g}" + (f" ± {std * scale:.2g}" if std else "") + (f" {u}" if u else ""))
    return ", ".join(bits)


def _effect_name(name: Any) -> str:
    return EFFECT_NAMES.get(str(name), str(name))


def joint_findings(data: dict | None, joint: str) -> list[dict]:
    """The values the diagnosis found for one joint's entries.

    Parameters
    ----------
    data : dict or None
        ``Diagnosis.to_json()``, or None.
    joint : str
        The joint's name.

    Returns
    -------
    list of dict
        ``{"effect", "parameter", "value", "unit", "std"}`` (``std`` None when not given) for
        each parameter of an effect in ``final_effects`` that acts on the joint: where it is
        the joint's name, or a model-file path ``joints.<name>.<k|c>.<entry>``.
    """
    if not data:
        return []
    found = []
    for effect in data.get("final_effects") or []:
        if not isinstance(effect, dict):
            continue
        where = str(effect.get("where", ""))
        path = None
        if where.startswith(f"joints.{joint}."):
            parts = where[len(f"joints.{joint}."):].split(".")
            path = "_".join(parts) if len(parts) == 2 else None
        elif where != joint:
            continue
        for name, spec in (effect.get("parameters") or {}).items():
            spec = spec if isinstance(spec, dict) else {"value": spec}
            found.append({"effect": effect.get("effect"), "parameter": path if path and name == "value" else name,
                          "value": _number(spec.get("value")), "unit": spec.get("unit", ""),
                          "std": _number(spec.get("std"))})
    return found


def joints_json(report: Any) -> list[dict]:
    """The joints of a report with their values and uncertainty, for ``--json``.

    Parameters
    ----------
    report : Report
        The report.

    Returns
    -------
    list of dict
        Per joint: ``name``, ``between``, ``rigid``, ``model`` (``k`` and ``c`` in SI units),
        ``identified`` (``IdentificationReport.to_json()`` or None), ``identification_error``
        (why it could not be identified, or None), ``diagnosis`` (:func:`joint_findings`) and
        ``provenance`` (where the values come from: ``kind``, ``source``, ``uncertainty``, ``warning``;
        :func:`~substructure.joint_priors.joint_provenances`; None for a rigid joint).
    """
    from ..joint_priors import joint_provenances

    where = {row["name"]: row for row in joint_provenances(report.assembly)}
    data = None if report.diagnosis is None else report.diagnosis.to_json()
    identified = {r.joint: r for r in report.identifications}
    failed = dict(report.identification_errors)
    out = []
    for j in report.assembly.joints:
        rigid = bool(getattr(j, "rigid", False))
        model = None
        if not rigid and hasattr(j, "k"):
            model = {kind: {e: getattr(j, kind).get(e) for e in ENTRY_NAMES} for kind in ("k", "c")}
        out.append({"name": j.name, "between": list(j.between), "rigid": rigid, "model": model,
                    "identified": identified[j.name].to_json() if j.name in identified else None,
                    "identification_error": failed.get(j.name), "diagnosis": joint_findings(data, j.name),
                    "provenance": where.get(j.name)})
    return out


def assumptions(report: Any) -> list[str]:
    """What the results assume, in plain words, with the numbers the report used.

    Parameters
    ----------
    report : Report
        The report.

    Returns
    -------
    list of str
        One entry per assumption.
    """
    out = []
    band = report.structure_band
    if band is not None:
        out.append(f"Stability uses the tool point receptance from {band.lo_hz:.5g} to {band.hi_hz:.5g} Hz "
                   f"({band.kind}): {band.reason}. Rigid-body and suspension lines do not exist on the machine "
                   "and are never used.")
    if report.assembly.sensors:
        names = ", ".join(f"{s.name} ({s.mass.to('g'):.3g~P} at {s.at})" for s in report.assembly.sensors)
        out.append(f"The sensors of the model file are on the structure in every result of this report: {names}.")
    cut = report.cut
    if cut is not None and hasattr(cut, "radial_depth"):
        tool = report.tool
        helix = getattr(tool, "helix", None) if tool is not None else None
        out.append("Straight teeth, equally spaced: the helix angle is not used"
                   + (f" (the tool's {helix:~P} is recorded only)" if helix is not None else "")
                   + "; no process damping, so at low speeds real cuts are more stable than shown.")
        wp = getattr(cut, "workpiece", None)
        if wp is not None:
            out.append(f"Cutting coefficients of {wp.name} from the project's table: {wp.describe()}. They depend "
                       "on the tool, its wear and the cutting speed: calibrate with your own cuts where it matters.")
        else:
            out.append(f"Cutting coefficients given by the user: Kt = {cut.kt_pa / 1e6:.4g} MPa, "
                       f"Kn = {cut.kn_pa / 1e6:.4g} MPa (Kn/Kt = {cut.kr:.3g}).")
        if report.recommendation is not None:
            r = report.recommendation
            out.append(f"The margin: the depth is at most {1 - r.margin:.0%} of the lowest chatter limit over "
                       f"the speed window +-{r.speed_tolerance:.0%}, because the lobes move when the tool's "
                       "natural frequency does (a sensor, temperature, wear, the joints).")
    elif cut is not None:
        out.append("Turning or boring: Tlusty's oriented single-direction cut; no recommendation is made.")
    for c in report.assembly.components:
        text = getattr(c, "description", "") or ""
        if "APPROXIMATE" in text:
            out.append(f"Approximate geometry: {c.name!r} is built from the holder catalogue ({text.split(':')[0]}); "
                       "its body and nose are typical values, not your holder's drawing. Check the diameters and "
                       "lengths with a caliper and override what differs.")
    from ..joint_priors import joint_provenances

    for row in joint_provenances(report.assembly):
        if row["warning"]:
            out.append(f"Joint values: {row['warning']}.")
        elif row["kind"] in ("prior", "borrowed", "predicted"):
            spread = f", within a factor {row['uncertainty']:g}" if row["uncertainty"] is not None else ""
            out.append(f"Joint {row['name']!r}: {row['kind']}{spread}, not identified on this machine"
                       + (f" ({row['source'].split(':')[0]})" if row["source"] else "") + ".")
    if report.band is not None:
        out.append(f"The stability band: the lobes of {len(report.band.members)} variants of the model, each joint "
                   "with a stated uncertainty at the ends and the middle of its range; the band's recommendation "
                   "is stable for every one of them, not for values beyond them.")
    if report.cutting is not None and report.cutting.get("range") is not None:
        row = report.cutting["range"]
        out.append(f"The cutting-speed and feed ranges of {row['workpiece']} with a {row['tool_material']} tool "
                   f"are {row['source'].split(';')[0]} ranges of the published orders of magnitude, for a warning "
                   "only: nothing is clipped to them.")
    data = None if report.diagnosis is None else report.diagnosis.to_json()
    if data is not None:
        floor = _number(data.get("noise_floor"))
        if floor is not None:
            out.append(f"Noise floor of the tap test: {floor:.3g} (about {floor:.1%} scatter, estimated from the "
                       "data themselves): no model can agree with the test more closely than that.")
        out.append("The lobes and the recommendation use the model as given. If the diagnosis found something that "
                   "belongs to the machine (not only to the test, like a sensor), save the improved model "
                   "(substructure diagnose --save-model) and make the report again from it.")
    if report.identifications:
        out.append("Joint identification assumes the rest of the model is right: what the model misses is "
                   "absorbed by the identified values, and their standard deviations do not include it.")
    if report.lobes is not None and report.lobes.method == "sdm":
        out.append("Semi-discretization uses modes fitted to the receptance; their fit error is listed with the "
                   "modes.")
    return out
