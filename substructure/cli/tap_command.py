"""The ``substructure tap`` command: time records of taps to an FRF with coherence (and a measurement set)."""

from __future__ import annotations

import argparse
import os
import warnings
from pathlib import Path

from ..errors import SubstructureWarning
from ._common import (UsageError, band_range_arg, check_outputs, check_plot, figures, positive_arg, print_json,
                      save_figure)

_TEXT_SUFFIXES = (".csv", ".txt", ".dat", ".asc")
_UFF_SUFFIXES = (".uff", ".unv", ".uf")
_RECORD_SUFFIXES = _TEXT_SUFFIXES + (".lvm", ".mat", ".tdms") + _UFF_SUFFIXES


def _read(path: str, args: argparse.Namespace) -> list:
    from ..io.tap_files import read_tap_csv, read_tap_lvm, read_tap_tdms, read_taps_mat, read_tap_uff, read_taps_uff

    suffix = Path(path).suffix.lower()
    columns = dict(sample_rate=args.sample_rate, force_column=args.force_column,
                   response_column=args.response_column)
    if suffix in _UFF_SUFFIXES:
        for option, value in (("--force-column", args.force_column), ("--response-column", args.response_column),
                              ("--sample-rate", args.sample_rate)):
            if value is not None:
                raise UsageError(f"{option} applies to columns of a text record, not to {path}: a universal file "
                                 "gives its records' sampling, and --force-record, --response-record choose them")
        if args.force_record is None and args.response_record is None:  # every tap of the file
            return read_taps_uff(path, args.sensitivity, args.hammer_sensitivity, args.quantity)
        return [read_tap_uff(path, args.sensitivity, args.hammer_sensitivity, args.quantity, args.force_record,
                             args.response_record)]
    if args.force_record is not None or args.response_record is not None:
        raise UsageError("--force-record and --response-record choose records of a universal file, "
                         f"not columns of {path} (use --force-column and --response-column)")
    if suffix == ".mat":
        return read_taps_mat(path, args.sensitivity, args.hammer_sensitivity, args.quantity, **columns)
    if suffix == ".tdms":
        return read_tap_tdms(path, args.sensitivity, args.hammer_sensitivity, args.quantity, **columns)
    if suffix == ".lvm":
        return read_tap_lvm(path, args.sensitivity, args.hammer_sensitivity, args.quantity, **columns)
    return [read_tap_csv(path, args.sensitivity, args.hammer_sensitivity, args.quantity, **columns)]


def _set_text(name: str, response: str, excitation: str, file: str, averages: int, tau: float | None,
              force_window: float | None, estimator: str) -> str:
    import tomli_w

    frf = {"response": response, "excitation": excitation, "file": file, "quantity": "receptance",
           "averages": averages, "estimator": estimator}
    if tau is not None:
        frf["window_tau_s"] = float(tau)
    if force_window:  # the file's force_noise column is correlated over 1 / force_window_s hertz
        frf["force_window_s"] = float(force_window)
    text = tomli_w.dumps({"name": name, "frf": [frf]})
    if tau is None:
        return text
    return (f"# measured through an exponential window, tau = {tau:.4g} s: it adds the damping ratio 1/(tau omega) to "
            "every mode;\n# diagnose and identify compare the model through the same window (window_tau_s), lobes "
            "removes it from the fitted modes; other uses of the FRF see the added damping (a longer record needs "
            "no window)\n" + text)


