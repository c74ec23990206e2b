"""Tests of substructure.frf: the Frequency axis and the FRF value object."""

from __future__ import annotations

import warnings

import attrs
import matplotlib
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from matplotlib.figure import Figure

from substructure.errors import (
    FrequencyAxisMismatchError,
    InvalidValueError,
    NonReciprocalWarning,
    UnitError,
    UnknownPointError,
)
from substructure.frf import FRF, Frequency
from substructure.units import Q_

matplotlib.use("Agg")


def sdof(hz, k=1.0e7, m=1.0, zeta=0.02):
    """Receptance 1/(k - m w^2 + i c w) of a single-DOF oscillator."""
    omega = 2 * np.pi * np.asarray(hz)
    c = 2 * zeta * np.sqrt(k * m)
    return 1.0 / (k - m * omega**2 + 1j * c * omega)


def random_frf(n_out=2, n_in=2, seed=0, grid=("10 Hz", "100 Hz", "1 Hz")):
    rng = np.random.default_rng(seed)
    f = Frequency.from_range(*grid)
    data = rng.normal(size=(f.n, n_out, n_in)) + 1j * rng.normal(size=(f.n, n_out, n_in))
    outputs = [f"p{i}:y" for i in range(n_out)]
    inputs = [f"q{j}:y" for j in range(n_in)]
    return FRF(f, data, outputs, inputs)


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    import matplotlib.pyplot as plt

    plt.close("all")


# -- Frequency ----------------------------------------------------------------


@pytest.mark.parametrize(
    "hz, match",
    [
        ([[1.0, 2.0]], "1-D"),
        ([], "non-empty"),
        ([1.0, np.nan], "finite"),
        ([1.0, np.inf], "finite"),
        ([-1.0, 2.0], ">= 0"),
        ([1.0, 3.0, 2.0], "strictly increasing"),
        ([1.0, 2.0, 2.0], "strictly increasing"),
        ([1.0 + 1j, 2.0], "complex"),
        (["a", "b"], "cannot read"),
    ],
)
def test_frequency_rejects_invalid_axes(hz, match):
    with pytest.raises(InvalidValueError, match=match) as info:
        Frequency.from_hz(hz)
    assert str(info.value).startswith("hz:")


def test_frequency_is_an_immutable_copy():
    values = np.array([1.0, 2.0, 3.0])
    f = Frequency.from_hz(values)
    values[0] = 0.5
    assert f.hz[0] == 1.0
    with pytest.raises(ValueError):
        f.hz[0] = 7.0
    with pytest.raises(attrs.exceptions.FrozenInstanceError):
        f.hz = np.array([1.0])
    assert f.hz.dtype == np.float64


def test_frequency_properties():
    f = Frequency.from_hz([0.0, 10.0, 25.0])
    assert (f.n, len(f), f.start, f.stop) == (3, 3, 0.0, 25.0)
    np.testing.assert_allclose(f.omega, 2 * np.pi * np.array([0.0, 10.0, 25.0]), rtol=1e-15)
    assert not f.omega.flags.writeable
    assert f == Frequency.from_hz([0.0, 10.0, 25.0]) and hash(f) == hash(Frequency.from_hz(f.hz))
    assert f != Frequency.from_hz([0.0, 10.0, 26.0])


def test_from_range_strings_and_quantities():
    f = Frequency.from_range("20 Hz", "30 Hz", "2 Hz")
    np.testing.assert_array_equal(f.hz, [20, 22, 24, 26, 28, 30])
    g = Frequency.from_range(Q_(0.02, "kHz"), "0.03 kHz", Q_(2000, "mHz"))
    np.testing.assert_allclose(g.hz, f.hz, rtol=1e-15)
    # stop off the grid: the last line is the one below it
    np.testing.assert_array_equal(Frequency.from_range("20 Hz", "29 Hz", "2 Hz").hz, [20, 22, 24, 26, 28])
    # a fractional step with the stop on the grid keeps the stop (no float accumulation)
    h = Frequency.from_range("20 Hz", "30 Hz", "0.1 Hz")
    assert h.n == 101
    np.testing.assert_array_equal(h.hz, 20.0 + 0.1 * np.arange(101))


