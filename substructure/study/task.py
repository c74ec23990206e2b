"""One task of a study: a combination on a machine, computed from plain data on any worker.

:func:`run_task` takes the task as a study makes it (plain data: the
machine's assembly file text, the tool, holder and joint tables, the
prediction's numbers, the cuts, what to compute and the grids), builds the
assembly, computes the tool point FRF and its band, the lobes and the
recommendation of every cut, draws the figure, and returns the rows of the
table with the files to write.  It never raises for a problem of the
combination: a row that cannot be computed fails with its message and the
others go on.  Everything it returns is plain data (the figure as PNG
bytes), so that the worker may be in another process or on another
computer, and the result of a task depends on its data alone (the seed of
the sampling comes with it), not on the order in which tasks run.
"""

from __future__ import annotations

import functools
import importlib
import io
import os
import re
import tempfile
import threading
import time
import warnings

import numpy as np

from ..errors import InvalidValueError, SubstructureError
from .table import empty_row

__all__ = ["run_task", "joint_at_quantile"]

_FIGURE_LOCK = threading.Lock()  # matplotlib's renderers are not thread-safe: one figure at a time per process


class _Failed(Exception):
    """A row (or every row) of the task fails with this message."""


def _message(exc: BaseException) -> str:
    text = " ".join(str(exc).split())
    if isinstance(exc, (SubstructureError, _Failed)):
        return text
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__


def _guard(where: str, what: str, fn, *args, **kwargs):
    """Call ``fn``; a problem becomes :class:`_Failed` naming the combination and the key."""
    try:
        return fn(*args, **kwargs)
    except _Failed:
        raise
    except Exception as exc:
        message = _message(exc)
        raise _Failed(f"{where}: {what}: {message}" if what else f"{where}: {message}") from None


_MINI = re.compile(r"^<study>(, line \d+)?: (components\[0\]\.?)?")


def _component_from_table(kind: str, table: dict):
    """A tool or holder from a table of an assembly file (segments, catalog), read by the assembly reader."""
    import tomli_w

    from ..io.assembly_toml import loads_assembly

    doc = {"name": "combination", "components": [{"name": kind, "type": kind, **table}]}
    try:
        return loads_assembly(tomli_w.dumps(doc), source="<study>").component(kind)
    except SubstructureError as exc:
        raise InvalidValueError(_MINI.sub("", " ".join(str(exc).split()))) from None
    except (TypeError, ValueError) as exc:  # a value tomli_w cannot write
        raise InvalidValueError(str(exc)) from None


def _tool(spec: dict | None, machine):
    from ..components import Tool

    if spec is None:
        tool = machine.component("tool")
        if not isinstance(tool, Tool):
            raise InvalidValueError("the machine's component 'tool' is not a Tool; give the combination a tool")
        return tool
    if "segments" in spec:
        return _component_from_table("tool", spec)
    from ..units import quantity

    for key in ("diameter", "overhang", "flute_length"):  # named as the combination gives them, with the value
        if spec.get(key) is not None:
            value = quantity(spec[key], f"tool.{key}", "[length]")
            if not value.magnitude > 0:
                raise InvalidValueError(f"tool.{key}: got {spec[key]!r}; expected a positive length")
    extra = {k: spec[k] for k in ("teeth", "helix") if k in spec}
    try:
        tool = Tool.end_mill(spec["diameter"], spec["overhang"], spec.get("flute_length"),
                             material=spec.get("material", "carbide"), diameter_ratio=spec.get("diameter_ratio", 0.8),
                             **extra)
    except SubstructureError as exc:
        raise InvalidValueError(f"tool: {' '.join(str(exc).split())}") from None
    if "description" in spec:
        import attrs

        tool = attrs.evolve(tool, description=spec["description"])
    return tool


