"""The ``substructure lobes`` command: stability lobes of a cut from an FRF, an assembly or modes."""

from __future__ import annotations

import argparse
import warnings

from ..errors import SubstructureError, WindowedFRFWarning
from ._common import (PROG, UsageError, check_outputs, positive_arg, check_plot, draw_to, grid_text,
                      one_line, point_arg, print_json)
from ._cutting import (
    MILLING_DEFAULT_NOTE,
    add_cut_options,
    add_lobes_options,
    cut_from_args,
    cutting_check,
    deep_cut_note,
    limits_from_args,
    structure_band_arg,
    tool_of,
)


def _window(args: argparse.Namespace) -> dict | None:
    """The exponential window of each direction's FRF file (``# window_tau_s``, or ``--window-tau``), None without."""
    from ..io.frf_files import read_csv_window

    positive_arg("--window-tau", args.window_tau)
    if args.frf is None:
        if args.window_tau is not None:
            raise UsageError("--window-tau is for measured FRFs (--frf X.csv): a model or modes have no window")
        return None
    files = {"x": args.frf, "y": args.frf_y or args.frf}
    taus = {}
    for d, path in files.items():
        said = read_csv_window(path) if str(path).lower().endswith(".csv") else None
        if said is not None and args.window_tau is not None and abs(said / args.window_tau - 1) > 1e-9:
            raise UsageError(f"--window-tau {args.window_tau:g}: {path} says it was measured through a window of "
                             f"{said!r} s (its '# window_tau_s' line); give the file's value or leave the option out")
        taus[d] = said if said is not None else args.window_tau
    return taus if any(t is not None for t in taus.values()) else None


def _unsaid_windows(args: argparse.Namespace) -> list[str]:
    """Measured FRF files that declare no window but whose noise is correlated as through an exponential one
    (``NoiseModel.seen_tau``): read as they are, every mode carries the window's damping."""
    from ..updating.noise import estimate_noise

    out = []
    for path in dict.fromkeys(p for p in (args.frf, args.frf_y) if p is not None):
        try:
            with warnings.catch_warnings():  # the data's own checks were said when the file was read
                warnings.simplefilter("ignore")
                tau = estimate_noise(_read_frf(path).to_receptance()).seen_tau
        except SubstructureError:  # too few lines to tell: nothing to say
            continue
        if tau is not None:
            out.append(f"{path}: its noise is correlated over neighbouring lines as an exponential window of tau = "
                       f"{tau:.3g} s would correlate it, and the file declares no window; if the analyser applied "
                       "one, every mode carries its damping 1/(tau omega) and these lobes promise depths the tool "
                       f"may not take: give --window-tau (the analyser's value, or {tau:.3g} as read)")
    return out


def _read_frf(path):
    """A measured tool point FRF by its suffix: CSV, a universal file of one type-58 record, or a MATLAB file of
    signal structures (a Testlab export) of one FRF."""
    from pathlib import Path

    from ..frf import FRF
    from ..frf.files.mat_reader import read_mat

    suffix = Path(path).suffix.lower()
    if suffix in (".uff", ".unv", ".mat"):
        frf = FRF.from_uff(path) if suffix != ".mat" else read_mat(path, record=_one_frf_channel(path))
        if frf.shape[1:] != (1, 1):
            raise SubstructureError(f"{path}: {frf.shape[1] * frf.shape[2]} FRF records ({', '.join(frf.outputs)} / "
                                    f"{', '.join(frf.inputs)}); --frf takes a file of one tool point FRF: export "
                                    "that record alone")
        return frf
    return FRF.from_csv(path)


def _one_frf_channel(path) -> int:
    """The index of a MATLAB file's one FRF channel, or an error naming them for ``--frf``."""
    from ..frf.files.mat_reader import frf_channels

    found = frf_channels(path)
    if len(found) != 1:
        raise SubstructureError(f"{path}: {len(found)} FRF channels ({', '.join(n for _, n in found) or 'none'}); "
                                "--frf takes a file of one tool point FRF: export that channel alone")
    return found[0][0]


