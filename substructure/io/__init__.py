"""Files in and out of `substructure`: measured FRFs (CSV, UFF type 58) and more.

Submodules are imported on use (``from substructure.io.frf_files import
read_csv``), so that importing the package stays cheap and the core layers
never depend on file formats.  This module holds what every file of the
package shares: :func:`read_text` (UTF-8, a byte-order mark allowed, clear
errors for a missing file, a directory, anything but a regular file and a
file over the cap of its kind: :data:`MAX_TEXT_BYTES`, :data:`MAX_DATA_BYTES`),
:func:`parse_toml`, and the one way files are written,
:func:`replacing`, :func:`write_text` and :func:`write_bytes`: through a
temporary file in the same directory and an atomic rename, so that a reader
(or a second writer) never sees half a file and an existing file is replaced
only when asked.
"""

from __future__ import annotations

from .. import _files
from .._files import (  # noqa: F401 (in the lowest layer, so that frf's files read and write through them)
    _mode_for_new_files,
    check_file,
    check_file as check_readable_file,  # the public name, for readers that hand the name to pyuff
    check_writable,
    file_name,
    parse_toml,
    read_bytes,
    read_text,
    replacing,
    write_bytes,
    write_text,
)

#: The largest TOML file or CSV table read (16 MiB): assembly, measurement set, study, workpiece, joint and
#: combination tables, modes CSV.
MAX_TEXT_BYTES = _files.MAX_TEXT_BYTES

#: The largest measured FRF file read, CSV or universal file (128 MiB).
MAX_DATA_BYTES = _files.MAX_DATA_BYTES

__public_submodules__ = ("assembly_toml", "frf_files", "measurements", "tap_files")
"""Submodules that are public API of their own (documented on their own pages)."""

__all__ = ["read_text", "read_bytes", "parse_toml", "MAX_TEXT_BYTES", "MAX_DATA_BYTES", "check_readable_file",
           "replacing", "write_text", "write_bytes", "check_writable"]

