"""``validate-sky``: score the sky classifier on a recorded file against references from it."""

from __future__ import annotations

import argparse

from ..errors import HybridtrackError
from ..outputs import claim, strict_json, write
from .base import (
    add_force_argument, add_record_arguments, add_site_arguments, command, read_record, real_number,
    site_from_arguments,
)


def _validate_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("file", help="recorded weather file with measured ghi, dni and dhi")
    add_site_arguments(parser, record=True)  # --tz is the file's zone, beside --site too, as in check and replay
    add_record_arguments(parser)
    group = parser.add_argument_group("classifier")
    group.add_argument("--config", help="sky inputs (TOML with a [sky] table); the measured-best default otherwise")
    group.add_argument("--published", action="store_true",
                       help="the published system: absolute mA, raw samples, the four published rules")
    group.add_argument("--classifier", help="fuzzy config (.toml or .fis) overriding the rule table")
    group.add_argument("--min-altitude", type=real_number, default=10.0,
                       help="count samples with the sun above this many degrees (default 10)")
    out = parser.add_argument_group("output")
    out.add_argument("--plot", metavar="PNG", help="draw one day: beam ratio, classifier inputs and labels")
    out.add_argument("--day", help="the day to draw, YYYY-MM-DD (default: the day that agrees least)")
    out.add_argument("--json", metavar="FILE", help="also write the scores as JSON here")
    out.add_argument("--out", metavar="CSV", help="write every sample's inputs, labels and references here")
    add_force_argument(out)


def _sky_config(args: argparse.Namespace):
    from ..skyinputs import SkyInputConfig

    if args.published and args.config:
        raise HybridtrackError("give either --published or --config, not both")
    if args.published:
        return SkyInputConfig.published()
    return SkyInputConfig.from_toml(args.config) if args.config else SkyInputConfig()


def _claim_outputs(args: argparse.Namespace) -> None:
    """Refuse the output files before the file is read and scored, not after (a file there
    already without --force, a folder, two flags naming one file)."""
    given = {flag: path for flag, path in (("--json", args.json), ("--out", args.out), ("--plot", args.plot)) if path}
    named: dict = {}
    for flag, path in zip(given, claim(given.values())):
        if path.resolve() in named:
            raise HybridtrackError(f"{named[path.resolve()]} and {flag} both name {path}; one would be written over "
                                   "the other")
        named[path.resolve()] = flag


@command("validate-sky", "score the sky classifier on a recorded file against beam-ratio and clear-sky references",
         _validate_arguments)
def _validate(args: argparse.Namespace) -> int:
    from ..skyvalidation import plot_day, validate_sky
    from .fuzzy import load_fuzzy_config

    if args.day and not args.plot:
        raise HybridtrackError("--day chooses the day to draw; give --plot PNG too")
    site = site_from_arguments(args)
    _claim_outputs(args)
    config = _sky_config(args)
    classifier = None
    if args.classifier:
        from ..fuzzy import FuzzyWeatherClassifier

        classifier = FuzzyWeatherClassifier(load_fuzzy_config(args.classifier))
    frame = read_record(args, args.file, site=site)
    result = validate_sky(frame, site, config=config, classifier=classifier, min_altitude=args.min_altitude)
    print(f"{args.file}: {site.name} ({site.latitude:g}, {site.longitude:g}), sky inputs: {config.mode} mode, "
          f"{config.rules} rules")
    print(result)
    if args.json:
        write(claim([args.json])[0], lambda file: file.write_text(strict_json(result.to_dict(), indent=2) + "\n"))
        print(f"wrote {args.json}")
    if args.out:
        write(claim([args.out])[0], lambda file: result.samples.to_csv(file, float_format="%.6g"))
        print(f"wrote {args.out}")
    if args.plot:
        from ..report import save_figure

        print(f"wrote {save_figure(plot_day(result, args.day), args.plot)}")
    return 0
