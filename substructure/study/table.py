"""The result table of a study: its columns, the rows as a pandas DataFrame, Parquet and CSV files, the ranking.

One row per combination (on one machine) and cut.  Every number is in SI
units (speeds in rpm, frequencies in Hz); a value that does not exist (a
failed row, no band without a surrogate, no limit found) is missing (NaN,
an empty cell in CSV, null in Parquet).  The rows are in the study's order
(combinations, then machines, then cuts), whatever order the tasks finished
in, so that a resumed study gives the same table as an uninterrupted one.
pandas and pyarrow are imported when a table is made.
"""

from __future__ import annotations

import io
from typing import Any

import numpy as np

from .._text import plain_text

__all__ = ["COLUMNS", "make_table", "write_table", "summary_figure", "rank_value"]

#: The columns of the table: ``(name, kind, meaning)``, kind ``str``, ``float`` or ``int``.
COLUMNS = (
    ("combination", "str", "the combination's name"),
    ("machine", "str", "the machine's name"),
    ("cut", "str", "the cut's name (empty when the study has no cuts)"),
    ("status", "str", "ok, failed (an error of this row; see error), crashed (the worker was lost; retried by "
                      "--resume) or pending (not computed yet: an interrupted run)"),
    ("error", "str", "why the row failed: file, line and key where known"),
    ("notes", "str", "warnings and choices made (structure band, modal fit, extrapolation), '; '-separated"),
    ("tool_diameter_m", "float", "cutting diameter of the tool [m]"),
    ("overhang_m", "float", "tool length out of the holder [m]"),
    ("flute_length_m", "float", "fluted length at the tip [m]"),
    ("teeth", "int", "tooth count of the tool"),
    ("holder", "str", "the catalogue holder, 'segments' (given explicitly) or 'machine' (the machine's)"),
    ("joint_source", "str", "where the holder-tool joint comes from: explicit, surrogate or machine"),
    ("joint_k_yf_n_per_m", "float", "holder-tool joint stiffness k_yf used (the median of a prediction) [N/m]"),
    ("joint_k_yf_lo_n_per_m", "float", "lower end of the 95 % interval of a predicted k_yf [N/m]"),
    ("joint_k_yf_hi_n_per_m", "float", "upper end of that interval [N/m]"),
    ("joint_k_tm_n_m_per_rad", "float", "joint stiffness k_tm used [N m/rad]"),
    ("joint_c_yf_n_s_per_m", "float", "joint damping c_yf used [N s/m]"),
    ("joint_c_tm_n_m_s_per_rad", "float", "joint damping c_tm used [N m s/rad]"),
    ("structure_band_lo_hz", "float", "lowest FRF line used for stability (rigid-body/suspension lines below) [Hz]"),
    ("structure_band_kind", "str", "free-free, suspended or supported"),
    ("tool_mode_hz", "float", "tool mode: the highest peak of |H| at the tool point in the structure band [Hz]"),
    ("tool_mode_lo_hz", "float", "lowest tool mode frequency over the quantiles of a predicted joint [Hz]"),
    ("tool_mode_hi_hz", "float", "highest tool mode frequency over those quantiles [Hz]"),
    ("tool_mode_compliance_m_per_n", "float", "|H| at the tool mode [m/N]"),
    ("workpiece", "str", "work material of the cut (empty for coefficients given)"),
    ("radial_depth_m", "float", "radial depth of cut [m]"),
    ("milling", "str", "up or down"),
    ("feed_per_tooth_m", "float", "feed per tooth [m]"),
    ("kt_pa", "float", "tangential cutting coefficient [Pa]"),
    ("kn_pa", "float", "normal cutting coefficient [Pa]"),
    ("zoa_min_limit_m", "float", "zero order: lowest depth limit over the speeds [m]"),
    ("zoa_absolute_limit_m", "float", "zero order: the speed-independent limit [m]"),
    ("sdm_min_limit_m", "float", "semi-discretization: lowest depth limit over its speeds [m]"),
    ("method", "str", "the lobes the recommendation is made from: zoa or sdm"),
    ("spindle_speed_rpm", "float", "recommended spindle speed [rpm]"),
    ("depth_m", "float", "recommended axial depth of cut [m]"),
    ("limit_depth_m", "float", "lowest stability limit over the speed window (and the band) [m]"),
    ("margin", "float", "the stated margin: depth <= (1 - margin) * limit_depth_m"),
    ("reserve", "float", "1 - depth / limit: the margin kept"),
    ("mrr_m3_per_s", "float", "material removal rate [m^3/s] (needs a feed per tooth)"),
    ("chatter_frequency_hz", "float", "chatter frequency where the window's limit is reached [Hz]"),
    ("limited_by", "str", "what set the depth: stability, max depth, power or torque"),
    ("power_w", "float", "cutting power [W] (needs a feed per tooth)"),
    ("torque_n_m", "float", "spindle torque of the cut [N m]"),
    ("window_lo_rpm", "float", "lower end of the speed window checked [rpm]"),
    ("window_hi_rpm", "float", "upper end of the speed window [rpm]"),
    ("band_members", "int", "lobe diagrams the window was checked on (1, or the quantiles of the band)"),
    ("runner_up_speed_rpm", "float", "the best speed of another pocket of the lobes [rpm]"),
    ("runner_up_depth_m", "float", "its depth [m]"),
    ("seed", "int", "seed of the sampling, from the combination's and the machine's names"),
    ("key", "str", "the name of the combination's files in the output directory"),
)

