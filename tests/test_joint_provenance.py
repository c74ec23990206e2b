"""Where joint values come from: provenance in assembly files, priors per holder type with their sources, the
stability band over the priors' uncertainty, and the report showing both."""

from __future__ import annotations

import html as html_module
import itertools
import re
from pathlib import Path

import numpy as np
import pytest

from substructure import Holder, Joint, default_assembly
from substructure.errors import FileFormatError, InvalidValueError
from substructure.io.assembly_toml import dumps_assembly, loads_assembly
from substructure.joint_priors import (joint_provenances, joint_variants, prior_joint, priors_table,
                                       with_joint_priors)
from substructure.joints import JointProvenance
from substructure.stability import MachineLimits, MillingCut

HOLDER_TEXT = (Path(__file__).parent / "test_holders.py").read_text(encoding="utf-8").split('TEXT = """')[1]
HOLDER_TEXT = HOLDER_TEXT.split('"""')[0]
HT = 'k = { yf = "2e7 N/m", tm = "1e5 N*m/rad" }'
SH = 'k = { yf = "5e7 N/m", tm = "4e6 N*m/rad" }'


def catalogue(name: str, priors: bool = True):
    a = default_assembly().with_component(Holder.from_catalog(name, bore="12 mm", gauge_length="80 mm"))
    return with_joint_priors(a) if priors else a


def test_provenance_changes_no_number():
    j = Joint("j", ("a.tip", "b.base"), k={"yf": "1e7 N/m"})
    p = Joint("j", ("a.tip", "b.base"), k={"yf": "1e7 N/m"}, provenance={"kind": "identified", "source": "tap"})
    assert j == p and hash(j) == hash(p) and p.provenance.kind == "identified"
    np.testing.assert_array_equal(j.dynamic_stiffness(np.array([10.0])), p.dynamic_stiffness(np.array([10.0])))
    with pytest.raises(InvalidValueError, match="provenance"):
        JointProvenance("guessed")
    with pytest.raises(InvalidValueError, match="factor"):
        JointProvenance("prior", "x", 0.5)


def test_provenance_keys_in_assembly_files_round_trip():
    text = HOLDER_TEXT.replace(SH, SH + '\nprovenance = "identified"\nsource = "tap test 2025-03"\nuncertainty = 1.2')
    text = text.replace(HT, "prior = true")
    a = loads_assembly(text)
    sh, ht = a.joint("sh"), a.joint("ht")
    assert sh.provenance == JointProvenance("identified", "tap test 2025-03", 1.2)
    assert ht.provenance.kind == "prior" and ht.provenance.uncertainty == 4.0 and "shrink-fit" in ht.provenance.source
    row = priors_table()["holder-tool"]["shrink-fit"]
    assert ht == Joint("ht", ht.between, k=row["k"], c=row["c"])
    again = loads_assembly(dumps_assembly(a))
    assert again == a and [j.provenance for j in again.joints] == [j.provenance for j in a.joints]


@pytest.mark.parametrize("change, match", [
    ((HT, "prior = true\n" + HT), r"joints\[1\]\.k: prior = true takes its values"),
    ((HT, HT + '\nsource = "a book"'), r"joints\[1\]\.source: goes with provenance"),
    ((HT, HT + '\nprovenance = "guessed"'), r"joints\[1\]\.provenance: got 'guessed'"),
    ((HT, HT + '\nprovenance = "prior"\nuncertainty = 0.5'), r"joints\[1\].*factor >= 1"),
    ((HT, 'prior = "yes"'), r"joints\[1\]\.prior: got 'yes'"),
    ((SH, "prior = true"), None),  # the spindle-holder joint of a catalogue holder has a prior too
])
def test_provenance_errors_name_the_file_line_and_key(change, match):
    text = HOLDER_TEXT.replace(*change)
    if match is None:
        assert loads_assembly(text).joint("sh").provenance.kind == "prior"
        return
    with pytest.raises(FileFormatError, match=match) as info:
        loads_assembly(text, source="m.toml")
    assert "m.toml, line" in str(info.value)


