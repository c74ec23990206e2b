"""CSV exports of measured FRFs as acquisition programs write them: what is read, and what is refused.

The files are written here from known values (numpy) and read back by
``substructure.io.frf_files.read_csv``; what cannot be read unambiguously
must be refused naming the file, the line and the column.
"""

from __future__ import annotations

import numpy as np
import pytest

from substructure.errors import FileFormatError
from substructure.io.frf_files import read_csv, read_csv_with_coherence

HZ = np.array([10.0, 20.0, 30.0, 40.0])
H = 1e-6 * np.array([1 - 0.2j, 0.5 - 1j, -0.3 - 0.6j, -0.1 - 0.1j])


def rows(*columns, sep=";", decimal=","):
    return "".join(sep.join(repr(float(v)).replace(".", decimal) for v in row) + "\n" for row in zip(*columns))


def test_a_units_row_that_contradicts_the_header_is_refused(tmp_path):
    """The header said m/N, the units row under it mm/N: the header's unit was taken, silently."""
    path = tmp_path / "export.csv"
    path.write_text("Frequency [Hz];Real [m/N];Imag [m/N]\nHz;mm/N;mm/N\n" + rows(HZ, H.real, H.imag),
                    encoding="utf-8")
    with pytest.raises(FileFormatError, match=r"export\.csv, line 2: column 'Real \[m/N\]': the units row says "
                                              r"'mm/N' but the header 'm/N'"):
        read_csv(path)


def test_a_units_row_that_says_the_headers_unit_again_is_read(tmp_path):
    path = tmp_path / "export.csv"
    path.write_text("Frequency [Hz];Real [(m/s^2)/N];Imag [(m/s^2)/N]\n[Hz];[m/s2/N];[m s^-2 N^-1]\n"
                    + rows(HZ, H.real, H.imag), encoding="utf-8")
    frf = read_csv(path)
    assert frf.quantity == "accelerance"
    np.testing.assert_allclose(frf.data[:, 0, 0], H, rtol=1e-15)


def test_a_frequency_hz_column_with_a_khz_units_row_is_refused(tmp_path):
    path = tmp_path / "export.csv"
    path.write_text("frequency_hz;real;imag\nkHz;m/N;m/N\n" + rows(HZ, H.real, H.imag), encoding="utf-8")
    with pytest.raises(FileFormatError, match=r"line 2: column 'frequency_hz': the units row says 'kHz'"):
        read_csv(path)


def test_a_phase_in_degrees_labelled_rad_is_refused(tmp_path):
    """Degrees under 'Phase [rad]' were read as radians: every value wrong, silently."""
    path = tmp_path / "export.csv"
    path.write_text("Frequency [Hz];Magnitude [m/N];Phase [rad]\n" + rows(HZ, np.abs(H), np.degrees(np.angle(H))),
                    encoding="utf-8")
    with pytest.raises(FileFormatError, match=r"export\.csv, line 2: Phase \[rad\] is '-11,3\d*', beyond 2 pi: "
                                              r"degrees labelled rad\?"):
        read_csv(path)


@pytest.mark.parametrize("unit, scale", [("rad", 1.0), ("deg", 180 / np.pi)])
def test_magnitude_and_phase_read_to_the_values_written(tmp_path, unit, scale):
    path = tmp_path / "export.csv"
    path.write_text(f"Frequency [Hz];Magnitude [m/N];Phase [{unit}]\n" + rows(HZ, np.abs(H), np.angle(H) * scale),
                    encoding="utf-8")
    np.testing.assert_allclose(read_csv(path).data[:, 0, 0], H, rtol=1e-14)


