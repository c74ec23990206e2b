"""What a diagnosis says when nothing explains the data, and which measurement separates two explanations.

:func:`unexplained_report` writes the lines of an honest verdict: that no
candidate explains the data (with the error against the noise floor and
the test), where the remaining error lives (bands of lines and FRFs, from
the band test of :func:`substructure.updating.selection.consistency`), the
best partial explanation labelled partial, how the modes of the model as
given sit against the measured ones, and the *signature*: which kind of
change would move the modes as the measurement has them.  The signature
compares the measured relative mode shifts ``d_i = ln(f_measured / f_model)``
with the sensitivities ``s_ij = d ln f_i / d ln theta_j`` of the model's
modes to the stiffness and the mass of each component, each joint's
stiffness and each component's supports (finite differences of 5 %); the
knob ``j`` whose pattern ``a s_j`` fits ``d`` best (largest share of
``|d|^2`` explained) names the kind of effect, and each mode is named after
the component whose stiffness moves it most.  :func:`level_signature`
recognises data that are a constant factor times the model with every mode
in place: a calibration or unit error, not the structure.

:func:`separation` ranks candidate measurements (point and cross FRFs at
the ends, quarter points and middle of every beam component; with a
non-contact sensor when one explanation belongs to the test) by how much
two explanations differ there relative to the noise of the data.

The numbers (the finite-difference factor, the shares, the bands) are fields
of :class:`~substructure.diagnose.settings.DiagnoseSettings`; the sentences
are written by :mod:`substructure.diagnose.words`.
"""

from __future__ import annotations

import numpy as np

from ..updating.structure import uniform_beam
from ..errors import SubstructureError
from ..measurements import model_of_measurement
from ..updating.parameters import set_parameters
from ..updating.selection import INDIFFERENCE
from . import words
from .effects import tested_at, written_back
from .settings import DEFAULT_SETTINGS, DiagnoseSettings
from .words import values_text

__all__ = ["unexplained_report", "separation", "signature", "level_signature", "values_text"]


def _plain_beams(assembly):
    return [c for c in assembly.components if uniform_beam(c)]


def _peak(f: np.ndarray, h: np.ndarray, near: float, width: float = 0.15) -> float | None:
    """The resonance of ``|h|`` nearest ``near`` (within ``width``, relative), by a parabola through the top
    three lines."""
    window = np.flatnonzero((f > (1.0 - width) * near) & (f < (1.0 + width) * near))
    if window.size < 3:
        return None
    a = np.log(np.abs(h[window]))
    i = int(np.argmax(a))
    if i == 0 or i == window.size - 1:
        return None
    y0, y1, y2 = a[i - 1], a[i], a[i + 1]
    den = y0 - 2 * y1 + y2
    shift = 0.0 if den == 0 else 0.5 * (y0 - y2) / den
    df = f[window[1]] - f[window[0]]
    return float(f[window[i]] + shift * df)


def _knobs(assembly) -> list[tuple[str, str, str]]:
    """``(path, kind, description)`` of the knobs of the signature analysis."""
    out = []
    for comp in _plain_beams(assembly):
        out.append((f"components.{comp.name}.E", "stiffness", f"the stiffness of the {comp.name}"))
        out.append((f"components.{comp.name}.rho", "mass", f"the mass of the {comp.name}"))
    for j in assembly.joints:
        if getattr(j, "rigid", True) is False and getattr(j, "k", None):
            out.append((f"joints.{j.name}.k", "stiffness", f"the stiffness of the joint {j.name}"))
    for comp in dict.fromkeys(s.at.split("@")[0].split(".")[0] for s in assembly.supports):
        out.append((f"components.{comp}.supports.k", "stiffness", f"the stiffness of the supports of the {comp}"))
    return out