def _check_sign(path, frf) -> None:
    """Refuse a driving point that reads as no receptance by its passivity: an imaginary part positive where most
    of ``|Im H|`` lies (a reversed sign, the other convention, or an accelerance), or a real part positive where
    most of ``|Re H|`` lies with an imaginary part of both signs (a mobility)."""
    import numpy as np

    from ..frf.passivity import driving_point_quantity, reversed_share

    h = frf.data[:, 0, 0]
    found = driving_point_quantity(h, frf.frequency.hz)
    if found is None:
        return
    kind, value = found
    if kind == "mobility":
        raise SubstructureError(
            f"{path}: Re(H) > 0 on lines holding {value:.0%} of |Re H|, and Im(H) of both signs: the pattern of a "
            "driving-point mobility (Re Y >= 0 on a passive structure), not of a receptance (Im H <= 0): a mobility "
            "whose units the file left out? give them in its header (`real [m/(N s)]`, `imag [m/(N s)]`); as read, "
            "the lobes would be wrong by a factor of 2 pi f")
    lines = float(np.mean(np.imag(h[np.isfinite(h)]) > 0))
    accelerance = ("an accelerance whose units the file left out (Im A >= 0 on a passive structure; give them in "
                   "its header: `real [m/(N s^2)]`, `imag [m/(N s^2)]`)")
    reversed_ = ("its sign is reversed (a channel's polarity: negate the data) or the data follow the other "
                 "convention, exp(-i omega t) (take their conjugate)")
    causes = (f"|H| grows as f^{value:.2g} over the band: {accelerance}; or {reversed_}" if kind == "accelerance"
              else f"{reversed_}; or {accelerance}")
    raise SubstructureError(
        f"{path}: Im(H) > 0 on {lines:.0%} of the lines, holding {reversed_share(h):.0%} of |Im H| (a tool point's "
        f"receptance has Im(H) <= 0, but for noise near its antiresonances): {causes}; as they are, the lobes "
        "would be many times too deep")


def _lobes_structure(args: argparse.Namespace):
    """The structure, a line describing it, the band chosen, the tool and the window removed (or None)."""
    from ..io.assembly_toml import load_assembly
    from ..stability import ModalModel, assembly_structure, choose_band, window_removed, xy_frf

    sources = [name for name, value in (("--assembly", args.assembly), ("--frf", args.frf), ("--modes", args.modes))
               if value is not None]
    if len(sources) != 1:
        raise UsageError("give the structure as one of --assembly A.toml --at POINT, --frf X.csv [--frf-y Y.csv] "
                          "or --modes MODES.csv" + (f" (got {', '.join(sources)})" if sources else ""))
    if (args.at is not None) != (args.assembly is not None):
        raise UsageError("--at POINT goes with --assembly A.toml (and --assembly needs --at)")
    if args.frf_y is not None and args.frf is None:
        raise UsageError("--frf-y goes with --frf")
    taus = _window(args)
    if args.modes is not None:
        if args.band is not None:
            raise UsageError("--band crops FRF data; --modes are used as they are")
        model = ModalModel.from_csv(args.modes)
        return model, f"modes from {args.modes}: {model.describe()}", None, None, None
    band = "auto" if args.band is None else args.band
    tool = None
    if args.assembly is not None:
        assembly = load_assembly(args.assembly)
        at = point_arg(args.at)
        if at.endswith(":theta"):
            raise SubstructureError(f"--at {args.at}: the cut needs a translational receptance (':y'), not ':theta'")
        if assembly.frequency is None:
            raise UsageError(f"{args.assembly} has no [frequency] table; lobes need the FRF on a grid")
        tool = tool_of(assembly, at)
        what = f"tool point FRF of {assembly.name} at {at}, y = x (a symmetric tool)"
        if band == "auto":  # the model says what its supports do
            one, band = assembly_structure(assembly, at)
            return xy_frf(one), f"{what}, {grid_text(one.frequency)}", band, tool, None
        frf = xy_frf(assembly.receptance(at, frequency=assembly.frequency))
    else:
        with warnings.catch_warnings():  # the window a file declares is taken out below
            warnings.simplefilter("ignore", WindowedFRFWarning)
            x = _read_frf(args.frf)
            y = _read_frf(args.frf_y) if args.frf_y else None
        for path, one in ((args.frf, x), (args.frf_y, y)):
            if one is not None:  # checked as the receptance it is read as (an accelerance whose units say so too)
                _check_sign(path, one.to_receptance())
        frf = xy_frf(x, y)
        what = f"FRF from {args.frf}" + (f" (x) and {args.frf_y} (y)" if args.frf_y else ", y = x (a symmetric tool)")
    frf, band = choose_band(frf, band)
    # through an exponential window every mode carries 1/(tau omega) of the window's damping: taken out of the
    # fitted modes, or the lobes would promise depths the tool cannot take
    window = None if taus is None else window_removed(frf, taus)
    return (frf if window is None else window.frf), f"{what}, {grid_text(frf.frequency)}", band, tool, window


