"""The ``skmotion`` command."""

import argparse
import sys
import time

from skmotion import __version__

__all__ = ["main"]


def _demo_error(message):
    print(f"skmotion demo: {message}", file=sys.stderr)
    return 2


def _demo(args):
    from pathlib import Path

    from skmotion._demo import SECTIONS, run_demo
    from skmotion._demo.data_folder import DemoDataError

    start = time.perf_counter()
    options = {}
    sections = SECTIONS
    if args.data is not None:
        folder = Path(args.data)
        if not folder.is_dir():
            what = "is a file, not a folder" if folder.exists() else "does not exist"
            return _demo_error(f"--data {args.data} {what}")
        for flag, value in (("--index", args.index), ("--labels", args.labels)):
            if value is not None and not Path(value).is_file():
                return _demo_error(f"{flag} {value}: no such file")
        sections = tuple(
            "skmotion._demo.data_folder" if s == "skmotion._demo.data" else s for s in SECTIONS
        )
        options = {
            "data_folder": args.data,
            "frame_rate": args.frame_rate,
            "index": args.index,
            "labels": args.labels,
            "layout": args.layout,
        }
    out = None if args.no_out else args.out
    if out is not None:
        try:
            Path(out).mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            return _demo_error(f"cannot write the output folder --out {out}: {exc.strerror}")
    print(f"skmotion {__version__} demo")
    try:
        context = run_demo(
            print,
            random_state=args.random_state,
            sections=sections,
            out=out,
            verbose=0 if args.quiet else 1,
            **options,
        )
    except DemoDataError as exc:
        return _demo_error(str(exc))
    print("")
    if context.report_path is not None:
        print(f"figures and report.html (text and figures in one file) written to {Path(out)}/")
    print(f"done in {time.perf_counter() - start:.1f} s")
    return 0


def _marker_preset(skeleton):
    """The ``marker preset`` line of ``skmotion info`` (presets live in preprocessing, not io)."""
    from skmotion.preprocessing import detect_marker_preset

    try:
        return [f"marker preset: {detect_marker_preset(skeleton)}"]
    except ValueError:
        return ["marker preset: none fits (define a MarkerSet)"]


def _layout_notes(motion, layout):
    """The ``layout check`` lines of ``skmotion info --layout`` (layouts live in kinematics)."""
    from skmotion.kinematics import check_layout

    try:
        problems = check_layout([motion.channels], layout)
    except ValueError as exc:
        return [f"layout check: not run ({exc})"]
    if not problems:
        return [f"layout check: the data fit the joint order of {layout} (bones, sides, posture)"]
    return [f"layout check: WARNING, the data do not fit the joint order of {layout}:"] + [
        f"  - {problem}" for problem in problems
    ]


def _info(args):
    from pathlib import Path

    from skmotion.io._info import describe_file, describe_folder

    notes = None
    if args.layout is not None:
        notes = lambda motion: _layout_notes(motion, args.layout)  # noqa: E731
    try:
        if Path(args.file).is_dir():
            lines = describe_folder(args.file, layout=args.layout, frame_rate=args.frame_rate)
        else:
            lines = describe_file(
                args.file,
                asf=args.asf,
                frame_rate=args.frame_rate,
                layout=args.layout,
                skeleton_notes=_marker_preset,
                position_notes=notes,
                units=None if args.units == "none" else args.units,
            )
    except (OSError, ValueError, ImportError, TypeError) as exc:
        print(f"skmotion info: {exc}", file=sys.stderr)
        return 1
    print("\n".join(lines))
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
    demo.add_argument(
        "--random-state", type=int, default=0, help="seed of the data and models (default 0)"
    )
    demo.add_argument(
        "--data",
        metavar="FOLDER",
        default=None,
        help="run on the motion files under FOLDER (BVH files and ASF/AMC subject folders, at "
        "any depth) instead of the synthetic data; CMU trials (NN_TT files) are labelled from the "
        "CMU index, other files by a motion keyword in their name, else by their folder",
    )
    demo.add_argument(
        "--index",
        metavar="CSV",
        default=None,
        help="with --data: the CMU index CSV (default: one found in FOLDER or a folder above it)",
    )
    demo.add_argument(
        "--labels",
        metavar="CSV",
        default=None,
        help="with --data: the label (and optionally the subject) of every file, a CSV with "
        "columns path,label[,subject] (path relative to FOLDER, a file name, or a name without "
        "suffix); without it, labels guessed from folder names that look like subjects are "
        "refused",
    )
    demo.add_argument(
        "--layout",
        metavar="NAME",
        default=None,
        help="with --data: read the keypoint files (.npy .npz .csv .txt) in FOLDER in this joint "
        "order (kinect_v1, kinect_v2, azure_kinect, coco17, openpose_body25, mediapipe_pose33, "
        "h36m17, smpl24), at --frame-rate, and check that the order fits the data",
    )
    demo.add_argument(
        "--frame-rate",
        type=float,
        default=30.0,
        help="with --data: resample every clip to this rate (default 30 Hz); with --layout also "
        "the keypoint files' rate",
    )
    demo.add_argument(
        "--out",
        metavar="DIR",
        default="skmotion-demo",
        help="write the figures and report.html here (default ./skmotion-demo; figures need "
        'matplotlib: pip install "skmotion[plot]")',
    )
    demo.add_argument("--plots", dest="out", help=argparse.SUPPRESS)  # the old name of --out
    demo.add_argument("--no-out", action="store_true", help="print the report only; write no files")
    demo.add_argument("--quiet", action="store_true", help="no progress lines on standard error")
    demo.set_defaults(func=_demo)
    from skmotion.io._formats import formats_help

    info = commands.add_parser(
        "info",
        help="print a motion file's skeleton or markers, channels, frame rate and duration",
        description="Formats read:\n" + formats_help(),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    info.add_argument(
        "file", help="a motion file of a format listed above, or a folder of them (a summary)"
    )
    info.add_argument(
        "--asf", default=None, help="the skeleton of an .amc file (default: NN.asf beside it)"
    )
    info.add_argument(
        "--frame-rate",
        type=float,
        default=None,
        help="frames per second of a file that does not record it (keypoint files)",
    )
    info.add_argument(
        "--layout",
        metavar="NAME",
        default=None,
        help="the joint order of a keypoint file (kinect_v1, kinect_v2, coco17, ...; a flat "
        "frames x joints*3 file needs it); checks that the order fits the data",
    )
    info.add_argument(
        "--units",
        choices=["m", "cm", "mm", "in", "ft", "none"],
        default="m",
        help="length unit C3D positions are shown in (default m); 'none' keeps the file's "
        "numbers, for files whose POINT:UNITS is empty",
    )
    info.set_defaults(func=_info)
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