@pytest.mark.parametrize("field", ["start", "stop", "step"])
def test_from_range_rejects_bare_numbers(field):
    args = {"start": "20 Hz", "stop": "30 Hz", "step": "2 Hz"}
    args[field] = 2.0
    with pytest.raises(UnitError, match=f"^{field}: .*bare number"):
        Frequency.from_range(**args)


@pytest.mark.parametrize(
    "args, error, match",
    [
        (("20 mm", "30 Hz", "2 Hz"), UnitError, "start: .*frequency"),
        (("-1 Hz", "30 Hz", "2 Hz"), InvalidValueError, "start: .*>= 0"),
        (("20 Hz", "30 Hz", "0 Hz"), InvalidValueError, "step: .*positive"),
        (("20 Hz", "10 Hz", "1 Hz"), InvalidValueError, "stop: .*below start"),
    ],
)
def test_from_range_rejects_invalid(args, error, match):
    with pytest.raises(error, match=match):
        Frequency.from_range(*args)


def test_from_hz_refuses_quantities():
    with pytest.raises(InvalidValueError, match="m_as"):
        Frequency.from_hz(Q_(np.array([1.0, 2.0]), "Hz"))


@settings(max_examples=60, deadline=None)
@given(
    start=st.integers(0, 1000),
    step_mhz=st.integers(1, 5000),
    count=st.integers(1, 400),  # one line is refused (test_hostile_inputs.test_one_line_grids_are_refused)
    extra=st.floats(0.0, 0.99),
)
def test_from_range_invariants(start, step_mhz, count, extra):
    step = step_mhz / 1000
    stop = start + (count + extra) * step
    f = Frequency.from_range(f"{start} Hz", f"{stop!r} Hz", f"{step!r} Hz")
    assert f.n == count + 1
    np.testing.assert_array_equal(f.hz, start + step * np.arange(count + 1))
    assert f.stop <= stop * (1 + 1e-12) and f.stop + step > stop


def test_frequency_crop_and_mask():
    f = Frequency.from_range("0 Hz", "100 Hz", "10 Hz")
    np.testing.assert_array_equal(f.crop(20, 50).hz, [20, 30, 40, 50])
    np.testing.assert_array_equal(f.crop("25 Hz", "0.05 kHz").hz, [30, 40, 50])
    np.testing.assert_array_equal(f.crop(hi=10).hz, [0, 10])
    mask = f.band_mask(lo=Q_(90, "Hz"))
    assert mask.dtype == bool and mask.sum() == 2 and mask[-1]
    # a line meant to be on the limit is kept despite rounding of start + step*k
    g = Frequency.from_range("20 Hz", "30 Hz", "0.1 Hz")
    assert g.hz[82] > 28.2 and g.crop(hi="28.2 Hz").stop == g.hz[82]
    assert g.crop(lo=28.2).start == g.hz[82]
    with pytest.raises(InvalidValueError, match="no line"):
        f.crop(41, 49)
    with pytest.raises(InvalidValueError, match="lo <= hi"):
        f.crop(50, 20)
    with pytest.raises(UnitError, match="lo:"):
        f.crop("20 mm", 50)


# -- FRF construction -----------------------------------------------------------


F5 = Frequency.from_hz([1.0, 2.0, 3.0, 4.0, 5.0])


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(data=np.ones(5)), r"data: got shape \(5,\).*FRF.single"),
        (dict(data=np.ones((4, 1, 1))), r"data: got shape \(4, 1, 1\)"),
        (dict(data=np.ones((5, 2, 1))), r"data: got shape \(5, 2, 1\)"),
        (dict(data=np.full((5, 1, 1), np.nan)), "data: got .*nan.*finite"),
        (dict(data=np.array([1, 1, np.inf, 1, 1])[:, None, None]), "data: got .*inf.* at 3 Hz"),
        (dict(outputs=["a:y", "a:y"], data=np.ones((5, 2, 1))), "outputs: .*more than once"),
        (dict(inputs=[""]), "inputs: .*non-empty"),
        (dict(inputs=[" a:y"]), "inputs: .*surrounding"),
        (dict(outputs=[3]), "outputs: .*label 3"),
        (dict(outputs=[]), "outputs: got no labels"),
        (dict(quantity="compliance"), "quantity: got 'compliance'"),
        (dict(data=np.array(["x"] * 5)[:, None, None]), "data: cannot read"),
    ],
)
def test_frf_rejects_invalid(kwargs, match):
    args = dict(frequency=F5, data=np.ones((5, 1, 1)), outputs=["a:y"], inputs=["b:y"])
    args.update(kwargs)
    with pytest.raises(InvalidValueError, match=match):
        FRF(**args)


