"""`substructure report`: a well-formed, self-contained HTML page with its figures and the recommendation.

The numbers of the page are checked against the workflows run here
(``recommend`` on lobes computed in the test, ``identify_joint``, the
``lobes`` command's JSON), the page's structure with ``html.parser`` and
``xml.etree``, the figures by decoding them, and the command's errors.
The browser check is ``tests/test_report_browser.py``.
"""

from __future__ import annotations

import base64
import html.parser
import io
import json
import re
import xml.etree.ElementTree as ET

import attrs
import numpy as np
import pytest

from substructure import Holder, Sensor, default_assembly, save_assembly
from substructure.cli import main
from substructure.errors import OutputExistsError
from substructure.identify import identify_joint
from substructure.measurements import MeasurementSet
from substructure.report import SUMMARY_KEYS, Report, report
from substructure.stability import (MachineLimits, MillingCut, TurningCut, assembly_structure, recommend,
                                    spindle_speeds, xy_frf, zoa)
from substructure.synthetic import simulate, write_measurement_set

VOID = {"meta", "img", "br", "hr", "input", "link", "source", "col", "area", "base", "wbr"}
CUT = ["--radial-depth", "3 mm", "--milling", "down", "--workpiece", "aluminium-7075", "--feed-per-tooth", "0.05 mm"]
MACHINE = ["--max-speed", "20000", "--power-curve", "0:0,6000:11,20000:11"]


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    import matplotlib.pyplot as plt

    plt.close("all")


def _cut(model):
    tool = model.component("tool")
    return MillingCut.for_workpiece(tool.teeth, tool.cutting_diameter, "aluminium-7075", radial_depth="3 mm",
                                    feed_per_tooth="0.05 mm", milling="down")


def _limits(model):
    return MachineLimits(max_speed="20000 rpm", power=[("0 rpm", "0 kW"), ("6000 rpm", "11 kW"),
                                                       ("20000 rpm", "11 kW")],
                         max_depth=model.component("tool").flute_length)


def _taps(model, seed=4):
    """A tap test with a 2 g accelerometer the record forgot (the demo's story)."""
    rig = model.attach(Sensor("accelerometer", "tool.tip", "2 g"))
    taps = simulate(rig, ["tool.tip"], frequency=model.frequency, noise=0.015, seed=seed,
                    sensors=["accelerometer"], name="tap test")
    return MeasurementSet(taps.name, tuple(attrs.evolve(m, sensors=()) for m in taps))


@pytest.fixture(scope="module")
def model():
    return default_assembly()


@pytest.fixture(scope="module")
def with_cut(model):
    return report(model, cut=_cut(model), limits=_limits(model))


@pytest.fixture(scope="module")
def with_taps(model):
    return report(model, _taps(model), cut=_cut(model), limits=_limits(model))


@pytest.fixture(scope="module")
def pages(with_cut, with_taps, model):
    return {"cut": with_cut.to_html(), "taps": with_taps.to_html(), "bare": report(model).to_html()}


# -- the page's structure ------------------------------------------------------------------------------


