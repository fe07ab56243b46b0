"""The sections of ``skmotion demo``, each in its own module.

A section module defines ``TITLE`` and ``run(context)``, which returns the lines
to print and may leave results on ``context`` for later sections. Add a section
by writing its module and listing it in ``SECTIONS``.
"""

import importlib
import time
from pathlib import Path
from types import SimpleNamespace

from skmotion.utils import say

__all__ = ["SECTIONS", "run_demo"]

SECTIONS = (
    "skmotion._demo.data",
    "skmotion._demo.markers",
    "skmotion._demo.recognition",
    "skmotion._demo.index",
    "skmotion._demo.primitives",
    "skmotion._demo.evaluation",
    "skmotion._demo.checks",
    "skmotion._demo.planning",
    "skmotion._demo.live",
)


def run_demo(write, *, random_state=0, sections=SECTIONS, out=None, verbose=0, **options):
    """Run the demo sections in order, passing each line to ``write``.

    Parameters
    ----------
    write : callable
        Receives each line of the report (``print``, say).
    random_state : int, default=0
        Seed of the synthetic data and of every estimator.
    sections : sequence of str, default=SECTIONS
        Modules of the sections to run.
    out : str or path-like, default=None
        The output folder for the figures and ``report.html`` (text and figures in one
        file); None writes nothing.
    verbose : int, default=0
        1 reports each section's start and time on standard error.
    **options
        Set on the context for the sections (``data_folder``, ``frame_rate``, ``index``).

    Returns
    -------
    context : SimpleNamespace
        What the sections computed (the data, fitted models, scores); ``report`` holds
        (title, lines, figures) per section and ``report_path`` the HTML file.
    """
    context = SimpleNamespace(
        random_state=random_state, out=out, verbose=verbose, figures=[], report=[], **options
    )
    for name in sections:
        module = importlib.import_module(name)
        say(verbose, f"demo: {module.TITLE} ...")
        start, before = time.perf_counter(), len(context.figures)
        write("")
        write(f"== {module.TITLE} ==")
        lines = []
        for line in module.run(context):
            write(line)
            lines.append(line)
        context.report.append((module.TITLE, lines, context.figures[before:]))
        say(verbose, f"demo: {module.TITLE}: {time.perf_counter() - start:.1f} s")
    context.report_path = None
    if out:
        from skmotion._demo._report import write_report

        Path(out).mkdir(parents=True, exist_ok=True)
        context.report_path = write_report(
            Path(out) / "report.html", "skmotion demo", context.report
        )
    return context
