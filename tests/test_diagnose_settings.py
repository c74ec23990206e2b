"""The diagnosis's settings (diagnose.settings), its words (diagnose.words) and the records of a Diagnosis.

Every field of DiagnoseSettings is checked on construction and named in the
error; a setting given to diagnose changes what it does (the threshold it
names, not another); the defaults are the numbers the other diagnosis tests
were written for (those tests run with them); every field is listed with its
default in docs/diagnose.md; the verdict's sentences are written in one module.
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import attrs
import numpy as np
import pytest

import hidden_data as hd
from substructure import FRF
from substructure.diagnose import DEFAULT_SETTINGS, DiagnoseSettings, diagnose
from substructure.diagnose.compare import compare
from substructure.diagnose.report import level_signature
from substructure.diagnose.result import Alternatives, Changes, Diagnosis, Measures, Verdict
from substructure.diagnose.scan import finer, places, trials
from substructure.errors import InvalidValueError
from substructure.updating.changes import ParamSpec

ROOT = Path(__file__).parent.parent
FIELDS = [f.name for f in attrs.fields(DiagnoseSettings)]

# one value out of range for every field (a new field must be added here, or the first test fails)
OUT_OF_RANGE = {
    "budget": 0.0, "budget_lines": 0, "time_limit": -1.0, "max_steps": 0, "most_changes": 0, "screen_lines": 0,
    "peak_lines": -1,
    "mode_peak_share": 1.0, "mode_prominence": 0.0, "mode_prominence_floors": -1.0, "mode_pairing": 1.0,
    "error_bands_share": 0.0, "error_bands_width": 1.5, "error_bands_floors": -2.0, "main_mode_share": 1.5,
    "shortlist_share": 0.0, "shortlist_max": 0, "tie_chi2": -1.0,
    "short_fit_evaluations": 0, "inertia_floor": 0.0, "scan_values": 1, "scan_values_placed": 1,
    "signed_decades": 0.0, "signed_values_min": 1, "body_positions": 1, "section_lengths": (0.5, 1.2),
    "section_starts": 1, "section_ratios": (0.7, -1.0), "named_grid": 1, "named_second": 1, "named_third": 1,
    "scale_span": 1.0, "scale_values": 1, "place_search": -1, "polish_points": 0, "brent_candidates": -1,
    "brent_evaluations": 0,
    "brent_tolerance": 0.0, "slope_divisions": 1, "jacobian_step": 1.0, "mode_window": 1.0, "mode_follow": 0.0,
    "mode_locate": -0.1, "in_place_lines": -1, "secant_iterations": -1, "secant_first_step": 0.0,
    "secant_max_step": -1.5, "secant_tolerance": 0.0, "element_probe_linear": 2.0, "element_probe_log": 0.0,
    "element_factors": (), "mode_start_places": 0, "rigid_places": 1, "rigid_sharpened": -1, "rigid_span": 0.0,
    "rigid_below": 0.6, "rigid_free": 1.0, "rigid_resonances": 1, "rigid_shifts": (), "rigid_places_alone": 1,
    "review_pool": -1, "review_near_share": 1.1,
    "pair_pool": -1,
    "same_direction": 1.01, "pair_screen_evaluations": 0, "pairs_fitted": -1,
    "other_firsts": -1, "pair_seconds": 0, "confirm_firsts": -1,
    "confirm_screen_step": 0, "confirm_named": -1, "other_starts": -1,
    "other_apart": 0.0, "other_apart_std": -3.0, "rivals_checked": -1, "explained_error_factor": 0.9,
    "partial_gain": -0.1, "seen_window": "yes",
    "calibration": 1.0, "point_reach": -0.001, "tip_share": 1.0, "calibration_hint": (0.01, 1.0),
    "signature_step": 1.0, "signature_window": 1.0, "signature_share": 1.0, "level_bands": 0,
    "level_floors": -2.0, "level_spread": 1.0, "level_in_place": 1.0, "report_bands": 0, "band_merge": 1.0,
    "separation_every": 0,
}


def test_every_field_has_an_out_of_range_case():
    assert sorted(OUT_OF_RANGE) == sorted(FIELDS)


@pytest.mark.parametrize("name", FIELDS)
def test_a_value_out_of_range_is_refused_naming_the_field(name):
    with pytest.raises(InvalidValueError, match=rf"^DiagnoseSettings\.{name}: got .*; expected "):
        DiagnoseSettings(**{name: OUT_OF_RANGE[name]})


@pytest.mark.parametrize("name", FIELDS)
@pytest.mark.parametrize("bad", ["3", True, float("nan"), [object()]], ids=["text", "bool", "nan", "list"])
def test_a_value_of_the_wrong_type_is_refused_naming_the_field(name, bad):
    if isinstance(getattr(DEFAULT_SETTINGS, name), bool) and bad is True:
        bad = 1  # a flag's (seen_window) wrong type is a number
    with pytest.raises(InvalidValueError, match=rf"^DiagnoseSettings\.{name}: "):
        DiagnoseSettings(**{name: bad})


def test_the_defaults_are_valid_frozen_and_keyword_only():
    assert DiagnoseSettings() == DEFAULT_SETTINGS
    with pytest.raises(attrs.exceptions.FrozenInstanceError):
        DEFAULT_SETTINGS.most_changes = 3  # type: ignore[misc]
    with pytest.raises(TypeError):
        DiagnoseSettings(3000)  # type: ignore[misc]
    assert DiagnoseSettings(section_ratios=[0.8, 1.1]).section_ratios == (0.8, 1.1)
    assert DiagnoseSettings(budget=None, time_limit=None).budget is None


def test_the_settings_read_back_from_their_json():
    changed = DiagnoseSettings(most_changes=3, section_lengths=(0.2, 0.5), budget=None)
    data = json.loads(json.dumps(changed.to_json(), allow_nan=False))
    assert DiagnoseSettings(**data) == changed


def test_the_settings_page_lists_every_field_with_its_default():
    page = (ROOT / "docs" / "diagnose.md").read_text(encoding="utf-8")
    section = re.split(r"^## \d+\. Settings$", page, flags=re.MULTILINE)[1].split("\n## ", 1)[0]
    rows = dict(re.findall(r"^\| `(\w+)` \| `([^`]*)` \|", section, flags=re.MULTILINE))
    assert sorted(rows) == sorted(FIELDS)
    for name in FIELDS:
        assert rows[name] == repr(getattr(DEFAULT_SETTINGS, name)), name


# -- the settings change what they name --------------------------------------------------------------


def _log_spec():
    return ParamSpec("k", "N/m", 1e5, 1e9, 1e7)


def test_the_scan_grids_follow_the_settings():
    """A change of one log parameter at one place: the grid's values, its nominal and its start."""
    from substructure.updating.elements import GroundSpring

    spring = GroundSpring("tool", 0.08)
    assert len(places(spring)) == 9
    assert len(places(spring, DiagnoseSettings(body_positions=4))) == 4
    positions = np.array([p["position"] for p in places(spring, DiagnoseSettings(body_positions=5))])
    assert positions.size == 5 and np.allclose(np.diff(positions), np.diff(positions)[0])
    count = len({round(t[spring.specs[0].name], 12) for t in trials(spring)})
    fewer = len({round(t[spring.specs[0].name], 12) for t in trials(spring, settings=DiagnoseSettings(
        scan_values_placed=3))})
    assert fewer == count - 2  # two values fewer on the grid; the start is the same


