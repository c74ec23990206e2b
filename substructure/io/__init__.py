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

import contextlib
import os
import tempfile
from pathlib import Path
from typing import Iterator

from .. import _files
from .._files import check_file, decode_text, parse_toml, read_bytes
from ..errors import FileFormatError, OutputExistsError

#: The largest TOML file or CSV table read (16 MiB): assembly, measurement set, study, workpiece, joint and
#: combination tables, modes CSV.
MAX_TEXT_BYTES = _files.MAX_TEXT_BYTES

#: The largest measured FRF file read, CSV or universal file (128 MiB).
MAX_DATA_BYTES = _files.MAX_DATA_BYTES

__public_submodules__ = ("assembly_toml", "frf_files", "measurements", "tap_files")
"""Submodules that are public API of their own (documented on their own pages)."""

__all__ = ["read_text", "read_bytes", "parse_toml", "MAX_TEXT_BYTES", "MAX_DATA_BYTES", "check_readable_file",
           "replacing", "write_text", "write_bytes", "check_writable"]


def check_readable_file(path, what: str = "file", limit: int = MAX_TEXT_BYTES) -> str:
    """The path's name, after checking that it is a regular file of at most ``limit`` bytes.

    For readers that hand the name to another library (pyuff); see
    ``substructure._files.check_file``.

    Parameters
    ----------
    path : str or path-like
        The file to read.
    what : str
        What the file is, for the message (e.g. ``"universal file"``).
    limit : int, default MAX_TEXT_BYTES
        The largest size allowed, in bytes (:data:`MAX_TEXT_BYTES` for
        tables and TOML files, :data:`MAX_DATA_BYTES` for FRF data files).

    Returns
    -------
    str
        ``os.fspath(path)``.

    Raises
    ------
    FileFormatError
        Naming the path, for a missing path, a directory, anything else that
        is not a regular file (a FIFO, a device) and a file over the cap.
    """
    return check_file(path, what, limit)


def read_text(path, what: str = "file", limit: int = MAX_TEXT_BYTES) -> str:
    """The text of a file, UTF-8 (or UTF-16 with its byte-order mark), without a leading byte-order mark.

    Only a regular file is read, and at most ``limit`` bytes of it
    (:func:`read_bytes`).

    Parameters
    ----------
    path : str or path-like
        The file.
    what : str, default "file"
        What the file is, for the message.
    limit : int, default MAX_TEXT_BYTES
        The largest size allowed, in bytes.

    Returns
    -------
    str
        Its text.

    Raises
    ------
    FileFormatError
        Naming the file, for a missing file, a directory, a FIFO or device,
        a file over the cap, an unreadable file or bytes that are not UTF-8
        (nor UTF-16 after a UTF-16 byte-order mark).
    """
    data = read_bytes(path, what, limit)
    return decode_text(data, os.fspath(path))


def check_writable(path, overwrite: bool, option: str | None = None) -> Path:
    """Check before any work that ``path`` may be written: not a directory, absent unless ``overwrite``.

    Parameters
    ----------
    path : str or path-like
        The file to be written.
    overwrite : bool
        Whether an existing file may be replaced.
    option : str, optional
        The command-line option that named the file, for the message.

    Returns
    -------
    pathlib.Path
        The path.

    Raises
    ------
    OutputExistsError
        (a ``FileExistsError``) when the file exists and ``overwrite`` is
        false; the message says how to replace it.
    FileFormatError
        When the path is a directory or its directory does not exist.
    """
    p = Path(path)
    who = f"{option} {p}" if option else str(p)
    if p.is_dir():
        raise FileFormatError(f"{who}: is a directory; expected a file name")
    parent = p.parent if str(p.parent) else Path(".")
    if not parent.is_dir():
        raise FileFormatError(f"{who}: the directory {parent} does not exist")
    if p.exists() and not overwrite:
        hint = "add --overwrite to replace it" if option else "pass overwrite=True to replace it"
        raise OutputExistsError(f"{who}: the file exists; {hint}")
    return p


def _mode_for_new_files() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


@contextlib.contextmanager
def replacing(path, overwrite: bool = True) -> Iterator[str]:
    """Write a file through a temporary file in its directory and an atomic rename.

    Yields the temporary file's name, which has the same suffix as ``path``
    (so that writers that choose the format by the suffix, such as
    matplotlib, choose right).  When the block ends without an exception
    the temporary file takes the place of ``path`` in one atomic step
    (``os.replace``), so that readers and concurrent writers see either the
    old file or one writer's complete file, never a mixture; on an exception
    the temporary file is removed and ``path`` is untouched.

    Parameters
    ----------
    path : str or path-like
        The file to write.
    overwrite : bool, default True
        Whether an existing file may be replaced.  Without it the rename is
        exclusive (a hard link that fails if the name exists, checked again at
        the last moment), and an existing file raises ``FileExistsError``.

    Yields
    ------
    str
        The temporary file to write to.

    Raises
    ------
    OutputExistsError
        (a ``FileExistsError``) when ``path`` exists and ``overwrite`` is false.
    FileFormatError
        When ``path`` is a directory or its directory is missing or not
        writable.
    """
    target = check_writable(path, overwrite)
    directory = str(target.parent) if str(target.parent) else "."
    try:
        fd, temporary = tempfile.mkstemp(prefix=f".{target.name}.", suffix=f".part{target.suffix}", dir=directory)
    except OSError as exc:
        raise FileFormatError(f"{target}: cannot write in {directory} ({exc.strerror or exc})") from None
    os.close(fd)
    try:
        yield temporary
        os.chmod(temporary, _mode_for_new_files())
        if overwrite:
            os.replace(temporary, target)
        else:
            try:
                os.link(temporary, target)  # atomic and exclusive: fails if the name exists
            except FileExistsError:
                raise OutputExistsError(f"{target}: the file exists; pass overwrite=True to replace it") from None
            except OSError:  # a file system without hard links: check, then rename
                if target.exists():
                    raise OutputExistsError(f"{target}: the file exists; pass overwrite=True to replace it") from None
                os.replace(temporary, target)
    finally:
        with contextlib.suppress(FileNotFoundError):
            os.remove(temporary)


def write_bytes(path, data: bytes, overwrite: bool = True) -> None:
    """Write ``data`` to ``path`` atomically (see :func:`replacing`).

    Parameters
    ----------
    path : str or path-like
        The file.
    data : bytes
        Its whole content.
    overwrite : bool, default True
        Whether an existing file may be replaced.
    """
    with replacing(path, overwrite) as temporary:
        with open(temporary, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())


def write_text(path, text: str, overwrite: bool = True) -> None:
    """Write ``text`` as UTF-8 with ``\\n`` line ends to ``path`` atomically (see :func:`replacing`).

    Parameters
    ----------
    path : str or path-like
        The file.
    text : str
        Its whole content.
    overwrite : bool, default True
        Whether an existing file may be replaced.
    """
    write_bytes(path, text.encode("utf-8"), overwrite)
