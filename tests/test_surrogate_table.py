"""The joint-parameter table: CSV round trip, appending identification results, errors."""

from __future__ import annotations

import numpy as np
import pytest

from substructure.errors import FileFormatError, InvalidValueError, UnitError
from substructure.surrogate import JointTable, thesis_table_4_2


def test_csv_round_trip(tmp_path):
    table = thesis_table_4_2()
    path = tmp_path / "joints.csv"
    table.to_csv(path)
    back = JointTable.from_csv(path)
    assert back.parameters == {"k_yf": "N/m"} and back.features == {"tool_diameter": "mm", "gauge_length": "mm"}
    np.testing.assert_array_equal(back.values("k_yf"), table.values("k_yf"))
    assert np.isnan(back.stds("k_yf")).all()


def test_append_converts_units_and_rejects_mismatch():
    table = thesis_table_4_2().append({"tool_diameter": "1.4 cm", "gauge_length": "0.09 m",
                                       "k_yf": "15 MN/m", "k_yf_std": "1 MN/m"})
    assert len(table) == 14
    assert table.feature("tool_diameter")[-1] == pytest.approx(14.0)
    assert table.values("k_yf")[-1] == pytest.approx(1.5e7) and table.stds("k_yf")[-1] == pytest.approx(1e6)
    with pytest.raises(UnitError, match="do not match"):
        table.append({"tool_diameter": "14 kg", "gauge_length": "90 mm", "k_yf": "1e7 N/m"})
    with pytest.raises(InvalidValueError, match="missing"):
        table.append({"tool_diameter": "14 mm", "k_yf": "1e7 N/m"})


def test_append_identification_report():
    class Report:  # the fields of substructure.identify.IdentificationReport that the table reads
        joint = "holder-tool"
        k = {"yf": 1.6e7, "ym": 0.0, "tf": 0.0, "tm": 8e4}
        c = {"yf": 12.0, "ym": 0.0, "tf": 0.0, "tm": 4.0}
        k_std = {"yf": 4e5, "ym": 0.0, "tf": 0.0, "tm": 0.0}
        c_std = {"yf": 0.0, "ym": 0.0, "tf": 0.0, "tm": 0.0}

    table = thesis_table_4_2().append_report(Report(), {"tool_diameter": "14 mm", "gauge_length": "90 mm"})
    assert table.values("k_yf")[-1] == 1.6e7 and table.stds("k_yf")[-1] == 4e5


def test_bad_files(tmp_path):
    empty = tmp_path / "empty.csv"
    empty.write_text("")
    with pytest.raises(FileFormatError, match="empty"):
        JointTable.from_csv(empty)
    nounit = tmp_path / "nounit.csv"
    nounit.write_text("tool_diameter [mm],k_yf\n12,1e7\n")
    with pytest.raises(FileFormatError, match="no unit"):
        JointTable.from_csv(nounit)
    header_only = tmp_path / "header.csv"
    header_only.write_text("tool_diameter [mm],k_yf [N/m]\n")
    assert len(JointTable.from_csv(header_only)) == 0


def test_toml_round_trip_and_errors(tmp_path):
    from substructure.surrogate import thesis_table_4_2

    table = thesis_table_4_2()
    path = tmp_path / "joints.toml"
    table.to_toml(path)
    back = JointTable.from_toml(path)
    assert back.parameters == table.parameters and back.features == table.features
    for name in (*table.parameters, *table.features):
        assert list(back.columns[name]) == list(table.columns[name])
    bad = tmp_path / "bad.toml"
    bad.write_text(path.read_text().replace('gauge_length = "65.0 mm"', 'gauge_length = "65.0 kg"'))
    with pytest.raises(FileFormatError, match=r"bad\.toml, line 2: joints\[0\]: gauge_length: .*units that do not "
                       "match"):  # the first row, written inline on line 2
        JointTable.from_toml(bad)
    with pytest.raises(FileFormatError, match="no such file"):
        JointTable.from_toml(tmp_path / "missing.toml")


def test_sizes_must_be_positive(tmp_path):
    path = tmp_path / "neg.csv"
    path.write_text("tool_diameter [mm],gauge_length [mm],k_yf [N/m]\n12,76,1.43e7\n-12,81,1.95e7\n16,85,1.2e7\n")
    with pytest.raises(FileFormatError, match=r"neg.csv, line 3: tool_diameter is -12 mm; expected a size > 0"):
        JointTable.from_csv(path)
    path.write_text("tool_diameter [mm],gauge_length [mm],k_yf [N/m]\n12,0,1.43e7\n")
    with pytest.raises(FileFormatError, match=r"line 2: gauge_length is 0 mm; expected a size > 0"):
        JointTable.from_csv(path)
    table = thesis_table_4_2()
    with pytest.raises(InvalidValueError, match=r"row: tool_diameter is -1.4 cm; expected a size > 0"):
        table.append({"tool_diameter": "-1.4 cm", "gauge_length": "90 mm", "k_yf": "1e7 N/m"})
    with pytest.raises(InvalidValueError, match=r"features: gauge_length is 0 mm; expected a size > 0"):
        table.feature_values({"tool_diameter": "14 mm", "gauge_length": "0 mm"})
    # a feature that is not a length (a clamping torque here) may be any finite number
    signed = JointTable.from_rows([{"tool_diameter": "12 mm", "offset_torque": f"{t} N*m", "k_yf": "1e7 N/m"}
                                   for t in (-2, 0, 3)])
    assert list(signed.feature("offset_torque")) == [-2, 0, 3]


def test_the_same_test_twice_is_refused_repeated_tests_are_kept(tmp_path):
    path = tmp_path / "dup.csv"
    path.write_text("tool_diameter [mm],gauge_length [mm],k_yf [N/m]\n12,76,1.43e7\n# again\n12,76,1.43e7\n"
                    "16,85,1.2e7\n")
    with pytest.raises(FileFormatError, match=r"dup.csv, line 4: the same joint as line 2 in every feature and "
                                              r"parameter \(tool_diameter, gauge_length, k_yf\): the same test listed"):
        JointTable.from_csv(path)
    row = {"tool_diameter": "12 mm", "gauge_length": "76 mm", "k_yf": "1.43e7 N/m"}
    with pytest.raises(InvalidValueError, match=r"row 2: the same joint as row 1"):
        JointTable.from_rows([row, dict(row, gauge_length="80 mm"), row][::2])
    # the same tool tested again, with another measured value: a repeated test, kept
    table = JointTable.from_rows([row, dict(row, k_yf="1.5e7 N/m"), dict(row, tool_diameter="16 mm")])
    assert len(table) == 3 and table.feature_groups() == [[0, 1], [2]]
    assert JointTable.from_rows([row]).feature_groups() == [[0]]