def test_german_column_names_as_german_programs_export_them(tmp_path):
    """'Frequenz', 'Realteil', 'Imaginärteil', 'Betrag', 'Kohärenz' were refused as unknown columns."""
    path = tmp_path / "export.csv"
    path.write_text("Frequenz [Hz];Realteil [µm/N];Imaginärteil [µm/N]\n" + rows(HZ, H.real * 1e6, H.imag * 1e6),
                    encoding="utf-8")
    np.testing.assert_allclose(read_csv(path).data[:, 0, 0], H, rtol=1e-14)
    path.write_text("Frequenz;Betrag;Phase;Kohärenz\nHz;m/N;°;%\n"
                    + rows(HZ, np.abs(H), np.degrees(np.angle(H)), np.full(4, 99.0)), encoding="utf-8")
    frf, coherence = read_csv_with_coherence(path)
    np.testing.assert_allclose(frf.data[:, 0, 0], H, rtol=1e-14)
    np.testing.assert_allclose(coherence, 0.99)


def test_metadata_lines_without_hash_above_the_header_are_pointed_at(tmp_path):
    """An export's block of metadata (date, channel) above the table: the error said 'column 'Date'', expected
    frequency..., without saying where the table starts or what to do."""
    path = tmp_path / "export.csv"
    path.write_text("Date;2026-11-27\nChannel;Tool tip Z\n\nFrequency [Hz];Real [m/N];Imag [m/N]\n"
                    + rows(HZ, H.real, H.imag), encoding="utf-8")
    with pytest.raises(FileFormatError, match=r"export\.csv, line 1: 'Date;2026-11-27' is not the table's header, "
                                              r"line 4 \('Frequency \[Hz\];Real \[m/N\];Imag \[m/N\]'\) is: start "
                                              r"the lines above it with '#'"):
        read_csv(path)
    path.write_text("# Date;2026-11-27\n# Channel;Tool tip Z\n\nFrequency [Hz];Real [m/N];Imag [m/N]\n"
                    + rows(HZ, H.real, H.imag), encoding="utf-8")
    np.testing.assert_allclose(read_csv(path).data[:, 0, 0], H, rtol=1e-15)


@pytest.mark.parametrize("unit, scale", [("HZ", 1.0), ("hz", 1.0), ("KHZ", 1e-3), ("RPM", 60.0),
                                         ("RAD/S", 2 * np.pi)])
def test_a_frequency_unit_in_capitals_reads_as_in_a_universal_file(tmp_path, unit, scale):
    """'RPM', 'KHZ', 'RAD/S' and 'hz' were refused in a CSV export and read in a universal file's abscissa."""
    path = tmp_path / "export.csv"
    path.write_text(f"Frequency [{unit}];Real [m/N];Imag [m/N]\n" + rows(HZ * scale, H.real, H.imag),
                    encoding="utf-8")
    np.testing.assert_allclose(read_csv(path).frequency.hz, HZ, rtol=1e-14)


def test_mhz_in_capitals_is_not_taken_for_megahertz(tmp_path):
    """'MHZ' was read as MHz; in capitals it may as well be mHz: refused, as in a universal file."""
    path = tmp_path / "export.csv"
    path.write_text("Frequency [MHZ];Real [m/N];Imag [m/N]\n" + rows(HZ * 1e-6, H.real, H.imag), encoding="utf-8")
    with pytest.raises(FileFormatError, match=r"export\.csv, line 1: column 'Frequency \[MHZ\]': 'MHZ' is not a "
                                              "frequency unit"):
        read_csv(path)


def test_a_coherence_in_percent_holding_fractions_is_refused(tmp_path):
    """Fractions (0.95) under 'Coherence [%]' were read as 0.0095, a coherence that weighs every line as noise."""
    path = tmp_path / "export.csv"
    path.write_text("Frequency [Hz];Real [m/N];Imag [m/N];Coherence [%]\n"
                    + rows(HZ, H.real, H.imag, np.array([0.95, 0.99, 0.98, 0.9])), encoding="utf-8")
    with pytest.raises(FileFormatError, match=r"export\.csv, line 1: column 'Coherence \[%\]' is in %, but no line "
                                              r"holds more than 0\.99"):
        read_csv_with_coherence(path)
    path.write_text("Frequency [Hz];Real [m/N];Imag [m/N];Coherence [%]\n"
                    + rows(HZ, H.real, H.imag, np.array([95.0, 99.0, 98.0, 0.5])), encoding="utf-8")
    np.testing.assert_allclose(read_csv_with_coherence(path)[1], [0.95, 0.99, 0.98, 0.005])


