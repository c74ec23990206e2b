"""TOML documents that know the line of every key: the one reader of the package's TOML files.

Every TOML file the package reads (assembly, measurement set, study,
workpiece, cutting-data and joint tables, and the package's own data) is
parsed by :func:`loads_toml` or :func:`read_toml` into a
:class:`TomlDocument`: the parsed data with the text they came from, so that
an error names the file, the line and the key path,
``"bench.toml, line 12: components[1].segments[0].od: ..."``.

The line of a key is found by a scan of the text's structure (table headers,
arrays of tables nested at any depth, dotted and quoted keys, inline tables,
arrays across lines, strings and comments skipped), run once, when a line is
first asked for; the text is valid TOML by then (:func:`parse_toml` read it).
A key path that is not in the text (a missing key, a field a constructor
named) is given the line of its nearest container that is.

This module sits in the lowest layer beside :mod:`substructure._files`, so
that every layer reads its TOML through it.
"""

from __future__ import annotations

import bisect
import os
import re
from typing import Any, Sequence

from ._files import MAX_TEXT_BYTES, parse_toml, read_text
from .errors import FileFormatError

__all__ = ["TomlDocument", "key_path", "loads_toml", "read_toml"]

_SPACE = re.compile(r"(?:[ \t\r\n]|#[^\n]*)*")  # blanks, line ends and comments between items
_BLANK = re.compile(r"[ \t]*")
_BARE = re.compile(r"[A-Za-z0-9_-]+")
_STRING = {  # the extent of each kind of string (escapes in basic strings; up to two quotes before the closing)
    '"""': re.compile(r'"""(?:[^"\\]+|\\[\s\S]|"(?!""))*"""(?:"{0,2})'),
    "'''": re.compile(r"'''(?:[^']+|'(?!''))*'''(?:'{0,2})"),
    '"': re.compile(r'"(?:[^"\\\n]+|\\.)*"'),
    "'": re.compile(r"'[^'\n]*'"),
}
_SCALAR = re.compile(r"[^,\]}#\n]*")  # a number, boolean or date: up to the next delimiter
_FIELD = re.compile(r"^([A-Za-z_][A-Za-z0-9_.\[\]]*): (.*)$", re.DOTALL)
_PART = re.compile(r"([^.\[\]]+)|\[(\d+)\]")

Path = tuple  # a key path: names (str) and array indices (int)


def key_path(parts: Sequence[str | int]) -> str:
    """A key path as messages write it: ``components[1].segments[0].od``.

    Parameters
    ----------
    parts : sequence of str and int
        Names of keys and 0-based array indices, outermost first.

    Returns
    -------
    str
        The path; ``""`` for the document itself.
    """
    text = ""
    for p in parts:
        text += f"[{p}]" if isinstance(p, int) else (f".{p}" if text else str(p))
    return text


