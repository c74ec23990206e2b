"""The noise of a real tap test, to lay on exact FRFs (test helper).

The five raw impact records shipped with the package (MIT, from the pyFRF project): their H1 estimate
computed here with numpy alone (not with the library's tap-test code), and its residual about a
Savitzky-Golay fit: heavy-tailed, and larger near the real structure's resonances and antiresonances.
"""

from __future__ import annotations

import functools
import warnings

import numpy as np

from substructure import FRF, Frequency, datasets
from substructure.smoothing import CoarseDataWarning, choose_window, smooth


@functools.cache
def real_residual() -> np.ndarray:
    """``H / S(H)`` of the real H1 estimate (20 Hz - 5 kHz at 1 Hz): the multiplicative noise of a real test."""
    records = datasets.impact_records()
    spectra = [(np.fft.rfft(r.force), np.fft.rfft(r.response)) for r in records]
    gff = sum(np.abs(f) ** 2 for f, _ in spectra)
    gfx = sum(np.conj(f) * x for f, x in spectra)
    rate = 1.0 / float(records[0].time[1] - records[0].time[0])
    freq = np.fft.rfftfreq(records[0].force.size, 1.0 / rate)
    keep = (freq >= 20) & (freq <= 5000)
    h1 = (gfx / gff)[keep]
    real = FRF(Frequency(freq[keep]), h1[:, None, None], ("a:y",), ("b:y",))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CoarseDataWarning)  # the real peaks are sharper than a line
        window = choose_window(real)
    residual = h1 / smooth(real, window=window).data[:, 0, 0]
    residual.setflags(write=False)
    return residual


@functools.cache
def free_free_residual() -> np.ndarray:
    """``H / S(H)`` of the three measured FRFs of a free-free beam (5 Hz - 1 kHz at 1 Hz, one after the other):
    the residual of another real test (another structure, another acquisition), with the Savitzky-Golay fit's
    misfit at the beam's sharp peaks left in (outliers of 1-2.5 in ln)."""
    parts = []
    for frf in datasets.free_free_beam_frfs():
        keep = frf.frequency.hz >= 5.0
        cut = FRF(Frequency(frf.frequency.hz[keep]), frf.data[keep], frf.outputs, frf.inputs)
        parts.append(cut.data[:, 0, 0] / smooth(cut, window=5).data[:, 0, 0])
    residual = np.concatenate(parts)
    residual.setflags(write=False)
    return residual


def with_real_noise(frfs, offset: int, level: float = 1.0, residual: np.ndarray | None = None) -> list[FRF]:
    """Each exact FRF times a real residual (default :func:`real_residual`; repeated where it is shorter than the
    FRFs) raised to ``level``, the j-th from line ``offset + 1300 j``."""
    residual = real_residual() if residual is None else residual
    if residual.size < 2 * max(f.frequency.n for f in frfs):
        residual = np.tile(residual, 2 * max(f.frequency.n for f in frfs) // residual.size + 1)
    out = []
    for j, exact in enumerate(frfs):
        n = exact.frequency.n
        start = (offset + 1300 * j) % (residual.size - n)
        rho = np.exp(level * np.log(residual[start:start + n]))
        out.append(FRF(exact.frequency, exact.data * rho[:, None, None], exact.outputs, exact.inputs))
    return out
