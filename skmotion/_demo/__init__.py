"""The sections of ``skmotion demo``, each in its own module.

A section module defines ``TITLE`` and ``run(context)``, which returns the lines
to print and may leave results on ``context`` for later sections. Add a section
by writing its module and listing it in ``SECTIONS``.
"""

import importlib
from types import SimpleNamespace

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


def run_demo(write, *, random_state=0, sections=SECTIONS, **options):
    """Run the demo sections in order, passing each line to ``write``.

    Parameters
    ----------
    write : callable
        Receives each line of the report (``print``, say).
    random_state : int, default=0
        Seed of the synthetic data and of every estimator.
    sections : sequence of str, default=SECTIONS
        Modules of the sections to run.
    **options
        Set on the context for the sections (``data_folder``, ``frame_rate``, ``plot_dir``: where
        sections save their figures when matplotlib is installed).

    Returns
    -------
    context : SimpleNamespace
        What the sections computed (the data, fitted models, scores).
    """
    context = SimpleNamespace(random_state=random_state, **options)
    for name in sections:
        module = importlib.import_module(name)
        write("")
        write(f"== {module.TITLE} ==")
        for line in module.run(context):
            write(line)
    return context
