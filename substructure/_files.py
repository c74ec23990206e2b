"""The one checked way the package opens a file to read it, and the one way it parses TOML.

Every reader of the package (assembly, measurement set, study, workpiece and
joint tables, modal CSV files, FRF files in CSV and UFF) goes through
:func:`read_bytes` (or :func:`check_file` for a reader that hands the name to
another library): only a regular file is read (a FIFO with no writer would
block forever, ``/dev/zero`` would never end), and never more than a cap of
its kind, :data:`MAX_TEXT_BYTES` for tables and TOML files, and
:data:`MAX_DATA_BYTES` for measured FRF files.  :func:`parse_toml` parses TOML
text with the errors of a broken or absurdly nested document named by file.

This module sits in the lowest layer (it needs only :mod:`substructure.errors`),
so that every layer may read files through it; :mod:`substructure.io`
re-exports it.
"""

from __future__ import annotations

import contextlib
import os
import stat
import tempfile
from pathlib import Path, PureWindowsPath
from typing import Iterator

from .errors import FileFormatError, OutputExistsError

__all__ = ["MAX_TEXT_BYTES", "MAX_DATA_BYTES", "relative_path", "check_file", "read_bytes", "decode_text",
           "parse_toml", "read_text", "check_writable", "replacing", "write_text", "write_bytes"]

MAX_TEXT_BYTES = 16 * 2**20
"""The largest TOML or CSV table the package reads (16 MiB): assembly, measurement set, study, workpiece
table, joint table, modal CSV.  Such files are a few kB; a larger one is not what it claims to be."""

MAX_DATA_BYTES = 128 * 2**20
"""The largest measured FRF file (CSV or universal file) the package reads (128 MiB): a million lines
(``MAX_GRID_LINES``) of full-precision CSV are about 70 MB."""


def relative_path(base, text: str) -> Path:
    """The file a file names, relative to the folder ``base`` unless absolute.

    A name written on Windows (``data\\tip.csv``) names, here, the file it named there: its backslashes
    separate folders when no file has the name as written.

    Parameters
    ----------
    base : str or os.PathLike
        The folder of the file that names it.
    text : str
        The name as written.

    Returns
    -------
    Path
        The path (which may not exist).
    """
    path = Path(base) / text
    if os.sep == "/" and "\\" in text and not path.exists():
        windows = PureWindowsPath(text)
        if not windows.drive:  # C:\\data is another machine's disk: said as written
            path = Path(base) / windows.as_posix()
    return path


def _name(path, what: str) -> str:
    try:
        return os.fspath(path)
    except TypeError:
        raise FileFormatError(f"got {path!r} of type {type(path).__name__}; expected the name of {_a(what)}") from None


def file_name(path, what: str = "file") -> str:
    """``path`` as text, or a :class:`FileFormatError` naming what was expected when it is no file name (a number,
    None): where a file's name enters, rather than a ``TypeError`` from deep inside."""
    name = os.fsdecode(_name(path, what))
    if "\0" in name:
        raise FileFormatError(f"got {name!r}; expected the name of {_a(what)} (a file name holds no NUL character)")
    return name


def _a(what: str) -> str:
    return f"{'an' if what[:1].lower() in 'aeiou' else 'a'} {what}"