def _holder(spec: dict | None, machine, tool):
    from ..units import format_quantity

    if spec is None:
        holder = machine.component("holder")
        tip = holder.segments[-1] if getattr(holder, "segments", None) else None
        insert = getattr(tip, "insert", None)
        bore = getattr(insert, "od", None) if insert is not None else getattr(tip, "id", None)
        shank = tool.segments[0].od
        if bore is not None and bore.m_as("m") > 0 and shank.m_as("m") > bore.m_as("m") * (1 + 1e-9):
            raise InvalidValueError(
                f"the machine's holder has a {format_quantity(bore.to('mm'))} bore; the tool's shank is "
                f"{format_quantity(shank.to('mm'))} (tool.diameter), it cannot take it: give the combination a "
                "holder that does (holder.catalog, e.g. 'BT40 ER32', or holder.segments)")
        return holder
    table = dict(spec)
    if "catalog" in table and "bore" not in table:  # the tool's shank fills the bore
        table["bore"] = format_quantity(tool.segments[0].od)
    return _component_from_table("holder", table)


def joint_at_quantile(joint, prediction: dict, q: float):
    """The joint with every predicted parameter at the quantile ``q`` of its log-normal prediction.

    Parameters
    ----------
    joint : Joint
        The joint whose other entries are kept.
    prediction : dict
        ``{"log_mean": {p: float}, "log_std": {p: float}, "units": {p: str}}``
        of one feature set, parameters named ``k_yf``, ``c_tm``, ...
    q : float
        Probability in (0, 1); 0.5 is the median.

    Returns
    -------
    Joint
        The joint with ``exp(log_mean + z_q log_std)`` (in the parameter's
        unit) in place of each predicted entry.
    """
    from scipy.stats import norm

    from ..errors import NonPassiveJointWarning

    z = 0.0 if q == 0.5 else float(norm.ppf(q))
    k, c = {}, {}
    for name, mean in prediction["log_mean"].items():
        kind, entry = name.split("_", 1)
        value = float(np.exp(mean + z * prediction["log_std"][name]))
        (k if kind == "k" else c)[entry] = f"{value!r} {prediction['units'][name]}"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", NonPassiveJointWarning)
        return joint.with_parameters(k=k, c=c)


_PASSIVE = {"k": ("a stiffness > 0", "a zero or negative"), "c": ("a damping >= 0", "a negative")}


def _check_passive(joint: dict) -> None:
    """Refuse a joint override whose diagonal entry (``yf``, ``tm``) would make the structure generate energy.

    A stiffness ``k.yf``, ``k.tm`` must be > 0 and a damping ``c.yf``,
    ``c.tm`` >= 0 (as in the joint table of ``substructure predict``): with
    a negative one the structure is not passive and its stability limit
    means nothing.  The cross entries ``ym``, ``tf`` are signed.
    """
    from ..units import Q_

    for kind, entries in joint.items():
        for entry in ("yf", "tm"):
            value = (entries or {}).get(entry)
            if value is None:
                continue
            try:
                magnitude = float(Q_(value).to_base_units().magnitude)
            except Exception:  # a unit or number the joint itself refuses, with its own message
                continue
            if not (magnitude > 0 if kind == "k" else magnitude >= 0):
                expected, which = _PASSIVE[kind]
                raise InvalidValueError(
                    f"joint.{kind}.{entry}: got {value!r}; expected {expected} ({which} one makes a structure that "
                    "is not passive, it could generate energy, and no stability limit of it means anything)")


def _assembly(task: dict):
    """The combination's assembly (nominal joint), its tool, and the joint's template."""
    where = task["where"]
    from ..io.assembly_toml import loads_assembly

    m = task["machine"]
    machine = _guard(where, f"machine {m['name']!r}", loads_assembly, m["text"], source=m["source"])
    for i, s in enumerate(m["supports"]):
        machine = _guard(where, f"machine {m['name']!r}: supports[{i}]", machine.support, s["at"], k=s.get("k"),
                         c=s.get("c"))
    tool = _guard(where, "", _tool, task["tool"], machine)
    holder = _guard(where, "holder", _holder, task["holder"], machine, tool)
    assembly = _guard(where, "tool", machine.with_component, tool)
    assembly = _guard(where, "holder", assembly.with_component, holder)
    template = _guard(where, f"joint {task['joint_name']!r} of machine {m['name']!r}", assembly.joint,
                      task["joint_name"])
    prediction = task["prediction"]
    if task["joint"] is not None:
        _guard(where, "", _check_passive, task["joint"])
        joint = _guard(where, "joint", template.with_parameters, k=task["joint"].get("k"), c=task["joint"].get("c"))
    elif prediction is not None:
        if "error" in prediction:
            raise _Failed(f"{where}: features: {prediction['error']}")
        joint = _guard(where, "joint", joint_at_quantile, template, prediction, 0.5)
    else:
        joint = template
    assembly = _guard(where, "joint", assembly.with_joint, joint)
    return assembly, tool, template


