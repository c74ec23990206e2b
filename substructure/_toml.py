"""TOML documents that know the line of every key: the one reader of the package's TOML files.

Every TOML file the package reads is parsed by :func:`loads_toml` or
:func:`read_toml` into a :class:`TomlDocument`, the data with their text, so
that errors name the file, the line and the key path
(``"bench.toml, line 12: components[1].segments[0].od: ..."``).  The lines come
from a scan of the text's structure (headers, arrays of tables at any depth,
dotted and quoted keys, inline tables, arrays across lines; strings and
comments skipped) on the first error; a key the text does not have gets the
line of its nearest container.
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
_STRING = {  # the extent of each kind of string (escapes in basic strings; up to two quotes before the closing;
    # one way to match each character, so that no text makes the search backtrack more than once over it)
    '"""': re.compile(r'"""(?:[^"\\]|\\[\s\S]|"(?!""))*"""(?:"{0,2})'),
    "'''": re.compile(r"'''(?:[^']|'(?!''))*'''(?:'{0,2})"),
    '"': re.compile(r'"(?:[^"\\\n]|\\.)*"'),
    "'": re.compile(r"'[^'\n]*'"),
}
_SCALAR = re.compile(r"[^,\]}#\n]*")  # a number, boolean or date: up to the next delimiter
_FIELD = re.compile(r"^([A-Za-z_][A-Za-z0-9_.\[\]]*): (.*)$", re.DOTALL)
_PART = re.compile(r"([^.\[\]]+)|\[(\d+)\]")

Parts = Sequence[str | int]


def key_path(parts: Parts) -> str:
    """A key path as messages write it, ``components[1].segments[0].od`` (``""`` for the document)."""
    text = ""
    for p in parts:
        text += f"[{p}]" if isinstance(p, int) else (f".{p}" if text else str(p))
    return text