class _Scanner:
    """The 1-based line of every key and array element of valid TOML text."""

    def __init__(self, text: str):
        self.text, self.pos = text, 0
        self.breaks = [m.start() for m in re.finditer("\n", text)]
        self.explicit: dict[Path, int] = {}  # where a key, table or element is written
        self.implicit: dict[Path, int] = {}  # where a table is first named inside a longer name
        self.arrays: dict[Path, int] = {}  # an array of tables (its concrete path) -> its tables so far

    def line_at(self, pos: int) -> int:
        return bisect.bisect_left(self.breaks, pos) + 1

    def mark(self, path: Path, line: int) -> None:
        self.explicit.setdefault(path, line)
        for size in range(1, len(path)):
            self.implicit.setdefault(path[:size], line)

    def skip(self, pattern: re.Pattern = _SPACE) -> None:
        m = pattern.match(self.text, self.pos)  # every pattern here matches the empty string
        self.pos = m.end() if m else self.pos

    def scan(self) -> None:
        table: Path = ()
        while True:
            self.skip()
            if self.pos >= len(self.text):
                return
            before = self.pos
            if self.text[self.pos] == "[":
                table = self.header()
            else:
                self.keyval(table)
            if self.pos == before:  # not TOML the parser accepted: keep what was found
                return

    def header(self) -> Path:
        line, array = self.line_at(self.pos), self.text.startswith("[[", self.pos)
        self.pos += 2 if array else 1
        keys = self.key()
        self.skip(_BLANK)
        self.pos += 2 if array else 1
        path: Path = ()
        for name in keys[:-1]:
            path += (name,)
            if path in self.arrays:  # [[a.b]] and [a.b] after [[a]]: in a's last table
                path += (self.arrays[path] - 1,)
        path += tuple(keys[-1:])
        if array:
            self.mark(path, line)
            self.arrays[path] = self.arrays.get(path, 0) + 1
            path += (self.arrays[path] - 1,)
        self.mark(path, line)
        return path

    def key(self) -> list[str]:
        names: list[str] = []
        while True:
            self.skip(_BLANK)
            quote = self.text[self.pos:self.pos + 1]
            if quote in ('"', "'"):
                start = self.pos
                self.string()
                names.append(_unquote(self.text[start:self.pos]))
            else:
                m = _BARE.match(self.text, self.pos)
                if not m:
                    return names
                names.append(m.group())
                self.pos = m.end()
            self.skip(_BLANK)
            if self.text[self.pos:self.pos + 1] != ".":
                return names
            self.pos += 1

    def keyval(self, table: Path) -> None:
        line = self.line_at(self.pos)
        keys = self.key()
        if not keys:
            return
        self.skip(_BLANK)
        if self.text[self.pos:self.pos + 1] == "=":
            self.pos += 1
        path = table + tuple(keys)
        self.mark(path, line)
        self.value(path)

    def value(self, path: Path) -> None:
        self.skip(_BLANK)
        first = self.text[self.pos:self.pos + 1]
        if first in ('"', "'"):
            self.string()
        elif first == "[":
            self.array(path)
        elif first == "{":
            self.inline_table(path)
        else:
            self.skip(_SCALAR)

    def string(self) -> None:
        quote = self.text[self.pos] * 3
        pattern = _STRING[quote] if self.text.startswith(quote, self.pos) else _STRING[quote[0]]
        m = pattern.match(self.text, self.pos)
        self.pos = m.end() if m else len(self.text)

    def array(self, path: Path) -> None:
        self.pos += 1
        index = 0
        while True:
            self.skip()
            char = self.text[self.pos:self.pos + 1]
            if char in ("]", ""):
                self.pos += 1
                return
            if char == ",":
                self.pos += 1
                continue
            before = self.pos
            self.mark(path + (index,), self.line_at(self.pos))
            self.value(path + (index,))
            if self.pos == before:
                return
            index += 1

    def inline_table(self, path: Path) -> None:
        self.pos += 1
        while True:
            self.skip()
            char = self.text[self.pos:self.pos + 1]
            if char in ("}", ""):
                self.pos += 1
                return
            if char == ",":
                self.pos += 1
                continue
            before = self.pos
            self.keyval(path)
            if self.pos == before:
                return


def _unquote(raw: str) -> str:
    """A quoted key's name, its escapes read by the TOML parser itself."""
    import tomllib

    try:
        return next(iter(tomllib.loads(f"{raw} = 0")))
    except (tomllib.TOMLDecodeError, StopIteration):
        return raw[1:-1]


