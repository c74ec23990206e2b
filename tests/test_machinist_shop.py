"""The machinist's words and numbers: windows inside the machine, lobes without a recommendation, the shop's
vocabulary, cutting speed and feed checked against a range, the machine's limits on the plot."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from substructure import default_assembly
from substructure.cli import main
from substructure.errors import FileFormatError, InvalidValueError, UnitError
from substructure.stability import (CuttingDataWarning, MachineLimits, MillingCut, NoRecommendationError,
                                    assembly_structure, check_cutting, cutting_conditions, cutting_data,
                                    load_workpieces, recommend, spindle_speeds, workpiece, xy_frf, zoa)
from substructure.units import Q_, show_value

ASSEMBLY = Path(__file__).parent.parent / "substructure" / "data" / "default_assembly.toml"
BASE = ["lobes", "--assembly", ASSEMBLY, "--at", "tool.tip", "--radial-depth", "3 mm"]
THESIS = ["--kt", "625 MPa", "--kn", "100 MPa"]


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    import matplotlib.pyplot as plt

    plt.close("all")


def run(capsys, *argv):
    status = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err and "<Quantity" not in out + err
    return status, out, err


@pytest.fixture(scope="module")
def lobes_and_cut():
    frf, band = assembly_structure(default_assembly(), "tool.tip:y")
    cut = MillingCut(4, "12 mm", "3 mm", kt="625 MPa", kn="100 MPa", feed_per_tooth="0.05 mm")
    return zoa(xy_frf(frf), cut, spindle_speeds("2000 rpm", "24000 rpm", "25 rpm"), band=band), cut


# -- issue 21: the whole window inside the machine; lobes without a recommendation ----------------


@pytest.mark.parametrize("max_speed", [2100.0, 3000.0, 9000.0, 20000.0])
def test_the_whole_speed_window_fits_the_machine(lobes_and_cut, max_speed):
    lobes, cut = lobes_and_cut
    x = 0.03
    try:
        best = recommend(lobes, cut, MachineLimits(max_speed=f"{max_speed} rpm"), speed_tolerance=x)
    except NoRecommendationError as exc:  # only when no computed window fits below the top speed
        assert 2000 * (1 + x) / (1 - x) > max_speed and "max speed" in str(exc)
        return
    for r in (best, *best.runners_up):
        lo, hi = r.window_rpm
        assert hi <= max_speed * (1 + 1e-12) and lo >= 2000 * (1 - 1e-12)
        assert hi == pytest.approx(r.spindle_speed_rpm * (1 + x))
    # the best speed is the fastest-removing of those whose window fits, found here by brute force
    speeds = lobes.spindle_speed_rpm
    ok = (speeds * (1 - x) >= speeds[0]) & (speeds * (1 + x) <= max_speed)
    window_min, _, _ = lobes.window_minimum(speeds[ok] * (1 - x), speeds[ok] * (1 + x))
    assert best.depth_m * best.spindle_speed_rpm == pytest.approx((0.8 * window_min * speeds[ok]).max(), rel=1e-9)


def test_the_minimum_speed_holds_the_window_too(lobes_and_cut):
    lobes, cut = lobes_and_cut
    best = recommend(lobes, cut, MachineLimits(min_speed="12000 rpm"))
    assert all(r.window_rpm[0] >= 12000 * (1 - 1e-12) for r in (best, *best.runners_up))


def test_three_speeds_give_lobes_and_a_reason_instead_of_a_recommendation(capsys):
    argv = [*BASE, *THESIS, "--speeds", "9900:10100:100"]
    code, out, err = run(capsys, *argv, "--json")
    assert code == 0, err
    result = json.loads(out)
    assert len(result["spindle_speed_rpm"]) == 3 and len(result["depth_limit_m"]) == 3
    assert result["recommended"] is None and "window" in result["no_recommendation_reason"]
    code, out, _ = run(capsys, *argv)
    assert code == 0 and "depth limit:" in out and "recommended: none; " in out
    # a recommendation that exists has no reason
    code, out, _ = run(capsys, *BASE, *THESIS, "--json")
    result = json.loads(out)
    assert result["recommended"] is not None and result["no_recommendation_reason"] is None


def test_max_speed_2100_recommends_nothing_rather_than_a_window_past_it(capsys):
    code, out, _ = run(capsys, *BASE, *THESIS, "--max-speed", "2100", "--json")
    result = json.loads(out)
    assert code == 0 and result["recommended"] is None and "2100 rpm" in result["no_recommendation_reason"]
    code, out, _ = run(capsys, *BASE, *THESIS, "--max-speed", "3000", "--json")
    rec = json.loads(out)["recommended"]
    assert rec["window_rpm"][1] <= 3000 and all(r["window_rpm"][1] <= 3000 for r in rec["runners_up"])


# -- the shop's vocabulary ---------------------------------------------------------------------


@pytest.mark.parametrize("name, entry", [
    ("aluminum-6061", "aluminium-6061"), ("6061-T651", "aluminium-6061"), ("Aluminum 6061-T6", "aluminium-6061"),
    ("al6061_t6", "aluminium-6061"), ("1045 steel", "steel-1045"), ("AISI 1045", "steel-1045"),
    ("STEEL_1045", "steel-1045"), ("7075 T73", "aluminium-7075"), ("gray cast iron", "grey-cast-iron"),
    ("ss304", "stainless-304"),
])
def test_the_shops_names_of_work_materials(name, entry):
    assert workpiece(name).name == entry


@pytest.mark.parametrize("name, suggested", [
    ("aluminum", ["aluminium-6061", "aluminium-7075"]),  # ambiguous: a choice, never a guess
    ("alumnium-6016", ["aluminium-6061"]),
    ("1054 steel", ["steel-1045"]),
])
def test_near_misses_get_suggestions_not_guesses(name, suggested):
    with pytest.raises(InvalidValueError, match="did you mean") as info:
        workpiece(name)
    assert all(s in str(info.value) for s in suggested)
    with pytest.raises(InvalidValueError, match="known: ") as info:
        workpiece("brass")
    assert "did you mean" not in str(info.value)


def test_aliases_as_a_string_are_refused_with_the_file_and_key(tmp_path):
    table = tmp_path / "mill.toml"
    table.write_text('[[workpiece]]\nname = "shop-alu"\naliases = "mill"\nmodel = "linear"\nkt = "700 MPa"\n'
                     'source = "our cuts"\n', encoding="utf-8")
    with pytest.raises(FileFormatError) as info:
        load_workpieces(table)
    text = str(info.value)
    assert str(table) in text and "workpiece[0]" in text and "aliases" in text and "list" in text
    table.write_text(table.read_text().replace('aliases = "mill"', 'aliases = ["mill"]'), encoding="utf-8")
    entry = load_workpieces(table)[0]
    assert entry.aliases == ("mill",) and workpiece("MILL", table).name == "shop-alu"


def test_climb_and_conventional_are_down_and_up():
    assert MillingCut(4, "12 mm", "3 mm", kt="1 MPa", kn="1 MPa", milling="Climb").milling == "down"
    assert MillingCut(4, "12 mm", "3 mm", kt="1 MPa", kn="1 MPa", milling="conventional").milling == "up"
    with pytest.raises(InvalidValueError, match="climb"):
        MillingCut(4, "12 mm", "3 mm", kt="1 MPa", kn="1 MPa", milling="sideways")


def test_the_milling_default_is_said_in_every_output(capsys):
    _, out, _ = run(capsys, *BASE, *THESIS, "--speeds", "8000:12000", "--json")
    default = json.loads(out)
    assert default["cut"]["milling"] == "up" and default["milling_default"] is True
    assert any("the default" in n and "climb" in n for n in default["notes"])
    _, out, _ = run(capsys, *BASE, *THESIS, "--speeds", "8000:12000")
    assert "up (conventional) milling" in out and "the default" in out
    _, out, _ = run(capsys, *BASE, *THESIS, "--speeds", "8000:12000", "--milling", "climb", "--json")
    climb = json.loads(out)
    assert climb["cut"]["milling"] == "down" and climb["milling_default"] is False
    _, out, _ = run(capsys, *BASE, *THESIS, "--speeds", "8000:12000", "--milling", "down", "--json")
    assert json.loads(out)["depth_limit_m"] == climb["depth_limit_m"]


@pytest.mark.parametrize("typed", ["5000:20000", "5000-20000", "5k-20k", "5000 to 20000", "5k:20k:50"])
def test_speed_ranges_in_the_forms_people_type(capsys, typed):
    option = "--speed-range" if "-" in typed else "--speeds"
    code, out, err = run(capsys, *BASE, *THESIS, option, typed, "--json")
    assert code == 0, err
    speeds = json.loads(out)["spindle_speed_rpm"]
    assert speeds[0] == 5000 and speeds[-1] == 20000 and np.allclose(np.diff(speeds), 50.0)


def test_thousands_and_plain_language_errors_for_speeds(capsys):
    code, out, _ = run(capsys, *BASE, *THESIS, "--max-speed", "20k", "--json")
    assert code == 0 and json.loads(out)["machine"]["max_speed_rpm"] == 20000
    code, _, err = run(capsys, *BASE, *THESIS, "--max-speed", "20 kHz")
    assert code == 2 and "--max-speed" in err and "rpm" in err
    code, _, err = run(capsys, *BASE, *THESIS, "--max-speed", "fast")
    assert code == 2 and "'fast'" in err


def test_a_quantity_in_a_message_is_shown_in_words():
    assert show_value(Q_(20, "k")) == "20 boltzmann_constant"
    assert show_value("20 mm") == "'20 mm'" and show_value(3.5) == "3.5"
    with pytest.raises(UnitError) as info:
        MachineLimits(max_speed=Q_(20, "k"))
    assert "<Quantity" not in str(info.value) and "20 boltzmann_constant" in str(info.value)


# -- cutting data ------------------------------------------------------------------------------


def test_cutting_speed_feed_and_feed_rate_against_the_hand_formulas(lobes_and_cut):
    lobes, cut = lobes_and_cut
    best = recommend(lobes, cut)
    n = best.spindle_speed_rpm
    vc = math.pi * 0.012 * n  # m/min: pi D n
    assert best.cutting_speed_m_per_min == pytest.approx(vc, rel=1e-12)
    out = best.to_json()
    assert out["cutting_speed_sfm"] == pytest.approx(vc * 3.280839895, rel=1e-9)  # 1 m = 3.2808 ft
    assert out["feed_per_tooth_m"] == pytest.approx(0.05e-3)
    assert out["feed_rate_m_per_min"] == pytest.approx(0.05e-3 * 4 * n, rel=1e-12)
    assert any("m/min" in line and "SFM" in line for line in best.describe())


def test_1045_steel_at_437_m_per_min_warns_and_aluminium_does_not():
    data = cutting_data("1045 steel", "carbide")
    cut = MillingCut.for_workpiece(4, "12 mm", "steel-1045", immersion=1.0, feed_per_tooth="0.05 mm", kr=0.3)
    reasons = check_cutting(cut, 11600.0, data)  # the 11,600 rpm: 437 m/min
    assert len(reasons) == 1 and "437 m/min" in reasons[0] and "above" in reasons[0]
    # the same tool at 4000 rpm is 151 m/min: inside the carbide range for steel
    assert check_cutting(cut, 4000.0, data) == []
    hss = check_cutting(cut, 4000.0, cutting_data("steel-1045", "hss"))  # 151 m/min is far too fast for HSS
    assert len(hss) == 1 and "above" in hss[0] and "hss" in hss[0]
    alu = MillingCut.for_workpiece(4, "12 mm", "aluminium-6061", immersion=0.25, feed_per_tooth="0.5 mm")
    reasons = check_cutting(alu, 11600.0, cutting_data("aluminium-6061"))
    assert len(reasons) == 1 and "feed per tooth 0.5 mm" in reasons[0]
    c = cutting_conditions(alu, np.array([1000.0, 50000.0]), cutting_data("aluminium-6061"))
    assert c["speed_in_range"].tolist() == [False, False]


def test_every_table_row_is_consistent_and_carbide_runs_faster_than_hss():
    from substructure.stability import load_cutting_data, workpieces

    rows = load_cutting_data()
    names = {w.name for w in workpieces()}
    assert {r.workpiece for r in rows} == names  # a row for every work material
    for name in names:
        carbide, hss = cutting_data(name, "carbide"), cutting_data(name, "hss")
        assert hss.speed_range_m_per_min[1] <= carbide.speed_range_m_per_min[1]
        assert hss.speed_range_m_per_min[0] < carbide.speed_range_m_per_min[0]
        assert "assumed" in carbide.source  # the table says what its numbers are


def test_the_command_shows_and_checks_the_cutting_data(capsys):
    argv = ["lobes", "--assembly", ASSEMBLY, "--at", "tool.tip", "--immersion", "1", "--workpiece", "1045 steel",
            "--kr", "0.3"]
    code, out, err = run(capsys, *argv, "--json")
    assert code == 0
    result = json.loads(out)
    rec, shop = result["recommended"], result["cutting_data"]
    assert result["cut"]["feed_per_tooth_m"] == pytest.approx(0.05e-3)  # the table's default, said in a note
    assert any("feed per tooth: 0.05 mm, the default" in n for n in result["notes"])
    assert shop["cutting_speed_m_per_min"] == pytest.approx(math.pi * 0.012 * rec["spindle_speed_rpm"])
    assert shop["speed_in_range"] is False and shop["warnings"] and "warning: cutting speed" in err
    _, human, _ = run(capsys, *argv)
    assert "SFM" in human and "outside the usual 80 to 250 m/min" in human
    code, out, _ = run(capsys, *argv, "--tool-material", "hss", "--json")
    assert json.loads(out)["cutting_data"]["range"]["tool_material"] == "hss"


def test_the_machine_limits_are_drawn_on_the_lobes(lobes_and_cut):
    lobes, cut = lobes_and_cut
    limits = MachineLimits(max_speed="18000 rpm", min_speed="3000 rpm", power="0.4 kW", max_depth="3 mm")
    fig = lobes.plot(limits=limits, cut=cut, recommendation=recommend(lobes, cut, limits))
    labels = [h.get_label() for h in fig.axes[0].get_children() if hasattr(h, "get_label")]
    assert "above the machine's 18,000 rpm" in labels and "below the machine's 3,000 rpm" in labels
    line = next(h for h in fig.axes[0].lines if h.get_label().startswith("depth the spindle"))
    n, depth = line.get_data()
    from substructure.stability import cut_power

    expected = 400.0 / cut_power(cut, 1.0, n) * 1e3  # mm at which the cut takes 0.4 kW
    assert np.allclose(depth, expected, rtol=1e-9, equal_nan=True)


def test_the_warning_category_is_a_substructure_warning():
    from substructure.errors import SubstructureWarning

    assert issubclass(CuttingDataWarning, SubstructureWarning)


def test_a_users_cutting_data_table_is_searched_first_and_checked(capsys, tmp_path):
    table = tmp_path / "shop.toml"
    table.write_text('[[cutting]]\nworkpiece = "steel-1045"\ntool_material = "carbide"\n'
                     'cutting_speed = ["100 m/min", "900 m/min"]\nfeed_per_tooth = ["0.01 mm", "0.1 mm"]\n'
                     'default_feed_per_tooth = "0.03 mm"\nsource = "our coated tools, 2025"\n', encoding="utf-8")
    argv = ["lobes", "--assembly", ASSEMBLY, "--at", "tool.tip", "--immersion", "1", "--workpiece", "steel-1045",
            "--kr", "0.3", "--cutting-data", table, "--json"]
    code, out, err = run(capsys, *argv)
    result = json.loads(out)
    assert code == 0 and result["cut"]["feed_per_tooth_m"] == pytest.approx(0.03e-3)
    assert result["cutting_data"]["range"]["source"] == "our coated tools, 2025"
    assert result["cutting_data"]["warnings"] == [] and "warning" not in err
    table.write_text(table.read_text().replace('cutting_speed = ["100 m/min", "900 m/min"]',
                                               'cutting_speed = "100 m/min"'), encoding="utf-8")
    code, _, err = run(capsys, *argv)
    assert code == 1 and str(table) in err and "cutting[0]" in err and "cutting_speed" in err
    code, _, err = run(capsys, "lobes", "--assembly", ASSEMBLY, "--at", "tool.tip", "--turning", "--kf", "2000 MPa",
                       "--tool-material", "hss")
    assert code == 2 and "--tool-material" in err
