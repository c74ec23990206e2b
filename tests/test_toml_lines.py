"""The one TOML reader (substructure._toml): the line of a key in every TOML construct, and errors of each
kind of project file that name the right line.

Expected lines are never taken from the locator: each text marks its line with a comment (``# <-A``) and the
test finds the marker by searching the text.
"""

from __future__ import annotations

import importlib.resources
import tomllib
from pathlib import Path

import pytest

from substructure._toml import TomlDocument, key_path, loads_toml, read_toml
from substructure.errors import FileFormatError


def marked(text: str, mark: str) -> int:
    """The 1-based line of the one line of ``text`` that holds ``# <-mark``, found by search."""
    hits = [n + 1 for n, line in enumerate(text.split("\n")) if line.rstrip().endswith(f"# <-{mark}")]
    assert len(hits) == 1, (mark, hits)
    return hits[0]


def value_at(data, parts):
    for p in parts:
        data = data[p]
    return data


# Each case: TOML text, then (marker, key path) pairs; every path exists in the parsed data (checked, so that a
# case cannot test a key the document does not have).
CONSTRUCTS = {
    "table": ('name = "x"\n[frequency]  # <-T\nstart = "20 Hz"\nstop = "5 kHz"  # <-S\n',
              [("T", ["frequency"]), ("S", ["frequency", "stop"])]),
    "array of tables": ('[[frf]]\nresponse = "a"\n\n[[frf]]  # <-F\nexcitation = "b"\nresponse = "c"  # <-R\n',
                        [("F", ["frf", 1]), ("R", ["frf", 1, "response"])]),
    "nested arrays of tables": (
        '[[a]]\nx = 1\n[[a.b]]\ny = 1\n[[a.b]]  # <-B\ny = 2  # <-Y\n[[a]]  # <-A\nx = 2\n[[a.b]]\ny = 3  # <-Z\n'
        '[a.c]\nw = 4  # <-W\n',
        [("B", ["a", 0, "b", 1]), ("Y", ["a", 0, "b", 1, "y"]), ("A", ["a", 1]), ("Z", ["a", 1, "b", 0, "y"]),
         ("W", ["a", 1, "c", "w"])]),
    "inline table": ('[[joints]]\nname = "ht"\nk = { yf = "1 N/m", tm = "2 N m/rad" }  # <-K\nc = {}\n',
                     [("K", ["joints", 0, "k", "tm"]), ("K", ["joints", 0, "k"])]),
    "array of inline tables across lines": (
        '[[components]]\nname = "tool"\nsegments = [  # <-S\n    { length = "30 mm", od = "12 mm" },\n'
        '    # { od = "a comment, not an element" },\n'
        '    { length = "40 mm", od = "11 mm" },  # <-E\n]\n',
        [("S", ["components", 0, "segments"]), ("E", ["components", 0, "segments", 1, "od"])]),
    "array of values across lines": ('between = [\n  "spindle.tip",\n  "holder.base",  # <-H\n]\n',
                                     [("H", ["between", 1])]),
    "dotted keys": ('[material]\nsteel.E = "210 GPa"\nsteel.rho = "7850 kg/m^3"  # <-R\nsite."a b".c = 1  # <-Q\n',
                    [("R", ["material", "steel", "rho"]), ("Q", ["material", "site", "a b", "c"])]),
    "quoted keys": ('"quoted key" = 1\n\'dot.ted\' = 2  # <-D\n"\\u0041bc" = 3  # <-U\n["a table"]\n"x" = 4  # <-X\n',
                    [("D", ["dot.ted"]), ("U", ["Abc"]), ("X", ["a table", "x"])]),
    "comments with key = inside": ('[tool]\n# od = "10 mm" was the old value\n#od="9 mm"\nod = "12 mm"  # <-O\n',
                                   [("O", ["tool", "od"])]),
    "strings with [ and =": (
        'description = "[[components]] od = 1 [tool]"\n'
        'note = """\n[[components]]\nod = 2\n[tool]\n"""\n'
        "raw = '''od = 3\n[tool]'''\n"
        '[tool]  # <-T\nlabel = "x = [1]" # od = 4\nod = "12 mm"  # <-O\n',
        [("T", ["tool"]), ("O", ["tool", "od"])]),
}


