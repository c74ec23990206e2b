"""No command line ends in a traceback, a non-JSON ``--json`` output or a changed input file.

Hypothesis builds invocations of every command from hostile pieces: files
that are empty, truncated, binary, with a byte-order mark, NaN, a dead
channel, wrong units, one row, directories and missing paths; grids, bands
and speeds with negative numbers, letters, angular units, one line; points
that do not exist; outputs that exist, are directories, have the wrong
suffix or are one of the inputs.  Whatever happens, the command returns 0,
1 or 2 (never 70, the status of an internal error), prints no traceback,
prints exactly one strict JSON object with ``--json`` when it succeeds and
nothing on standard output when it fails, and no file it was given as an
input changes; an existing output changes only with ``--overwrite``.  The
calls are in-process (``main([...])``) and the examples bounded, so that the
test stays fast.
"""

from __future__ import annotations

import hashlib
import itertools
import json
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from substructure import Frequency
from substructure.cli import main

EXAMPLE_TEXT = (Path(__file__).parent / "data" / "formats_example.toml").read_text(encoding="utf-8")
SMALL_GRID = ('start = "200 Hz"', 'stop = "3000 Hz"', 'step = "40 Hz"')


@pytest.fixture(scope="module")
def pool(tmp_path_factory):
    """The input files, written once; the test checks after every call that none of them changed."""
    from substructure.io.assembly_toml import loads_assembly
    from substructure.io.frf_files import write_uff

    d = tmp_path_factory.mktemp("pool")
    model = EXAMPLE_TEXT.replace('start = "20 Hz"', SMALL_GRID[0]).replace('stop = "5000 Hz"', SMALL_GRID[1])
    model = model.replace('step = "2 Hz"', SMALL_GRID[2])
    files = {
        "model.toml": model,
        "model_rpm.toml": model.replace('"200 Hz"', '"12000 rpm"'),
        "model_nan.toml": model.replace('od = "12 mm" }', 'od = "nan mm" }', 1),
        "model_badkey.toml": model.replace('[frequency]', 'colour = "red"\n[frequency]'),
        "empty.toml": "",
        "empty.csv": "",
    }
    for name, text in files.items():
        (d / name).write_text(text, encoding="utf-8")
    (d / "model_bom.toml").write_bytes(b"\xef\xbb\xbf" + model.encode())
    (d / "binary.toml").write_bytes(bytes(range(256)) * 4)
    assembly = loads_assembly(model)
    frf = assembly.receptance("tool.tip:y")
    rows = "".join(f"{float(f)!r},{float(v.real)!r},{float(v.imag)!r}\n"
                   for f, v in zip(frf.frequency.hz, frf.data[:, 0, 0]))
    (d / "tap.csv").write_text("frequency_hz,real,imag\n" + rows)
    (d / "tap_bom.csv").write_bytes(b"\xef\xbb\xbffrequency_hz,real,imag\n" + rows.encode())
    (d / "nan.csv").write_text("frequency_hz,real,imag\n" + rows.replace(rows.splitlines()[3], "280.0,nan,1e-7"))
    (d / "dead.csv").write_text("frequency_hz,real,imag\n"
                                + "".join(f"{float(f)!r},0.0,0.0\n" for f in frf.frequency.hz))
    (d / "one.csv").write_text("frequency_hz,real,imag\n" + rows.splitlines()[0] + "\n")
    (d / "windowed.csv").write_text("# window_tau_s = 0.5\nfrequency_hz,real,imag\n" + rows)
    (d / "window_bad.csv").write_text("# window_tau_s = -1\nfrequency_hz,real,imag\n" + rows)
    (d / "window_short.csv").write_text("# window_tau_s = 1e-6\nfrequency_hz,real,imag\n" + rows)
    write_uff(frf.with_labels(("tool.tip:y",), ("tool.tip:y",)), d / "tap.uff")
    lines = (d / "tap.uff").read_text().splitlines()
    (d / "trunc.uff").write_text("\n".join(lines[: len(lines) // 2]) + "\n")
    for name, data in (("meas", "tap.csv"), ("meas_bom", "tap_bom.csv"), ("meas_dead", "dead.csv"),
                       ("meas_nan", "nan.csv"), ("meas_uff", "tap.uff"), ("meas_trunc", "trunc.uff"),
                       ("meas_missing", "absent.csv"), ("meas_dir", "folder"), ("meas_windowed", "windowed.csv"),
                       ("meas_window_bad", "window_bad.csv")):
        (d / f"{name}.toml").write_text(f'name = "tap"\n[[frf]]\nresponse = "tool.tip"\nexcitation = "tool.tip"\n'
                                        f'file = "{data}"\n')
    header = "tool_diameter [mm],gauge_length [mm],k_yf [N/m]\n"
    body = "".join(f"{d_},{g},{k}\n" for d_, g, k in ((8, 60, 0.9e7), (10, 70, 1.2e7), (12, 76, 1.4e7),
                                                      (16, 80, 2.0e7), (20, 90, 2.6e7)))
    tables = {"table.csv": header + body, "table1.csv": header + body.splitlines()[0] + "\n",
              "table_n.csv": header.replace("[N/m]", "[N]") + body, "table_nan.csv": header + body.replace("76", "nan"),
              "table_const.csv": header + body.replace("60,", "76,").replace("70,", "76,").replace("80,", "76,")
              .replace("90,", "76,"), "table_neg.csv": header + body.replace("1.4e7", "-1.4e7")}
    for name, text in tables.items():
        (d / name).write_text(text)
    (d / "modes.csv").write_text("direction,frequency_hz,damping_ratio,stiffness_n_per_m\nx,1500,0.03,2e7\n"
                                 "y,1500,0.03,2e7\n")
    (d / "folder").mkdir()
    return d


def digest(directory: Path) -> dict:
    return {p.relative_to(directory): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in directory.rglob("*") if p.is_file()}


ASSEMBLIES = ["model.toml", "model_bom.toml", "model_rpm.toml", "model_nan.toml", "model_badkey.toml", "empty.toml",
              "binary.toml", "folder", "absent.toml", "tap.csv"]
MEASUREMENTS = ["meas.toml", "meas_bom.toml", "meas_dead.toml", "meas_nan.toml", "meas_uff.toml", "meas_trunc.toml",
                "meas_missing.toml", "meas_dir.toml", "empty.toml", "model.toml", "folder", "meas_windowed.toml",
                "meas_window_bad.toml"]
FRF_FILES = ["tap.csv", "tap_bom.csv", "nan.csv", "dead.csv", "one.csv", "empty.csv", "folder", "absent.csv",
             "tap.uff", "windowed.csv", "window_bad.csv", "window_short.csv"]
TABLES = ["table.csv", "table1.csv", "table_n.csv", "table_nan.csv", "table_const.csv", "table_neg.csv", "empty.csv",
          "folder", "absent.csv", "tap.csv"]
POINTS = ["tool.tip", "tool.tip:theta", "holder.tip", "tool.nose", "tool@500 mm", "tool.tip:z", "", "-1", "x" * 300]
GRIDS = ["200:3000:40", "-20:5000:2", "20:5000:1e-6", "a:b:c", "20:20:1", "628 rad/s:6283 rad/s:62.83 rad/s",
         "12000 rpm:180000 rpm:2400 rpm", "1e400:1e401:1", "nan:100:1", "20:5000", "", "20 mm:5000:2", "5000:20:2",
         "-0.0:100:25"]
BANDS = ["auto", "500:2500", "-5:10", "10:5", "a:b", "1e9:2e9", "0:0", "nan:5", "1 kHz:2 kHz", "6000 rpm:60000 rpm",
         "", "5"]
NUMBERS = ["2", "0", "-3", "x", "1e400", "nan", "2.5", ""]
QUANTITIES = ["12 mm", "-12 mm", "12", "nan mm", "12 kg", "mm", ""]
PRESSURES = ["600 MPa", "-1 MPa", "x", "600", "1e400 MPa", "600 m"]
SPEEDS = ["2000:24000:500", "-2000:24000:50", "a:b:c", "100 Hz:300 Hz:1 Hz", "24000:2000:50", "2000:2000:1"]
OUTPUT_NAMES = ["new.csv", "new.uff", "new.png", "new.pdf", "existing.csv", "existing.png", ".", "bad.xyz",
                "noext", "missing_dir/x.csv"]
REPORT_NAMES = ["new.html", "existing.html", "new.htm", ".", "new.csv", "noext", "missing_dir/x.html"]

flag = st.booleans()


def pick(values):
    """One of ``values``, the first (the valid one) about half of the time, so that some calls get far."""
    return st.sampled_from(values + [values[0]] * (len(values) - 1))


@st.composite
def invocation(draw):
    """(argv with {pool}/{out} placeholders, the pool files this call reads)."""
    command = draw(st.sampled_from(["frf", "identify", "diagnose", "lobes", "predict", "report", "demo"]))
    argv, inputs = [command], []

    def pool_file(choices):
        name = draw(pick(choices))
        inputs.append(name)
        return f"{{pool}}/{name}"

    def output(option, names=OUTPUT_NAMES):
        choice = draw(st.one_of(pick(names), st.just("INPUT")))
        if choice == "INPUT" and inputs:
            return [option, f"{{pool}}/{draw(pick(inputs))}"]
        return [option, f"{{out}}/{choice if choice != 'INPUT' else 'new.csv'}"]

    if command == "frf":
        argv += [pool_file(ASSEMBLIES), "--at", draw(pick(POINTS))]
        if draw(flag):
            argv += ["--to", draw(pick(POINTS))]
        if draw(flag):
            argv += ["--grid=" + draw(pick(GRIDS))]
        if draw(flag):
            argv += output("--out")
        if draw(flag):
            argv += output("--plot")
    elif command in ("identify", "diagnose"):
        argv += [pool_file(ASSEMBLIES), pool_file(MEASUREMENTS)]
        if command == "identify":
            argv += ["--joint", draw(pick(["holder-tool", "spindle-holder", "nope", ""])),
                     "--parameters", draw(pick(["k_yf", "k_yf,c_yf", "k_zz", ""]))]
            if draw(flag):
                argv += ["--bootstrap", draw(pick(["0", "2", "-1", "x"]))]
        else:
            argv += ["--quiet", "--effects", draw(pick(["sensor-mass", "gremlins"]))]
            if draw(flag):
                argv += output("--save-model")
        if draw(flag):
            argv += ["--band=" + draw(pick(BANDS))]
        if draw(flag):
            argv += output("--plot")
    elif command == "lobes":
        source = draw(pick(["frf", "modes", "assembly", "none", "two"]))
        if source in ("frf", "two"):
            argv += ["--frf", pool_file(FRF_FILES)]
        if source in ("modes", "two"):
            argv += ["--modes", pool_file(["modes.csv", "tap.csv", "empty.csv", "folder"])]
        if source == "assembly":
            argv += ["--assembly", pool_file(ASSEMBLIES), "--at", draw(pick(POINTS))]
        argv += ["--teeth", draw(pick(NUMBERS)), "--diameter", draw(pick(QUANTITIES)),
                 "--immersion", draw(pick(["0.5", "2", "-1", "nan", "1"])), "--kt", draw(pick(PRESSURES)),
                 "--kr", draw(pick(["0.3", "-0.3", "x"]))]
        if draw(flag):
            argv += ["--speeds=" + draw(pick(SPEEDS))]
        if draw(flag):
            argv += ["--band=" + draw(pick(BANDS))]
        if draw(flag):
            argv += ["--window-tau=" + draw(pick(["0.5", "0", "-1", "x", "nan", "1e-6", ""]))]
        if draw(flag):
            argv += output("--plot")
    elif command == "predict":
        argv += [pool_file(TABLES)]
        if draw(flag):
            argv += ["--cross-validate", draw(pick(["loo", "group:tool_diameter", "group:colour", "kfold"]))]
        else:
            argv += ["--features", draw(pick(["tool_diameter=14 mm,gauge_length=80 mm", "tool_diameter=14",
                                              "tool_diameter=14 kg,gauge_length=80 mm", "", "x",
                                              "tool_diameter=14 mm,gauge_length=100 mm"]))]
        if draw(flag):
            argv += output("--plot")
    elif command == "report":
        argv += [pool_file(ASSEMBLIES)]
        if draw(flag):
            argv += [pool_file(MEASUREMENTS), "--identify", draw(pick(["auto", "none", "nope", "holder-tool,x"]))]
        argv += ["--quiet"] + output("--out", REPORT_NAMES)
        if draw(flag):
            argv += ["--radial-depth", draw(pick(QUANTITIES)), "--kt", draw(pick(PRESSURES)),
                     "--kr", draw(pick(["0.3", "-0.3", "x"]))]
            if draw(flag):
                argv += ["--speeds=" + draw(pick(SPEEDS))]
            if draw(flag):
                argv += ["--max-speed", draw(pick(NUMBERS)), "--feed-per-tooth", draw(pick(QUANTITIES)),
                         "--power", draw(pick(["5 kW", "-5 kW", "5"]))]
        elif draw(flag):
            argv += ["--max-depth", draw(pick(QUANTITIES))]  # machine options without a cut: refused
        if draw(flag):
            argv += ["--at", draw(pick(POINTS))]
        if draw(flag):
            argv += ["--band=" + draw(pick(BANDS))]
    else:  # demo: only where it must refuse before any work (a full run is tested elsewhere)
        argv += ["--out", draw(pick(["{out}", "{out}/existing.csv"]))]
    if command != "demo" and draw(flag):  # (demo --overwrite would run the whole demo: tested elsewhere)
        argv.append("--overwrite")
    if draw(flag):
        argv.append("--json")
    return argv, inputs


counter = itertools.count()


@settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture,
                                                                 HealthCheck.too_slow])
@given(case=invocation())
def test_no_command_line_ends_in_a_traceback_bad_json_or_a_changed_input(pool, tmp_path_factory, case, capsys):
    argv, _ = case
    out_dir = tmp_path_factory.mktemp(f"out{next(counter)}")
    for name in ("existing.csv", "existing.png", "existing.html", "default_assembly.toml"):  # a user's files
        (out_dir / name).write_bytes(b"a user's file\n")
    before, before_out = digest(pool), digest(out_dir)
    args = [a.replace("{pool}", str(pool)).replace("{out}", str(out_dir)) for a in argv]
    status = main(args)
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err, (args, err)
    assert status in (0, 1, 2), (args, status, err)
    if status == 0:
        if "--json" in args:
            def refuse(constant):
                raise AssertionError(f"{constant} in the JSON output of {args}")

            assert isinstance(json.loads(out, parse_constant=refuse), dict), args
            assert out.count("\n") == 1
    else:
        assert out == "", (args, out)
        assert err.rstrip("\n").splitlines()[-1].startswith("substructure: error: "), (args, err)
    assert digest(pool) == before, args  # no input changed
    if "--overwrite" not in args:
        after = digest(out_dir)
        assert {k: after.get(k) for k in before_out} == before_out, args  # no existing output replaced


def test_the_pool_is_hostile_enough(pool):
    """The generator's files do what their names say (so that the property test tests something)."""
    from substructure.errors import FileFormatError
    from substructure.io.frf_files import read_csv, read_uff

    assert read_csv(pool / "tap.csv").frequency == Frequency.from_range("200 Hz", "3000 Hz", "40 Hz")
    for name, message in (("dead.csv", "dead channel"), ("nan.csv", "finite"), ("one.csv", "at least 2")):
        with pytest.raises(FileFormatError, match=message):
            read_csv(pool / name)
    with pytest.raises(FileFormatError, match="truncated"):
        read_uff(pool / "trunc.uff")
    assert math.isclose(read_uff(pool / "tap.uff").frequency.start, 200.0)
    assert np.isfinite(read_csv(pool / "tap_bom.csv").data).all()
