"""A plugin for the study tests: a spindle whose receptances kill the process computing them.

A study whose machine uses ``type = "crashing-spindle"`` loses the worker
that computes it (``os._exit``), as a segmentation fault or the kernel's
out-of-memory killer would; the study must fail that combination's rows
and go on.  Imported by the test and, through ``plugins``, by every worker.
"""

import os

import attrs

from substructure.components import Spindle, register_component


@register_component("crashing-spindle")
@attrs.frozen
class CrashingSpindle(Spindle):
    """A spindle that ends its process when asked for receptances."""

    def receptance_matrix(self, refs, frequency_hz):
        os._exit(3)
