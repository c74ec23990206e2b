"""The computations of :func:`~substructure.report.report` that concern the cut: the lobes, the stability band over
the joints' stated uncertainty (its lobes, the recommendation stable across it, each variant's own recommended
depth) and the cutting data of a recommended speed. They call the library's workflows, as the commands do."""

from __future__ import annotations

from typing import Any, Callable

import attrs

from ..errors import InvalidValueError


def _lobes(structure: Any, band: Any, cut: Any, speeds: Any, method: str, intervals: Any, progress: Callable) -> Any:
    from ..stability import fit_modes, sdm, xy_frf, zoa

    xy = xy_frf(structure)
    if method == "zoa":
        progress("lobes: zero-order approximation")
        return zoa(xy, cut, speeds, band=band)
    progress("lobes: semi-discretization (modes fitted to the receptance)")
    return attrs.evolve(sdm(fit_modes(xy), cut, speeds, intervals=intervals), band=band)


def _structure(assembly: Any, at: str, band: Any, frf: Any = None) -> tuple[Any, Any]:
    """The receptance stability uses and its band: ``"auto"`` as :func:`~substructure.stability.assembly_structure`,
    else the band chosen of the tool point receptance ``frf`` (computed when not given)."""
    from ..stability import assembly_structure, choose_band

    if isinstance(band, str) and band == "auto":
        return assembly_structure(assembly, at)
    return choose_band(assembly.receptance(at, frequency=assembly.frequency) if frf is None else frf, band)


def _joint_band(assembly, at, band, lobes, cut, limits, speeds, method, intervals, margin, tolerance, say):
    """The lobes over the joints' stated uncertainty, the recommendation stable across them (or why none is) and
    each variant's own recommended depth (None, None, None, () when no joint states an uncertainty)."""
    from ..joint_priors import joint_variants
    from ..stability import NoRecommendationError, lobes_band, recommend

    variants = joint_variants(assembly)
    if len(variants) < 2:
        return None, None, None, ()
    say(f"stability band: lobes of {len(variants)} variants of the joints within their uncertainty")
    members = []
    for variant in variants:
        members.append(_lobes(*_structure(variant, at, band), cut, speeds, method, intervals, lambda text: None))
    spread = lobes_band(members, nominal=lobes, label="joints within their uncertainty")
    own = []  # each variant's own recommended depth, as if its joints were known: their range is the uncertainty
    for member in members:
        try:
            own.append(recommend(member, cut, limits, margin=margin, speed_tolerance=tolerance).depth_m)
        except InvalidValueError:
            own.append(None)
    try:
        robust = recommend(lobes, cut, limits, margin=margin, speed_tolerance=tolerance, band=spread)
        return spread, robust, None, own
    except NoRecommendationError as exc:
        return spread, None, " ".join(str(exc).split()), own


def _cutting(cut: Any, best: Any, tool: Any, table: Any, material: str | None) -> dict | None:
    """The recommendation's cutting speed and feed against the usual range of the work and tool material."""
    from ..stability import check_cutting, cutting_conditions, cutting_data

    if best is None:
        return None
    wp = getattr(cut, "workpiece", None)
    if material is None and tool is not None:
        names = " ".join(s.material.name.lower() for s in getattr(tool, "segments", ()) if s.material is not None)
        material = next((m for m in ("carbide", "hss") if m in names), None)
    data = cutting_data(wp, material or "carbide", table) if wp is not None else None
    out = cutting_conditions(cut, best.spindle_speed_rpm, data)
    out["tool_material"] = material or ("carbide (assumed)" if wp is not None else None)
    out["warnings"] = check_cutting(cut, best.spindle_speed_rpm, data)
    return out
