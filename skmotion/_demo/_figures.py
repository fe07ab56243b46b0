"""Saving a demo section's figure into the output folder, or saying why none was drawn."""

import os
from pathlib import Path

PLOT_EXTRA = 'matplotlib is not installed (pip install "skmotion[plot]")'


def _pyplot():
    """matplotlib's pyplot with a file backend, or None when matplotlib is not installed."""
    try:
        import matplotlib
    except ImportError:
        return None
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save_figure(context, filename, draw, description):
    """Draw a figure with ``draw(plotting)``, save it in the output folder; return report lines.

    ``plotting`` is the :mod:`skmotion.plotting` module, passed in so that it is imported
    only after matplotlib is known to be installed (with a file backend). The figure is
    listed on ``context.figures`` for the HTML report. Without an output folder
    (``context.out`` None) nothing is drawn and no line is returned.
    """
    out = getattr(context, "out", None)
    if not out:
        return []
    plt = _pyplot()
    if plt is None:
        return [f"figure {filename}: not drawn, {PLOT_EXTRA}"]
    from skmotion import plotting

    path = Path(out) / filename
    path.parent.mkdir(parents=True, exist_ok=True)
    figure = draw(plotting)
    temporary = path.with_name(f".{path.stem}.{os.getpid()}.part{path.suffix}")
    try:
        figure.savefig(temporary, dpi=100, bbox_inches="tight")
        os.replace(temporary, path)
    finally:
        plt.close(figure)
        temporary.unlink(missing_ok=True)
    context.figures.append((path, description))
    return [f"figure: {description} -> {path}"]


def save_animation(context, filename, clip, body, frame_rate, description, *, seconds=3.0):
    """Write the first ``seconds`` of a clip as an animated GIF in the output folder."""
    out = getattr(context, "out", None)
    if not out:
        return []
    if _pyplot() is None:
        return [f"animation {filename}: not drawn, {PLOT_EXTRA}"]
    from skmotion.plotting import animate_clip

    n_frames = min(len(clip), max(2, int(round(seconds * frame_rate))))
    step = max(1, int(round(frame_rate / 12)))  # about 12 pictures a second keeps the file small
    path = animate_clip(
        clip[:n_frames], body, Path(out) / filename, frame_rate=frame_rate, step=step, dpi=80
    )
    context.figures.append((path, description))
    return [f"animation: {description} -> {path}"]
