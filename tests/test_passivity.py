"""The sign of a driving point (substructure.frf.passivity) and where a reversed one is refused."""

from __future__ import annotations

import attrs
import numpy as np
import pytest

from substructure import Frequency, default_assembly
from substructure.diagnose import diagnose
from substructure.errors import InvalidValueError
from substructure.frf import REVERSED_SHARE, reversed_share
from substructure.measurements import Measurement
from substructure.updating import Likelihood, measured_frfs


def _sdof(hz: np.ndarray, k: float = 1e7, m: float = 0.5, zeta: float = 0.02) -> np.ndarray:
    w = 2 * np.pi * hz
    c = 2 * zeta * np.sqrt(k * m)
    return 1.0 / (k - m * w**2 + 1j * c * w)  # x(t) = X exp(i omega t): Im H = -c omega |H|^2 <= 0


def test_the_share_of_a_closed_form_driving_point():
    hz = np.linspace(10.0, 2000.0, 500)
    h = _sdof(hz) + _sdof(hz, 4e7, 0.3, 0.05)  # two modes in parallel: still passive
    assert reversed_share(h) == 0.0
    assert reversed_share(-h) == 1.0 and reversed_share(np.conj(h)) == 1.0
    assert np.isnan(reversed_share(np.abs(h)))  # no imaginary part: no sign to read
    h_nan = h.copy()
    h_nan[3] = np.nan
    assert reversed_share(h_nan) == 0.0  # a line that is not finite is left out
    with pytest.raises(InvalidValueError, match="receptance: got str; expected an array of complex values"):
        reversed_share("tool.tip")


def test_noise_alone_stays_far_from_the_threshold():
    rng = np.random.default_rng(7)
    shares = [reversed_share(rng.normal(size=2000) + 1j * rng.normal(size=2000)) for _ in range(50)]
    assert max(abs(s - 0.5) for s in shares) < 0.1 < REVERSED_SHARE - 0.5
    # a passive FRF with noise of a third of its size on every line keeps its sign
    hz = np.linspace(10.0, 2000.0, 2000)
    h = _sdof(hz)
    noisy = h + (rng.normal(size=h.size) + 1j * rng.normal(size=h.size)) * np.abs(h) / 3
    assert reversed_share(noisy) < 0.2 and reversed_share(-noisy) > REVERSED_SHARE


@pytest.fixture(scope="module")
def measured():
    model = default_assembly()
    grid = Frequency.from_hz(np.linspace(150.0, 5000.0, 971))
    tip = Measurement.from_frf(model.frf("tool.tip:y", "tool.tip:y", grid), "tool.tip", "tool.tip")
    cross = Measurement.from_frf(model.frf("holder.tip:y", "tool.tip:y", grid), "holder.tip", "tool.tip")
    return model, tip, cross


def test_a_reversed_driving_point_is_refused_where_it_enters(measured):
    model, tip, cross = measured
    reversed_tip = attrs.evolve(tip, frf=-tip.frf)
    message = (r"measured FRF tool.tip:y / tool.tip:y: a driving point, whose receptance has Im\(H\) <= 0 on a "
               r"passive structure, has a positive imaginary part on lines holding 100% of \|Im H\|, and its phase "
               r"error against the model falls from 3.14 rad RMS to 0.00 when it is negated: one "
               r"channel's sign is reversed .* --reverse-polarity\)$")
    with pytest.raises(InvalidValueError, match=message):
        diagnose(model, [reversed_tip], progress=False)
    conjugate = attrs.evolve(tip, frf=attrs.evolve(tip.frf, data=np.conj(tip.frf.data)))
    with pytest.raises(InvalidValueError, match="when it is conjugated: the data follow the convention "
                                                 "exp\\(-i omega t\\), not exp\\(\\+i omega t\\)"):
        Likelihood(model, measured_frfs([conjugate])[0])
    # a cross point has no sign of its own: its negative is a model the data may test, not an input error
    assert Likelihood(model, measured_frfs([attrs.evolve(cross, frf=-cross.frf), tip])[0]).n > 0