def _tool_mode(frf, band, near: float | None = None) -> tuple[float, float]:
    """The frequency [Hz] and |H| [m/N] of the highest peak in the band (or of the peak nearest ``near``).

    The peak is refined by a parabola through the three lines around it in
    ``log |H|`` (sub-line accuracy on a coarse grid).
    """
    f = frf.frequency.hz
    h = np.abs(frf.data[:, 0, 0])
    inside = np.flatnonzero((f >= band.lo_hz) & (f <= band.hi_hz))
    if inside.size == 0:
        return float("nan"), float("nan")
    i = int(inside[np.argmax(h[inside])])
    if near is not None:
        peaks = [int(np.searchsorted(f, p)) for p in frf.peaks()]
        peaks = [p for p in peaks if band.lo_hz <= f[p] <= band.hi_hz]
        if peaks:
            i = min(peaks, key=lambda p: abs(f[p] - near))
    if 0 < i < f.size - 1 and f[i + 1] - f[i] == f[i] - f[i - 1]:
        a, b, c = np.log(h[i - 1:i + 2])
        denominator = a - 2 * b + c
        if denominator < 0:
            shift = 0.5 * (a - c) / denominator
            if abs(shift) <= 1:
                return float(f[i] + shift * (f[i + 1] - f[i])), float(np.exp(b - 0.25 * (a - c) * shift))
    return float(f[i]), float(h[i])


def _mode_below_grid(assembly, point: str, frequency, frf) -> tuple[str, float] | None:
    """Why the grid misses the tool point's dominant mode (a mode below its first line) and its frequency, or None.

    The tool point receptance is computed on 77 lines from a twentieth of
    the grid's first line up to it, its rigid-body lines left out as for the
    grid; when the lines below the grid hold a more negative real part and
    a larger magnitude than every line of the grid, a mode below the grid
    dominates, and the lobes from the grid alone would be far too deep.
    Nothing flexible below the grid (a mass line only) is no finding.
    """
    from ..frf import Frequency
    from ..stability import assembly_structure

    f0 = float(frequency.hz[0])
    if not f0 > 0:
        return None
    low = Frequency.from_range(f"{f0 / 20!r} Hz", f"{f0!r} Hz", f"{0.95 * f0 / 76!r} Hz")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            probe, _ = assembly_structure(assembly, point, low)
    except Exception:  # a mass line only (no flexible mode below the grid), nothing to compute there, or a mode
        return None      # above these lines as flexible as theirs (assembly_structure refuses them): no finding
    lines = probe.frequency.hz < f0
    h, inside = probe.data[lines, 0, 0], frf.data[:, 0, 0]
    if not h.size or not (h.real.min() < inside.real.min() and np.abs(h).max() > np.abs(inside).max()):
        return None
    i = int(np.argmax(np.abs(h)))
    mode = float(probe.frequency.hz[lines][i])
    return (f"the tool point receptance has a mode below the frequency grid's first line ({f0:g} Hz), near "
            f"{mode:.3g} Hz, more compliant than any inside the grid (|H| {np.abs(h[i]):.3g} "
            f"m/N against at most {np.abs(inside).max():.3g} m/N inside)"), mode


@functools.lru_cache(maxsize=8)
def _user_table(text: str):
    from ..stability import load_workpieces

    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "workpieces.toml")
        with open(path, "w", encoding="utf-8") as fh:
            fh.write(text)
        return load_workpieces(path)


def _cut(spec: dict, tool):
    from ..stability import MillingCut, workpiece

    if tool.teeth is None:
        raise InvalidValueError("tool.teeth: missing; the cut needs the tool's tooth count (teeth = 4)")
    diameter = tool.cutting_diameter
    common = {"radial_depth": spec["radial_depth"], "immersion": spec["immersion"], "milling": spec["milling"]}
    if spec["workpiece"] is not None:
        table = None if spec["workpiece_table"] is None else _user_table(spec["workpiece_table"])
        entry = workpiece(spec["workpiece"], table)
        return MillingCut.for_workpiece(tool.teeth, diameter, entry, feed_per_tooth=spec["feed_per_tooth"],
                                        kn=spec["kn"], kr=spec["kr"], **common)
    extra = {"feed_per_tooth": spec["feed_per_tooth"]} if spec["feed_per_tooth"] is not None else {}
    return MillingCut.from_spec(tool.teeth, diameter, kt=spec["kt"], kn=spec["kn"], kr=spec["kr"], **common, **extra)


