"""Study files for the study tests: a small library on the built-in spindle (written into a folder)."""

from __future__ import annotations

from pathlib import Path

STUDY = """\
name = "test library"
combinations_csv = "tools.csv"
{extra_top}
[grid]
frequency = {{ start = "100 Hz", stop = "5000 Hz", step = "5 Hz" }}
speeds = {{ start = "5000 rpm", stop = "20000 rpm", step = "100 rpm" }}

[compute]
figures = {figures}
frf_files = {frf_files}

[surrogate]
table = "joints.csv"
features = {{ tool_diameter = "tool.diameter", gauge_length = "tool.overhang" }}

[[machines]]
name = "bench"
limits = {{ max_speed = "20000 rpm", power = "11 kW" }}
{extra_machines}
[[cuts]]
name = "aluminium"
workpiece = "aluminium-7075"
radial_depth = "3 mm"
milling = "down"
feed_per_tooth = "0.05 mm"

[[cuts]]
name = "steel slot"
kt = "2000 MPa"
kr = 0.3
immersion = 1.0
feed_per_tooth = "0.08 mm"

[[combinations]]
name = "explicit 12 mm"
tool = {{ diameter = "12 mm", overhang = "76 mm", flute_length = "30 mm", teeth = 4 }}
joint = {{ k = {{ yf = "1.43e7 N/m" }} }}
{extra_combinations}"""

JOINTS = """\
# thesis Table 4.2: identified holder-tool stiffnesses
tool_diameter [mm],gauge_length [mm],k_yf [N/m]
10,65,9.7e6
10,68,8.4e6
10,73,5.8e6
12,76,1.43e7
12,81,1.95e7
12,85,1.20e7
16,83,2.20e7
16,86,2.25e7
16,89,2.20e7
16,92,2.26e7
20,98,3.48e7
20,100,3.68e7
20,106,3.75e7
"""

BAD_JOINT = """
[[combinations]]
name = "bad joint"
tool = { diameter = "12 mm", overhang = "80 mm", flute_length = "30 mm", teeth = 4 }
joint = { k = { yf = "1.4e7 N" } }
"""


def tools_csv(n: int) -> str:
    """``n`` tools: diameters 10 to 16 mm, overhangs 65 to 92 mm, some in catalogue holders."""
    lines = ["name,tool.diameter [mm],tool.overhang [mm],tool.flute_length [mm],tool.teeth,holder.catalog"]
    diameters = (10, 12, 16)
    for i in range(n):
        d = diameters[i % 3]
        overhang = 65 + (i * 7) % 28
        holder = "BT40 ER32" if i % 4 == 3 or d > 12 else ""  # the machine's holder has a 12 mm bore
        lines.append(f"T{i:02d},{d},{overhang},{min(30, overhang - 20)},{3 + i % 2},{holder}")
    return "\n".join(lines) + "\n"


def write_study(folder: Path, n: int = 4, figures: bool = False, frf_files: bool = False, bad: bool = False,
                extra_top: str = "", extra_machines: str = "", extra_combinations: str = "") -> Path:
    """Write the study file, its joint table and its tools into ``folder``; returns the study file."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "joints.csv").write_text(JOINTS)
    (folder / "tools.csv").write_text(tools_csv(n))
    text = STUDY.format(figures=str(figures).lower(), frf_files=str(frf_files).lower(), extra_top=extra_top,
                        extra_machines=extra_machines,
                        extra_combinations=extra_combinations + (BAD_JOINT if bad else ""))
    path = folder / "study.toml"
    path.write_text(text)
    return path