def test_frf_requires_a_frequency_object():
    with pytest.raises(InvalidValueError, match="frequency: got list; expected a Frequency"):
        FRF([1.0, 2.0], np.ones((2, 1, 1)), ["a:y"], ["a:y"])


def test_single_and_immutability():
    values = sdof(F5.hz)
    frf = FRF.single(F5, values, output="tool.tip:y", input="tool.tip:y")
    assert frf.shape == (5, 1, 1) and frf.data.dtype == np.complex128
    values[0] = 0.0
    assert frf.data[0, 0, 0] != 0.0
    with pytest.raises(ValueError):
        frf.data[0, 0, 0] = 1.0
    with pytest.raises(InvalidValueError, match="values: got shape"):
        FRF.single(F5, np.ones((5, 1)))
    # a single label string is one label, not its characters
    assert FRF(F5, np.ones((5, 1, 1)), "ab", "cd").outputs == ("ab",)


# -- labels -----------------------------------------------------------------------


def test_entry_and_label_indexing():
    frf = random_frf(3, 2)
    np.testing.assert_array_equal(frf.entry("p1:y", "q0:y"), frf.data[:, 1, 0])
    sub = frf["p2:y", "q1:y"]
    assert sub.shape == (frf.frequency.n, 1, 1) and sub.outputs == ("p2:y",)
    np.testing.assert_array_equal(sub.data[:, 0, 0], frf.data[:, 2, 1])
    sub = frf[["p2:y", "p0:y"], :]
    assert sub.outputs == ("p2:y", "p0:y") and sub.inputs == frf.inputs
    np.testing.assert_array_equal(sub.data, frf.data[:, [2, 0], :])
    assert frf.select(inputs="q1:y") == frf[:, "q1:y"]
    assert frf.select() == frf


def test_unknown_label_lists_the_available_ones():
    frf = random_frf(2, 2)
    with pytest.raises(UnknownPointError, match=r"output 'x:y' .*'p0:y', 'p1:y'") as info:
        frf["x:y", "q0:y"]
    assert isinstance(info.value, KeyError)
    with pytest.raises(UnknownPointError, match="input 'p0:y'"):
        frf.entry("p0:y", "p0:y")
    with pytest.raises(InvalidValueError, match="pair"):
        frf["p0:y"]


def test_with_labels_and_units():
    frf = random_frf(2, 2).with_labels(["a:y", "a:theta"], ["a:y", "a:theta"])
    assert frf.outputs == ("a:y", "a:theta")
    assert [frf.unit(o, i) for o in frf.outputs for i in frf.inputs] == ["m/N", "1/N", "1/N", "1/(N m)"]
    assert attrs.evolve(frf, quantity="accelerance").unit("a:y", "a:y") == "m/(N s^2)"
    with pytest.raises(InvalidValueError, match="1 output label"):
        frf.with_labels(["a:y"], ["a:y", "a:theta"])


def test_views():
    frf = random_frf(2, 1)
    np.testing.assert_array_equal(frf.magnitude, np.abs(frf.data))
    np.testing.assert_array_equal(frf.phase(), np.angle(frf.data))
    np.testing.assert_allclose(frf.phase(deg=True), np.degrees(np.angle(frf.data)), rtol=1e-14)
    np.testing.assert_array_equal(frf.real + 1j * frf.imag, frf.data)
    np.testing.assert_array_equal(frf.omega, frf.frequency.omega)


def test_repr_is_short():
    frf = random_frf(2, 2, grid=("1 Hz", "10000 Hz", "1 Hz"))
    text = repr(frf)
    assert len(text) < 200 and "2x2" in text and "p1:y" in text and "10000" in text
    assert "j" not in text and "e-" not in text  # no complex array dump


# -- band and interpolation -------------------------------------------------------------


def test_crop():
    frf = random_frf()
    cropped = frf.crop("20 Hz", 30.0)
    assert cropped.frequency.start == 20.0 and cropped.frequency.stop == 30.0
    np.testing.assert_array_equal(cropped.data, frf.data[10:21])