def empty_row() -> dict:
    """A row with every column missing (``None``).

    Returns
    -------
    dict
        ``{column: None}`` for every column of :data:`COLUMNS`.
    """
    return {name: None for name, _, _ in COLUMNS}


def make_table(rows: list[dict]):
    """The rows as a DataFrame with the columns of :data:`COLUMNS` and their types.

    Parameters
    ----------
    rows : list of dict
        ``{column: value}``; a column left out or ``None`` is missing.

    Returns
    -------
    pandas.DataFrame
        Strings as ``string``, numbers as ``float64``, counts as ``Int64``
        (missing allowed); the index is 0, 1, ...
    """
    import pandas as pd

    data = {}
    for name, kind, _ in COLUMNS:
        values = [row.get(name) for row in rows]
        if kind == "str":
            data[name] = pd.array(["" if v is None else str(v) for v in values], dtype="string")
        elif kind == "int":
            data[name] = pd.array([None if v is None else int(v) for v in values], dtype="Int64")
        else:
            data[name] = np.array([np.nan if v is None else float(v) for v in values], dtype=float)
    return pd.DataFrame(data)


def write_table(table, parquet: Any, csv: Any, overwrite: bool = True) -> None:
    """Write the table to a Parquet file and a CSV file, each atomically.

    Parameters
    ----------
    table : pandas.DataFrame
        From :func:`make_table`.
    parquet : str or path
        The Parquet file.
    csv : str or path
        The CSV file (for spreadsheets): every digit of every number, empty
        cells for missing values.
    overwrite : bool, default True
        Whether existing files may be replaced.
    """
    from ..io import replacing, write_text

    with replacing(parquet, overwrite) as temporary:
        table.to_parquet(temporary, index=False, engine="pyarrow")
    buffer = io.StringIO()
    table.to_csv(buffer, index=False, lineterminator="\n")
    write_text(csv, buffer.getvalue(), overwrite)