_KINDS = ((stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a named pipe (FIFO)"), (stat.S_ISCHR, "a character device"),
          (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"))


def _kind(mode: int) -> str:
    return next((name for test, name in _KINDS if test(mode)), "not a regular file")


def _check_stat(name: str, st: os.stat_result, what: str, limit: int) -> None:
    if not stat.S_ISREG(st.st_mode):
        raise FileFormatError(f"{name}: is {_kind(st.st_mode)}; expected {_a(what)} (a regular file)")
    if st.st_size > limit:
        raise FileFormatError(f"{name}: {st.st_size:,} bytes, more than the {limit:,} bytes {_a(what)} may have "
                              "(docs/file-formats.md); is it the right file?")


def check_file(path, what: str = "file", limit: int = MAX_TEXT_BYTES) -> str:
    """The path's name, after checking that it is a regular file of at most ``limit`` bytes.

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
        Naming the path, for a missing path, a directory, a FIFO, a device or
        anything else that is not a regular file, and a file larger than
        ``limit``.
    """
    name = _name(path, what)
    try:
        st = os.stat(name)
    except FileNotFoundError:
        raise FileFormatError(f"{name}: no such file") from None
    except (OSError, ValueError) as exc:
        raise FileFormatError(f"{name}: cannot read the file ({getattr(exc, 'strerror', None) or exc})") from None
    _check_stat(name, st, what, limit)
    return name


def read_bytes(path, what: str = "file", limit: int = MAX_TEXT_BYTES) -> bytes:
    """The bytes of a regular file of at most ``limit`` bytes.

    The file is opened without blocking (a FIFO with no writer does not hang)
    and checked on the open descriptor; at most ``limit + 1`` bytes are read
    (a file that grows, or reports a size of 0, is still capped).

    Parameters
    ----------
    path : str or path-like
        The file.
    what : str
        What the file is, for the message.
    limit : int
        The largest size allowed, in bytes.

    Returns
    -------
    bytes
        The file's content.

    Raises
    ------
    FileFormatError
        As ``check_file``, and for a file that cannot be read.
    """
    name = check_file(path, what, limit)
    try:
        fd = os.open(name, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_BINARY", 0))
    except FileNotFoundError:
        raise FileFormatError(f"{name}: no such file") from None
    except OSError as exc:
        raise FileFormatError(f"{name}: cannot read the file ({exc.strerror or exc})") from None
    try:
        _check_stat(name, os.fstat(fd), what, limit)  # the file opened is the file checked
        chunks, size = [], 0
        while size <= limit:
            chunk = os.read(fd, min(limit + 1 - size, 2**20))
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
    except OSError as exc:
        raise FileFormatError(f"{name}: cannot read the file ({exc.strerror or exc})") from None
    finally:
        os.close(fd)
    if size > limit:
        raise FileFormatError(f"{name}: more than the {limit:,} bytes {_a(what)} may have (docs/file-formats.md); "
                              "is it the right file?")
    return b"".join(chunks)


def decode_text(data: bytes, name: str) -> str:
    """UTF-8 text (or UTF-16 after its byte-order mark) without a leading byte-order mark.

    Parameters
    ----------
    data : bytes
        The file's content.
    name : str
        The file, for messages.

    Returns
    -------
    str
        The text.

    Raises
    ------
    FileFormatError
        Naming the file and the byte, for bytes that are not UTF-8 (nor UTF-16
        after a UTF-16 byte-order mark), and for a NUL character (UTF-16
        text without its byte-order mark, UTF-32).
    """
    if data[:2] in (b"\xff\xfe", b"\xfe\xff"):  # UTF-16 with its byte-order mark (Excel's "Unicode text")
        try:
            text = data.decode("utf-16")
        except UnicodeDecodeError as exc:
            raise FileFormatError(f"{name}: starts with a UTF-16 byte-order mark but is not UTF-16 text "
                                  f"(byte {exc.start}); save the file as UTF-8") from None
    else:
        try:
            text = data.decode("utf-8-sig")  # a BOM (Windows editors write one) is not part of the text
        except UnicodeDecodeError as exc:
            raise FileFormatError(
                f"{name}: not UTF-8 text (byte {exc.start}: {data[exc.start:exc.start + 1]!r}); "
                "save the file as UTF-8"
            ) from None
    nul = text.find("\x00")
    if nul >= 0:  # valid UTF-8 to the decoder, but no text file of the package holds one
        line = text.count("\n", 0, nul) + 1
        column = nul - (text.rfind("\n", 0, nul) + 1) + 1
        raise FileFormatError(
            f"{name}, line {line}: a NUL character (column {column}): the file is not UTF-8 text (UTF-16 without "
            "its byte-order mark, UTF-32, or no text at all); save the file as UTF-8"
        )
    return text


def parse_toml(text: str, source: str) -> dict:
    """Parse TOML text; a syntax error or an absurdly deep nesting is an error naming ``source``.

    Parameters
    ----------
    text : str
        The TOML text.
    source : str
        The file (or a description of the text), for messages.

    Returns
    -------
    dict
        The parsed document.

    Raises
    ------
    FileFormatError
        For invalid TOML (with the line and column of the parser), and for
        arrays or inline tables nested so deep that the parser runs out of
        recursion (hundreds of levels).
    """
    import tomllib

    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise FileFormatError(f"{source}: invalid TOML: {exc}") from None
    except RecursionError:  # the parser recurses once per level of nesting
        raise FileFormatError(f"{source}: invalid TOML: arrays or inline tables nested hundreds of levels "
                              "deep; no file of the package needs more than a few levels") from None


# -- text and the one way files are written (substructure.io re-exports them) --------------------

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
    return decode_text(read_bytes(path, what, limit), os.fspath(path))


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
    p = Path(file_name(path, "file to write"))
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
            except OSError as exc:  # the name exists, or a file system without hard links: check, then rename
                if isinstance(exc, FileExistsError) or target.exists():
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