def test_a_prior_needs_a_catalogue_holder():
    text = default_assembly_text().replace(
        'k = { yf = "1.43e7 N/m", tm = "8e4 N*m/rad" }\nc = { yf = "12 N*s/m", tm = "4 N*m*s/rad" }', "prior = true")
    assert "prior = true" in text
    with pytest.raises(FileFormatError, match=r"line 7\d: joints\[1\]\.prior: .*catalogue holder"):
        loads_assembly(text, source="d.toml")


def default_assembly_text() -> str:
    return (Path(__file__).parent.parent / "substructure" / "data" / "default_assembly.toml").read_text("utf-8")


def test_the_priors_follow_their_sources():
    table = priors_table()
    ht, sh = table["holder-tool"], table["spindle-holder"]
    for rows in (ht, sh):
        for row in rows.values():
            assert row["basis"] in ("measured", "assumed") and row["source"] and row["uncertainty"] >= 2
    # the measured collet prior holds every identified holder-tool value of the thesis's tables within its factor
    from substructure.datasets import thesis_table

    f = ht["collet"]["uncertainty"]
    kyf = float(ht["collet"]["k"]["yf"].split()[0])
    identified = [4.19e7, 5.3e7, 5.2e7, 0.47e7] + [float(r["k_yf_identified_1e7_N_per_m"]) * 1e7
                                                    for r in thesis_table("4.2")]
    assert all(kyf / f <= k <= kyf * f for k in identified)
    # shrink-fit stiffer than hydraulic stiffer than collet; HSK stiffer than a steep taper
    k = {name: float(row["k"]["yf"].split()[0]) for name, row in ht.items()}
    assert k["shrink-fit"] > k["hydraulic"] > k["collet"]
    assert float(sh["hsk"]["k"]["yf"].split()[0]) > float(sh["steep-taper"]["k"]["yf"].split()[0])


def test_catalogue_holders_in_the_order_of_their_sources_at_the_tool_tip():
    """A shrink-fit's stiffer holder-tool joint makes the tool tip statically stiffer than a collet's in the
    same holder body; the recommendation itself need not follow (see docs/machinist.md)."""
    base = catalogue("BT40 ER32")  # held in stiff bearings, so that 1 Hz is the static compliance
    base = base.support("spindle@30 mm", k={"yf": "1e9 N/m"}).support("spindle@250 mm", k={"yf": "1e9 N/m"})
    static = {}
    for clamp in ("collet", "hydraulic", "shrink-fit"):
        a = base.with_joint(prior_joint("holder-tool", clamp, "holder-tool", ("holder.tip", "tool.base")))
        static[clamp] = abs(a.receptance("tool.tip:y", frequency=np.array([1.0])).data[0, 0, 0])
    assert static["shrink-fit"] < static["hydraulic"] < static["collet"]


def test_unstated_values_at_a_catalogue_holder_are_flagged_and_priors_replace_them():
    a = catalogue("HSK-A63 shrink-fit", priors=False)
    rows = {r["name"]: r for r in joint_provenances(a)}
    assert rows["holder-tool"]["kind"] == "not stated" and "another holder" in rows["holder-tool"]["warning"]
    assert rows["spindle-holder"]["role"] == "spindle-holder" and rows["spindle-holder"]["warning"]
    with_priors = with_joint_priors(a)
    rows = {r["name"]: r for r in joint_provenances(with_priors)}
    assert rows["holder-tool"]["kind"] == "prior" and rows["holder-tool"]["warning"] is None
    assert with_priors.joint("holder-tool").k.get("yf") == pytest.approx(3e7)
    assert with_priors.joint("spindle-holder").k.get("yf") == pytest.approx(6.15e7)
    # identified values are kept
    kept = a.with_joint(Joint("holder-tool", ("holder.tip", "tool.base"), k={"yf": "9e6 N/m"},
                              provenance="identified"))
    assert with_joint_priors(kept).joint("holder-tool").k.get("yf") == pytest.approx(9e6)
    # the thesis's own holder (not from the catalogue) is not flagged
    assert all(r["warning"] is None for r in joint_provenances(default_assembly()))