def rank_value(table) -> tuple[Any, str]:
    """What the summary ranks the rows by, and its label.

    Parameters
    ----------
    table : pandas.DataFrame
        The study's table.

    Returns
    -------
    (pandas.Series, str)
        The removal rate in cm^3/min where the cuts have a feed per tooth,
        else the recommended depth times speed in mm x 1000 rpm (the removal
        rate per unit feed and tooth); without recommendations, the tool
        mode's dynamic stiffness ``1/|H|`` in N/um.  Higher is better.
    """
    if table["mrr_m3_per_s"].notna().any():
        return table["mrr_m3_per_s"] * 6e7, "material removal rate [cm^3/min]"
    if table["depth_m"].notna().any():
        return table["depth_m"] * 1e3 * table["spindle_speed_rpm"] / 1e3, \
            "recommended depth x speed [mm x 1000 rpm] (no feed per tooth given)"
    return 1e-6 / table["tool_mode_compliance_m_per_n"], "dynamic stiffness at the tool mode, 1/|H| [N/um]"


def summary_figure(table, title: str = "", top: int = 25):
    """Bar charts ranking the combinations, one panel per cut.

    Parameters
    ----------
    table : pandas.DataFrame
        The study's table.
    title : str
        The figure's title.
    top : int, default 25
        The best this many rows per cut are drawn (the rest are counted).

    Returns
    -------
    matplotlib.figure.Figure
        Bars best first, coloured by machine; failed rows named below each panel.
    """
    from matplotlib.figure import Figure

    value, label = rank_value(table)
    cuts = list(dict.fromkeys(table["cut"].tolist())) or [""]
    machines = list(dict.fromkeys(table["machine"].tolist()))
    colours = {m: f"C{i % 10}" for i, m in enumerate(machines)}
    heights = []
    for cut in cuts:
        n = int(((table["cut"] == cut) & value.notna()).sum())
        heights.append(1.4 + 0.22 * min(max(n, 1), top))
    fig = Figure(figsize=(8.5, sum(heights) + 0.6), layout="constrained")
    axes = fig.subplots(len(cuts), 1, squeeze=False, height_ratios=heights)[:, 0]
    for ax, cut in zip(axes, cuts):
        rows = table[table["cut"] == cut]
        v = value[rows.index]
        good = rows[v.notna()].assign(_v=v[v.notna()]).sort_values("_v", ascending=False, kind="stable")
        shown = good.head(top)
        names = [f"{c}" + (f" ({m})" if len(machines) > 1 else "") for c, m in zip(shown["combination"],
                                                                                  shown["machine"])]
        y = np.arange(len(shown))[::-1]
        ax.barh(y, shown["_v"], color=[colours[m] for m in shown["machine"]])
        for yy, (_, r) in zip(y, shown.iterrows()):
            what = (f" {r['spindle_speed_rpm']:,.0f} rpm, {r['depth_m'] * 1e3:.3g} mm"
                    if r["spindle_speed_rpm"] == r["spindle_speed_rpm"] else f" {r['tool_mode_hz']:.0f} Hz")
            ax.text(r["_v"], yy, what, va="center", fontsize="xx-small")
        ax.margins(x=0.15)
        ax.set_yticks(y, [plain_text(n) for n in names], fontsize="x-small")
        ax.set_xlabel(label, fontsize="small")
        ax.grid(True, axis="x", alpha=0.3)
        failed = rows[rows["status"] != "ok"]
        text = f"cut {cut!r}: " if cut else ""
        text += f"{len(good)} ranked" + (f", best {len(shown)} shown" if len(good) > len(shown) else "")
        if len(failed):
            text += f"; not ranked ({len(failed)}): " + ", ".join(
                f"{c} [{s}]" for c, s in zip(failed["combination"].head(8), failed["status"].head(8)))
            text += ", ..." if len(failed) > 8 else ""
        ax.set_title(plain_text(text), fontsize="small", loc="left")
        if not len(shown):
            ax.text(0.5, 0.5, "nothing to rank", transform=ax.transAxes, ha="center", va="center")
    if len(machines) > 1:
        from matplotlib.patches import Patch

        axes[0].legend(handles=[Patch(color=colours[m], label=plain_text(m)) for m in machines], fontsize="x-small",
                       loc="lower right")
    if title:
        fig.suptitle(plain_text(title), fontsize="medium")
    return fig
