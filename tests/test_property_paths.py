"""Random parameter paths, values and names thrown at the API and the assembly file reader.

Whatever comes in, what comes out is a result or one of the project's own errors
(``SubstructureError``: it names the path or the key and what exists), never a bare
``KeyError``, ``IndexError``, ``AttributeError`` or ``TypeError`` from inside, and a
path that works changes the value it names.
"""

from __future__ import annotations

import math

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from substructure import default_assembly, loads_assembly
from substructure.errors import SubstructureError
from substructure.updating import Structure, get_parameter, set_parameters
from substructure.updating.paths import apply_path_si, check_path

MODEL = default_assembly()

_TOKENS = st.sampled_from([
    "components", "joints", "materials", "supports", "sensors", "masses", "tool", "holder", "spindle",
    "holder-tool", "spindle-holder", "carbide", "steel", "segments", "0", "1", "2", "7", "-1", "01", "1e3", "",
    "length", "od", "id", "od_tip", "end", "insert", "flutes", "diameter_ratio", "overhang", "material",
    "k", "c", "q", "yf", "ym", "tf", "tm", "xx", "YF", "E", "e", "rho", "nu", "loss_factor", "colour",
    " ", "$x$", "\x00", "ü", "..",
])
_PATHS = st.lists(_TOKENS, min_size=0, max_size=7).map(".".join) | st.text(max_size=30)
_VALUES = st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.integers(-10**6, 10**6),
                    st.sampled_from([0.0, -1.0, 1e-300, 1e300, 0.5, 1.0, 2.0]))


@settings(max_examples=300, suppress_health_check=[HealthCheck.too_slow])
@given(path=_PATHS, value=_VALUES)
def test_any_path_and_value_give_a_result_or_a_clear_error(path, value):
    try:
        changed = set_parameters(MODEL, {path: value})
    except SubstructureError as exc:
        assert str(exc)
        try:
            check_path(MODEL, path)
        except SubstructureError:
            return
        assert repr(path) in str(exc), f"a value refused at a path that exists does not name the path: {exc}"
        return
    # accepted: the value reads back where it was written (linked parameters are factors of 1 after)
    if isinstance(value, (int, float)) and math.isfinite(float(value)):
        got = get_parameter(changed, path)
        assert math.isfinite(got)


STRUCTURE = Structure.from_assembly(MODEL)


@settings(max_examples=300, suppress_health_check=[HealthCheck.too_slow])
@given(path=_PATHS)
def test_the_si_form_reads_a_path_as_the_assembly_does(path):
    # one parser: a path the assembly refuses is refused on the SI form with the same error and message
    # (asked twice: the second answer comes from the SI form's memory of paths already read)
    try:
        check_path(MODEL, path)
    except SubstructureError as exc:
        for _ in range(2):
            try:
                apply_path_si(STRUCTURE, path, 1.0)
            except SubstructureError as si_exc:
                assert (type(si_exc), str(si_exc)) == (type(exc), str(exc))
            else:
                raise AssertionError(f"the SI form took {path!r}, which the assembly refuses ({exc})")


@settings(max_examples=200, suppress_health_check=[HealthCheck.too_slow])
@given(path=_PATHS)
def test_any_path_read_gives_a_value_or_a_clear_error(path):
    try:
        value = get_parameter(MODEL, path)
    except SubstructureError as exc:
        assert str(exc)
        return
    assert isinstance(value, float)


_NAMES = st.text(max_size=24) | st.sampled_from(["$\\alpha$", "a\x07b", "tool", "", " ", "x" * 300, "ü\u202e"])


@settings(max_examples=150, suppress_health_check=[HealthCheck.too_slow])
@given(name=_NAMES, component=_NAMES)
def test_any_names_in_an_assembly_file_load_or_are_refused_by_key(name, component):
    text = f'''
name = {_toml_string(name)}

[[components]]
name = {_toml_string(component)}
type = "tool"
material = "carbide"
segments = [{{ length = "30 mm", od = "12 mm" }}]
'''
    try:
        assembly = loads_assembly(text)
    except SubstructureError as exc:
        assert str(exc)
        return
    assert assembly.name == name


def _toml_string(value: str) -> str:
    """A TOML basic string holding ``value`` exactly (escapes for quotes, backslashes and controls)."""
    out = []
    for ch in value:
        if ch in '"\\':
            out.append("\\" + ch)
        elif ord(ch) < 0x20 or ord(ch) == 0x7F or 0xD800 <= ord(ch) <= 0xDFFF:
            out.append(f"\\u{ord(ch):04x}" if not 0xD800 <= ord(ch) <= 0xDFFF else "\ufffd")
        else:
            out.append(ch)
    return '"' + "".join(out) + '"'
