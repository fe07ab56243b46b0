"""The ``skmotion`` command."""

import argparse
import sys
import time

from skmotion import __version__

__all__ = ["main"]


def _demo(args):
    from skmotion._demo import run_demo

    start = time.perf_counter()
    print(f"skmotion {__version__} demo")
    run_demo(print, random_state=args.random_state, plot_dir=args.plots)
    print("")
    print(f"done in {time.perf_counter() - start:.1f} s")
    return 0


def build_parser():
    """The argument parser of the ``skmotion`` command."""
    parser = argparse.ArgumentParser(
        prog="skmotion",
        description="scikit-learn-compatible estimators for human motion capture clips.",
    )
    parser.add_argument("--version", action="version", version=f"skmotion {__version__}")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND")
    demo = commands.add_parser(
        "demo", help="run the main job on the built-in synthetic data and print a report"
    )
    demo.add_argument("--random-state", type=int, default=0, help="seed of the data and models (default 0)")
    demo.add_argument("--plots", metavar="DIR", default=None, help="save the sections' figures in DIR (needs matplotlib)")
    demo.set_defaults(func=_demo)
    return parser


def main(argv=None):
    """Run the ``skmotion`` command; returns the exit status."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help()
        return 2
    return args.func(args)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
