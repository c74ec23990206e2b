"""Files in and out of `substructure`: measured FRFs (CSV, UFF type 58) and more.

Submodules are imported on use (``from substructure.io.frf_files import
read_csv``), so that importing the package stays cheap and the core layers
never depend on file formats.
"""

import os

from ..errors import FileFormatError


def read_text(path) -> str:
    """The UTF-8 text of a file; a missing or unreadable file is a FileFormatError naming it."""
    name = os.fspath(path)
    try:
        with open(path, "rb") as fh:
            return fh.read().decode("utf-8")
    except FileNotFoundError:
        raise FileFormatError(f"{name}: no such file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise FileFormatError(f"{name}: cannot read the file ({exc})") from None

