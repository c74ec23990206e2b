"""Joint tables (CSV or TOML) written the way people get them wrong: errors with file, line and column."""

from __future__ import annotations

import pytest

from substructure.errors import FileFormatError
from substructure.surrogate import JointTable

TOML = '''[parameters]
k_yf = "N/m"

[features]
tool_diameter = "mm"

[[joints]]
tool_diameter = "12.0 mm"
k_yf = "14300000.0 N/m"
'''


@pytest.mark.parametrize("written, said", [
    ('"12,5 mm"', "a comma"),      # read as 125 mm before
    ('"1 2 mm"', "a number written after '1'"),  # read as 2 mm before
    ("12.0", "bare number"),
])
def test_a_toml_row_value_is_refused_naming_its_row_and_key(tmp_path, written, said):
    path = tmp_path / "joints.toml"
    path.write_text(TOML.replace('"12.0 mm"', written), encoding="utf-8")
    where = r"joints\.toml, line 7: joints\[0\]: tool_diameter: (got|cannot read) "
    with pytest.raises(FileFormatError, match=rf"{where}.*{said}"):
        JointTable.from_toml(path)


def test_a_std_column_without_a_unit_is_refused(tmp_path):
    # it was read in the parameter's unit, a guess: a std may be written in another unit of the same dimension
    path = tmp_path / "joints.csv"
    path.write_text("tool_diameter [mm],k_yf [N/m],k_yf_std\n12,1.43e7,2e5\n", encoding="utf-8")
    with pytest.raises(FileFormatError, match=r"joints\.csv, line 1: standard deviation column 'k_yf_std' has no "
                                              r"unit"):
        JointTable.from_csv(path)


@pytest.mark.parametrize("separator", [";", "\t"])
def test_a_table_separated_by_semicolons_or_tabs_says_so(tmp_path, separator):
    path = tmp_path / "joints.csv"
    path.write_text(separator.join(["tool_diameter [mm]", "k_yf [N/m]"]) + "\n12" + separator + "1,43e7\n",
                    encoding="utf-8")
    with pytest.raises(FileFormatError, match=r"joints\.csv, line 1: the header .* has no comma; the columns .* are "
                                              r"separated by commas"):
        JointTable.from_csv(path)