def test_linear_interpolation_reproduces_a_linear_function():
    old = Frequency.from_range("10 Hz", "100 Hz", "3 Hz")
    a = np.array([[1.0 + 2j, -3.0], [0.5j, 4.0 - 1j]])
    b = np.array([[0.25 - 1j, 2.0j], [-1.5, 0.125]])
    frf = FRF(old, a + b * old.hz[:, None, None], ["a:y", "b:y"], ["a:y", "b:y"])
    new = Frequency.from_hz(np.sort(np.random.default_rng(1).uniform(10, 100, 57)))
    result = frf.interpolate(new)
    assert result.frequency == new
    np.testing.assert_allclose(result.data, a + b * new.hz[:, None, None], rtol=1e-13)
    # the end points of the old grid are reproduced exactly
    ends = frf.interpolate(Frequency.from_hz([10.0, 100.0]))
    np.testing.assert_array_equal(ends.data, frf.data[[0, -1]])


def test_cubic_interpolation_reproduces_a_cubic():
    old = Frequency.from_range("0 Hz", "10 Hz", "0.5 Hz")
    poly = lambda f: (1 - 2j) + 0.5 * f - (0.3 + 0.1j) * f**2 + 0.02j * f**3  # noqa: E731
    frf = FRF.single(old, poly(old.hz))
    new = Frequency.from_hz(np.linspace(0.1, 9.9, 33))
    np.testing.assert_allclose(frf.interpolate(new, kind="cubic").data[:, 0, 0], poly(new.hz), rtol=1e-12)
    # linear interpolation of the same cubic is measurably wrong: the test can fail
    assert np.abs(frf.interpolate(new).data[:, 0, 0] - poly(new.hz)).max() > 1e-3


def test_interpolate_refuses_to_extrapolate():
    frf = random_frf()
    with pytest.raises(InvalidValueError, match=r"leaves this FRF's range 10\.\.100 Hz"):
        frf.interpolate(Frequency.from_range("5 Hz", "50 Hz", "1 Hz"))
    with pytest.raises(InvalidValueError, match="leaves"):
        frf.interpolate(Frequency.from_hz([50.0, 100.5]))
    with pytest.raises(InvalidValueError, match="kind"):
        frf.interpolate(frf.frequency.crop(20, 30), kind="quadratic")
    with pytest.raises(InvalidValueError, match="expected a Frequency"):
        frf.interpolate(np.array([20.0, 30.0]))
    assert frf.interpolate(frf.frequency) is frf


# -- arithmetic ---------------------------------------------------------------------------


def test_arithmetic():
    a, b = random_frf(seed=1), random_frf(seed=2)
    np.testing.assert_array_equal((a + b).data, a.data + b.data)
    np.testing.assert_array_equal((a - b).data, a.data - b.data)
    np.testing.assert_array_equal((-a).data, -a.data)
    np.testing.assert_array_equal((2.5 * a).data, 2.5 * a.data)
    np.testing.assert_array_equal((a * 1j).data, 1j * a.data)
    np.testing.assert_array_equal((np.float64(3.0) * a).data, 3.0 * a.data)
    assert (a - a).magnitude.max() == 0.0
    with pytest.raises(TypeError):
        a + 1.0
    with pytest.raises(TypeError):
        a * a
    with pytest.raises(InvalidValueError, match="factor: .*finite"):
        a * np.inf


def test_combining_different_axes_or_labels_raises():
    a = random_frf()
    b = random_frf(grid=("10 Hz", "100 Hz", "2 Hz"))
    with pytest.raises(FrequencyAxisMismatchError, match=r"\.interpolate.*\.crop"):
        a + b
    with pytest.raises(FrequencyAxisMismatchError):
        a - b.interpolate(b.frequency)
    assert isinstance(a + b.interpolate(a.frequency.crop(10, 100)), FRF)
    with pytest.raises(InvalidValueError, match="different labels"):
        a + a.with_labels(["x:y", "p1:y"], a.inputs)
    with pytest.raises(InvalidValueError, match="to_receptance"):
        a + attrs.evolve(a, quantity="mobility")


# -- peaks -------------------------------------------------------------------------------------