@pytest.mark.parametrize("name", list(CONSTRUCTS))
def test_the_line_of_a_key_in_each_toml_construct(name):
    text, cases = CONSTRUCTS[name]
    doc = loads_toml(text, "t.toml")
    for mark, parts in cases:
        value_at(doc.data, parts)  # the key exists
        assert doc.line(parts) == marked(text, mark), (name, parts)


def test_a_key_the_text_lacks_has_the_line_of_its_container():
    text = 'name = "x"\n[[frf]]\nresponse = "a"\n[[frf]]  # <-F\nfile = "b.csv"\n'
    doc = loads_toml(text, "t.toml")
    assert doc.line(["frf", 1, "excitation"]) == marked(text, "F")
    assert doc.line(["frf", 1]) == marked(text, "F")
    assert doc.line(["excitation"]) is None and doc.line([]) is None  # top level: no line to give
    assert doc.line(["frf", 5, "file"]) == 2  # an array of tables the text has, at its first table


def test_errors_name_file_line_and_key_path():
    text = 'name = "x"\n[[components]]\nname = "tool"\nsegments = [\n  { od = "1 mm" },\n  { od = "0 mm" },  # <-E\n]\n'
    doc = loads_toml(text, "bench.toml")
    line = marked(text, "E")
    assert key_path(["components", 0, "segments", 1, "od"]) == "components[0].segments[1].od"
    error = doc.error(["components", 0, "segments", 1, "od"], "got 0 mm; expected > 0")
    assert isinstance(error, FileFormatError)
    assert str(error) == f"bench.toml, line {line}: components[0].segments[1].od: got 0 mm; expected > 0"
    assert str(doc.error([], "no components")) == "bench.toml: no components"
    # a constructor's field merged into the key path; a path from the top kept; a located message kept
    at = ["components", 0, "segments", 1]
    assert str(doc.wrap(at, "od: got 0 mm")) == f"bench.toml, line {line}: components[0].segments[1].od: got 0 mm"
    assert str(doc.wrap(at, "components[0].segments[1].od: bad")).endswith(": components[0].segments[1].od: bad")
    assert str(doc.wrap(at, "bench.toml, line 1: as it is")) == "bench.toml, line 1: as it is"
    assert str(doc.wrap(at, "no field here")) == f"bench.toml, line {line}: components[0].segments[1]: no field here"


def test_table_checks_name_the_key():
    text = '[[cutting]]\nworkpiece = "x"\nsource = "s"\n[[cutting]]  # <-C\nworkpiece = "y"\nspeed = 3  # <-S\n'
    doc = loads_toml(text, "c.toml")
    with pytest.raises(FileFormatError, match=rf"^c\.toml, line {marked(text, 'S')}: cutting\[1\]\.speed: unknown key; "
                       "allowed keys: workpiece, source$"):
        doc.tables("cutting", ("workpiece", "source"))
    with pytest.raises(FileFormatError, match=rf"^c\.toml, line {marked(text, 'C')}: cutting\[1\]\.source: missing"):
        doc.tables("cutting", ("workpiece", "speed", "source"), ("source",))
    with pytest.raises(FileFormatError, match=r"^c\.toml: no \[\[rows\]\] table$"):
        loads_toml("", "c.toml").tables("rows", ())
    with pytest.raises(FileFormatError, match=r"^c\.toml, line 1: rows: got 3; expected \[\[rows\]\] tables$"):
        loads_toml("rows = 3", "c.toml").tables("rows", ())


def test_reading_refuses_what_is_not_a_toml_document(tmp_path):
    with pytest.raises(FileFormatError, match=r"^a\.toml: got bytes; expected the TOML text as a str$"):
        loads_toml(b"x = 1", "a.toml")
    with pytest.raises(FileFormatError, match=r"^a\.toml: the file is empty; expected an assembly"):
        loads_toml(" \n", "a.toml", "assembly")
    with pytest.raises(FileFormatError, match=r"^a\.toml: invalid TOML: .*line 2"):
        loads_toml("x = 1\ny = \n", "a.toml")
    path = tmp_path / "b.toml"
    path.write_bytes("\ufeff[t]\nk = 1\n".encode())  # a byte-order mark is not part of the document
    doc = read_toml(path, "table")
    assert isinstance(doc, TomlDocument) and doc.data == {"t": {"k": 1}} and doc.line(["t", "k"]) == 2
    assert doc.source == str(path)
    with pytest.raises(FileFormatError, match="is a directory; expected a table"):
        read_toml(tmp_path, "table")