def run(args: argparse.Namespace) -> int:
    from ..io import write_text
    from ..io.frf_files import write_csv
    from ..measurements import dof_label
    from ..frf import REVERSED_SHARE, reversed_share
    from ..tap import HAMMER_BAND_DB, PRE_TRIGGER_S, process_taps

    for path in args.records:
        if Path(path).suffix.lower() not in _RECORD_SUFFIXES:
            raise UsageError(f"{path}: expected a tap record in a .csv, .uff or .unv file (or text in .txt, "
                             ".dat or .asc, a LabVIEW .lvm file, an NI .tdms file, a MATLAB .mat file, a .uf "
                             "universal file)")
    given: dict[Path, str] = {}
    for path in args.records:  # one file twice is its taps averaged twice: coherence 1, the scatter understated
        resolved = Path(path).resolve()
        if resolved in given:
            raise UsageError(f"{path}: the record file is given more than once (also as {given[resolved]}); "
                             "expected each record once (its taps would be averaged twice)")
        given[resolved] = path
    if args.out and Path(args.out).suffix.lower() != ".csv":
        raise UsageError(f"argument --out: {args.out!r}: expected a .csv file (frequency_hz,real,imag,coherence)")
    if args.measurements:
        if not args.out:
            raise UsageError("--measurements needs --out: the FRF's data file that the set names")
        if not (args.response and args.excitation):
            raise UsageError("--measurements needs --response POINT and --excitation POINT")
        if Path(args.measurements).suffix.lower() != ".toml":
            raise UsageError(f"argument --measurements: {args.measurements!r}: expected a .toml file")
    elif args.response or args.excitation:
        raise UsageError("--response and --excitation name the points of the measurement set; give --measurements")
    response = dof_label(args.response, "--response") if args.response else None
    excitation = dof_label(args.excitation, "--excitation") if args.excitation else None
    check_plot(args.plot)
    check_outputs([("--out", args.out), ("--measurements", args.measurements), ("--plot", args.plot)],
                  args.records, args.overwrite)
    for option, value, zero in (("--tap-length", args.tap_length, False), ("--pre-trigger", args.pre_trigger, True),
                                ("--tau", args.tau, False), ("--hammer-band-db", args.hammer_band_db, False)):
        positive_arg(option, value, zero)
    pre_trigger = PRE_TRIGGER_S if args.pre_trigger is None else args.pre_trigger
    if args.tap_length is not None and not args.tap_length > pre_trigger:
        raise UsageError(f"argument --tap-length: got {args.tap_length:g} s, not longer than --pre-trigger "
                         f"{pre_trigger:g} s{' (its default)' if args.pre_trigger is None else ''}; expected a tap "
                         "longer than the time kept before its hit")
    if args.no_exponential_window and args.tau is not None:
        raise UsageError("--tau sets the exponential window's time constant; it cannot go with --no-exponential-window")
    records = [record for path in args.records for record in _read(path, args)]
    nyquist = records[0].sample_rate / 2.0
    if args.band is not None and args.band[0] >= nyquist:
        raise UsageError(f"argument --band: got {args.band[0]:g}:{args.band[1]:g} Hz; the records' lines end at "
                         f"the Nyquist frequency, {nyquist:g} Hz: expected a band starting below it")
    result = process_taps(records, args.estimator, tap_length=args.tap_length,
                          pre_trigger=pre_trigger,
                          exponential=True if args.exponential_window else False if args.no_exponential_window
                          else None, tau=args.tau, band=args.band,
                          hammer_band_db=HAMMER_BAND_DB if args.hammer_band_db is None else args.hammer_band_db)
    if args.band is not None and args.band[0] > result.hammer_band_hz:
        raise UsageError(f"argument --band: got {args.band[0]:g}:{args.band[1]:g} Hz, above the hammer's usable "
                         f"band (up to {result.hammer_band_hz:.0f} Hz, where its force spectrum has fallen "
                         f"{result.hammer_band_db:g} dB; the Nyquist frequency is {nyquist:g} Hz): the taps do not "
                         f"excite it; expected a band starting below {result.hammer_band_hz:.0f} Hz")
    if args.reverse_polarity:  # one channel's sign reversed: the FRF negated, its coherence and noise as they are
        import attrs

        result = attrs.evolve(result, frf=-result.frf, measured=-result.measured)
    share = reversed_share(result.frf.data[:, 0, 0]) if response is not None and response == excitation else 0.0
    if share > REVERSED_SHARE:
        warnings.warn(f"the FRF of the driving point {response} has a positive imaginary part on lines holding "
                      f"{share:.0%} of |Im H| (a passive structure's is <= 0): one channel's sign is reversed (the "
                      "hammer's or the sensor's polarity, or a sensor facing the other way); --reverse-polarity "
                      "negates it", SubstructureWarning, stacklevel=2)
    peaks = result.peaks()
    written = []
    if args.out:
        write_csv(result.frf, args.out, args.overwrite, coherence=result.coherence, force_noise=result.force_noise,
                  truncation=result.truncation, window_tau=result.tau)
        written.append(args.out)
    if args.measurements:
        relative = os.path.relpath(os.path.abspath(args.out), os.path.dirname(os.path.abspath(args.measurements)))
        name = args.name or f"tap test: {response} / {excitation}"
        write_text(args.measurements, _set_text(name, response, excitation, Path(relative).as_posix(),
                                                result.averages, result.tau,
                                                result.force_window_s if result.force_noise is not None else None,
                                                result.estimator),
                   overwrite=args.overwrite)
        written.append(args.measurements)
    if args.plot:
        figures()
        from ..plot import plot_taps

        save_figure(plot_taps(result, title=", ".join(Path(p).name for p in args.records[:3])
                              + (" ..." if len(args.records) > 3 else "")), args.plot, args.overwrite)
        written.append(args.plot)
    added = result.added_damping(peaks) if len(peaks) else []
    damping = result.damping(peaks) if args.correct_window_damping else None
    if args.json:
        out = result.summary()
        out["peaks"] = [{"frequency_hz": float(f), "added_damping_ratio": float(z)} for f, z in zip(peaks, added)]
        if damping is not None:
            for entry, d in zip(out["peaks"], damping):
                entry["damping_ratio"] = d["damping_ratio"]
                entry["damping_ratio_corrected"] = d["damping_ratio_corrected"]
        return print_json(out)
    import numpy as np

    print(f"records: {len(records)}, {result.sample_rate:g} Hz, {result.tap_samples} samples per tap "
          f"({result.tap_samples / result.sample_rate:g} s" + ("" if result.shortest is None else
                                                                f"; every tap cut to the shortest, {result.shortest}")
          + ")")
    print(f"taps: {len(result.taps)} found, {result.averages} averaged ({result.estimator}), "
          f"{len(result.rejected)} rejected")
    for tap in result.taps:
        state = "kept" if tap.kept else f"rejected: {tap.reason}"
        print(f"  tap {tap.number} ({tap.source}, t = {tap.start_s:.4g} s): peak {tap.peak_force:.4g} N, "
              f"pulse {tap.pulse_width_s * 1e3:.3g} ms, band {tap.band_hz:.0f} Hz; {state}")
    print(f"hammer's usable band: up to {result.hammer_band_hz:.0f} Hz (force spectrum -{result.hammer_band_db:g} dB)")
    usable = result.frf.frequency.hz <= result.hammer_band_hz
    gamma = result.coherence[usable] if usable.any() else result.coherence
    print(f"coherence within the band: median {np.median(gamma):.4f}, minimum {np.min(gamma):.4f}")
    peak = np.mean([t.peak_force for t in result.taps if t.kept])
    scatter = result.force_scatter()
    print(f"hammer's noise: {result.force_noise_rms:.3g} N RMS outside the pulse ({result.force_noise_rms / peak:.2g} "
          "of the peak)" + ("" if scatter is None else
                            f"; H1{'' if result.estimator == 'H1' else ' (gamma^2 H2, which the diagnosis compares)'}"
                            f" scatters by up to {scatter:.2%} from it within the band, a smooth error over "
                            f"about {1.0 / result.force_window_s:.0f} Hz (the force window's "
                            f"{result.force_window_s * 1e3:.2g} ms)"))
    if result.tau is None:
        print(f"exponential window: {result.window}")
    else:
        print(f"exponential window: tau = {result.tau:.4g} s, {result.window}; it adds a damping ratio "
              "1/(tau omega) to every mode (the --out file says so; diagnose and identify compare the model through "
              "the same window, lobes takes it out of the fitted modes; other uses of the FRF see it)")
    cut = result.truncation_error()
    if cut is not None:
        print(f"truncation: the response still rang at the taps' end; the error it leaves in the FRF is at most "
              f"{cut[0]:.2g} (relative) near {cut[1]:.0f} Hz, and counted as noise by the fits (the file's truncation "
              "column; a longer record removes it)")
    shown = list(zip(peaks, added))
    print(f"peaks within the band ({result.measured.quantity}):" if shown else "peaks: none within the band")
    for k, (f, z) in enumerate(shown):
        line = f"  {f:10.6g} Hz" + ("" if result.tau is None else f"   window's added damping ratio {z:.2e}")
        if damping is not None:
            d = damping[k]
            line += ("; half-power damping not found (peak too narrow or too close to another)"
                     if d["damping_ratio"] is None else
                     f"; half-power damping ratio {d['damping_ratio']:.3e}" + ("" if result.tau is None else
                                                                              f", without the window's "
                                                                              f"{d['damping_ratio_corrected']:.3e}"))
        print(line)
    for path in written:
        print(f"wrote {path}")
    return 0