def _limits(spec: dict | None, max_depth):
    from ..stability import MachineLimits

    spec = spec or {}

    def value(v, unit):
        if v is None:
            return None
        if isinstance(v, dict):
            return [(f"{n!r} rpm", f"{x!r} {unit}") for n, x in zip(v["spindle_speed_rpm"], v["values"])]
        return f"{v!r} {unit}"

    return MachineLimits(max_speed=value(spec.get("max_speed_rpm"), "rpm"),
                         min_speed=value(spec.get("min_speed_rpm"), "rpm"),
                         power=value(spec.get("power_w"), "W"), torque=value(spec.get("torque_n_m"), "N*m"),
                         max_depth=max_depth)


def _lobes(method: str, frf, band, cut, speeds, notes: list[str]):
    import attrs

    from ..stability import fit_modes, sdm, xy_frf, zoa

    if method == "zoa":
        return zoa(xy_frf(frf), cut, speeds, band=band)
    modes = fit_modes(band.crop(frf))
    if not any(notes_line.startswith("modal fit") for notes_line in notes):
        notes.append(f"modal fit: {modes.describe()}")
    return attrs.evolve(sdm(modes, cut, speeds), band=band)


def _caught(record: list) -> list[str]:
    return list(dict.fromkeys(" ".join(str(w.message).split()) for w in record))


def _entry(joint, kind: str, entry: str) -> float | None:
    from ..units import Q_

    if joint.rigid:
        return None
    value = getattr(joint, kind).as_dict().get(entry)
    return 0.0 if value is None else float(Q_(value).to_base_units().magnitude)


def _combination_row(task: dict, tool, assembly, template, frf_band, tool_mode, members) -> dict:
    from ..units import Q_

    row = empty_row()
    row.update(combination=task["combination"], machine=task["machine"]["name"], seed=task["seed"], key=task["key"])
    row["tool_diameter_m"] = float(tool.cutting_diameter.m_as("m"))
    row["overhang_m"] = float(tool.length.m_as("m"))
    row["flute_length_m"] = None if tool.flute_length is None else float(tool.flute_length.m_as("m"))
    row["teeth"] = tool.teeth
    holder = task["holder"]
    row["holder"] = "machine" if holder is None else holder.get("catalog", "segments")
    row["joint_source"] = ("explicit" if task["joint"] is not None else
                           "surrogate" if task["prediction"] is not None else "machine")
    joint = assembly.joint(task["joint_name"])
    row["joint_k_yf_n_per_m"] = _entry(joint, "k", "yf")
    row["joint_k_tm_n_m_per_rad"] = _entry(joint, "k", "tm")
    row["joint_c_yf_n_s_per_m"] = _entry(joint, "c", "yf")
    row["joint_c_tm_n_m_s_per_rad"] = _entry(joint, "c", "tm")
    prediction = task["prediction"]
    if row["joint_source"] == "surrogate" and "k_yf" in prediction["log_mean"]:
        m, s = prediction["log_mean"]["k_yf"], prediction["log_std"]["k_yf"]
        unit = Q_(1.0, prediction["units"]["k_yf"]).m_as("N/m")
        row["joint_k_yf_lo_n_per_m"] = float(np.exp(m - 1.959963984540054 * s)) * unit
        row["joint_k_yf_hi_n_per_m"] = float(np.exp(m + 1.959963984540054 * s)) * unit
    frf, band = frf_band
    row["structure_band_lo_hz"] = float(band.lo_hz)
    row["structure_band_kind"] = band.kind
    row["tool_mode_hz"], row["tool_mode_compliance_m_per_n"] = tool_mode
    if members:
        modes = [m["tool_mode"][0] for m in members]
        row["tool_mode_lo_hz"], row["tool_mode_hi_hz"] = float(np.nanmin(modes)), float(np.nanmax(modes))
    return row


