"""Tap-test processing benchmark: 10 taps of 1 s at 51.2 kHz to an FRF with coherence.

Timed (median seconds): ``substructure.tap.process_taps`` of ten synthetic
tap records (a half-sine hammer pulse through two modes, noise on both
channels, fixed seed) with the default windows and H1, the records built in
the setup.  Goal: well under 1 s on 2 cores.
"""

from __future__ import annotations

import numpy as np

from substructure.tap import TapRecord, process_taps

RATE = 51_200.0
TAPS = 10


def _records() -> list[TapRecord]:
    rng = np.random.default_rng(12)
    n = int(RATE)
    t = np.arange(n) / RATE
    records = []
    for k in range(TAPS):
        start, width, peak = 0.01, 0.4e-3, 60.0 + 3.0 * k
        force = np.where((t >= start) & (t <= start + width), peak * np.sin(np.pi * (t - start) / width), 0.0)
        response = np.zeros(n)
        for fn, zeta, gain in ((850.0, 0.02, 1.0), (2300.0, 0.015, 0.6)):  # impulse responses of two modes
            wd = 2 * np.pi * fn * np.sqrt(1 - zeta**2)
            tau = np.clip(t - start, 0.0, None)
            response += gain * peak * np.exp(-zeta * 2 * np.pi * fn * tau) * np.sin(wd * tau) * (t >= start)
        records.append(TapRecord(t, np.clip(force, 0.0, None) + 0.01 * rng.standard_normal(n),
                                 response + 0.05 * rng.standard_normal(n), "acceleration", f"tap{k + 1}"))
    return records


def benchmarks():
    yield "tap_10_taps_seconds", _records, process_taps, 7