def test_peak_of_a_single_dof_receptance():
    k, m, zeta = 1.0e7, 1.0, 0.02
    f = Frequency.from_range("100 Hz", "1000 Hz", "0.5 Hz")
    frf = FRF.single(f, sdof(f.hz, k, m, zeta))
    # |H| is largest at omega_n sqrt(1 - 2 zeta^2)
    expected = np.sqrt(k / m) * np.sqrt(1 - 2 * zeta**2) / (2 * np.pi)
    peaks = frf.peaks()
    assert peaks.shape == (1,)
    assert abs(peaks[0] - expected) <= 0.5 * 0.5 + 1e-9


def test_two_modes_ascending_and_prominence():
    f = Frequency.from_range("50 Hz", "2000 Hz", "1 Hz")
    hz = f.hz
    # two strong modes and a weak third one (about 3 % of the largest |FRF| in prominence)
    values = sdof(hz, 4e7, 1.0, 0.03) + sdof(hz, 1e7, 1.0, 0.02) + sdof(hz, 6e6, 0.1, 0.01) * 1e-2
    frf = FRF.single(f, values)
    f1, f2, f3 = (np.sqrt(k / m) / (2 * np.pi) for k, m in ((1e7, 1.0), (4e7, 1.0), (6e6, 0.1)))
    peaks = frf.peaks()
    assert np.all(np.diff(peaks) > 0)
    assert len(peaks) == 3
    np.testing.assert_allclose(peaks, [f1, f2, f3], rtol=0.01)
    strong = frf.peaks(prominence=0.05)
    np.testing.assert_allclose(strong, [f1, f2], rtol=0.01)


def test_peaks_need_an_entry_when_there_are_several():
    f = Frequency.from_range("100 Hz", "1000 Hz", "1 Hz")
    data = np.stack([sdof(f.hz), sdof(f.hz, k=2e7)], axis=-1)[:, None, :]
    frf = FRF(f, data, ["a:y"], ["a:y", "b:y"])
    with pytest.raises(InvalidValueError, match="input: .*2 inputs"):
        frf.peaks()
    assert frf.peaks(input="b:y")[0] > frf.peaks(input="a:y")[0]
    with pytest.raises(InvalidValueError, match="prominence"):
        frf.peaks(input="a:y", prominence=2.0)


# -- reciprocity --------------------------------------------------------------------------------


def point_matrix(seed=3, symmetric=True):
    rng = np.random.default_rng(seed)
    f = Frequency.from_range("10 Hz", "20 Hz", "1 Hz")
    m = rng.normal(size=(f.n, 3, 3)) + 1j * rng.normal(size=(f.n, 3, 3))
    if symmetric:
        m = m + np.swapaxes(m, 1, 2)
    labels = ["a:y", "a:theta", "b:y"]
    return FRF(f, m, labels, labels)


def test_reciprocity_of_symmetric_and_asymmetric_matrices():
    sym = point_matrix()
    assert sym.reciprocity_error() == 0.0
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert sym.check_reciprocity() == 0.0
    data = np.array(sym.data)
    data[4, 0, 2] *= 1.1  # one cross term 10 % off at one line
    asym = attrs.evolve(sym, data=data)
    assert asym.reciprocity_error() == pytest.approx(0.1 / 1.1, rel=1e-12)
    with pytest.warns(NonReciprocalWarning, match="not reciprocal"):
        assert asym.check_reciprocity(rtol=1e-3) == pytest.approx(0.1 / 1.1)
    assert point_matrix(symmetric=False).reciprocity_error() > 0.1


def test_reciprocity_matches_labels_not_positions():
    sym = point_matrix()
    # outputs in another order: the matrix is still reciprocal
    shuffled = sym[["b:y", "a:y", "a:theta"], :]
    assert shuffled.reciprocity_error() == 0.0
    # relabelling the outputs positionally breaks it
    assert shuffled.with_labels(sym.outputs, sym.inputs).reciprocity_error() > 0.1
    # a rectangular FRF with one shared label has no pair to compare
    assert sym[["a:y"], ["a:y", "b:y"]].reciprocity_error() == 0.0


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(2, 5))
def test_reciprocity_of_random_symmetric_blocks(seed, n):
    rng = np.random.default_rng(seed)
    f = Frequency.from_hz([1.0, 2.0])
    m = rng.normal(size=(2, n, n)) + 1j * rng.normal(size=(2, n, n))
    labels = [f"p{i}:y" for i in range(n)]
    order = list(rng.permutation(labels))
    frf = FRF(f, m + np.swapaxes(m, 1, 2), labels, labels)[order, :]
    assert frf.reciprocity_error() == 0.0
    skew = FRF(f, m - np.swapaxes(m, 1, 2), labels, labels)
    assert skew.reciprocity_error() == pytest.approx(2.0)