class _Scanner:
    """The 1-based line of every key, table and array element of valid TOML text (``lines``)."""

    def __init__(self, text: str):
        self.text, self.pos = text, 0
        self.breaks = [m.start() for m in re.finditer("\n", text)]
        self.lines: dict[tuple, int] = {}  # a key path -> the line where it first appears
        self.arrays: dict[tuple, int] = {}  # an array of tables (its path) -> its tables so far
        table: tuple = ()
        while True:
            self.skip()
            before = self.pos
            if self.pos >= len(text):
                return
            if text[self.pos] == "[":
                table = self.header()
            else:
                self.keyval(table)
            if self.pos == before:  # not TOML the parser accepted: keep what was found
                return

    def mark(self, path: tuple, pos: int) -> None:
        line = bisect.bisect_left(self.breaks, pos) + 1
        for size in range(1, len(path) + 1):
            self.lines.setdefault(path[:size], line)

    def skip(self, pattern: re.Pattern = _SPACE) -> None:
        m = pattern.match(self.text, self.pos)  # every pattern given matches the empty string
        self.pos = m.end() if m else self.pos

    def header(self) -> tuple:
        start, array = self.pos, self.text.startswith("[[", self.pos)
        self.pos += 2 if array else 1
        keys = self.key()
        self.skip(_BLANK)
        self.pos += 2 if array else 1
        path: tuple = ()
        for i, name in enumerate(keys):
            path += (name,)
            if path in self.arrays and i < len(keys) - 1:
                path += (self.arrays[path] - 1,)  # [[a.b]] and [a.b] after [[a]]: in a's last table
        if array:
            self.arrays[path] = self.arrays.get(path, 0) + 1
            path += (self.arrays[path] - 1,)
        self.mark(path, start)
        return path

    def key(self) -> list[str]:
        names: list[str] = []
        while True:
            self.skip(_BLANK)
            if self.text[self.pos:self.pos + 1] in ('"', "'"):
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

    def keyval(self, table: tuple) -> None:
        start = self.pos
        keys = self.key()
        if keys:
            self.skip(_BLANK)
            self.pos += self.text[self.pos:self.pos + 1] == "="
            self.mark(table + tuple(keys), start)
            self.value(table + tuple(keys))

    def value(self, path: tuple) -> None:
        self.skip(_BLANK)
        first = self.text[self.pos:self.pos + 1]
        if first in ('"', "'"):
            self.string()
        elif first in ("[", "{"):
            self.items(path, first == "[")
        else:
            self.skip(_SCALAR)

    def string(self) -> None:
        quote = self.text[self.pos] * 3
        m = (_STRING[quote] if self.text.startswith(quote, self.pos) else _STRING[quote[0]]).match(self.text, self.pos)
        self.pos = m.end() if m else len(self.text)

    def items(self, path: tuple, array: bool) -> None:
        """An array (its elements numbered) or an inline table, from its opening bracket."""
        self.pos += 1
        index = 0
        while True:
            self.skip()
            char, before = self.text[self.pos:self.pos + 1], self.pos
            if char in ("]", "}", ""):
                self.pos += 1
                return
            if char == ",":
                self.pos += 1
                continue
            if array:
                self.mark(path + (index,), self.pos)
                self.value(path + (index,))
                index += 1
            else:
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
    """A parsed TOML document (``data``) with its ``text`` and ``source`` (the file's name, the start of messages).

    Key paths (``parts``) are key names and 0-based indices of arrays (of
    tables or of values), outermost first.
    """

    def __init__(self, source: str, text: str, data: dict):
        self.source, self.text, self.data = source, text, data
        self._lines: dict[tuple, int] | None = None

    def line(self, parts: Parts) -> int | None:
        """The 1-based line of a key path (or of its nearest container in the text), or None."""
        if self._lines is None:
            self._lines = _Scanner(self.text).lines
        path = tuple(parts)
        return next((self._lines[path[:n]] for n in range(len(path), 0, -1) if path[:n] in self._lines), None)

    def where(self, parts: Parts = ()) -> str:
        """``"<file>, line N"`` for a key path (``"<file>"`` when it has no line)."""
        line = self.line(parts)
        return f"{self.source}, line {line}" if line else self.source

    def error(self, parts: Parts, message: str, cls: type[FileFormatError] = FileFormatError) -> FileFormatError:
        """The error ``"<file>, line N: key.path: message"`` (of class ``cls``), to be raised."""
        key = key_path(parts)
        return cls(f"{self.where(parts)}: {key}: {message}" if key else f"{self.where(parts)}: {message}")

    def wrap(self, parts: Parts, message: str, cls: type[FileFormatError] = FileFormatError) -> FileFormatError:
        """A constructor's message for the value at ``parts`` as an error, its field path merged into the key path.

        ``"od: got 0 mm; ..."`` for the segment at ``components[1].segments[0]``
        is the error at ``components[1].segments[0].od``; a message that gives
        the path from the top already is kept, one that starts with the file's
        name is returned as it is.
        """
        if message.startswith(self.source):
            return cls(message)
        m = _FIELD.match(message)
        if not m:
            return self.error(parts, message, cls)
        field = [int(i) if i else k for k, i in _PART.findall(m.group(1))]
        own = key_path(parts)
        full = bool(parts) and (m.group(1) == own or m.group(1).startswith(own + "."))
        return self.error(field if full else [*parts, *field], m.group(2), cls)

    def table(self, value: Any, parts: Parts, allowed: Sequence[str], required: Sequence[str] = (),
              what: str = "a table") -> dict:
        """``value`` (at ``parts``), checked to be a table of ``allowed`` keys that has the ``required`` ones."""
        if not isinstance(value, dict):
            raise self.error(parts, f"got {value!r}; expected {what}")
        for key in value:
            if key not in allowed:
                raise self.error([*parts, key], f"unknown key; allowed keys: {', '.join(allowed)}")
        for key in required:
            if key not in value:
                raise self.error([*parts, key], "missing; this value is required")
        return value

    def tables(self, key: str, allowed: Sequence[str], required: Sequence[str] = ()) -> list[dict]:
        """The ``[[key]]`` tables of a document of nothing else (at least one), each checked by :meth:`table`."""
        for other in [k for k in self.data if k != key][:1]:
            raise self.error([other], f"unknown key; expected [[{key}]] tables")
        rows = self.data.get(key)
        if rows is None or rows == []:
            raise self.error([], f"no [[{key}]] table")
        if not isinstance(rows, list):
            raise self.error([key], f"got {rows!r}; expected [[{key}]] tables")
        return [self.table(row, [key, i], allowed, required) for i, row in enumerate(rows)]


def loads_toml(text: Any, source: str = "<string>", what: str | None = None) -> TomlDocument:
    """TOML text (a leading byte-order mark dropped) parsed into a :class:`TomlDocument` named ``source``.

    Text that is not a str, invalid TOML and, with ``what`` (what the
    document is: ``"assembly"``), an empty text are errors naming ``source``.
    """
    if not isinstance(text, str):
        raise FileFormatError(f"{source}: got {type(text).__name__}; expected the TOML text as a str")
    text = text.removeprefix("\ufeff")  # a byte-order mark left by an editor is not part of the document
    if what is not None and not text.strip():
        article = "an" if what[:1] in "aeiou" else "a"
        raise FileFormatError(f"{source}: the file is empty; expected {article} {what} (docs/file-formats.md)")
    if "\r" in text.rstrip("\r") and "\n" not in text:  # TOML ends a line with LF or CRLF, never CR alone
        raise FileFormatError(f"{source}: the lines end in a carriage return alone (CR, as old Mac OS wrote "
                              "them); TOML needs LF or CRLF line ends: save the file with LF line ends")
    return TomlDocument(source, text, parse_toml(text, source))


def read_toml(path: Any, what: str = "TOML file", limit: int = MAX_TEXT_BYTES) -> TomlDocument:
    """A TOML file read through :func:`~substructure._files.read_text` (``what`` names it there) and parsed."""
    return loads_toml(read_text(path, what, limit), os.fspath(path))