def _zoa_noted(structure, cut, speeds, band, notes: list[str], lobes: bool = True):
    """``zoa`` of the structure (or, without ``lobes``, only its checks of the band: ``check_band``); its warnings
    that the absolute limit sits on an edge of the band, or that a mode lies above it, are also notes."""
    from ..stability import StabilityWarning, zoa
    from ..stability.zoa import ABOVE_WARNING, EDGE_WARNING, check_band

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        band = band if band is not None else "auto"
        result = zoa(structure, cut, speeds, band=band) if lobes else check_band(structure, cut, band)
    for item in caught:
        if issubclass(item.category, StabilityWarning) and str(item.message).startswith(
                (EDGE_WARNING.split("{")[0], ABOVE_WARNING.split("{")[0])):
            notes.append(f"warning: {item.message}")
        warnings.warn_explicit(item.message, item.category, item.filename, item.lineno)
    return result


def run(args: argparse.Namespace) -> int:
    import sys

    import attrs
    import numpy as np

    def progress(text: str) -> None:  # semi-discretization takes minutes at low speeds: its steps on stderr
        if not args.quiet:
            print(f"{PROG}: {text}", file=sys.stderr, flush=True)

    from ..frf import FRF
    from ..stability import (MillingCut, ModalFitter, ModalFitWarning, ModalModel, NoRecommendationError, recommend,
                             sdm)
    from ..stability.sdm import check_intervals

    check_plot(args.plot)
    check_outputs([("--plot", args.plot)], [args.assembly, args.frf, args.frf_y, args.modes, args.workpiece_table,
                                            args.cutting_data], args.overwrite)
    if args.intervals is not None and args.method != "sdm":
        raise UsageError("--intervals sets the semi-discretization: use it with --method sdm")
    structure, what, band, tool, window = _lobes_structure(args)
    notes: list[str] = []
    if band is not None:
        notes.append(f"structure band: {band.lo_hz:g} to {band.hi_hz:g} Hz ({band.kind}); {band.reason}")
    if window is None and args.frf is not None and args.window_tau is None:
        for line in _unsaid_windows(args):
            notes.append(f"warning: {line}")
            warnings.warn(line, WindowedFRFWarning, stacklevel=2)
    if window is not None:
        said = ", ".join(f"{d} {t:.4g} s" for d, t in window.tau.items() if t is not None)
        notes.append(f"exponential window: tau {said}; its damping 1/(tau omega) taken out of the "
                     f"{len(window.modes.modes)} fitted modes (the FRF less each mode as fitted, plus the mode without "
                     "the window)")
        notes.extend(f"  {line}" for line in window.describe())
    cut = cut_from_args(args, tool, notes)
    limits = limits_from_args(args, tool, notes) if isinstance(cut, MillingCut) else None
    if args.method == "zoa":
        lobes = _zoa_noted(structure, cut, args.speeds, band, notes)
        method = "zero-order approximation (Altintas & Budak 1995)"
    else:
        if isinstance(structure, FRF):  # semi-discretization needs modes: fit them to x and y (without the window)
            _zoa_noted(structure, cut, args.speeds, band, notes, lobes=False)  # the band's resonance: as for zoa
            fits = [ModalFitter().fit(FRF.single(structure.frequency, structure.data[:, i, i], output=d, input=d), d)
                    for i, d in enumerate("xy")]
            structure = ModalModel([m for fit in fits for m in fit.modes_])
            errors = ", ".join(f"{d} {fit.modal_error_:.1%}" for d, fit in zip("xy", fits))
            notes.append(f"modal fit: {len(structure.modes)} modes ({structure.describe()}); relative error {errors}")
            if max(fit.modal_error_ for fit in fits) > 0.2:
                warnings.warn(f"the fitted modes miss the FRF by {errors}; choose the band with --band LO:HI",
                              ModalFitWarning, stacklevel=2)
        check_intervals(structure, cut, args.speeds, args.intervals, name="--intervals")
        lobes = sdm(structure, cut, args.speeds, intervals=args.intervals, progress=progress)
        if band is not None:
            lobes = attrs.evolve(lobes, band=band)
        info = lobes.discretisation
        method = "semi-discretization (updated first order, Insperger & Stepan 2004)"
        lo, hi = info["intervals_in_cut"]
        n_lo, n_hi = info["monodromy_order"]
        big = "" if n_hi < info["arnoldi_from_order"] else (
            f", the largest multipliers by Arnoldi iterations from order {info['arnoldi_from_order']}")
        notes.append(f"discretisation: {lo}" + (f" to {hi}" if hi != lo else "") + " intervals in the cut per "
                     f"delay period (monodromy matrices of order {n_lo}" + (f" to {n_hi}" if n_hi != n_lo else "")
                     + f"{big}); boundary to {info['depth_rtol']:.1%}")
    best = why = None
    if limits is not None:
        try:
            if args.method == "sdm":
                progress("the recommendation: the lowest limit within each candidate's speed window, by new runs "
                         "of semi-discretization")
            best = recommend(lobes, cut, limits, margin=args.margin, speed_tolerance=args.speed_tolerance)
            deep = deep_cut_note(best, cut, limits)
            if deep:
                notes.append(deep)
        except NoRecommendationError as exc:  # the lobes stand; the recommendation is absent, with the reason
            why = one_line(exc)
    else:
        why = "the machinist's recommendation is for milling cuts"
        notes.append(f"no recommendation: {why}")
    shop = cutting_check(args, cut, tool, best, notes) if isinstance(cut, MillingCut) else None
    if args.plot:
        draw_to(args.plot, args.overwrite, lambda: lobes.plot(
            lobes=args.method == "zoa", recommendation=best, title=f"Stability lobes: {cut.describe()}",
            limits=limits, cut=cut if isinstance(cut, MillingCut) else None))
    if args.json:
        out = lobes.to_json()
        out["recommended"] = None if best is None else best.to_json()
        out["no_recommendation_reason"] = why
        if limits is not None:
            out["machine"] = limits.to_json()
        if getattr(cut, "workpiece", None) is not None:
            out["workpiece"] = cut.workpiece.to_json()
        if isinstance(cut, MillingCut):
            out["cut"] = cut.to_json()
            out["milling_default"] = MILLING_DEFAULT_NOTE in notes
        out["cutting_data"] = shop
        out["window"] = None if window is None else {
            "tau_s": window.tau, "modal_error": window.modal_error,
            "modes": [{"direction": m.direction, "frequency_hz": m.frequency_hz,
                       "damping_ratio_measured": m.damping_ratio, "damping_ratio": c.damping_ratio}
                      for m, c in zip(window.measured.modes, window.modes.modes)],
            "uncorrected": [{"direction": m.direction, "frequency_hz": m.frequency_hz,
                             "damping_ratio_measured": m.damping_ratio, "why": why} for m, why in window.uncorrected]}
        out["notes"] = notes
        return print_json(out)
    speeds = lobes.spindle_speed_rpm
    print(f"structure: {what}")
    print(f"cut: {cut.describe()}")
    print(f"method: {method}")
    for note in notes:
        print(note)
    print(f"speeds: {speeds[0]:g} to {speeds[-1]:g} rpm, {speeds.size} speeds")
    if lobes.absolute_limit_m is not None:
        if np.isfinite(lobes.absolute_limit_m):
            print(f"absolute limit: {lobes.absolute_limit_m * 1e3:.4g} mm at every speed "
                  f"(chatter at {lobes.absolute_limit_frequency_hz:.5g} Hz)")
        else:
            print("absolute limit: none (no chatter possible with this FRF and cut)")
    depth = lobes.depth_limit_m
    finite = np.isfinite(depth)
    if finite.any():
        i, j = np.argmin(depth), np.argmax(np.where(finite, depth, -np.inf))
        print(f"depth limit: {depth[i] * 1e3:.4g} mm (lowest, at {speeds[i]:g} rpm) to "
              f"{depth[j] * 1e3:.4g} mm (highest, at {speeds[j]:g} rpm)")
    if not finite.all():
        print(f"no limit found at {int((~finite).sum())} speeds")
    peaks = lobes.best_speeds(3)
    if peaks:
        print("best speeds (the tips of the lobes: the limit itself, no margin):")
        for n, a in peaks:
            k = int(np.argmin(np.abs(speeds - n)))
            print(f"  {n:9.6g} rpm   depth limit {a * 1e3:.4g} mm   chatter {lobes.chatter_frequency_hz[k]:.5g} Hz")
    if best is not None:
        lines = best.describe()
        print(f"recommended: {lines[0]}")
        for line in lines[1:]:
            print(f"  {line}")
        if best.mrr_m3_per_s is None:
            print("  (give --feed-per-tooth for the removal rate and the power check)")
        if shop is not None and shop.get("range") is not None:
            row = shop["range"]
            state = "outside" if shop["warnings"] else "inside"
            print(f"  {state} the usual {row['cutting_speed_m_per_min'][0]:.0f} to "
                  f"{row['cutting_speed_m_per_min'][1]:.0f} m/min and {row['feed_per_tooth_m'][0] * 1e3:.3g} to "
                  f"{row['feed_per_tooth_m'][1] * 1e3:.3g} mm/tooth for {row['workpiece']} with a "
                  f"{row['tool_material']} tool")
        for k, other in enumerate(best.runners_up, 1):
            print(f"runner-up {k}: {other.describe()[0]} (limit {other.limit_depth_m * 1e3:.3g} mm within "
                  f"{other.window_rpm[0]:.0f}..{other.window_rpm[1]:.0f} rpm)")
    elif why is not None and limits is not None:
        print(f"recommended: none; {why}")
    if args.plot:
        print(f"wrote {args.plot}")
    return 0


