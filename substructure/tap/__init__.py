"""Tap tests: time records of an instrumented hammer and a response sensor to an FRF with coherence.

The package sits next to :mod:`substructure.frf` in the layers: it needs
``frf``, ``units`` and ``errors`` and knows nothing of models.

- :mod:`~substructure.tap.records`: :class:`TapRecord` (force and response on
  one uniform time axis, SI units) and the conversion of channels in volts
  with a sensor's sensitivity.
- :mod:`~substructure.tap.detect`: the pulse of a tap, double hits,
  clipping, records without a hit, swapped channels, the taps of a long
  record; the thresholds as named constants.
- :mod:`~substructure.tap.process`: :func:`process_taps` (windows, H1/H2/Hv,
  coherence, the hammer's usable band).
- :mod:`~substructure.tap.result`: :class:`TapResult` (and :class:`Tap`):
  the FRF, its coherence, peaks and damping, the window's added damping.
- :mod:`~substructure.tap.record_end`: the end of a tap: whether the
  exponential window is needed, and the error the truncation of a response
  that still rings leaves in the FRF (counted by the noise model).

Files are read by :mod:`substructure.io.tap_files` (``read_tap_csv``,
``read_tap_lvm``, ``read_tap_mat``, ``read_taps_mat``, ``read_tap_uff``, ``read_taps_uff``), the figure to check a
result is
:func:`substructure.plot.plot_taps`; the command is ``substructure tap``
(docs/tap.md).
"""

from .detect import (CLIP_REACH, CLIP_RUN, CLIP_TOLERANCE, CREST_FACTOR_PULSE, DOUBLE_HIT_FRACTION, NO_HIT_FACTOR,
                     PRE_TRIGGER_S, TRIGGER_FRACTION, SwappedChannelsError)
from .process import (ESTIMATORS, EXP_WINDOW_END, FORCE_WINDOW_BEFORE, FORCE_WINDOW_EXTRA, HAMMER_BAND_DB,
                      PULSE_LONGEST_S, PULSE_SHORTEST_S, SHORT_TAP_SHARE, process_taps)
from .record_end import (DECAYED_SHARE, TRUNCATION_NEGLIGIBLE, TRUNCATION_RATIO_MAX, TRUNCATION_SEGMENT,
                         TRUNCATION_SIGNIFICANCE, WINDOW_SHARE)
from .records import RESPONSE_QUANTITIES, TapRecord, channel_to_si, unit_of
from .result import HALF_POWER_LINES, PEAK_PROMINENCE, Tap, TapResult, added_damping

__all__ = [
    "TapRecord", "process_taps", "TapResult", "Tap", "added_damping", "channel_to_si", "unit_of",
    "SwappedChannelsError", "ESTIMATORS", "RESPONSE_QUANTITIES", "TRIGGER_FRACTION", "NO_HIT_FACTOR",
    "DOUBLE_HIT_FRACTION", "CLIP_RUN", "CLIP_TOLERANCE", "CLIP_REACH", "PRE_TRIGGER_S", "CREST_FACTOR_PULSE",
    "EXP_WINDOW_END", "FORCE_WINDOW_EXTRA", "FORCE_WINDOW_BEFORE", "HAMMER_BAND_DB", "PEAK_PROMINENCE",
    "HALF_POWER_LINES", "DECAYED_SHARE", "WINDOW_SHARE", "TRUNCATION_SEGMENT", "TRUNCATION_RATIO_MAX",
    "TRUNCATION_SIGNIFICANCE", "TRUNCATION_NEGLIGIBLE", "SHORT_TAP_SHARE", "PULSE_SHORTEST_S", "PULSE_LONGEST_S",
]