class TomlDocument:
    """A parsed TOML document with its text and name: errors that name the file, the line and the key path.

    Parameters
    ----------
    source : str
        The file (or a description of the text), the start of every message.
    text : str
        The TOML text.
    data : dict
        The document parsed from ``text``.
    """

    def __init__(self, source: str, text: str, data: dict):
        self.source, self.text, self.data = source, text, data
        self._scanner: _Scanner | None = None

    def __repr__(self) -> str:
        return f"TomlDocument({self.source!r}, {len(self.text)} characters)"

    def line(self, parts: Sequence[str | int]) -> int | None:
        """The 1-based line of a key path, or None when neither it nor a container of it is in the text.

        Parameters
        ----------
        parts : sequence of str and int
            Names of keys and 0-based array indices (of arrays of tables and
            of arrays of values), outermost first.

        Returns
        -------
        int or None
            The line of the key (of the element, of the table's header);
            for a key the text does not have, the line of its nearest
            container that it has; None for a top-level key the text does
            not have.
        """
        if self._scanner is None:
            self._scanner = _Scanner(self.text)
            self._scanner.scan()
        found = self._scanner
        path = tuple(parts)
        for size in range(len(path), 0, -1):
            line = found.explicit.get(path[:size]) or found.implicit.get(path[:size])
            if line:
                return line
        return None

    def where(self, parts: Sequence[str | int] = ()) -> str:
        """``"<file>, line N"`` for a key path (``"<file>"`` when it has no line).

        Parameters
        ----------
        parts : sequence of str and int
            The key path (see :meth:`line`).

        Returns
        -------
        str
            The place, for the start of a message.
        """
        line = self.line(parts)
        return f"{self.source}, line {line}" if line else self.source

    def error(self, parts: Sequence[str | int], message: str,
              cls: type[FileFormatError] = FileFormatError) -> FileFormatError:
        """The error ``"<file>, line N: key.path: message"`` (the key path left out when empty).

        Parameters
        ----------
        parts : sequence of str and int
            The key path (see :meth:`line`).
        message : str
            What was given and what was expected.
        cls : type, default FileFormatError
            The class of the error (FileFormatError or a subclass).

        Returns
        -------
        FileFormatError
            The error, to be raised.
        """
        key = key_path(parts)
        return cls(f"{self.where(parts)}: {key}: {message}" if key else f"{self.where(parts)}: {message}")

    def wrap(self, parts: Sequence[str | int], message: str,
              cls: type[FileFormatError] = FileFormatError) -> FileFormatError:
        """A constructor's message for the value at ``parts``, its own field path merged into the key path.

        ``"od: got 0 mm; expected ..."`` from the segment at
        ``components[1].segments[0]`` becomes the error at
        ``components[1].segments[0].od``; a message that names a path from
        the top (``components[1].segments[0].od: ...``) is kept as it is,
        and one that starts with the file's name already is returned
        unchanged.

        Parameters
        ----------
        parts : sequence of str and int
            The key path of the value the constructor was given.
        message : str
            The constructor's message.
        cls : type, default FileFormatError
            The class of the error (FileFormatError or a subclass).

        Returns
        -------
        FileFormatError
            The error, to be raised.
        """
        if message.startswith(self.source):
            return cls(message)
        m = _FIELD.match(message)
        if not m:
            return self.error(parts, message, cls)
        field: list[str | int] = [int(i) if i else k for k, i in _PART.findall(m.group(1))]
        own = key_path(parts)
        full = bool(parts) and (m.group(1) == own or m.group(1).startswith(own + "."))
        return self.error(field if full else [*parts, *field], m.group(2), cls)


def _article(what: str) -> str:
    return f"{'an' if what[:1].lower() in 'aeiou' else 'a'} {what}"


def loads_toml(text: Any, source: str = "<string>", what: str | None = None) -> TomlDocument:
    """Parse TOML text into a :class:`TomlDocument`.

    Parameters
    ----------
    text : str
        The TOML text; a leading byte-order mark is dropped.
    source : str, default "<string>"
        The file (or a description of the text), for messages.
    what : str, optional
        What the document is (``"assembly"``, ``"measurement set"``); given,
        an empty or blank text is an error saying what was expected.

    Returns
    -------
    TomlDocument
        The parsed document with its text.

    Raises
    ------
    FileFormatError
        Naming ``source``: text that is not a str, an empty text (with
        ``what``), invalid TOML (with the parser's line and column).
    """
    if not isinstance(text, str):
        raise FileFormatError(f"{source}: got {type(text).__name__}; expected the TOML text as a str")
    text = text.removeprefix("\ufeff")  # a byte-order mark left by an editor is not part of the document
    if what is not None and not text.strip():
        raise FileFormatError(f"{source}: the file is empty; expected {_article(what)} (docs/file-formats.md)")
    return TomlDocument(source, text, parse_toml(text, source))


def read_toml(path: Any, what: str = "TOML file", expected: str | None = None,
              limit: int = MAX_TEXT_BYTES) -> TomlDocument:
    """Read a TOML file through the checked read (:func:`~substructure._files.read_text`) and parse it.

    Parameters
    ----------
    path : str or path-like
        The file.
    what : str, default "TOML file"
        What the file is, for the messages of the read (``"workpiece table"``).
    expected : str, optional
        What the document is, for the message of an empty file (see
        :func:`loads_toml`).
    limit : int, default MAX_TEXT_BYTES
        The largest size allowed, in bytes.

    Returns
    -------
    TomlDocument
        The document, named by ``os.fspath(path)``.

    Raises
    ------
    FileFormatError
        As :func:`~substructure._files.read_text` and :func:`loads_toml`.
    """
    text = read_text(path, what, limit)
    return loads_toml(text, os.fspath(path), expected)