def test_an_elements_size_is_searched_at_each_of_its_places():
    """The minimum of a body's size at every place: a cost whose minimum at each place is a known mass between the
    scan's grid values, lowest at the holder's tip, where the grid's values are far off: the scan's best trial is
    elsewhere."""
    from substructure.updating.elements import AddedMass

    body = AddedMass("holder", 0.066, 0.9, (0.0, 0.066), 1e-3)
    best_mass = {p["position"]: 0.013 * (1.0 + 3.0 * p["position"] / 0.066) for p in places(body)}  # 13 g to 52 g

    def cost(trial):  # steep in the log of the mass, lowest at the tip
        miss = np.log(trial["mass"] / best_mass[trial["position"]])
        return 1e4 * miss**2 + 100.0 * (1.0 - trial["position"] / 0.066)

    tried = trials(body)
    costs = [cost(t) for t in tried]
    assert min(zip(costs, tried), key=lambda ct: ct[0])[1]["position"] < 0.066  # the grid's best is not the tip
    batches = []

    def evaluate(batch):
        batches.append(len(batch))
        return [cost(t) for t in batch]

    more, more_costs = finer(body, tried, costs, evaluate)
    assert set(batches) == {len(places(body))}  # the places together at each step
    assert len(batches) == DiagnoseSettings().place_search + 1
    assert more_costs == [cost(t) for t in more]
    # every place's minimum, within the golden section's last interval (two grid steps shrunk at each step)
    step = np.log(0.9 / body.specs[0].lower) / (DiagnoseSettings().scan_values_placed - 1)
    last = 2.0 * step * ((np.sqrt(5.0) - 1.0) / 2.0) ** (DiagnoseSettings().place_search - 1)
    for x, mass in best_mass.items():
        found = min((c, t["mass"]) for c, t in zip(more_costs, more) if t["position"] == x)[1]
        assert abs(np.log(found / mass)) < last, x
        assert abs(np.log(found / mass)) > 0.0  # the grid holds no minimum: the search moved
    assert min(zip(more_costs, more), key=lambda ct: ct[0])[1]["position"] == pytest.approx(0.066)
    assert finer(body, tried, costs, evaluate, DiagnoseSettings(place_search=0)) == ([], [])
    # below: only the places where some trial costs less are searched
    least = {x: min(c for c, t in zip(costs, tried) if t["position"] == x) for x in best_mass}
    below = float(np.median(list(least.values())))
    searched = {t["position"] for t in finer(body, tried, costs, evaluate, below=below)[0]}
    assert searched == {x for x, c in least.items() if c < below} and 0 < len(searched) < len(least)
    from substructure import default_assembly
    from substructure.updating.parameters import model_parameters, parameter_change

    one_place = parameter_change(model_parameters(default_assembly())[0])  # a parameter of the model: no places
    assert finer(one_place, trials(one_place), [0.0] * len(trials(one_place)), evaluate) == ([], [])