class _Balance(html.parser.HTMLParser):
    """Every element closed in order; the tags, attributes and style text seen."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.stack, self.problems, self.tags, self.style = [], [], [], []

    def handle_starttag(self, tag, attrs):
        self.tags.append((tag, dict(attrs)))
        if tag not in VOID:
            self.stack.append(tag)

    def handle_startendtag(self, tag, attrs):
        self.tags.append((tag, dict(attrs)))
        if tag not in VOID:
            self.problems.append(f"<{tag} /> is not a void element")

    def handle_endtag(self, tag):
        if tag in VOID:
            self.problems.append(f"</{tag}> closes a void element")
        elif not self.stack or self.stack[-1] != tag:
            self.problems.append(f"</{tag}> closes <{self.stack[-1] if self.stack else None}>")
        else:
            self.stack.pop()

    def handle_data(self, data):
        if self.stack and self.stack[-1] == "style":
            self.style.append(data)


def _parse(page: str) -> _Balance:
    parser = _Balance()
    parser.feed(page)
    parser.close()
    return parser


@pytest.mark.parametrize("which", ["cut", "taps", "bare"])
def test_the_page_is_well_formed_html_and_xml(pages, which):
    page = pages[which]
    assert page.startswith("<!DOCTYPE html>\n<html")
    parsed = _parse(page)
    assert not parsed.problems and not parsed.stack, (parsed.problems, parsed.stack)
    root = ET.fromstring(page.split("\n", 1)[1])  # every element closed, no named entity: it is XML too
    assert root.tag == "html" and root.find("head/title").text.startswith("Tool report: ")
    ids = [e.get("id") for e in root.iter() if e.get("id")]
    assert len(ids) == len(set(ids))
    for link in root.iter("a"):  # the contents' links go to sections of the page
        assert link.get("href")[1:] in ids


def _urls(page: str) -> list[str]:
    parsed = _parse(page)
    found = [v for _, a in parsed.tags for k, v in a.items() if k in ("src", "href", "action", "data", "poster")]
    for text in parsed.style + [a.get("style", "") for _, a in parsed.tags]:
        found += re.findall(r"url\(\s*['\"]?([^'\")]*)", text)
        found += re.findall(r"@import\s+['\"]?([^'\";]+)", text)
    return found


@pytest.mark.parametrize("which", ["cut", "taps", "bare"])
def test_the_page_fetches_nothing(pages, which):
    page = pages[which]
    parsed = _parse(page)
    tags = {t for t, _ in parsed.tags}
    assert not tags & {"script", "link", "iframe", "object", "embed", "frame", "base", "video", "audio"}
    assert not any(k.startswith("on") for _, a in parsed.tags for k in a)  # no event handlers: no script at all
    for url in _urls(page):
        assert url.startswith("data:image/png;base64,") or re.fullmatch(r"#[\w-]+", url), url[:80]
        assert not url.startswith("//") and "://" not in url and not url.lower().startswith("file:")
    for scheme in ("http:", "https:", "file:", "ftp:"):
        assert scheme not in page.lower()
    assert "@import" not in page and "url(" not in page


def _images(page: str) -> list[np.ndarray]:
    from PIL import Image

    out = []
    for src in re.findall(r'<img src="data:image/png;base64,([^"]+)"', page):
        data = base64.b64decode(src, validate=True)
        assert data[:8] == b"\x89PNG\r\n\x1a\n"
        with Image.open(io.BytesIO(data)) as image:
            image.verify()
        with Image.open(io.BytesIO(data)) as image:
            out.append(np.asarray(image.convert("RGB")))
    return out


def test_the_figures_are_embedded_valid_pngs_with_something_drawn(pages):
    counts = {}
    for which, page in pages.items():
        images = _images(page)
        counts[which] = len(images)
        assert len(images) == page.count("<img ")
        for image in images:
            h, w, _ = image.shape
            assert 250 <= h and 500 <= w <= 1030  # shown at its own size on the page
            grey = image.mean(axis=2)
            assert (grey < 128).mean() > 0.005 and grey.std() > 10  # axes, lines, text: not blank
            assert ((image.max(axis=2).astype(int) - image.min(axis=2)) > 60).mean() > 0.001  # coloured curves
    # the tool point FRF; + the lobes; + where it fails, the error fall and one figure per identified joint
    assert counts == {"bare": 1, "cut": 2, "taps": 2 + 2 + 2}


# -- the numbers on the page -------------------------------------------------------------------------------


def test_the_recommendation_on_the_page_is_the_one_recommend_gives(model, with_cut, pages):
    frf, band = assembly_structure(model, "tool.tip:y")
    lobes = zoa(xy_frf(frf), _cut(model), spindle_speeds("2000 rpm", "24000 rpm", "50 rpm"), band=band)
    best = recommend(lobes, _cut(model), _limits(model), margin=0.2, speed_tolerance=0.03)
    assert with_cut.to_json()["recommended"] == best.to_json()
    page = pages["cut"]
    glance = page.split('id="answer"')[1].split("</section>")[0]
    assert f"Run at <strong>{best.spindle_speed_rpm:,.0f} rpm</strong>" in glance
    assert f"<strong>{best.depth_m * 1e3:.3g} mm</strong>" in glance
    assert f"the chatter limit, {best.limit_depth_m * 1e3:.3g} mm" in glance
    assert f"Removal rate {best.mrr_m3_per_s * 6e7:.3g} cm³/min" in glance
    table = page.split('id="stability"')[1].split("</table>")[0]
    for k, r in enumerate((best, *best.runners_up)):
        row = table.split("<tr>")[2 + k]
        cells = re.findall(r"<td>(.*?)</td>", row)
        assert cells[1] == f"{r.spindle_speed_rpm:,.0f}" and cells[2] == f"{r.depth_m * 1e3:.3g}"
        assert cells[3] == f"{r.limit_depth_m * 1e3:.3g}" and cells[5] == r.limited_by
        assert cells[4] == f"{r.window_rpm[0]:,.0f}–{r.window_rpm[1]:,.0f}"
    assert len(best.runners_up) == 2 and "runner-up 2" in table


def test_the_tool_point_modes_and_band(with_cut, pages, model):
    frf = model.receptance("tool.tip:y")
    data = with_cut.to_json()
    assert data["structure_band"]["kind"] == "free-free" and data["structure_band"]["lo_hz"] > 100
    peaks = frf.crop(data["structure_band"]["lo_hz"], 5000).peaks(prominence=0.05)
    fitted = [m["frequency_hz"] for m in data["modes"]]
    assert len(fitted) == len(peaks) and np.allclose(fitted, peaks, rtol=0.01)
    mag = np.abs(frf.data[:, 0, 0])
    top = max(data["modes"], key=lambda m: m["peak_m_per_n"])
    assert top["peak_m_per_n"] == pytest.approx(mag[frf.frequency.hz > 180].max(), rel=1e-12)
    assert f"most flexible at <strong>{top['frequency_hz']:,.0f} Hz</strong>" in pages["cut"]
    for m in data["modes"]:
        assert 0 < m["damping_ratio"] < 0.2 and m["stiffness_n_per_m"] > 0


def test_the_tap_test_and_the_joints(model, with_taps, pages):
    data = with_taps.to_json()
    diagnosis = data["diagnosis"]
    assert diagnosis["missing_effect"] == "sensor-mass" and diagnosis["final_error"] < 1.5 * diagnosis["noise_floor"]
    page = pages["taps"]
    assert 'class="verdict explained"' in page and "sensor-mass" in page
    expected = identify_joint(model, _taps(model), "holder-tool")
    joint = next(j for j in data["joints"] if j["name"] == "holder-tool")
    assert joint["identified"] == expected.to_json()
    assert joint["model"]["k"]["yf"] == pytest.approx(1.43e7)
    section = page.split('id="joints"')[1].split("</section>")[0]
    assert "Caution: the diagnosis found" in section  # identified values absorb the forgotten sensor
    mantissa = f"{expected.k['yf'] / 1e7:.3f}"
    assert f"{mantissa}&#8201;×&#8201;10<sup>7</sup>" in section
    assert f"Noise floor of the tap test: {diagnosis['noise_floor']:.3g}" in page


@attrs.frozen
class _LaterDiagnosis:
    """A diagnosis as a later version may give it: more keys, standard deviations, an "explained" verdict."""

    real: object
    extra: dict

    def to_json(self):
        out = dict(self.real.to_json())
        out.update(self.extra)
        for effect in out["final_effects"]:
            for spec in effect["parameters"].values():
                spec["std"] = 0.1 * spec["value"]
        return out

    def plot_where(self):
        return self.real.plot_where()

    def plot_history(self):
        return self.real.plot_history()


def test_keys_a_later_diagnosis_adds_are_shown(with_taps):
    later = attrs.evolve(with_taps, diagnosis=_LaterDiagnosis(with_taps.diagnosis,
                                                              {"explained": False, "open_world_candidates": 42}))
    page = later.to_html()
    assert 'class="verdict unexplained"' in page and "Not explained" in page and "partial" in page
    assert "open_world_candidates" in page and ">42<" in page
    assert "mass</span> 2.000 g ± 0.20 g" in page  # the standard deviation of a fitted value
    assert later.to_json()["diagnosis"]["explained"] is False


def test_what_the_data_allow_as_well_is_shown_beside_the_change(with_taps):
    """``equivalents``: another way of changing the same part, said under the change it could stand for; an entry
    pointing nowhere (a hand-edited file) is shown without the change, not a crash."""
    other = {"of": 0, "effect": "added-mass", "where": "tool@75 mm", "error": 0.01,
             "parameters": {"mass": {"value": 0.002, "unit": "kg"}}}
    later = attrs.evolve(with_taps, diagnosis=_LaterDiagnosis(with_taps.diagnosis, {
        "equivalents": [other, {**other, "of": 7}, {**other, "of": "x"}, "not an entry"]}))
    page = later.to_html()
    assert "As well as sensor-mass at tool.tip, the data allow added-mass at tool@75 mm (" in page
    assert page.count("the data allow added-mass at tool@75 mm") == 3 and "As well as ? at ?" in page
    assert "not an entry" not in page


def test_catalogue_holder_taper_and_a_turning_cut(tmp_path):
    base = default_assembly()
    holder = Holder.from_catalog("HSK-A63 shrink-fit", bore="12 mm", gauge_length="80 mm")
    model = base.with_component(holder)
    result = report(model, cut=TurningCut("2000 MPa"))
    page = result.to_html()
    assert "APPROXIMATE" in page and "The geometry of holder is approximate" in page
    assert "→" in page  # a tapered segment: its diameter at both ends
    assert any("Approximate geometry: 'holder'" in a for a in result.assumptions())
    assert result.recommendation is None and "for milling cuts" in result.no_recommendation
    assert result.to_json()["recommended"] is None and page.count("<img ") == 2
    assert not _parse(page).problems


def test_hostile_text_is_escaped(tmp_path):
    model = attrs.evolve(default_assembly(), name='<script>alert("x")</script> & <b>')
    page = report(model).to_html()
    parsed = _parse(page)
    tags = {t for t, _ in parsed.tags}
    assert not parsed.problems and "script" not in tags and "b" not in tags
    assert "&lt;script&gt;" in page
    ET.fromstring(page.split("\n", 1)[1])


def test_save_is_atomic_and_never_replaces_unless_asked(with_cut, tmp_path):
    path = tmp_path / "r.html"
    path.write_text("mine", encoding="utf-8")
    with pytest.raises(OutputExistsError):
        with_cut.save(path)
    assert path.read_text(encoding="utf-8") == "mine"
    assert with_cut.save(path, overwrite=True) == path
    assert path.read_text(encoding="utf-8").startswith("<!DOCTYPE html>")
    assert [p.name for p in tmp_path.iterdir()] == ["r.html"]


def test_report_checks_its_inputs(model):
    with pytest.raises(ValueError, match="margin"):
        report(model, cut=_cut(model), margin=1.0)
    with pytest.raises(ValueError, match="method"):
        report(model, method="fast")
    with pytest.raises(ValueError, match=":theta"):
        report(model, at="tool.tip:theta")
    with pytest.raises(ValueError, match="feed_per_tooth"):
        report(model, cut=attrs.evolve(_cut(model), feed_per_tooth=None), limits=MachineLimits(power="5 kW"))
    with pytest.raises(ValueError, match="frequency grid"):
        report(attrs.evolve(model, frequency=None))
    with pytest.raises(ValueError, match="two|tool components"):
        report(model.without("tool"))
    with pytest.raises(ValueError, match="MeasurementSet"):
        report(model, measurements=list(_taps(model)))
    with pytest.raises(ValueError, match="MillingCut"):
        report(model, cut="3 mm slot")
    with pytest.raises(ValueError, match="rigid"):
        report(model.connect("holder.tip", "tool@1 mm", name="glued"), _taps(model), identify=["glued"])
    stranger = MeasurementSet("t", tuple(attrs.evolve(m, sensors=("nope",)) for m in _taps(model)))
    with pytest.raises(ValueError, match="no sensor 'nope'"):
        report(model, stranger)
    assert isinstance(report(model, at="holder.tip"), Report)


# -- the command --------------------------------------------------------------------------------------------


def _run(capsys, *argv):
    status = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err
    return status, out, err


@pytest.fixture
def files(tmp_path, model):
    save_assembly(model, tmp_path / "model.toml")
    write_measurement_set(_taps(model), tmp_path / "tap")
    return tmp_path / "model.toml", tmp_path / "tap" / "measurements.toml"


def test_command_writes_the_page_and_says_so(capsys, files, tmp_path):
    assembly, taps = files
    out = tmp_path / "report.html"
    status, text, err = _run(capsys, "report", assembly, taps, "--out", out, *CUT, *MACHINE)
    assert status == 0 and out.exists()
    assert f"wrote {out}" in text and "recommended: 18850 rpm" in text and "tap test: The model misses" in text
    assert "substructure: diagnosis against 1 measured FRF" in err  # progress on standard error
    page = out.read_text(encoding="utf-8")
    assert "command: <code>substructure report" in page and "--workpiece aluminium-7075" in page
    assert page.count("<img ") == 6 and not _parse(page).problems


def test_command_json_is_the_summary_and_matches_the_lobes_command(capsys, files, tmp_path):
    assembly, _ = files
    out = tmp_path / "report.html"
    status, text, _ = _run(capsys, "report", assembly, "--out", out, *CUT, *MACHINE, "--json", "--quiet")
    assert status == 0

    def no_constants(name):
        raise AssertionError(f"{name} is not JSON")

    data = json.loads(text, parse_constant=no_constants)
    assert set(data) == set(SUMMARY_KEYS) | {"file", "bytes"}
    assert data["file"] == str(out) and data["bytes"] == out.stat().st_size
    status, text, _ = _run(capsys, "lobes", "--assembly", assembly, "--at", "tool.tip", *CUT, *MACHINE, "--json")
    lobes = json.loads(text)
    assert data["recommended"] == lobes["recommended"]
    assert data["cut"] == lobes["cut"] and data["machine"] == lobes["machine"]
    assert data["structure_band"] == lobes["structure_band"] and data["workpiece"] == lobes["workpiece"]
    assert any(n.startswith("teeth: 4 from the tool") for n in data["notes"])


def test_command_errors_are_clear(capsys, files, tmp_path):
    assembly, taps = files
    out = tmp_path / "r.html"
    cases = [
        ((tmp_path / "nope.toml", "--out", out), 1, "nope.toml"),
        ((assembly, tmp_path / "none.toml", "--out", out), 1, "none.toml"),
        ((assembly, "--out", out, "--radial-depth", "3 mm"), 2, "the milling cut needs --kt or --workpiece"),
        ((assembly, "--out", out, "--radial-depth", "3 mm", "--workpiece", "al", "--kt", "1 GPa"), 2, "not both"),
        ((assembly, "--out", out, "--radial-depth", "30 mm", "--workpiece", "aluminium-7075"), 1, "radial_depth"),
        ((assembly, "--out", out, "--max-speed", "12000"), 2, "--max-speed goes with a cut"),
        ((assembly, "--out", out, "--speeds", "-5:10:1", *CUT), 2, "--speeds"),
        ((assembly, "--out", tmp_path / "r.txt"), 2, "expected an HTML file"),
        ((assembly, "--out", out, "--identify", "holder-tool"), 2, "give MEASUREMENTS.toml"),
        ((assembly, taps, "--out", out, "--identify", "nojoint"), 1, "no joint 'nojoint'"),
        ((assembly, "--out", out, "--at", "tol.tip"), 1, "no component 'tol'"),
        ((assembly, "--out", out, "--turning", "--kf", "2 GPa", "--max-speed", "9000"), 2, "milling cut"),
        ((assembly,), 2, "--out"),
    ]
    for argv, code, message in cases:
        status, text, err = _run(capsys, "report", *argv)
        assert status == code, (argv, err)
        assert text == "" and message in err and err.startswith("substructure: error: "), (argv, err)
        assert not out.exists()
    out.write_text("keep", encoding="utf-8")
    status, _, err = _run(capsys, "report", assembly, "--out", out)
    assert status == 1 and "--overwrite" in err and out.read_text(encoding="utf-8") == "keep"
    status, _, _ = _run(capsys, "report", assembly, "--out", out, "--overwrite", "--quiet")
    assert status == 0 and out.read_text(encoding="utf-8").startswith("<!DOCTYPE html>")


def test_an_identified_value_on_its_search_bound_reads_as_not_a_measurement_in_the_joint_table():
    """The holder-tool joint's c_tm of 1e-6 N m s/rad, 1/4000 of the model's: its fit ends on the lower bound of its
    search (4e-3), which the report's table says beside the value (no +- either); plain FRFs, which say nothing of
    where they were measured, are refused by identify_joint by position."""
    from types import SimpleNamespace

    from substructure import Frequency
    from substructure.errors import InvalidValueError
    from substructure.measurements import Measurement
    from substructure.report import html as report_html

    asm = default_assembly()
    truth = asm.with_joint(asm.joint("holder-tool").with_parameters(c={"tm": "1e-6 N*m*s/rad"}))
    h = truth.receptance("tool.tip:y", frequency=Frequency.from_range("1000 Hz", "5000 Hz", "4 Hz"))
    rng = np.random.default_rng(0)
    noise = 0.02 * (rng.standard_normal(h.data.shape) + 1j * rng.standard_normal(h.data.shape)) / np.sqrt(2)
    h = attrs.evolve(h, data=h.data * (1 + noise))
    with pytest.raises(InvalidValueError, match=r"measurements\[0\]: got FRF; expected a measurement"):
        identify_joint(asm, [h], "holder-tool", parameters=("c_tm",))
    ident = identify_joint(asm, [Measurement.from_frf(h, "tool.tip", "tool.tip")], "holder-tool",
                           parameters=("c_tm",))
    assert ident.at_bound == {"c_tm": "lower"}
    text = report_html._joints(SimpleNamespace(diagnosis=None, identifications=[ident], identification_errors=[],
                                               assembly=asm))
    (cell,) = [c for c in re.findall(r"<td>[^<]*</td>", text) if "bound" in c]
    assert "0.004000" in cell and "on the lower bound of its search: not a measurement" in cell and "±" not in cell


def test_tap_tests_outside_the_models_grid_are_said(model):
    """Tests on lines the model's grid does not reach at all (a kHz column read as Hz, another file) gave a page
    whose receptance and diagnosis showed different bands, without a word."""
    import warnings

    from substructure import Frequency
    from substructure.errors import SubstructureWarning

    elsewhere = attrs.evolve(model, frequency=Frequency.from_hz(np.arange(10_000.0, 12_000.0, 10.0)))
    with warnings.catch_warnings():
        warnings.simplefilter("error", SubstructureWarning)
        with pytest.raises(SubstructureWarning, match=r"the tap tests \(20 to 5000 Hz\) lie outside the model's "
                                                      r"frequency grid \(10000 to 11990 Hz"):
            report(elsewhere, _taps(model), identify=None)


def test_the_compared_band_is_written_in_plain_numbers(with_taps):
    """A band from 20,020 Hz read 'compared from 2.002e+04 to 25000 Hz' (four digits for the first, five for
    the last)."""
    later = attrs.evolve(with_taps, diagnosis=_LaterDiagnosis(with_taps.diagnosis, {"band_hz": [20020.0, 125000.5]}))
    assert "compared from 20020 to 125000 Hz" in later.to_html()
