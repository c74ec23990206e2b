"""Intersphinx inventories that need no network: written from small text lists kept in the repository.

The documentation links to numpy, scipy, pint, matplotlib, scikit-learn, dask
and Python's own documentation through intersphinx.  Intersphinx normally
downloads each project's ``objects.inv`` at build time; the machines that
build these docs (and CI) have no access to those sites, so the build would
not be reproducible.  Instead, ``docs/_inventories/<project>.txt`` lists the
external objects our docs refer to, one a line, with their real address in
the project's online documentation::

    # url: https://numpy.org/doc/stable/
    numpy.ndarray  py:class  reference/generated/numpy.ndarray.html#$

(``$`` stands for the name, as in Sphinx's own inventories; an optional
fourth column is the display name).  At the start of a build
:func:`write_inventories` turns every list into an ``objects.inv`` in
Sphinx's inventory format (version 2: a four-line header, then the zlib-
compressed lines ``name domain:role priority uri dispname``) under
``docs/_build/inventories/``, and ``conf.py`` hands those files to
intersphinx with the projects' real base addresses: the built pages link to
the online documentation, and the build reads no network.

A reference to an external object missing from the lists fails the build
(nitpicky mode): add a line to the project's list.  To check the lists against
a project's real inventory (a downloaded ``objects.inv``, or its address when
a network is at hand)::

    python docs/_ext/offline_inventories.py --verify numpy PATH_OR_URL_OF_objects.inv
"""

from __future__ import annotations

import argparse
import io
import sys
import urllib.request
import zlib
from pathlib import Path

HERE = Path(__file__).resolve().parent
LISTS = HERE.parent / "_inventories"


def read_list(path: Path) -> tuple[dict[str, str], list[tuple[str, str, str, str]]]:
    """The header fields (``# key: value``) and the entries (name, domain:role, uri, dispname) of a list."""
    header, entries = {}, []
    for number, raw in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
        line = raw.strip()
        if not line:
            continue
        if line.startswith("#"):
            key, sep, value = line[1:].partition(":")
            if sep and key.strip() in {"project", "version", "url"}:
                header[key.strip()] = value.strip()
            continue
        fields = line.split(None, 3)
        if len(fields) < 3 or ":" not in fields[1]:
            raise ValueError(f"{path}:{number}: expected 'name domain:role uri [display name]', got {raw!r}")
        name, role, uri = fields[:3]
        entries.append((name, role, uri, fields[3] if len(fields) > 3 else "-"))
    for key in ("project", "version", "url"):
        if key not in header:
            raise ValueError(f"{path}: the header line '# {key}: ...' is missing")
    return header, entries


def inventory_bytes(header: dict[str, str], entries) -> bytes:
    """An ``objects.inv`` (Sphinx inventory version 2) with these entries."""
    head = ("# Sphinx inventory version 2\n"
            f"# Project: {header['project']}\n"
            f"# Version: {header['version']}\n"
            "# The remainder of this file is compressed using zlib.\n").encode("utf-8")
    body = "".join(f"{name} {role} 1 {uri} {disp}\n" for name, role, uri, disp in sorted(entries))
    return head + zlib.compress(body.encode("utf-8"), 9)


def write_inventories(out_dir: Path, lists_dir: Path = LISTS) -> dict[str, tuple[str, Path]]:
    """Write ``<project>.inv`` for every list; return {project key: (base url, inventory path)}.

    The key is the list's file name without ``.txt`` (``numpy``, ``sklearn``, ...).
    """
    out_dir.mkdir(parents=True, exist_ok=True)
    mapping = {}
    for path in sorted(lists_dir.glob("*.txt")):
        header, entries = read_list(path)
        target = out_dir / f"{path.stem}.inv"
        data = inventory_bytes(header, entries)
        if not target.exists() or target.read_bytes() != data:
            target.write_bytes(data)
        mapping[path.stem] = (header["url"], target)
    return mapping


def _load_inventory(source: str) -> dict[tuple[str, str], str]:
    """{(name, domain:role): uri with $ expanded} of a real objects.inv (file or URL)."""
    if "://" in source:
        with urllib.request.urlopen(source, timeout=60) as response:  # only in --verify, by hand
            data = response.read()
    else:
        data = Path(source).read_bytes()
    stream = io.BytesIO(data)
    for _ in range(4):
        stream.readline()
    text = zlib.decompress(stream.read()).decode("utf-8")
    found = {}
    for line in text.splitlines():
        # name may contain spaces for some roles (std:label); domain:role is the first field
        # of the form x:y followed by a priority number
        parts = line.split(" ")
        for i in range(1, len(parts) - 2):
            if ":" in parts[i] and parts[i + 1].lstrip("-").isdigit():
                name, role, uri = " ".join(parts[:i]), parts[i], parts[i + 2]
                found[(name, role)] = uri.replace("$", name) if uri.endswith("$") else uri
                break
    return found


def verify(project: str, source: str, lists_dir: Path = LISTS) -> list[str]:
    """Entries of ``<project>.txt`` missing from the real inventory or with another address."""
    _, entries = read_list(lists_dir / f"{project}.txt")
    real = _load_inventory(source)
    problems = []
    for name, role, uri, _ in entries:
        ours = uri.replace("$", name) if uri.endswith("$") else uri
        theirs = real.get((name, role))
        if theirs is None:
            problems.append(f"{name} ({role}): not in the real inventory")
        elif theirs != ours:
            problems.append(f"{name} ({role}): the real address is {theirs}, the list has {ours}")
    return problems


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--verify", nargs=2, metavar=("PROJECT", "OBJECTS_INV"),
                        help="check docs/_inventories/PROJECT.txt against a real objects.inv (path or URL)")
    parser.add_argument("--out", type=Path, default=HERE.parent / "_build" / "inventories",
                        help="where to write the .inv files (default docs/_build/inventories)")
    args = parser.parse_args(argv)
    if args.verify:
        problems = verify(*args.verify)
        for line in problems:
            print(line)
        print(f"{args.verify[0]}: {len(problems)} problem(s)")
        return 1 if problems else 0
    for key, (url, path) in write_inventories(args.out).items():
        print(f"{key}: {path} -> {url}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