def _paths(value, parts=()):
    """Every key path of parsed TOML (tables' keys, elements of arrays), outermost first."""
    if isinstance(value, dict):
        for key, inner in value.items():
            yield (*parts, key)
            yield from _paths(inner, (*parts, key))
    elif isinstance(value, list):
        for i, inner in enumerate(value):
            yield (*parts, i)
            yield from _paths(inner, (*parts, i))


@pytest.mark.parametrize("name", ["default_assembly.toml", "holders.toml", "joint_priors.toml", "cutting_data.toml",
                                  "cutting_coefficients.toml"])
def test_every_key_of_the_projects_files_is_found_on_a_line_that_names_it(name):
    """The package's own files: each key's line holds the key's name (or, for a table of an array of tables,
    the header ``[[...]]``), found independently by the parser's data and a text search."""
    text = (importlib.resources.files("substructure") / "data" / name).read_text(encoding="utf-8")
    doc = loads_toml(text, name)
    lines = text.split("\n")
    for parts in _paths(tomllib.loads(text)):
        line = doc.line(parts)
        assert line is not None, parts
        if isinstance(parts[-1], str):
            assert parts[-1] in lines[line - 1], (parts, line)
        elif lines[line - 1].lstrip().startswith("[["):  # a table of an array of tables: its header
            assert f"{parts[-2]}]]" in lines[line - 1], (parts, line)
        else:  # an element of an array of values: on or after the line of its key
            assert line >= doc.line(parts[:-1]), (parts, line)


# -- errors of each kind of project file name the right line --------------------------------------------------

def test_an_assembly_error_names_the_line(tmp_path):
    from substructure.io.assembly_toml import load_assembly

    text = (importlib.resources.files("substructure") / "data" / "default_assembly.toml").read_text("utf-8")
    note = 'description = """a note\n[[components]]\nsegments = [{ od = "1 mm" }]\n"""\n'  # headers in a string
    edited = text.replace('name = "tool"\ntype = "tool"\n', 'name = "tool"\ntype = "tool"\n' + note).replace(
        '"12 mm", flutes = { diameter_ratio = 0.8 } },  # fluted: equivalent diameter 0.8 * 12 mm',
        '"12 kg", flutes = { diameter_ratio = 0.8 } },  # <-O')
    assert edited.count("# <-O") == 1 and note in edited
    path = tmp_path / "bench.toml"
    path.write_text(edited, encoding="utf-8")
    with pytest.raises(FileFormatError) as info:
        load_assembly(path)
    assert str(info.value).startswith(f"{path}, line {marked(edited, 'O')}: components[2].segments[1].od: "), \
        str(info.value)


def test_a_measurement_set_error_names_the_line(tmp_path):
    from substructure.io.measurements import load_measurements

    text = ('name = "bench"\n[[frf]]\n# averages = 5 in the first try\nresponse = "tool.tip"\n'
            'excitation = "tool.tip"\nfile = "a.csv"\naverages = 0  # <-A\n')
    path = tmp_path / "set.toml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(FileFormatError, match=rf"^{path}, line {marked(text, 'A')}: frf\[0\]\.averages: got 0"):
        load_measurements(path)


def test_a_study_error_names_the_line(tmp_path):
    from study_files import write_study

    from substructure.study import Study

    path = write_study(tmp_path / "s", n=1)
    text = path.read_text().replace('radial_depth = "3 mm"', 'radial_depth = "3 kg"  # <-R')
    path.write_text(text)
    with pytest.raises(FileFormatError) as info:
        Study.from_file(path)
    assert str(info.value).startswith(f"{path}, line {marked(text, 'R')}: cuts[0].radial_depth: "), str(info.value)