def _scaled_baseline(factor: float):
    model = hd.nominal_model()
    frfs = [FRF(f.frequency, f.data * factor, f.outputs, f.inputs)
            for f in hd.measure(seed=31, points=("tool.tip", "tool.tip-30 mm"))]
    return [compare(model.frf(list(f.outputs), list(f.inputs), f.frequency), f) for f in frfs]


def test_the_level_signatures_threshold_in_noise_floors_is_the_setting():
    """The median log ratio of each FRF against its noise floor, computed here: the calibration line is
    written when the setting is below that ratio and not when it is above."""
    baseline = _scaled_baseline(1.1)
    floor = max(c.noise_floor for c in baseline)
    ratio = min(abs(float(np.median(np.log(np.abs(c.measured.data[:, 0, 0]) / np.abs(c.model.data[:, 0, 0])))))
                for c in baseline) / floor
    assert ratio > 2.0  # the default finds it (tests/test_diagnose_level.py)
    below, _ = level_signature(baseline, floor, DiagnoseSettings(level_floors=0.95 * ratio))
    above, info = level_signature(baseline, floor, DiagnoseSettings(level_floors=1.05 * ratio))
    assert len(below) == 1 and "calibration" in below[0]
    assert (above, info) == ([], {})


def test_the_comparisons_of_the_diagnosis_follow_the_settings():
    """A tool 4 mm longer shifts every mode: paired by default (within a factor 1.5), unpaired when two modes
    may differ by a millionth at most; the error bands stop at the first when one covers the share asked for."""
    from substructure.diagnose.diagnosis import _comparisons
    from substructure.updating.likelihood import Likelihood, measured_frfs

    measured, _ = measured_frfs(hd.measure(seed=9, tool_length=0.080), None)
    lik = Likelihood(hd.nominal_model(), measured)
    floors = [m.noise.floor for m in measured]
    (default,) = _comparisons(lik, lik.log_ratios([]), floors)
    (strict,) = _comparisons(lik, lik.log_ratios([]), floors, DiagnoseSettings(mode_pairing=1.000001,
                                                                                error_bands_share=1e-6))
    shifts = [abs(math.log(p.model_hz / p.measured_hz)) for p in default.modes if p.model_hz is not None]
    assert len(shifts) >= 2 and min(shifts) > 1e-6
    assert [p.measured_hz for p in strict.modes] == [p.measured_hz for p in default.modes]
    assert all(p.model_hz is None for p in strict.modes)
    assert len(default.bands) >= 1 and strict.bands == default.bands[:1]


def test_an_explicit_budget_wins_over_the_settings_and_the_settings_budget_is_used():
    model = hd.nominal_model()
    data = hd.measure(seed=5, sh_cross=3.0e5, nut=(0.06, 2e-5, 0.04))
    for d in (diagnose(model, data, settings=DiagnoseSettings(budget=1e-3)),
              diagnose(model, data, budget=1e-3, settings=DiagnoseSettings(budget=None))):
        assert d.search["cut"] and d.search["steps_screened"] == 0 and d.search["budget"] == 1e-3
        assert any("cut by its budget" in line for line in d.report)
        assert d.settings.budget in (1e-3, None)
    with pytest.raises(InvalidValueError, match="^settings: got"):
        diagnose(model, data, settings={"most_changes": 1})
    with pytest.raises(InvalidValueError, match="^max_steps: got 0"):
        diagnose(model, data, max_steps=0)