# -- conversion --------------------------------------------------------------------------------


def test_mobility_and_accelerance_to_receptance():
    f = Frequency.from_range("10 Hz", "1000 Hz", "5 Hz")
    omega = 2 * np.pi * f.hz
    h = sdof(f.hz)
    mobility = FRF.single(f, 1j * omega * h, quantity="mobility")
    accelerance = FRF.single(f, -(omega**2) * h, quantity="accelerance")
    for frf in (mobility, accelerance):
        converted = frf.to_receptance()
        assert converted.quantity == "receptance"
        np.testing.assert_allclose(converted.data[:, 0, 0], h, rtol=1e-14)
    receptance = FRF.single(f, h)
    assert receptance.to_receptance() is receptance
    at_zero = FRF.single(Frequency.from_hz([0.0, 1.0]), [1.0, 1.0], quantity="mobility")
    with pytest.raises(InvalidValueError, match="0 Hz.*crop"):
        at_zero.to_receptance()


# -- plot ------------------------------------------------------------------------------------


def test_plot_returns_a_figure_and_overlays():
    f = Frequency.from_range("100 Hz", "1000 Hz", "1 Hz")
    frf = FRF.single(f, sdof(f.hz), output="tool.tip:y", input="tool.tip:y")
    fig = frf.plot(label="model", unit="m/N")
    assert isinstance(fig, Figure) and len(fig.axes) == 2
    assert fig.axes[0].get_yscale() == "log" and "m/N" in fig.axes[0].get_ylabel()
    again = (2 * frf).plot(ax=fig.axes, label="stiffer", linestyle="--", unit="m/N")
    assert again is fig and len(fig.axes[0].lines) == 2 and len(fig.axes[1].lines) == 2
    np.testing.assert_allclose(fig.axes[0].lines[1].get_ydata(), 2 * np.abs(sdof(f.hz)))
    np.testing.assert_allclose(fig.axes[1].lines[0].get_ydata(), np.angle(sdof(f.hz), deg=True))
    assert [t.get_text() for t in fig.axes[0].get_legend().get_texts()] == ["model", "stiffer"]


def test_plot_parts_entries_and_errors():
    frf = point_matrix()
    fig = frf.plot(parts=("magnitude", "phase", "real", "imag"))
    assert len(fig.axes) == 4 and len(fig.axes[2].lines) == 9
    fig = frf.plot(entries=[("a:theta", "a:theta")], parts=("real",))
    assert len(fig.axes) == 1 and "1/(N m)" in fig.axes[0].get_ylabel()
    with pytest.raises(InvalidValueError, match="ax: got 1 axes"):
        frf.plot(ax=fig.axes[0], parts=("magnitude", "phase"))
    with pytest.raises(InvalidValueError, match="parts"):
        frf.plot(parts=("bode",))
    with pytest.raises(UnknownPointError):
        frf.plot(entries=[("z:y", "a:y")])


# -- plots a person reads (issue 11) ------------------------------------------------------


def free_free_tip():
    from substructure.io.assembly_toml import default_assembly

    asm = default_assembly()
    return asm.receptance("tool.tip:y", frequency=Frequency.from_range("10 Hz", "3000 Hz", "5 Hz"))


