"""Standard tool holders as data: the public name of the holder catalogue.

The catalogue (interfaces BT40, CAT40, HSK-A63 with ER collet, shrink-fit or
hydraulic noses; approximate geometry from ``substructure/data/holders.toml``
with its sources, overridable by name) lives in
``substructure.components.holder``, beside the ``Holder``
class it builds; see that module and docs/holders.md.
"""

from __future__ import annotations

# The catalogue lives beside the Holder class it builds (one module: no import circle between them).
from .components.holder import HolderDesign, catalog_names, catalog_parameters, design

__all__ = ["HolderDesign", "catalog_names", "catalog_parameters", "design"]
