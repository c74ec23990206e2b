"""The ``substructure predict`` command: joint parameters for an untested tool from a joint table."""

from __future__ import annotations

import argparse
from pathlib import Path

from ._common import UsageError, check_outputs, check_plot, count_arg, draw_to, point_arg, print_json


def _features(text: str) -> dict[str, str]:
    out = {}
    for part in text.split(","):
        if not part.strip():
            continue
        name, sep, value = part.partition("=")
        if not sep or not name.strip() or not value.strip():
            raise UsageError(f"--features: cannot read {part.strip()!r}; expected NAME=VALUE, e.g. tool_diameter=14 mm")
        if name.strip() in out:
            raise UsageError(f"--features: {name.strip()} given twice ({out[name.strip()]!r} and {value.strip()!r}); "
                             "give each feature once")
        out[name.strip()] = value.strip()
    return out


def run(args: argparse.Namespace) -> int:
    from ..io.assembly_toml import load_assembly
    from ..surrogate import JointTable, cross_validate, make_surrogate

    if args.plot and not args.cross_validate and not args.assembly:
        raise UsageError("--plot draws the FRF band of --assembly A.toml --joint NAME or the parity plot of "
                         "--cross-validate, and neither is given; add one of them or leave out --plot")
    check_plot(args.plot)
    check_outputs([("--plot", args.plot)], [args.table, args.assembly], args.overwrite)
    count_arg("--samples", args.samples, minimum=1)
    read = JointTable.from_toml if Path(args.table).suffix.lower() == ".toml" else JointTable.from_csv
    table = read(args.table)
    table.check_not_empty()
    surrogate = make_surrogate(args.model)
    if args.cross_validate:
        target = args.target or next(iter(table.parameters))
        cv = cross_validate(surrogate, table, target, args.cross_validate)
        if args.plot:
            draw_to(args.plot, args.overwrite, cv.plot)
        if args.json:
            return print_json(cv.to_json())
        print(f"{args.model}, {args.cross_validate} on {args.table}: {len(cv.folds)} folds, {target} [{cv.unit}]")
        print(f"  mean |error| {cv.mean_abs_percent_error:.1f} %, max {cv.max_abs_percent_error:.1f} %")
        print(f"  inside the 68 % interval {cv.coverage(0.68):.0%}, the 95 % interval {cv.coverage(0.95):.0%}")
        return 0
    if args.features is None:
        raise UsageError("give --features NAME=VALUE,... (or --cross-validate)")
    if bool(args.assembly) != bool(args.joint):
        raise UsageError("--assembly and --joint go together: the assembly file and the joint to replace")
    features = _features(args.features)  # read and checked before the fit: a mistake costs no time
    table.feature_values(features, field="--features")
    targets = [args.target] if args.target else None
    model = surrogate.fit(table, targets)
    prediction = model.predict(features)
    result = prediction.to_json()
    band = None
    if args.assembly:
        from ..surrogate import predict_frf_band

        band = predict_frf_band(load_assembly(args.assembly), args.joint, prediction, at=point_arg(args.at),
                                n_samples=args.samples)
        if args.plot:
            draw_to(args.plot, args.overwrite, lambda: band.plot(label=f"{args.model} prediction"))
    if args.json:
        out = {"model": args.model, "features": features, "parameters": result,
               "extrapolation": prediction.outside()}
        if band is not None:
            out["frf"] = {"at": point_arg(args.at), "joint": args.joint, **band.to_json()}
        return print_json(out)
    print(f"{args.model} surrogate on {table.describe()}")
    for name, p in result.items():
        lo, hi = p["interval_95"]
        print(f"  {name} = {p['value']:.4g} +- {p['std']:.3g} {p['unit']} (95 %: {lo:.4g} to {hi:.4g})")
    if band is not None:
        nominal = band.nominal
        peaks = nominal.peaks()
        print(f"tool point FRF ({point_arg(args.at)}) with the predicted {args.joint!r} joint, "
              f"{len(next(iter(band.samples.values())))} samples: peaks of the median joint at "
              + ", ".join(f"{f:.0f} Hz" for f in peaks))
        if args.plot:
            print(f"wrote {args.plot}")
    return 0


def add_parser(commands) -> None:
    """Add the ``predict`` subcommand to the subparsers ``commands``."""
    pred = commands.add_parser("predict", help="joint parameters for an untested tool from a joint table")
    pred.add_argument("table", metavar="TABLE",
                      help="joint-parameter table: CSV (units in the header) or TOML (.toml, [[joints]] rows)")
    pred.add_argument("--features", metavar="NAME=VALUE,...", help="features of the tool, e.g. 'tool_diameter=14 mm'")
    pred.add_argument("--model", choices=("mlp", "gp"), default="gp", help="surrogate (default gp)")
    pred.add_argument("--target", metavar="PARAMETER", help="parameter to predict (default: all of the table)")
    pred.add_argument("--cross-validate", metavar="loo|group:FEATURE", help="evaluate the surrogate instead")
    pred.add_argument("--assembly", metavar="A.toml", help="assembly file: the tool point FRF and its band")
    pred.add_argument("--joint", metavar="NAME", help="the joint of --assembly the prediction replaces")
    pred.add_argument("--at", default="tool.tip", metavar="POINT[:dof]", help="FRF point (default tool.tip:y)")
    pred.add_argument("--samples", type=int, default=64, metavar="N",
                      help="samples of the predictive distribution for the FRF band (default 64)")
    pred.add_argument("--plot", metavar="FILE.png",
                      help="the FRF band of --assembly, or the parity plot of --cross-validate")
    pred.add_argument("--overwrite", action="store_true", help="let --plot replace an existing file")
    pred.add_argument("--json", action="store_true", help="print one JSON object instead of the summary")
    pred.set_defaults(run=run)