def test_variants_span_the_stated_uncertainty():
    a = catalogue("BT40 ER32")
    variants = joint_variants(a, levels=3)
    assert len(variants) == 9  # two uncertain joints, three levels each
    kyf = sorted({v.joint("holder-tool").k.get("yf") for v in variants})
    assert kyf == pytest.approx([1.5e7 / 4, 1.5e7, 1.5e7 * 4])
    cyf = sorted({v.joint("holder-tool").c.get("yf") for v in variants})
    assert cyf == pytest.approx([150 / 4, 150, 600])
    assert any(v == a for v in variants)  # the nominal among them
    assert joint_variants(default_assembly()) == [default_assembly()]  # nothing stated, no band


@pytest.fixture(scope="module")
def banded():
    from substructure.report import report

    a = catalogue("HSK-A63 shrink-fit")
    cut = MillingCut.for_workpiece(4, "12 mm", "steel-1045", immersion=1.0, feed_per_tooth="0.05 mm", kr=0.3)
    return report(a, cut=cut, limits=MachineLimits(max_depth="30 mm"))


def test_the_band_recommendation_holds_for_every_variant(banded):
    from substructure.stability import zoa

    r, robust, band = banded.recommendation, banded.band_recommendation, banded.band
    assert len(band.members) == 9 and robust.band_members == 10
    assert robust.depth_m <= r.depth_m  # never more than the nominal joints allow
    lo, hi = robust.window_rpm
    for member in band.members:  # recomputed on a fine grid of the window, the margin holds for every variant
        fine = member.window_minimum(np.array([lo]), np.array([hi]))[0][0]
        assert robust.depth_m <= (1 - robust.margin) * fine * (1 + 1e-9)
    assert zoa  # the lobes of the members are zero-order lobes like the nominal's
    assert all(m.method == banded.lobes.method for m in band.members)


def test_the_report_shows_provenance_band_and_cutting_data(banded):
    page = banded.to_html()
    text = re.sub(r"<[^>]+>", "", page)
    assert "Stability band: with every joint anywhere within its stated uncertainty (9 variants)" in text
    assert f"{banded.band_recommendation.depth_m * 1e3:.3g} mm" in text
    assert f"{banded.recommendation.depth_m * 1e3:.3g} mm" in text
    assert text.count("Where the values come from: a prior for this type of holder") == 2
    assert "Weck and Schubert" in text and "within a factor 4" in text
    assert "Cutting speed" in text and "SFM" in text and "Outside the usual cutting data" in text
    assert "up (conventional) milling" in text
    out = banded.to_json()
    assert out["stability_band"]["members"] == 9 and out["stability_band"]["recommended"]["depth_m"] > 0
    assert out["cutting_data"]["warnings"] and out["cutting_data"]["speed_in_range"] is False
    assert [j["provenance"]["kind"] for j in out["joints"]] == ["prior", "prior"]


def test_the_answer_is_the_bands_speed_and_depth_with_its_cutting_data(banded):
    """With joints of stated uncertainty the headline is the speed and depth stable across them, and the margin,
    cutting speed and feed rate are those of that speed (v_c = pi D n, v_f = f_z z n, computed here)."""
    robust, nominal = banded.band_recommendation, banded.recommendation
    assert robust.spindle_speed_rpm != nominal.spindle_speed_rpm or robust.depth_m < nominal.depth_m
    answer = re.sub(r"\s+", " ", re.sub(r"<[^>]+>", "", banded.to_html().split('<section id="stability">')[0]))
    assert (f"Until the joints are identified, run at {robust.spindle_speed_rpm:,.0f} rpm with an axial depth of cut "
            f"of {robust.depth_m * 1e3:.3g} mm.") in answer
    assert f"which is the lowest limit anywhere between {robust.window_rpm[0]:,.0f} and" in answer
    assert "for every variant of the joints" in answer
    vc = np.pi * 0.012 * robust.spindle_speed_rpm  # m/min
    vf = 0.05 * 4 * robust.spindle_speed_rpm  # mm/min
    assert f"Cutting speed {vc:,.0f} m/min ({vc / 0.3048:,.0f} SFM)" in answer
    assert f"feed rate {vf:,.0f} mm/min" in answer
    band = banded.to_json()["stability_band"]
    assert band["cutting_data"]["cutting_speed_m_per_min"] == pytest.approx(vc)
    assert banded.to_json()["cutting_data"]["cutting_speed_m_per_min"] == pytest.approx(
        np.pi * 0.012 * nominal.spindle_speed_rpm)  # the summary's own keys stay the nominal answer's
    # without a band the headline is the nominal answer, as before
    from substructure.report import report

    cut, limits = _slotting()
    plain = report(default_assembly(), cut=cut, limits=limits)
    assert plain.band is None and plain.band_cutting is None
    assert plain.depth_range_m == (plain.recommendation.depth_m,) * 2
    assert f"Run at {plain.recommendation.spindle_speed_rpm:,.0f} rpm" in re.sub(r"<[^>]+>", "", plain.to_html())