def signature(model, measured_frf, pairs, settings: DiagnoseSettings = DEFAULT_SETTINGS) -> tuple[list[str], dict]:
    """Name the modes and the kind of change their shifts point to.

    Parameters
    ----------
    model : Assembly
        The best model (in the configuration of ``measured_frf``).
    measured_frf : FRF
        One measured entry.
    pairs : list of ModePair
        Measured modes paired with the model's.
    settings : DiagnoseSettings
        ``signature_step``, ``signature_window``, ``signature_share``, ``in_place_lines``.

    Returns
    -------
    (list of str, dict)
        Report lines and the numbers (``modes``: names and shifts,
        ``knob``: the best-matching change and its share).
    """
    f = measured_frf.frequency.hz
    out, inp = list(measured_frf.outputs), list(measured_frf.inputs)
    paired = [p for p in pairs if p.model_hz is not None]
    if not paired:
        return [], {}
    base = model.frf(out, inp, measured_frf.frequency).data[:, 0, 0]
    width = settings.signature_window
    f0 = [_peak(f, base, p.model_hz, width) for p in paired]
    keep = [i for i, v in enumerate(f0) if v is not None]
    if not keep:
        return [], {}
    paired = [paired[i] for i in keep]
    f0 = np.array([f0[i] for i in keep])
    measured_hz = np.array([p.measured_hz for p in paired])
    d = np.log(measured_hz / f0)
    sens, names = [], []
    for path, kind, text in _knobs(model):
        try:
            changed = set_parameters(model, {path: settings.signature_step})
            h = changed.frf(out, inp, measured_frf.frequency).data[:, 0, 0]
        except (SubstructureError, ValueError):
            continue
        f1 = np.array([_peak(f, h, v, width) or v for v in f0])
        sens.append(np.log(f1 / f0) / np.log(settings.signature_step))
        names.append((path, kind, text))
    if not sens:
        return [], {}
    s = np.array(sens)
    lines = []
    step = float(f[1] - f[0]) if f.size > 1 else 1.0
    mode_names = []
    for i, p in enumerate(paired):
        # strain energy share of a stiffness: 2 d ln f / d ln k; kinetic energy share of a mass: -2 d ln f / d ln m
        strain = [(s[j, i], names[j][2].replace("the stiffness of the ", "")) for j in range(len(names))
                  if names[j][1] == "stiffness"]
        motion = [(-s[j, i], names[j][2].replace("the mass of the ", "")) for j in range(len(names))
                  if names[j][1] == "mass"]
        where_strain = max(strain)[1] if strain else "?"
        where_motion = max(motion)[1] if motion else "?"
        mode_names.append(where_strain)
        in_place = abs(p.measured_hz - f0[i]) < settings.in_place_lines * step
        lines.append(words.mode_line(f0[i], where_strain, where_motion, None if in_place else float(d[i]),
                                     settings.in_place_lines))
    moved = np.abs(measured_hz - f0) >= settings.in_place_lines * step
    info = {"modes": [{"model_hz": float(v), "measured_hz": float(p.measured_hz), "strain": n}
                      for v, p, n in zip(f0, paired, mode_names)]}
    if not moved.any():
        return lines, info
    dd = float(d @ d)
    best = None
    if dd > 0:
        for j, (path, kind, text) in enumerate(names):
            ss = float(s[j] @ s[j])
            if ss <= 0:
                continue
            a = float(s[j] @ d) / ss
            share = 1.0 - float(np.sum((d - a * s[j]) ** 2)) / dd
            if best is None or share > best[0]:
                best = (share, a, path, kind, text)
    if best is not None and best[0] > settings.signature_share:
        share, a, path, kind, text = best
        lines.append(words.signature_line(f0[moved & (d < 0)].tolist(), f0[moved & (d > 0)].tolist(), text, kind, a,
                                          share))
        info["knob"] = {"path": path, "kind": kind, "factor": float(np.exp(a)), "share": share}
    return lines, info


def level_signature(baseline, floor: float, settings: DiagnoseSettings = DEFAULT_SETTINGS) -> tuple[list[str], dict]:
    """A measurement that is a constant factor times the model everywhere, with the modes in place.

    Per measured FRF, the ratio ``r = ln |H_measured / H_model|`` of the
    model as given, its median ``m`` over all lines and its medians over
    ``settings.level_bands`` bands of lines.  When for every FRF ``|m|`` is
    above ``settings.level_floors`` (two) noise floors, every band's median
    has the sign of ``m`` and lies between ``1 / settings.level_spread`` and
    ``settings.level_spread`` (half and twice) times it, and every paired
    mode is within ``settings.level_in_place`` (1 %, or
    ``settings.in_place_lines`` lines) of the model's (or, the factor taken
    out, the FRF's error is within ``settings.explained_error_factor`` of
    its noise floor: a peak picked on noisy lines near a node moves more
    than the modes do), the FRFs differ from the model by a scale: what a
    calibration or unit error does (the hammer's or the sensor's
    sensitivity, g taken for m/s^2), and what a change of the structure
    does only by scaling every mass and stiffness alike.

    Parameters
    ----------
    baseline : sequence of Comparison
        The model as given against each measured FRF.
    floor : float
        The noise floor (``rms_log_ratio`` of a perfect model).
    settings : DiagnoseSettings
        The bands and thresholds of the test.

    Returns
    -------
    (list of str, dict)
        The report line (none when the pattern is absent) and the factors
        per FRF (``level``).
    """
    factors = []
    for c in baseline:
        f = c.measured.frequency.hz
        with np.errstate(divide="ignore", invalid="ignore"):
            full = np.log(c.measured.data[:, 0, 0] / c.model.data[:, 0, 0])
        ok = np.isfinite(full)
        if ok.sum() < 4 * settings.level_bands:  # at least four lines a band
            return [], {}
        r = full.real[ok]
        m = float(np.median(r))
        bands = np.array([np.median(b) for b in np.array_split(r, settings.level_bands)])
        step = float(f[1] - f[0]) if f.size > 1 else 1.0
        # a peak picked on noisy lines moves by a few lines: "in place" is within 1 % (or two lines)
        in_place = all(p.model_hz is not None and abs(p.model_hz - p.measured_hz)
                       <= max(settings.in_place_lines * step, settings.level_in_place * p.model_hz) for p in c.modes)
        # or the factor taken out, the FRF as good as the data (a peak picked off by noise near a node moves)
        in_place = in_place or (float(np.sqrt(np.mean(np.abs(full[ok] - m) ** 2)))
                                <= settings.explained_error_factor * c.noise_floor)
        spread = settings.level_spread
        if not (in_place and c.modes and abs(m) > settings.level_floors * floor and np.all(bands / m > 1.0 / spread)
                and np.all(bands / m < spread)):
            return [], {}
        factors.append((str(c.measured.outputs[0]), str(c.measured.inputs[0]), float(np.exp(m))))
    if not factors:
        return [], {}
    return [words.level_line(factors)], {"level": [{"response": o, "excitation": i, "factor": x}
                                                   for o, i, x in factors]}