def _cut_row(base: dict, spec: dict, cut) -> dict:
    row = dict(base)
    row["cut"] = spec["name"]
    row["workpiece"] = spec["workpiece"] or ""
    row["milling"] = spec["milling"]
    if cut is not None:
        row["radial_depth_m"] = float(cut.radial_depth.m_as("m"))
        row["feed_per_tooth_m"] = None if cut.feed_per_tooth is None else float(cut.feed_per_tooth.m_as("m"))
        row["kt_pa"], row["kn_pa"] = float(cut.kt_pa), float(cut.kn_pa)
    return row


def _recommendation_columns(best) -> dict:
    def num(v):
        return None if v is None or not np.isfinite(v) else float(v)

    out = {"spindle_speed_rpm": best.spindle_speed_rpm, "depth_m": best.depth_m,
           "limit_depth_m": num(best.limit_depth_m), "margin": best.margin, "reserve": best.reserve,
           "mrr_m3_per_s": num(best.mrr_m3_per_s), "chatter_frequency_hz": num(best.chatter_frequency_hz),
           "limited_by": best.limited_by, "power_w": num(best.power_w), "torque_n_m": num(best.torque_n_m),
           "window_lo_rpm": best.window_rpm[0], "window_hi_rpm": best.window_rpm[1],
           "band_members": best.band_members}
    if best.runners_up:
        out["runner_up_speed_rpm"] = best.runners_up[0].spindle_speed_rpm
        out["runner_up_depth_m"] = best.runners_up[0].depth_m
    return out


def _one_cut(task: dict, spec: dict, tool, nominal: dict, members: list[dict], notes: list[str]):
    """Lobes (every method), the recommendation and the row of one cut."""
    from ..stability import lobes_band, recommend, spindle_speeds

    compute, grid = task["compute"], task["grid"]
    where = f"{task['where']}: cut {spec['name']!r}"
    cut = _guard(where, "", _cut, spec, tool)
    speeds = spindle_speeds(*grid["speeds"])
    sdm_speeds = spindle_speeds(*(grid["sdm_speeds"] or grid["speeds"]))
    row = {"cut": cut}
    lobes = {}
    for method in compute["lobes"]:
        n = speeds if method == "zoa" else sdm_speeds
        lobes[method] = _guard(where, f"{method} lobes", _lobes, method, *nominal["frf_band"], cut, n, notes)
        row[f"{method}_min_limit_m"] = float(np.min(lobes[method].depth_limit_m))
        if method == "zoa" and lobes[method].absolute_limit_m is not None:
            row["zoa_absolute_limit_m"] = float(lobes[method].absolute_limit_m)
    best = band = None
    method = compute["recommend_method"]
    if compute["recommend"] and method is not None:
        if len(members) > 1:
            n = speeds if method == "zoa" else sdm_speeds
            others = [lobes[method] if m["q"] == 0.5 else
                      _guard(where, f"{method} lobes at quantile {m['q']:g}", _lobes, method, *m["frf_band"], cut, n,
                             notes) for m in members]
            band = lobes_band(others, nominal=lobes[method], label="quantiles of the predicted joint")
        max_depth = spec["max_depth"] if spec["max_depth"] is not None else tool.flute_length
        limits = _guard(where, "limits", _limits, task["machine"]["limits"], max_depth)
        best = _guard(where, "recommendation", recommend, lobes[method], cut, limits, margin=compute["margin"],
                      speed_tolerance=compute["speed_tolerance"], band=band)
        row["method"] = method
        row.update(_recommendation_columns(best))
    return row, lobes, best, band