def test_the_table_of_where_the_joint_values_come_from():
    """One row per elastic joint: measured or assumed as the prior table says, identified, or not stated (marked)."""
    from substructure.report.shop import provenance_table

    def rows_of(assembly):
        html = provenance_table(joint_provenances(assembly))
        return [html_module.unescape(re.sub(r"\s+", " ", re.sub(r"<[^>]+>", " ", row))).strip()
                for row in re.findall(r"<tr[^>]*>(.*?)</tr>", html)[1:]], html

    rows, _ = rows_of(catalogue("BT40 shrink-fit"))
    table = priors_table()
    assert table["spindle-holder"]["steep-taper"]["basis"] == "measured"
    assert table["holder-tool"]["shrink-fit"]["basis"] == "assumed"
    assert rows[0].startswith("spindle-holder spindle – holder Prior for this type of holder, measured on a similar")
    assert rows[1].startswith("holder-tool holder – tool Prior for this type of holder, assumed (no measurement")
    assert all("from 1/4 to 4 times the values" in r for r in rows)
    # a prior whose source is the user's own, not the shipped row: no basis claimed
    a = catalogue("BT40 ER32")
    own = a.with_joint(Joint("holder-tool", ("holder.tip", "tool.base"), k={"yf": "2e7 N/m"},
                             provenance=JointProvenance("prior", "our shop's notes", 3.0)))
    rows, _ = rows_of(own)
    assert "Prior for this type of holder from 1/3 to 3 times the values our shop's notes" in rows[1]
    assert {r["name"]: r["basis"] for r in joint_provenances(own)} == {"spindle-holder": "measured",
                                                                      "holder-tool": None}
    # identified, and not stated at a catalogue holder (marked)
    ident = a.with_joint(Joint("holder-tool", ("holder.tip", "tool.base"), k={"yf": "2e7 N/m"},
                               provenance=JointProvenance("identified", "tap test 2025-03", 1.1)))
    rows, _ = rows_of(ident)
    assert "Measured: identified from a tap test of this assembly from 1/1.1 to 1.1 times" in rows[1]
    rows, html = rows_of(catalogue("BT40 ER32", priors=False))
    assert all("Not stated none stated" in r for r in rows) and html.count('<tr class="flag">') == 2
    assert provenance_table([]) == ""


def test_the_report_warns_of_borrowed_joint_values():
    from substructure.report import report

    a = catalogue("HSK-A63 shrink-fit", priors=False)
    page = report(a).to_html()
    text = re.sub(r"<[^>]+>", "", page)
    assert "were not identified or predicted for the catalogue holder" in text
    assert "their provenance is not stated" in text


def test_more_from_the_diagnosis_is_readable_not_json():
    from substructure.report.shop import readable

    html = readable({"noise_model": "per line", "budget": {"evaluations": 1200, "used_s": 8.61234},
                     "rivals": [{"effect": "added mass", "error": 0.0123}, {"effect": "spring", "error": 0.02}],
                     "lines": [1.0, 2.5, 3.25]})
    text = re.sub(r"<[^>]+>", " ", html)
    assert "{" not in text and '"' not in text and ":" in text
    assert "<table" in html and "added mass" in html and "8.612" in html and "1,200" in html
    assert "1, 2.5, 3.25" in html