def add_parser(commands) -> None:
    """Add the ``lobes`` subcommand to the subparsers ``commands``."""
    lobes = commands.add_parser("lobes", help="stability lobe diagram of a cut, from an FRF, an assembly or modes")
    where = lobes.add_argument_group("structure (one of)")
    where.add_argument("--assembly", metavar="A.toml", help="assembly file; the tool point FRF at --at")
    where.add_argument("--at", metavar="POINT", help="the tool point of --assembly, e.g. tool.tip")
    where.add_argument("--frf", metavar="X.csv", help="tool point FRF in the feed direction x (CSV; a universal file "
                       "of one record or a MATLAB file of one FRF, a Testlab export, with their units)")
    where.add_argument("--frf-y", metavar="Y.csv", help="FRF in y, likewise (default: equal to x, a symmetric tool)")
    where.add_argument("--modes", metavar="MODES.csv",
                       help="modal parameters, header direction,frequency_hz,damping_ratio,stiffness_n_per_m")
    where.add_argument("--window-tau", type=float, metavar="SECONDS",
                       help="the FRF was measured through an exponential window of this time constant: its damping "
                            "is taken out of the fitted modes (default: what the file's '# window_tau_s' line says, "
                            "as substructure tap writes it)")
    where.add_argument("--band", type=structure_band_arg, metavar="auto|all|LO:HI",
                       help="FRF lines to use: auto (default: leave out rigid-body and suspension lines, "
                            "reported), all, or LO:HI in Hz")
    add_cut_options(lobes)
    add_lobes_options(lobes)
    lobes.add_argument("--plot", metavar="FILE.png", help="plot the lobes to an image file")
    lobes.add_argument("--overwrite", action="store_true", help="let --plot replace an existing file")
    lobes.add_argument("--json", action="store_true", help="print one JSON object instead of the summary")
    lobes.add_argument("--quiet", action="store_true", help="no progress lines on standard error (--method sdm)")
    lobes.set_defaults(run=run)