def _figure(task: dict, nominal: dict, members: list, envelope, cuts: list) -> bytes:
    """The combination's figure: the tool point FRF (and its band) above the lobes of each cut."""
    from matplotlib.figure import Figure

    from ..stability.plotting import plot_recommendation, wrap_title
    from .._text import plain_text

    panels = 1 + len(cuts)
    fig = Figure(figsize=(8.0, 3.2 + 3.6 * len(cuts)), layout="constrained")
    axes = fig.subplots(panels, 1, squeeze=False)[:, 0]
    ax = axes[0]
    frf, band = nominal["frf_band"]
    f = frf.frequency.hz
    ax.semilogy(f, np.abs(frf.data[:, 0, 0]) * 1e6, color="tab:blue", lw=1.2,
                label="tool point FRF" + (" (median joint)" if envelope is not None else ""))
    if envelope is not None:
        ax.fill_between(envelope.frequency.hz, envelope.lower * 1e6, envelope.upper * 1e6, color="tab:blue",
                        alpha=0.2, lw=0, label=f"envelope of {len(next(iter(envelope.samples.values())))} samples "
                                               "of the predicted joint")
    if band.excluded_hz is not None and band.excluded_hz[0] < band.lo_hz:
        ax.axvspan(band.excluded_hz[0], band.lo_hz, color="0.85", lw=0, label=f"left out of stability ({band.kind})")
    mode, _ = nominal["tool_mode"]
    if np.isfinite(mode):
        label = f"tool mode {mode:.0f} Hz"
        if len(members) > 1:
            modes = [m["tool_mode"][0] for m in members]
            ax.axvspan(min(modes), max(modes), color="tab:orange", alpha=0.3, lw=0)
            label += f" ({min(modes):.0f} to {max(modes):.0f} Hz over the quantiles)"
        ax.axvline(mode, color="tab:orange", lw=1.0, ls="--", label=label)
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("|H| [um/N]")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="x-small")
    wrap_title(ax, f"{task['combination']} on {task['machine']['name']}: tool point receptance {task['compute']['at']}",
               width=80)
    for ax, (spec, lobes, best, lband) in zip(axes[1:], cuts):
        if lobes is None:
            ax.text(0.5, 0.5, plain_text(f"cut {spec['name']!r}: failed"), transform=ax.transAxes, ha="center")
            ax.set_axis_off()
            continue
        chosen = task["compute"]["recommend_method"]
        if lband is not None:  # the band and its nominal lobes, then the other method, then the recommendation
            lband.plot(ax=ax, color="tab:blue", alpha=0.2)
        for k, (method, result) in enumerate(lobes.items()):
            if lband is None or method != chosen:
                result.plot(ax=ax, recommendation=best if method == chosen and lband is None else None,
                            color=f"C{k}")
        if lband is not None and best is not None:
            plot_recommendation(best, ax=ax)
        wrap_title(ax, f"cut {spec['name']!r}", width=80)
    buffer = io.BytesIO()
    with _FIGURE_LOCK:
        fig.savefig(buffer, format="png", dpi=90)
    return buffer.getvalue()


def run_task(task: dict) -> dict:
    """Compute one combination on one machine.

    Parameters
    ----------
    task : dict
        Plain data made by :meth:`substructure.study.Study.tasks`: ``key``,
        ``fingerprint``, ``combination``, ``where``, ``seed``, ``machine``,
        ``tool``, ``holder``, ``joint``, ``joint_name``, ``prediction``,
        ``cuts``, ``compute``, ``grid``, ``plugins``.

    Returns
    -------
    dict
        ``key``, ``fingerprint``, ``status`` (``"done"``: every row was
        computed or failed with its message), ``rows`` (one per cut, the
        columns of :data:`~substructure.study.table.COLUMNS`), ``figure``
        (PNG bytes or ``None``), ``frf`` (``{"frequency_hz", "real",
        "imag"}`` or ``None``), ``elapsed_s`` (wall time [s]).
    """
    start = time.perf_counter()
    out = {"key": task["key"], "fingerprint": task["fingerprint"], "status": "done", "figure": None, "frf": None}
    cuts = task["cuts"] or [None]
    try:
        for module in task["plugins"]:
            importlib.import_module(module)
        rows = _compute(task, out)
    except _Failed as exc:
        rows = [_failed_row(task, spec, str(exc)) for spec in cuts]
    except Exception as exc:  # a bug or an unforeseen input: this combination fails, the study goes on
        rows = [_failed_row(task, spec, f"{task['where']}: internal error: {_message(exc)}") for spec in cuts]
    out["rows"] = rows
    out["elapsed_s"] = time.perf_counter() - start
    return out