# -- the catalogue holders for one tool: what the sources order, and what the data leave open -------------------

HOLDERS = ("BT40 ER32", "BT40 hydraulic", "BT40 shrink-fit")  # collet, hydraulic, shrink-fit on one interface


def _slotting():
    """Slotting 1045 steel with the built-in assembly's tool: a 12 mm 4-flute carbide end mill, 30 mm flutes."""
    return (MillingCut.for_workpiece(4, "12 mm", "steel-1045", immersion=1.0, feed_per_tooth="0.05 mm", kr=0.3),
            MachineLimits(max_depth="30 mm"))


def _with_factor(assembly, factor: float):
    """The assembly with every prior's uncertainty factor set to ``factor`` (values unchanged)."""
    import attrs

    for j in assembly.joints:
        if j.provenance is not None and j.provenance.kind == "prior":
            assembly = assembly.with_joint(attrs.evolve(j, provenance=attrs.evolve(j.provenance, uncertainty=factor)))
    return assembly


@pytest.fixture(scope="module")
def holder_reports():
    from substructure.report import report

    cut, limits = _slotting()
    out = {}
    for factor in (None, 1.2):  # the priors' own factor 4, and a narrow one for contrast
        for name in HOLDERS:
            a = catalogue(name)
            assert default_assembly().component("tool") == a.component("tool")  # one tool, one stick-out
            out[name, factor] = report(a if factor is None else _with_factor(a, factor), cut=cut, limits=limits)
    return out


def test_the_catalogue_holders_tool_mode_in_the_order_of_their_sources(holder_reports):
    """The sources order the holder-tool joints shrink-fit > hydraulic > collet in stiffness; for one tool in the
    catalogue's holders, the tool point's most flexible mode comes in that order in frequency, found twice: the
    largest peak of |H| on a fine grid and the report's fitted modes."""
    from scipy.signal import find_peaks

    grid = np.linspace(300.0, 3000.0, 10801)  # 0.25 Hz
    peak, fitted = {}, {}
    for name in HOLDERS:
        h = np.abs(catalogue(name).receptance("tool.tip:y", frequency=grid).data[:, 0, 0])
        found, _ = find_peaks(h)
        peak[name] = grid[found[np.argmax(h[found])]]
        fitted[name] = max(holder_reports[name, None].modes, key=lambda m: m.peak_m_per_n).frequency_hz
        assert fitted[name] == pytest.approx(peak[name], rel=0.005)
    assert peak["BT40 shrink-fit"] > peak["BT40 hydraulic"] > peak["BT40 ER32"]
    assert fitted["BT40 shrink-fit"] > fitted["BT40 hydraulic"] > fitted["BT40 ER32"]


def test_the_catalogue_bodies_differ_statically_by_a_few_percent():
    """Statically (stiff bearings, 1 Hz) the three catalogue holders differ by less than 5 % at the tool tip: the
    collet body, thicker at the nose, offsets its softer joint (docs/machinist.md, section 9). The joint alone, in
    one body, orders them as the sources do (test_catalogue_holders_in_the_order_of_their_sources_at_the_tool_tip)."""
    stiffness = {}
    for name in HOLDERS:
        a = catalogue(name).support("spindle@30 mm", k={"yf": "1e9 N/m"}).support("spindle@250 mm", k={"yf": "1e9 N/m"})
        stiffness[name] = 1.0 / abs(a.receptance("tool.tip:y", frequency=np.array([1.0])).data[0, 0, 0])
    assert max(stiffness.values()) / min(stiffness.values()) < 1.05