def test_plot_units_convert_exactly_and_label():
    frf = point_matrix()
    fig = frf.plot(entries=[("a:y", "a:y")])
    y = np.abs(frf.entry("a:y", "a:y"))
    assert fig.axes[0].get_ylabel() == "receptance |H| (µm/N)" and fig.axes[1].get_ylabel() == "phase (deg)"
    np.testing.assert_array_equal(fig.axes[0].lines[0].get_ydata(), y * 1e6)
    for unit, factor, shown in (("m/N", 1.0, "m/N"), ("mm/N", 1e3, "mm/N"), ("nm/N", 1e9, "nm/N"),
                                ("µm/N", 1e6, "µm/N")):
        fig = frf.plot(entries=[("a:y", "a:y")], kind="real-imag", unit=unit)
        np.testing.assert_array_equal(fig.axes[0].lines[0].get_ydata(), frf.entry("a:y", "a:y").real * factor)
        np.testing.assert_array_equal(fig.axes[1].lines[0].get_ydata(), frf.entry("a:y", "a:y").imag * factor)
        assert fig.axes[0].get_ylabel() == f"receptance, real part ({shown})"
        assert fig.axes[1].get_ylabel() == f"receptance, imaginary part ({shown})"
        assert fig.axes[1].get_xlabel() == "frequency (Hz)"
    # rotational entries stay in SI, whatever the unit
    fig = frf.plot(entries=[("a:theta", "a:theta")], unit="um/N")
    np.testing.assert_array_equal(fig.axes[0].lines[0].get_ydata(), np.abs(frf.entry("a:theta", "a:theta")))
    assert "1/(N m)" in fig.axes[0].get_ylabel()
    mob = attrs.evolve(frf.select("a:y", "a:y"), quantity="mobility")
    assert mob.plot().axes[0].get_ylabel() == "mobility |Y| (µm/(N s))"
    with pytest.raises(InvalidValueError, match="unit"):
        frf.plot(unit="in/N")
    with pytest.raises(InvalidValueError, match="kind"):
        frf.plot(kind="polar")
    with pytest.raises(InvalidValueError, match="parts"):
        frf.plot(kind="nyquist", parts=("real",))


def test_plot_limits_carry_their_unit_whatever_the_axes_show():
    """Limits with units land on the axes in the display unit (the lesson 01 bug: m/N on a um/N axis)."""
    frf = point_matrix().select("a:y", "a:y")
    for unit, factor in (("um/N", 1e6), ("m/N", 1.0), ("nm/N", 1e9)):
        fig = frf.plot(unit=unit, limits=("2e-3 um/N", "1e-6 m/N"))
        assert fig.axes[0].get_ylim() == pytest.approx((2e-9 * factor, 1e-6 * factor))
        assert fig.axes[1].get_ylim()[1] < 200       # the phase panel keeps its own limits
    fig = frf.plot(kind="real-imag", limits=(Q_(-3, "um/N"), None))
    assert fig.axes[0].get_ylim()[0] == pytest.approx(-3) and fig.axes[1].get_ylim()[0] == pytest.approx(-3)
    fig = frf.plot(kind="nyquist", unit="mm/N", limits=("-2 um/N", "2 um/N"))
    assert fig.axes[0].get_xlim() == pytest.approx((-2e-3, 2e-3)) == fig.axes[0].get_ylim()
    fig = frf.plot()
    (2 * frf).plot(ax=fig, limits=(None, "1 mm/N"))          # on an overlay, the last call sets them
    lo, hi = fig.axes[0].get_ylim()
    assert hi == pytest.approx(1e3) and 0 < lo <= np.abs(frf.data).min() * 1e6
    with pytest.raises(UnitError, match=r"limits \(upper\): got the bare number 0.001.*write e.g. '100 µm/N'"):
        frf.plot(limits=(None, 1e-3))
    with pytest.raises(UnitError, match=r"limits \(lower\).*dimension \[length\]"):
        frf.plot(limits=("1 mm", None))
    with pytest.raises(InvalidValueError, match="logarithmic"):
        frf.plot(limits=("0 um/N", None))
    with pytest.raises(InvalidValueError, match="pair"):
        frf.plot(limits="1 um/N")
    with pytest.raises(InvalidValueError, match="different units"):
        point_matrix().plot(limits=(None, "1 m/N"))