def _failed_row(task: dict, spec: dict | None, message: str) -> dict:
    row = empty_row()
    row.update(combination=task["combination"], machine=task["machine"]["name"], cut="" if spec is None else
               spec["name"], status="failed", error=message, seed=task["seed"], key=task["key"])
    if spec is not None:
        row.update(workpiece=spec["workpiece"] or "", milling=spec["milling"])
    return row


def _compute(task: dict, out: dict) -> list[dict]:
    from ..frf import Frequency
    from ..stability import assembly_structure

    where, compute, grid = task["where"], task["compute"], task["grid"]
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        assembly, tool, template = _assembly(task)
        if grid["frequency"] is not None:
            frequency = Frequency.from_range(*grid["frequency"])
        elif assembly.frequency is not None:
            frequency = assembly.frequency
        else:
            raise _Failed(f"{where}: the machine's assembly has no [frequency] and the study no [grid] frequency")
        point = compute["point"]
        nominal = {"q": 0.5, "frf_band": _guard(where, f"FRF at {point}", assembly_structure, assembly, point,
                                                   frequency)}
        nominal["tool_mode"] = _tool_mode(*nominal["frf_band"])
        below = _mode_below_grid(assembly, point, frequency, nominal["frf_band"][0])
        if below:
            key = ("grid.frequency.start" if grid["frequency"] is not None
                   else "[grid] frequency (the study's; the machine's assembly [frequency] is used now)")
            raise _Failed(f"{where}: {below[0]}; no depth from this grid can be trusted: start the frequency grid "
                          f"below the mode, {key} = '{below[1] / 2:.2g} Hz' for instance")
        members: list[dict] = []
        envelope = None
        prediction = task["prediction"]
        banded = compute["band"] and task["joint"] is None and prediction is not None
        if banded:
            for q in compute["quantiles"]:
                if q == 0.5:
                    members.append(nominal)
                    continue
                variant = assembly.with_joint(joint_at_quantile(template, prediction, q))
                member = {"q": q, "frf_band": _guard(where, f"FRF at quantile {q:g}", assembly_structure, variant,
                                                     point, frequency)}
                member["tool_mode"] = _tool_mode(*member["frf_band"], near=nominal["tool_mode"][0])
                members.append(member)
    if banded and compute["figures"]:  # for the figure only: the rows do not depend on it
        from ..surrogate import Prediction, predict_frf_band

        p = Prediction({k: np.array([v]) for k, v in prediction["log_mean"].items()},
                       {k: np.array([v]) for k, v in prediction["log_std"].items()}, prediction["units"])
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            envelope = _guard(where, "FRF envelope", predict_frf_band, assembly, task["joint_name"], p, at=point,
                              frequency=frequency, n_samples=compute["samples"], seed=task["seed"])
    common = _caught(record) + list(prediction.get("warnings", ()) if prediction else ())
    band = nominal["frf_band"][1]
    common.insert(0, f"structure band from {band.lo_hz:.5g} Hz ({band.kind})")
    base = _combination_row(task, tool, assembly, template, nominal["frf_band"], nominal["tool_mode"], members)
    base["status"], base["error"] = "ok", ""
    rows, drawn = [], []
    for spec in task["cuts"]:
        notes = list(common)
        with warnings.catch_warnings(record=True) as record:
            warnings.simplefilter("always")
            try:
                values, lobes, best, lband = _one_cut(task, spec, tool, nominal, members, notes)
                cut = values.pop("cut")
                row = _cut_row(base, spec, cut)
                row.update(values)
                drawn.append((spec, lobes, best, lband))
            except _Failed as exc:
                row = _cut_row(base, spec, None)
                row.update(status="failed", error=str(exc), method=None)
                drawn.append((spec, None, None, None))
        notes += [n for n in _caught(record) if n not in notes]
        row["notes"] = "; ".join(notes)
        rows.append(row)
    if not task["cuts"]:
        row = dict(base)
        row["cut"] = ""
        row["notes"] = "; ".join(common)
        rows.append(row)
    if compute["figures"]:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            out["figure"] = _figure(task, nominal, members, envelope, drawn)
    if compute["frf_files"]:
        frf = nominal["frf_band"][0]
        out["frf"] = {"frequency_hz": frf.frequency.hz.tolist(), "real": frf.data[:, 0, 0].real.tolist(),
                      "imag": frf.data[:, 0, 0].imag.tolist(), "label": point}
    return rows