def test_each_variant_recommends_its_own_depth(holder_reports):
    """The range of depths a report states is each variant's own recommendation, recomputed here for the softest
    and the stiffest variant from their assemblies."""
    from substructure.stability import assembly_structure, recommend, spindle_speeds, xy_frf, zoa
    from substructure.report import DEFAULT_SPEEDS

    cut, limits = _slotting()
    r = holder_reports["BT40 shrink-fit", None]
    variants = joint_variants(catalogue("BT40 shrink-fit"))
    assert len(r.band_depths_m) == len(variants) == 9
    for index in (0, len(variants) - 1):
        frf, band = assembly_structure(variants[index], "tool.tip:y")
        lobes = zoa(xy_frf(frf), cut, spindle_speeds(*DEFAULT_SPEEDS), band=band)
        alone = recommend(lobes, cut, limits, margin=0.2, speed_tolerance=0.03).depth_m
        assert r.band_depths_m[index] == pytest.approx(alone, rel=1e-12)
    lo, hi = r.depth_range_m
    assert lo == min(r.band_depths_m) and hi == max(r.band_depths_m)
    assert lo <= r.recommendation.depth_m <= hi
    assert r.to_json()["stability_band"]["depth_range_m"] == [lo, hi]


def test_the_order_of_the_recommended_depths_is_not_decided_by_the_priors(holder_reports):
    """With the priors' factor 4 the catalogue holders' ranges of recommended depth overlap: the report says the
    order is not decided by the data; with a narrow factor (1.2) the collet's range lies above the others and the
    order is decided (the model's order, not the sources': no source gives the joints' damping per holder)."""
    from substructure.report import depth_order

    wide = {name: holder_reports[name, None] for name in HOLDERS}
    narrow = {name: holder_reports[name, 1.2] for name in HOLDERS}
    for a, b in itertools.combinations(HOLDERS, 2):
        (lo1, hi1), (lo2, hi2) = wide[a].depth_range_m, wide[b].depth_range_m
        assert lo1 <= hi2 and lo2 <= hi1  # overlap
        said = depth_order(wide[a], wide[b], (a, b))
        assert said["order"] is None and "not decided by the data" in said["text"]
    for name in HOLDERS:
        text = re.sub(r"\s+", " ", re.sub(r"<[^>]+>", "", wide[name].to_html()))
        lo, hi = wide[name].depth_range_m
        assert f"would recommend from {lo * 1e3:.3g} to {hi * 1e3:.3g} mm" in text
        assert "the order of the recommended depths is not decided by the data" in text
    # the nominal depths alone would rank the collet first; the narrow factor makes that order a decided one
    assert wide["BT40 ER32"].recommendation.depth_m > wide["BT40 shrink-fit"].recommendation.depth_m
    said = depth_order(narrow["BT40 ER32"], narrow["BT40 shrink-fit"], ("the collet chuck", "the shrink-fit chuck"))
    assert said["order"] == "first" and said["text"].startswith("The collet chuck allows a larger depth")
    assert narrow["BT40 ER32"].depth_range_m[0] > narrow["BT40 shrink-fit"].depth_range_m[1]
    said = depth_order(narrow["BT40 shrink-fit"], narrow["BT40 ER32"])
    assert said["order"] == "second"


def test_depth_order_needs_two_recommendations():
    from substructure.report import depth_order, report

    bare = report(default_assembly())
    with pytest.raises(InvalidValueError, match="recommended depth"):
        depth_order(bare, bare)


def test_the_command_says_to_use_the_band_and_what_the_variants_leave_open(tmp_path, capsys):
    from substructure.cli import main
    from substructure.report import report

    path = tmp_path / "shrink.toml"
    path.write_text(dumps_assembly(catalogue("BT40 shrink-fit")), encoding="utf-8")  # the priors, saved
    cut = ["--radial-depth", "3 mm", "--milling", "down", "--workpiece", "aluminium-7075",
           "--feed-per-tooth", "0.05 mm"]
    status = main(["report", str(path), "--out", str(tmp_path / "r.html"), *cut, "--quiet"])
    text = capsys.readouterr().out
    assert status == 0 and "Traceback" not in text
    expected = report(loads_assembly(path.read_text(encoding="utf-8")),
                      cut=MillingCut.for_workpiece(4, "12 mm", "aluminium-7075", radial_depth="3 mm",
                                                   feed_per_tooth="0.05 mm", milling="down"))
    lo, hi = expected.depth_range_m
    assert f"each variant alone allows {lo * 1e3:.3g} to {hi * 1e3:.3g} mm" in text
    assert "the order is not decided by the data" in text