@pytest.mark.parametrize("sep", [";", "\t"])
def test_a_thousands_separator_beside_decimal_commas_is_named_as_written(tmp_path, sep):
    """'1.234,5e-9' with decimal commas: the message showed '1.234.5e-9' (the cell after the commas were turned
    into points), which is not what the file says; now the cell as written and why."""
    path = tmp_path / "h.csv"
    path.write_text(sep.join(["frequency_hz", "re", "im"]) + "\n"
                    + "".join(sep.join(row) + "\n" for row in (("100", "1,5e-6", "-2,0e-7"),
                                                                ("102", "1.234,5e-9", "-2,0e-7"),
                                                                ("104", "1,6e-6", "-2,1e-7"))))
    with pytest.raises(FileFormatError, match=r"h\.csv, line 3: 're' is '1\.234,5e-9'; expected a number \(with "
                                              r"decimal commas, a point is a thousands separator"):
        read_csv(path)
    path.write_text(path.read_text().replace("1.234,5e-9", "1234,5e-9"))
    assert read_csv(path).data[1, 0, 0] == pytest.approx(1234.5e-9 - 2.0e-7j)


@pytest.mark.parametrize("head, first", [("", 0), ("index", 0), ('""', 1), ("Unnamed: 0", 0)])
def test_a_row_number_column_as_pandas_or_r_write_it_is_skipped(tmp_path, head, first):
    """``DataFrame.to_csv`` writes its index first, under an empty name; R's ``write.csv`` numbers from 1.
    Such a file was refused ("column ''")."""
    path = tmp_path / "export.csv"
    numbers = np.arange(first, first + len(HZ))
    body = rows(HZ, H.real, H.imag, HZ / 50, sep=",", decimal=".").splitlines()
    path.write_text(f"{head},frequency_hz,real,imag,coherence\n"
                    + "".join(f'"{k}",{line}\n' if head == '""' else f"{k},{line}\n" for k, line in zip(numbers, body)),
                    encoding="utf-8")
    frf, coherence = read_csv_with_coherence(path)
    np.testing.assert_array_equal(frf.frequency.hz, HZ)
    np.testing.assert_allclose(frf.data[:, 0, 0], H, rtol=1e-15)
    np.testing.assert_allclose(coherence, HZ / 50, rtol=1e-15)


@pytest.mark.parametrize("numbers", [[0, 1, 3, 4], [2, 3, 4, 5], [0.5, 1.5, 2.5, 3.5]])
def test_a_first_column_that_does_not_count_rows_is_not_taken_for_an_index(tmp_path, numbers):
    path = tmp_path / "export.csv"
    body = rows(HZ, H.real, H.imag, sep=",", decimal=".").splitlines()
    path.write_text(",frequency_hz,real,imag\n" + "".join(f"{k},{line}\n" for k, line in zip(numbers, body)),
                    encoding="utf-8")
    with pytest.raises(FileFormatError, match=r"line 1: column ''; expected frequency"):
        read_csv(path)


def test_an_index_column_with_a_units_row_is_skipped(tmp_path):
    path = tmp_path / "export.csv"
    body = rows(HZ, H.real * 1e3, H.imag * 1e3).splitlines()
    path.write_text(";Frequency;Real;Imag\n;Hz;mm/N;mm/N\n" + "".join(f"{k};{line}\n" for k, line in enumerate(body)),
                    encoding="utf-8")
    np.testing.assert_allclose(read_csv(path).data[:, 0, 0], H, rtol=1e-12)