def unexplained_report(lik, assembly, current, baseline, cons, final_error: float, floor: float,
                       explained: bool, say=None, settings: DiagnoseSettings = DEFAULT_SETTINGS,
                       check=None) -> list[str]:
    """The lines of the verdict when the data are not explained (see the module docstring).

    Parameters
    ----------
    lik : Likelihood
        The data.
    assembly : Assembly
        The model as given.
    current : list of (Change, dict)
        The best (partial) model's changes.
    baseline : sequence of Comparison
        The model as given against each measured FRF (its modes give the signature).
    cons : Consistency
        The test of the best model.
    final_error : float
        Its error.
    floor : float
        The noise floor.
    explained : bool
        The verdict.
    say : callable, optional
        Progress.
    settings : DiagnoseSettings
        The numbers of the signatures and of the bands named.
    check : ErrorCheck, optional
        The plain check of the error (said when it failed).

    Returns
    -------
    list of str
        The report, the verdict first.
    """
    scored = None if check is None or check.passed else (check.ratio, check.allowed)
    local = bool(cons.bands) and cons.chi2_reduced <= cons.threshold and scored is None
    lines = [words.unexplained(final_error, floor, cons.chi2_reduced, cons.threshold, scored, local)]
    near = settings.band_merge
    merged = []
    for b in cons.bands:
        label = lik.measured[b.item].label
        for i, (lab, lo, hi, share) in enumerate(merged):
            if lab == label and (b.lo_hz <= hi * (1.0 + near) and b.hi_hz >= lo * (1.0 - near)):
                merged[i] = (lab, min(lo, b.lo_hz), max(hi, b.hi_hz), share + b.share)
                break
        else:
            merged.append((label, b.lo_hz, b.hi_hz, b.share))
    merged.sort(key=lambda m: -m[3])
    if merged:
        lines.append(words.error_lives(merged[:settings.report_bands]))
    elif cons.chi2_reduced > cons.threshold:
        lines.append(words.error_spread())
    level = level_signature(baseline, floor, settings)[0]
    if current:
        lines.append(words.best_partial([(c.effect, c.place(v), values_text(c, v)) for c, v in current]))
    elif not level:  # with a calibration's signature no change of the structure is fitted (the line below says why)
        lines.append(words.nothing_improves())
    try:  # the signature of the data against the model as given: what kind of change is missing
        first = lik.measured[0]
        sig_lines, _ = signature(model_of_measurement(assembly, first.measurement), first.frf, baseline[0].modes,
                                 settings)
        lines += sig_lines
    except (SubstructureError, ValueError) as exc:
        if say:
            say(f"signature skipped: {exc}")
    lines += level
    return lines


def _measurement_points(assembly) -> list[str]:
    points = []
    for comp in _plain_beams(assembly):
        inner = [f"{comp.name}@{share * comp.length_m * 1e3:.4g} mm" for share in (0.25, 0.5, 0.75)]
        points += [f"{comp.name}.base", *inner, f"{comp.name}.tip"]
    return points


