"""From a predicted joint to the tool point FRF, with the uncertainty carried through.

The predictive distribution of the joint parameters (log-normal, from a
surrogate) is sampled with stratified samples; each sample's joint replaces
the assembly's joint, and the FRFs of all samples are computed at once as a
sweep.  The band is the envelope (minimum and maximum of ``|H|`` over the
samples) with the median: an envelope rather than pointwise percentiles,
because where a parameter value puts a resonance, that value's ``|H|`` is
the largest of all, and a percentile band would miss exactly it.
"""

from __future__ import annotations

import warnings

import attrs
import numpy as np

from .._text import plain_text
from ..assembly import Assembly
from ..errors import InvalidValueError, NonPassiveJointWarning
from ..frf import FRF, Frequency
from ..sweep import sweep

__all__ = ["FRFBand", "predict_frf_band"]

_ENTRIES = {"k_yf": ("k", "yf"), "k_tm": ("k", "tm"), "k_ym": ("k", "ym"), "k_tf": ("k", "tf"),
            "c_yf": ("c", "yf"), "c_tm": ("c", "tm"), "c_ym": ("c", "ym"), "c_tf": ("c", "tf")}


@attrs.frozen
class FRFBand:
    """The tool point FRF of a predicted joint: median and envelope of ``|H|`` over samples.

    Parameters
    ----------
    frequency : Frequency
        The frequency lines, in Hz.
    median : ndarray
        Median of ``|H|`` over the samples (m/N for translations), per line.
    lower : ndarray
        Lowest ``|H|`` over the samples, per line.
    upper : ndarray
        Highest ``|H|`` over the samples, per line.
    nominal : FRF
        The FRF with the median parameters.
    samples : dict of str to ndarray
        The sampled parameter values (SI).
    """

    frequency: Frequency
    median: np.ndarray = attrs.field(eq=False)
    lower: np.ndarray = attrs.field(eq=False)
    upper: np.ndarray = attrs.field(eq=False)
    nominal: FRF = attrs.field(eq=False)
    samples: dict = attrs.field(eq=False)

    def contains(self, frf: FRF, rtol: float = 1e-9) -> np.ndarray:
        """Lines where ``|frf|`` lies inside the band.

        Parameters
        ----------
        frf : FRF
            A one-entry FRF on the band's lines (m/N).
        rtol : float
            Relative tolerance on the envelope.

        Returns
        -------
        ndarray
            Boolean, one value per line.
        """
        h = np.abs(frf.data[:, 0, 0])
        return (h >= self.lower * (1 - rtol)) & (h <= self.upper * (1 + rtol))

    def to_json(self) -> dict:
        """The band for JSON output.

        Returns
        -------
        dict
            ``frequency_hz`` (Hz), ``magnitude_median``, ``magnitude_lower``, ``magnitude_upper``
            (m/N), ``n_samples``.
        """
        return {"frequency_hz": self.frequency.hz.tolist(), "magnitude_median": self.median.tolist(),
                "magnitude_lower": self.lower.tolist(), "magnitude_upper": self.upper.tolist(),
                "n_samples": int(len(next(iter(self.samples.values()))))}

    def plot(self, ax=None, label="predicted"):
        """The envelope shaded and the FRF of the median joint, ``|H|`` on a log scale.

        Parameters
        ----------
        ax : Axes, optional
            Where to draw; a new figure when None.
        label : str
            Legend label.

        Returns
        -------
        Figure
            The figure: ``|H|`` in m/N against frequency in Hz.
        """
        import matplotlib.pyplot as plt

        if ax is None:
            fig, ax = plt.subplots(figsize=(7.5, 4.0), layout="constrained")
        else:
            fig = ax.figure
        f = self.frequency.hz
        ax.fill_between(f, self.lower, self.upper, color="tab:blue", alpha=0.25, label=plain_text(f"{label}: envelope"))
        ax.semilogy(f, np.abs(self.nominal.data[:, 0, 0]), color="tab:blue", lw=1.2,
                    label=plain_text(f"{label}: median joint"))
        ax.set_xlabel("frequency [Hz]")
        ax.set_ylabel(plain_text(f"|{self.nominal.outputs[0]} / {self.nominal.inputs[0]}| [m/N]"))
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize="small")
        return fig


def predict_frf_band(assembly: Assembly, joint: str, prediction, at: str = "tool.tip:y", to: str | None = None,
                     frequency=None, n_samples: int = 64, seed: int = 0, index: int = 0) -> FRFBand:
    """The FRF band of an assembly whose joint takes the predicted parameters.

    Parameters
    ----------
    assembly : Assembly
        The model; its joint ``joint`` supplies the parameters not predicted.
    joint : str
        Name of the joint the prediction is for (e.g. ``"holder-tool"``).
    prediction : Prediction
        From a surrogate's ``predict``; parameters named ``k_yf``, ``k_tm``, ``c_yf``, ...
    at, to : str
        Response and excitation DOFs (one FRF entry).
    frequency : Frequency or array_like, optional
        Frequency lines (plain numbers in Hz); default the assembly's grid.
    n_samples : int
        Stratified samples of the predictive distribution.
    seed : int
        Seed of the sampling.
    index : int
        Which feature set of the prediction.

    Returns
    -------
    FRFBand
        The median FRF and the envelope of ``|H|`` (m/N) over the samples.
    """
    if n_samples < 2:
        raise InvalidValueError(f"n_samples: got {n_samples!r}; expected at least 2")
    template = assembly.joint(joint)
    unknown = [p for p in prediction.log_mean if p not in _ENTRIES]
    if unknown:
        raise InvalidValueError(f"prediction: parameters {unknown} are not joint entries ({', '.join(_ENTRIES)})")
    samples = prediction.sample(n_samples, rng=seed, index=index)
    medians = {p: float(prediction.value(p)[index]) for p in prediction.log_mean}

    def joint_with(values):
        k, c = {}, {}
        for name, value in values.items():
            kind, entry = _ENTRIES[name]
            (k if kind == "k" else c)[entry] = f"{float(value)!r} {prediction.units[name]}"
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", NonPassiveJointWarning)
            return template.with_parameters(k=k, c=c)

    variants = [assembly.with_joint(joint_with({p: samples[p][i] for p in samples})) for i in range(n_samples)]
    result = sweep(variants, [at], [to or at], frequency)
    mag = np.abs(result.data[:, :, 0, 0])
    nominal = assembly.with_joint(joint_with(medians)).frf([at], [to or at], result.frequency)
    return FRFBand(result.frequency, np.median(mag, axis=0), mag.min(axis=0), mag.max(axis=0), nominal, samples)
