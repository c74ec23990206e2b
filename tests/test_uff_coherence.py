"""A coherence record beside the FRF in a universal file (type 58, function type 6), as analysers export a
test: read with its FRF into a measurement (the measurement set's coherence_record), and checked."""

from __future__ import annotations

import numpy as np
import pyuff
import pytest

from substructure.errors import FileFormatError
from substructure.io.frf_files import read_uff, read_uff_coherence
from substructure.io.measurements import load_measurements

HZ = 100.0 + 2.0 * np.arange(200)
W = 2 * np.pi * HZ
H = 1.0 / (1e7 - 0.5 * W**2 + 1j * 300.0 * W)  # a receptance (m/N)
GAMMA = np.clip(0.6 + 0.4 * np.cos(HZ / 60.0) ** 2, 0.0, 1.0)


def _record(func_type, data, hz=HZ, **more):
    common = dict(rsp_node=1, rsp_dir=2, ref_node=1, ref_dir=2, abscissa_spacing=1, x=hz, id1="tap test",
                  ordinate_spec_data_type=8 if func_type == 4 else 0,
                  orddenom_spec_data_type=13 if func_type == 4 else 0, ordinate_axis_units_lab="m",
                  orddenom_axis_units_lab="N" if func_type == 4 else "")
    common.update(more)
    return pyuff.prepare_58(func_type=func_type, data=data, **common)


def _file(tmp_path, *sets, name="test.uff"):
    path = tmp_path / name
    pyuff.UFF(str(path)).write_sets(list(sets), mode="add")
    return path


def _set(tmp_path, extra):
    text = ('[[frf]]\nresponse = "tool.tip"\nexcitation = "tool.tip"\nfile = "test.uff"\nrecord = 0\n'
            'averages = 5\n' + extra)
    (tmp_path / "set.toml").write_text(text, encoding="utf-8")
    return tmp_path / "set.toml"


def test_a_coherence_record_reads_into_the_measurement(tmp_path):
    path = _file(tmp_path, _record(4, H), _record(6, GAMMA))
    hz, gamma = read_uff_coherence(path, 1)
    np.testing.assert_allclose(hz, HZ)
    np.testing.assert_allclose(gamma, GAMMA, rtol=1e-9)
    (m,) = load_measurements(_set(tmp_path, "coherence_record = 1\n")).measurements
    np.testing.assert_allclose(m.coherence, GAMMA, rtol=1e-9)
    np.testing.assert_allclose(m.frf.data[:, 0, 0], H, rtol=1e-9)
    assert m.averages == 5
    # without the key the FRF reads alone; the whole file read as FRFs says how to take the coherence
    assert load_measurements(_set(tmp_path, "")).measurements[0].coherence is None
    with pytest.raises(FileFormatError, match=r"type-58 record 1: a coherence \(function type 6\), not a frequency "
                                              r"response function .* coherence_record = M"):
        read_uff(path)


@pytest.mark.parametrize("records, key, message", [
    ("frf frf", "coherence_record = 1", r"frf\[0\]\.coherence_record: .*type-58 record 1: a frequency response "
                                         r"function \(function type 4\), not a coherence"),
    ("frf coh", "coherence_record = 5", r"frf\[0\]\.coherence_record: .*coherence record 5; the file has 2"),
    ("frf coh>1", "coherence_record = 1", r"type-58 record 1: value 1 is .*expected a coherence in \[0, 1\]"),
    ("frf coh-grid", "coherence_record = 1", r"the coherence's 100 lines from 100 to 298 Hz are not the FRF's"),
    ("frf coh", "coherence_record = -1", r"frf\[0\]\.coherence_record: got -1; expected the 0-based index"),
])
def test_a_wrong_coherence_record_is_refused_by_key(tmp_path, records, key, message):
    sets = {"frf": _record(4, H), "coh": _record(6, GAMMA), "coh>1": _record(6, GAMMA + 0.5),
            "coh-grid": _record(6, GAMMA[:100], hz=HZ[:100])}
    _file(tmp_path, *(sets[r] for r in records.split()))
    with pytest.raises(FileFormatError, match=message):
        load_measurements(_set(tmp_path, key + "\n"))


def test_a_csv_file_has_no_coherence_record(tmp_path):
    from substructure import FRF, Frequency
    from substructure.io.frf_files import write_csv

    write_csv(FRF.single(Frequency.from_hz(HZ), H, output="tool.tip:y", input="tool.tip:y"), tmp_path / "tip.csv")
    (tmp_path / "set.toml").write_text('[[frf]]\nresponse = "tool.tip"\nexcitation = "tool.tip"\nfile = "tip.csv"\n'
                                       'coherence_record = 1\n', encoding="utf-8")
    with pytest.raises(FileFormatError, match=r"coherence_record: a CSV file \(tip.csv\) has no records"):
        load_measurements(tmp_path / "set.toml")