class Explanation:
    """Several fitted changes taken as one explanation (for :func:`separation`).

    Parameters
    ----------
    founds : sequence of Found
        The changes with their values.
    """

    def __init__(self, founds):
        self.founds = list(founds)
        self.name = " + ".join(f.name for f in self.founds) or "nothing"
        self.where = " + ".join(f.where for f in self.founds)
        self.test_only = any(f.change.test_only for f in self.founds)
        self.change = self

    def apply(self, assembly):
        """The assembly with every change applied (:func:`~substructure.diagnose.effects.written_back`)."""
        return written_back(assembly, [(f.change, f.values) for f in self.founds])


def _applied(explanation, config, non_contact: bool):
    """``config`` with the explanation applied (as it is when that fails, or without a test-only change)."""
    if non_contact and explanation.change.test_only:
        return config
    try:
        return explanation.apply(config)
    except SubstructureError:
        return config


def separation(assembly, measured, a, b, say=None, contact_only: bool = False,
               settings: DiagnoseSettings = DEFAULT_SETTINGS) -> dict | None:
    """The measurement that best tells two explanations apart.

    Parameters
    ----------
    assembly : Assembly
        The model as given.
    measured : sequence of Measured
        The data (the first one's configuration and excitation are used).
    a, b : Found or Explanation
        The two explanations.
    say : callable, optional
        Progress.
    contact_only : bool
        Only measurements with the test's sensors on, as in the data (no
        non-contact variant): do the two explanations differ as structures?
    settings : DiagnoseSettings
        ``separation_every``: the lines the predictions are compared on.

    Returns
    -------
    dict or None
        ``response``, ``excitation``, ``non_contact`` (bool), ``chi2`` (the
        difference of the two predictions relative to the noise, over the
        band), ``text``; None when nothing can be computed.
    """
    first = measured[0]
    f = first.frf.frequency
    sub = f.hz[::settings.separation_every]
    config = model_of_measurement(assembly, first.measurement)
    v_typ = float(np.median(0.5 * (first.noise.var_re + first.noise.var_im)))
    excitation = str(first.frf.inputs[0]).split(":")[0]
    done = {(str(m.frf.outputs[0]).split(":")[0], str(m.frf.inputs[0]).split(":")[0]) for m in measured}
    points = list(dict.fromkeys(_measurement_points(config) + [p for pair in done for p in pair]))
    # a point an explanation says the test took elsewhere (a tip tested below its edge) is read there in its model;
    # a point a quarter of the component from it (named from it, as a sensor is placed) is a measurement too
    pairs = [[(f.change, f.values) for f in getattr(e, "founds", (e,))] for e in (a, b)]
    moved = [tested_at(p) for p in pairs]
    length_m = {comp.name: comp.length_m for comp in _plain_beams(config)}
    tips = [w for w in dict.fromkeys(w for place in moved for w in place)
            if w.endswith(".tip") and w.split(".")[0] in length_m]
    points += [f"{w}-{0.25 * length_m[w.split('.')[0]] * 1e3:.3g} mm" for w in tips]
    labels = [[f"{place.get(p, p)}:y" for p in points] for place in moved]
    # and its hits where it says the hammer hit, apart from the sensor
    hit_labels = [[f"{hit.get(p, place.get(p, p))}:y" for p in points]
                  for place, hit in zip(moved, (tested_at(p, hits=True) for p in pairs))]
    variants = [False] + ([True] if (a.change.test_only or b.change.test_only) and not contact_only else [])
    best = None
    for non_contact in variants:
        models = [_applied(e, config, non_contact) for e in (a, b)]
        try:
            ha, hb = (m.frf(at, hit, sub).data for m, at, hit in zip(models, labels, hit_labels))
        except (SubstructureError, ValueError) as exc:
            if say:
                say(f"separating measurement skipped: {exc}")
            return None
        with np.errstate(divide="ignore", invalid="ignore"):
            r = np.log(ha / hb)
        score = np.nansum(np.where(np.isfinite(r), np.abs(r) ** 2, 0.0), axis=0) / (2 * v_typ) * (f.n / sub.size)
        for i, resp in enumerate(points):
            for j, exc in enumerate(points):
                if j != i and exc != excitation:
                    continue
                if ((resp, exc) in done) != non_contact:  # a new test, or the same test again without the sensor
                    continue
                value = float(score[i, j])
                if best is None or value > best[0]:
                    best = (value, resp, exc, non_contact)
    if best is None:
        return None
    value, resp, exc, non_contact = best
    text = words.separation_text(a.name, a.where, b.name, b.where, value, INDIFFERENCE, resp, exc, non_contact)
    return {"response": f"{resp}:y", "excitation": f"{exc}:y", "non_contact": non_contact, "chi2": value,
            "text": text}