def test_plot_rigid_body_line_is_left_out_of_the_scale():
    from substructure.plot import rigid_body_cutoff

    frf = free_free_tip()
    h = np.abs(frf.data[:, 0, 0]) * 1e6
    cutoff = rigid_body_cutoff(frf.frequency.hz, h)
    # the mass line falls from 20 Hz to the first antiresonance, found independently here
    first_min = frf.frequency.hz[np.nonzero(np.diff(h) > 0)[0][0]]
    assert cutoff == first_min and 50 < cutoff < 1000
    rest = h[frf.frequency.hz > cutoff]
    fig = frf.plot()
    lo, hi = fig.axes[0].get_ylim()
    assert hi < h[0] / 10                        # the mass line's values at 10 Hz are off the scale
    assert lo <= rest.min() and hi >= rest.max()  # every mode and antiresonance above it is inside
    assert hi == pytest.approx(2 * rest.max()) and lo == pytest.approx(rest.min() / 2)
    np.testing.assert_array_equal(fig.axes[0].lines[0].get_ydata(), h)    # still drawn, whole
    note = [t.get_text() for t in fig.axes[-1].texts]
    assert any("rigid-body" in t and "receptance" in t for t in note)
    # the same for the real/imaginary and Nyquist views
    fig = frf.plot(kind="real-imag")
    re_rest = (frf.data[:, 0, 0].real * 1e6)[frf.frequency.hz > cutoff]
    lo, hi = fig.axes[0].get_ylim()
    assert lo > frf.data[0, 0, 0].real * 1e6 and lo <= re_rest.min() and hi >= re_rest.max()
    fig = frf.plot(kind="nyquist")
    assert len(fig.axes) == 1 and fig.axes[0].get_xlabel() == "receptance, real part (µm/N)"
    assert fig.axes[0].get_xlim()[0] > frf.data[0, 0, 0].real * 1e6
    # a supported structure (flat at low frequency) has no rigid-body line
    sdof = 1 / (1e7 * (1 - (np.arange(1, 400) / 200.0) ** 2 + 0.02j * np.arange(1, 400) / 200.0))
    assert rigid_body_cutoff(np.arange(1.0, 400.0), np.abs(sdof)) is None
    assert rigid_body_cutoff(np.array([1.0, 2.0]), np.array([1.0, 0.25])) is None


def test_plot_titles_wrap_and_overlays_keep_one_note():
    frf = free_free_tip()
    long = "a very long assembly name " * 8
    fig = frf.plot(title=long)
    lines = fig._suptitle.get_text().split("\n")
    assert len(lines) > 1 and all(len(line) <= 80 for line in lines)
    assert " ".join(lines).split() == long.split()
    again = (2 * frf).plot(ax=fig, label="stiffer")
    assert again is fig and len(fig.axes[0].lines) == 2
    assert len([t for t in fig.axes[-1].texts if "convention" in t.get_text()]) == 1
    lo, hi = fig.axes[0].get_ylim()
    rest = (np.abs(frf.data[:, 0, 0]) * 1e6)[frf.frequency.hz > 100]
    assert hi >= 2 * rest.max()   # the overlay's larger values are inside the new limits


def test_local_maxima_are_those_of_scipy_find_peaks():
    """The numpy peak search against scipy.signal.find_peaks (plateaus, ends, noise, prominence)."""
    from scipy.signal import find_peaks

    from substructure.frf import local_maxima

    rng = np.random.default_rng(7)
    cases = [np.array([]), np.array([1.0]), np.array([1.0, 2.0]), np.array([1.0, 2.0, 1.0]),
             np.array([3.0, 1.0, 3.0]), np.array([1.0, 2.0, 2.0, 1.0]), np.array([1.0, 2.0, 2.0, 2.0, 1.0]),
             np.array([1.0, 2.0, 2.0, 3.0, 1.0]), np.array([2.0, 2.0, 1.0, 2.0, 2.0]), np.ones(6)]
    for _ in range(300):
        n = int(rng.integers(3, 60))
        cases.append(rng.integers(0, 4, size=n).astype(float))  # many plateaus and ties
        cases.append(rng.normal(size=n))
    for x in cases:
        expected, _ = find_peaks(x)
        np.testing.assert_array_equal(local_maxima(x), expected)
    # and as FRF.peaks with a prominence, on a noisy FRF with many small peaks
    f = Frequency.from_range("10 Hz", "3000 Hz", "1 Hz")
    values = sdof(f.hz, 4e7, 1.0, 0.03) * (1.0 + 0.05 * rng.normal(size=f.n))
    frf = FRF.single(f, values)
    for p in (None, 0.0, 0.01, 0.3):
        kw = {} if p is None else {"prominence": p * np.abs(values).max()}
        np.testing.assert_array_equal(frf.peaks(prominence=p), f.hz[find_peaks(np.abs(values), **kw)[0]])
