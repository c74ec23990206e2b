"""Every file is written through a temporary file and an atomic rename (substructure.io.replacing).

Eight processes write the same output path at once, through the library and
through the command; the file afterwards is one writer's complete output,
never a mixture.  A failed write leaves the old file as it was and no
temporary file behind; without ``overwrite`` an existing file is kept.
"""

from __future__ import annotations

import multiprocessing
import os
from pathlib import Path

import numpy as np
import pytest

from substructure import FRF, Frequency
from substructure.cli import main
from substructure.errors import FileFormatError
from substructure.io import read_text, replacing, write_text
from substructure.io.frf_files import read_csv, write_csv

WRITERS = 8
EXAMPLE = Path(__file__).parent / "data" / "formats_example.toml"


def frf_of(writer: int) -> FRF:
    """A long FRF that differs from writer to writer in every line."""
    f = Frequency.from_range("1 Hz", "20000 Hz", "1 Hz")
    return FRF.single(f, (writer + 1) * 1e-7 * np.exp(1j * f.hz / 1000.0))


def _library_writer(writer: int, path: str, barrier) -> None:
    frf = frf_of(writer)
    barrier.wait()
    for _ in range(3):
        write_csv(frf, path, overwrite=True)


def _command_writer(writer: int, path: str, barrier) -> None:
    barrier.wait()
    grid = f"{100 + writer}:{2100 + writer}:1"  # a different grid per writer
    status = main(["frf", str(EXAMPLE), "--at", "tool.tip", "--grid", grid, "--out", path, "--overwrite"])
    assert status == 0


def run_writers(target, path) -> None:
    # children forked from a single-threaded server that has imported the package once (fast and safe)
    context = multiprocessing.get_context("forkserver")
    context.set_forkserver_preload(["substructure.cli.frf_command", "substructure.io.frf_files", "test_atomic_writes"])
    barrier = context.Barrier(WRITERS)
    processes = [context.Process(target=target, args=(w, str(path), barrier)) for w in range(WRITERS)]
    for p in processes:
        p.start()
    for p in processes:
        p.join(120)
    assert all(p.exitcode == 0 for p in processes), [p.exitcode for p in processes]


def test_eight_processes_writing_one_csv_leave_one_writers_file(tmp_path):
    path = tmp_path / "same.csv"
    run_writers(_library_writer, path)
    text = path.read_text(encoding="utf-8")
    expected = {}
    for w in range(WRITERS):
        write_csv(frf_of(w), tmp_path / f"alone{w}.csv")
        expected[w] = (tmp_path / f"alone{w}.csv").read_text(encoding="utf-8")
    assert sum(text == e for e in expected.values()) == 1
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []  # no temporary left


def test_eight_commands_writing_one_output(tmp_path):
    path = tmp_path / "tip.csv"
    run_writers(_command_writer, path)
    written = read_csv(path)
    start = written.frequency.start
    assert written.frequency.n == 2001 and start in {100.0 + w for w in range(WRITERS)}
    from substructure.io.assembly_toml import load_assembly

    grid = Frequency.from_range(f"{start} Hz", f"{start + 2000} Hz", "1 Hz")
    expected = load_assembly(EXAMPLE).receptance("tool.tip:y", frequency=grid)
    np.testing.assert_array_equal(written.data, expected.data)


def test_a_failed_write_keeps_the_old_file_and_leaves_no_temporary(tmp_path):
    path = tmp_path / "kept.txt"
    write_text(path, "old\n")
    with pytest.raises(RuntimeError, match="disk full"):
        with replacing(path) as temporary:
            Path(temporary).write_text("half of the new")
            raise RuntimeError("disk full")
    assert read_text(path) == "old\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["kept.txt"]


def test_without_overwrite_an_existing_file_is_kept_even_if_it_appears_late(tmp_path):
    path = tmp_path / "late.txt"
    with pytest.raises(FileExistsError, match="late.txt: the file exists"):
        with replacing(path, overwrite=False) as temporary:
            Path(temporary).write_text("mine")
            path.write_text("someone else's")  # appears while we write
    assert path.read_text() == "someone else's"
    write_text(tmp_path / "new.txt", "fresh", overwrite=False)
    assert (tmp_path / "new.txt").read_text() == "fresh"
    assert oct(os.stat(tmp_path / "new.txt").st_mode & 0o777) != oct(0o600)  # usual permissions, not mkstemp's


def test_directories_and_missing_directories_are_clear_errors(tmp_path):
    with pytest.raises(FileFormatError, match="is a directory"):
        write_text(tmp_path, "x")
    with pytest.raises(FileFormatError, match="does not exist"):
        write_text(tmp_path / "nowhere" / "x.txt", "x")
    with pytest.raises(FileFormatError, match="is a directory"):
        read_text(tmp_path)
    (tmp_path / "bom.txt").write_bytes(b"\xef\xbb\xbfname = 1\n")
    assert read_text(tmp_path / "bom.txt") == "name = 1\n"
