"""Files in and out of `substructure`: measured FRFs (CSV, UFF type 58) and more.

Submodules are imported on use (``from substructure.io.frf_files import
read_csv``), so that importing the package stays cheap and the core layers
never depend on file formats.  This module holds what every file of the
package shares: :func:`read_text` (UTF-8, a byte-order mark allowed, clear
errors for a missing file or a directory) and the one way files are written,
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

from ..errors import FileFormatError, OutputExistsError

__public_submodules__ = ("assembly_toml", "frf_files", "measurements", "tap_files")
"""Submodules that are public API of their own (documented on their own pages)."""

__all__ = ["read_text", "check_readable_file", "replacing", "write_text", "write_bytes", "check_writable"]


def check_readable_file(path, what: str = "file") -> str:
    """The path's name; a missing path or a directory is a :class:`FileFormatError` naming it.

    Parameters
    ----------
    path : str or path-like
        The file to read.
    what : str
        What the file is, for the message (e.g. ``"universal file"``).

    Returns
    -------
    str
        ``os.fspath(path)``.
    """
    try:
        name = os.fspath(path)
    except TypeError:
        raise FileFormatError(f"got {path!r} of type {type(path).__name__}; expected the name of a {what}") from None
    if os.path.isdir(name):
        raise FileFormatError(f"{name}: is a directory; expected a {what}")
    if not os.path.exists(name):
        raise FileFormatError(f"{name}: no such file")
    return name


def read_text(path) -> str:
    """The text of a file, UTF-8 (or UTF-16 with its byte-order mark), without a leading byte-order mark.

    Parameters
    ----------
    path : str or path-like
        The file.

    Returns
    -------
    str
        Its text.

    Raises
    ------
    FileFormatError
        Naming the file, for a missing file, a directory, an unreadable file
        or bytes that are not UTF-8 (nor UTF-16 after a UTF-16 byte-order mark).
    """
    name = check_readable_file(path)
    try:
        with open(name, "rb") as fh:
            data = fh.read()
    except OSError as exc:
        raise FileFormatError(f"{name}: cannot read the file ({exc.strerror or exc})") from None
    if data[:2] in (b"\xff\xfe", b"\xfe\xff"):  # UTF-16 with its byte-order mark (Excel's "Unicode text")
        try:
            return data.decode("utf-16")
        except UnicodeDecodeError as exc:
            raise FileFormatError(f"{name}: starts with a UTF-16 byte-order mark but is not UTF-16 text "
                                  f"(byte {exc.start}); save the file as UTF-8") from None
    try:
        return data.decode("utf-8-sig")  # a BOM (Windows editors write one) is not part of the text
    except UnicodeDecodeError as exc:
        raise FileFormatError(
            f"{name}: not UTF-8 text (byte {exc.start}: {data[exc.start:exc.start + 1]!r}); "
            "save the file as UTF-8"
        ) from None


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
