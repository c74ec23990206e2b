"""CSV exports of measured FRFs as spreadsheet and acquisition programs write them.

The reader lives in ``substructure.frf.files.exports``, beside the CSV reader that hands
it every header other than its own (one package, no import circle); this module keeps the name
``substructure.io.frf_exports.parse_export`` working.
"""

from __future__ import annotations

from ..frf.files.exports import parse_export

__all__ = ["parse_export"]
