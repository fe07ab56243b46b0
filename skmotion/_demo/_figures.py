"""Saving a demo section's figure, or saying why none was drawn."""

from pathlib import Path


def save_figure(plot_dir, filename, draw, description):
    """Draw a figure with ``draw(plotting)`` and save it as ``plot_dir/filename``; return the report lines.

    ``plotting`` is the :mod:`skmotion.plotting` module, passed in so that it is
    imported only after matplotlib is known to be installed (with a file backend).
    """
    try:
        import matplotlib

        matplotlib.use("Agg")
    except ImportError:
        return ['plots: matplotlib is not installed (pip install "skmotion[plot]")']
    from skmotion import plotting

    path = Path(plot_dir) / filename
    path.parent.mkdir(parents=True, exist_ok=True)
    draw(plotting).savefig(path, dpi=100)
    return [f"plot: {description} -> {path}"]