def test_workpiece_cutting_data_and_joint_tables_name_the_line(tmp_path):
    from substructure.stability import load_cutting_data, load_workpieces
    from substructure.surrogate import JointTable

    text = ('[[workpiece]]\nname = "a"\nmodel = "linear"\nkt = "700 MPa"\nsource = "s"\n\n'
            '[[workpiece]]\nname = "b"\nmodel = "linear"\nkt = "700 mm"  # <-K\nsource = "s"\n')
    path = tmp_path / "work.toml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(FileFormatError, match=rf"^{path}, line {marked(text, 'K')}: workpiece\[1\]\.kt: "):
        load_workpieces(path)
    path.write_text(text.replace('"700 mm"', '"700 MPa"').replace('name = "b"', 'name = "B"\naliases = ["A"]  # <-L'))
    with pytest.raises(FileFormatError, match=rf"line {marked(path.read_text(), 'L')}: workpiece\[1\]\.aliases: "
                       "the name 'A' is used by 'a' and 'B'"):
        load_workpieces(path)

    row = ('[[cutting]]\nworkpiece = "steel-1045"\ntool_material = "carbide"\n{speed}\n'
           'feed_per_tooth = ["0.01 mm", "0.1 mm"]\ndefault_feed_per_tooth = "0.03 mm"\nsource = "ours"\n')
    text = row.format(speed='cutting_speed = ["100 m/min", "900 m/min"]') + "\n" + row.format(
        speed='cutting_speed = "100 m/min"  # <-C')
    path = tmp_path / "cut.toml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(FileFormatError, match=rf"^{path}, line {marked(text, 'C')}: cutting\[1\]\.cutting_speed: "):
        load_cutting_data(path)

    text = ('[parameters]\nk_yf = "N/m"\n\n[features]\ntool_diameter = "mm"\n\n[[joints]]\n'
            'tool_diameter = "12 mm"\nk_yf = "1e7 N/m"\n\n[[joints]]  # <-J\ntool_diameter = "12 kg"\n'
            'k_yf = "1e7 N/m"\n')
    path = tmp_path / "joints.toml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(FileFormatError, match=rf"^{path}, line {marked(text, 'J')}: joints\[1\]: tool_diameter"):
        JointTable.from_toml(path)


def test_the_old_line_finders_are_gone():
    """One reader: no module of the package finds lines of TOML keys by itself."""
    root = Path(__file__).resolve().parents[1] / "substructure"
    for path in root.rglob("*.py"):
        source = path.read_text(encoding="utf-8")
        assert "class _Locator" not in source and "class _Lines" not in source, path
        if path.name not in ("_files.py", "_toml.py"):
            assert "tomllib.loads" not in source, path


def _random_document(rng, depth=0):
    """Random nested data of every kind TOML holds; keys bare, with spaces, dots or accents (quoted when written)."""
    keys = ["od", "k", "name", "a b", "x.y", "é", "segments", "1", "-z"]
    scalars = [lambda: int(rng.integers(-9, 9)), lambda: float(rng.normal()), lambda: bool(rng.integers(2)),
               lambda: rng.choice(["plain", "[[frf]]", "od = 3 # not a comment", "'quoted'", 'say "hi"', "a\nb"])]
    out = {}
    for key in rng.choice(keys, size=int(rng.integers(1, 5)), replace=False):
        kind = rng.integers(5) if depth < 3 else 0
        if kind == 0:
            out[str(key)] = scalars[int(rng.integers(len(scalars)))]()
        elif kind == 1:
            out[str(key)] = _random_document(rng, depth + 1)
        elif kind == 2:  # an array of tables
            out[str(key)] = [_random_document(rng, depth + 1) for _ in range(int(rng.integers(1, 4)))]
        elif kind == 3:
            out[str(key)] = [scalars[0]() for _ in range(int(rng.integers(0, 4)))]
        else:
            out[str(key)] = [[scalars[0]()], {"in": scalars[3]()}]
    return out


def test_documents_written_by_another_program_have_every_key_on_a_line_that_names_it():
    """tomli_w (the package's writer) lays random documents out as it likes; every key path the parser finds has
    a line, and a named key's line holds its name."""
    import numpy as np
    import tomli_w

    rng = np.random.default_rng(22)
    for _ in range(200):
        text = tomli_w.dumps(_random_document(rng))
        doc, lines = loads_toml(text, "r.toml"), text.split("\n")
        for parts in _paths(doc.data):
            line = doc.line(parts)
            assert line is not None, (parts, text)
            if isinstance(parts[-1], str):
                assert parts[-1] in lines[line - 1], (parts, line, text)