@pytest.fixture(scope="module")
def reground_one_change():
    """The held-out reground tool with a forgotten sensor (tests/test_diagnose_heldout.py), at most one change."""
    frfs = hd.measure(seed=21, tool_length=0.072, sensor_kg=0.003)
    return diagnose(hd.nominal_model(), frfs, settings=DiagnoseSettings(most_changes=1))


def test_with_one_change_at_most_two_effects_are_a_missing_effect_not_an_explanation(reground_one_change):
    """By default the case is explained by two changes (the held-out test); with ``most_changes=1`` the same
    two changes are reported as partial, and the verdict says one effect is missing."""
    d = reground_one_change
    assert not d.explained
    assert d.report[0].startswith("unexplained: no candidate explains the data with at most 1 changes; 2 together")
    assert "the mark of one effect the search lacks" in d.report[0]
    assert d.report[1].startswith("the best (composite) explanation is reported as partial")
    assert sorted(e.name for e in d.effects) == ["model-parameter", "sensor-mass"]
    assert d.to_json()["settings"]["most_changes"] == 1


def test_the_verdict_of_too_many_changes_says_how_far_each_step_passed_its_test(reground_one_change):
    """Two real effects (a reground tool, a forgotten sensor) each pass their step's test many times over: the
    verdict gives those factors and how to take the changes as one explanation, rather than calling every such
    composite changes that "each buy a small improvement" (three effects at once were said so)."""
    d = reground_one_change
    steps = [s for s in d.changes.refinement if s.statistic is not None]
    factors = re.search(r"the forward steps passed their tests ([0-9.e+, ]+) times over", d.report[0])
    assert factors, d.report[0]
    said = [float(x) for x in factors.group(1).split(", ")]
    assert said == pytest.approx([s.statistic / s.threshold for s in steps], rel=5e-3) and min(said) > 10
    assert "DiagnoseSettings(most_changes=2) takes them as one" in d.report[0]


# -- the records of a Diagnosis ------------------------------------------------------------------------


def test_the_records_are_read_under_their_old_names_and_cannot_be_set():
    model = hd.nominal_model()
    d = Diagnosis(verdict=Verdict(False, ("unexplained: x",), "added-mass", "tool"),
                  measures=Measures("rms_log_ratio", (20.0, 5000.0), 0.01, 0.3, 0.2),
                  changes=Changes((), model),
                  alternatives=Alternatives(ambiguous_with=("sensor-mass",), suggestion="measure"))
    assert (d.explained, d.report, d.missing_effect, d.missing_where) == (False, ("unexplained: x",), "added-mass",
                                                                          "tool")
    assert (d.metric, d.band, d.noise_floor, d.baseline_error, d.final_error) == ("rms_log_ratio", (20.0, 5000.0),
                                                                                   0.01, 0.3, 0.2)
    assert d.refined_assembly is model and d.effects == [] and d.candidates == () and d.refinement == ()
    assert d.ambiguous_with == ("sensor-mass",) and d.suggestion == "measure" and d.rivals == ()
    assert d.consistency is None and math.isnan(Measures("m", (0.0, 1.0), 1.0, 1.0).final_error)
    assert d.settings is DEFAULT_SETTINGS
    with pytest.raises(AttributeError):
        d.explained = True  # type: ignore[misc]


# -- the words ---------------------------------------------------------------------------------------------


def test_the_verdicts_sentences_are_written_in_one_module():
    """No module of the diagnosis but words composes the verdict's lines."""
    sentences = ("no candidate explains the data", "is reported as partial", "the bound of its search",
                 "to tell them apart", "cut by its budget", "the remaining error lives in", "signature: ",
                 "measure the {kind}", "best partial explanation", "missing effect")
    for path in sorted((ROOT / "substructure" / "diagnose").glob("*.py")):
        if path.name == "words.py":
            continue
        code = "\n".join(line for line in path.read_text(encoding="utf-8").splitlines()
                         if not line.strip().startswith("#"))
        # docstrings may speak of the sentences; code strings (f-strings, literals in calls) may not
        strings = re.findall(r"""f?"(?:[^"\\\n]|\\.)*"(?!"")""", code)
        for text in sentences:
            assert not any(text in s for s in strings), (path.name, text)
    cli = (ROOT / "substructure" / "cli" / "diagnose_command.py").read_text(encoding="utf-8")
    assert "missing effect" not in cli and "verdict:" not in cli