def add_parser(commands) -> None:
    """Add the ``tap`` subcommand to the subparsers ``commands``."""
    tap = commands.add_parser("tap", help="time records of hammer taps to an FRF with coherence")
    tap.add_argument("records", nargs="+", metavar="RECORD",
                     help="tap records: CSV or text (time [s],force [N],acceleration [m/s^2], a preamble "
                     "allowed), LabVIEW .lvm, NI .tdms (a group of channels per tap, units in unit_string), "
                     "MATLAB .mat (vectors, or matrices of a tap a column, with "
                     "<name>_unit texts), or UFF type-58 time records (a force and a response record per tap)")
    tap.add_argument("--out", metavar="FRF.csv", help="write the receptance with its coherence column")
    tap.add_argument("--measurements", metavar="SET.toml", help="write a measurement set naming --out")
    tap.add_argument("--response", metavar="POINT", help="the response point of the measurement set")
    tap.add_argument("--excitation", metavar="POINT", help="the excitation point of the measurement set")
    tap.add_argument("--name", help="the measurement set's name")
    tap.add_argument("--plot", metavar="FILE.png", help="force spectra, coherence and FRF to an image file")
    tap.add_argument("--estimator", choices=("H1", "H2", "Hv"), default="H1",
                     help="H1 (noise on the response, default), H2 (noise on the force), Hv (both)")
    tap.add_argument("--quantity", choices=("acceleration", "velocity", "displacement"),
                     help="what the response is (must agree with the file's unit)")
    tap.add_argument("--sensitivity", metavar="VALUE", help="response sensor sensitivity for a channel in volts, "
                     "e.g. '10.2 mV/g'")
    tap.add_argument("--hammer-sensitivity", metavar="VALUE",
                     help="hammer sensitivity for a force channel in volts, e.g. '2.25 mV/N'")
    tap.add_argument("--sample-rate", metavar="VALUE",
                     help="text, .tdms and .mat records without a time column: samples per second, e.g. '51.2 kHz' "
                     "(refused when the file states another rate)")
    tap.add_argument("--force-column", metavar="NAME|INDEX",
                     help="text, .lvm, .tdms and .mat records: the force column (channel, vector) by name or "
                     "1-based index, "
                     "when the file has more than one candidate")
    tap.add_argument("--response-column", metavar="NAME|INDEX",
                     help="text, .lvm, .tdms and .mat records: the response column (channel, vector) by name or "
                     "1-based index "
                     "(a second accelerometer, a trigger channel)")
    tap.add_argument("--force-record", type=int, metavar="N",
                     help="UFF: 0-based index of the force record (one tap; default: every tap of the file)")
    tap.add_argument("--response-record", type=int, metavar="N", help="UFF: 0-based index of the response record")
    tap.add_argument("--tap-length", type=float, metavar="SECONDS",
                     help="cut long records into taps of this length (default: one tap per record)")
    tap.add_argument("--pre-trigger", type=float, metavar="SECONDS",
                     help="time kept before the force's trigger crossing (default 0.005 s, tap.PRE_TRIGGER_S)")
    tap.add_argument("--tau", type=float, metavar="SECONDS",
                     help="time constant of the exponential window (default: 1%% left at the end of the tap)")
    window = tap.add_mutually_exclusive_group()
    window.add_argument("--exponential-window", action="store_true",
                        help="an exponential window on both channels whatever the response does at the end of "
                             "the tap (default: only when it still rings above 10%% of its peak there; below, "
                             "the error of its end is counted instead)")
    window.add_argument("--no-exponential-window", action="store_true", help="no exponential window")
    tap.add_argument("--correct-window-damping", action="store_true",
                     help="also each peak's half-power damping ratio, and the same less the window's 1/(tau omega)")
    tap.add_argument("--hammer-band-db", type=float, metavar="DB",
                     help="force spectrum drop that ends the hammer's usable band (default 20 dB, tap.HAMMER_BAND_DB)")
    tap.add_argument("--band", type=band_range_arg, metavar="LO:HI", help="keep only these lines (Hz)")
    tap.add_argument("--reverse-polarity", action="store_true",
                     help="negate the FRF: one channel's sign is reversed (a driving point's Im(H) must be <= 0)")
    tap.add_argument("--overwrite", action="store_true", help="let the outputs replace existing files")
    tap.add_argument("--json", action="store_true", help="print one JSON object instead of the summary")
    tap.set_defaults(run=run)
