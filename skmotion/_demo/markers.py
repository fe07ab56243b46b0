"""Demo section: virtual markers, one feature space for every skeleton.

The representation of Yamane, Yamaguchi and Nakamura (2011), section III-A.
"""

from collections import Counter

import numpy as np
from sklearn.linear_model import RidgeClassifier
from sklearn.pipeline import make_pipeline
from sklearn.preprocessing import StandardScaler

from skmotion._demo._split import evaluation_of
from skmotion._demo.data_folder import to_rate
from skmotion.io import as_motions
from skmotion.preprocessing import (
    FlattenClips,
    ResampleClips,
    VirtualMarkerTransform,
    detect_marker_preset,
    to_markers,
)

TITLE = "Virtual markers: positions and velocities in the body frame"


def _markers(context):
    """Body-frame marker clips, their names and how they were placed (or why they cannot be)."""
    data = context.data
    if data.get("kind") == "series":
        return None, None, "labelled time series have no body to place markers on"
    motions = data.get("motions")
    if motions and all(m.skeleton is None for m in motions):  # joint positions, no skeleton
        if data.layout is None:
            return None, None, "position clips whose joints match no named layout"
        transform = VirtualMarkerTransform(layout=data.layout, frame_rate=data.frame_rate)
        clips = transform.fit_transform(data.clips)
        return clips, list(transform.marker_names_), f"the {data.layout.name} layout"
    motions = motions or as_motions(data.clips, data.skeletons, data.frame_rate)
    presets = Counter(detect_marker_preset(m.skeleton) for m in motions)
    marker_clips, names = to_markers(motions)
    clips = [to_rate(c, m.frame_rate, data.frame_rate) for c, m in zip(marker_clips, motions)]
    how = "the preset of each clip's skeleton: " + ", ".join(
        f"{p} {n} clips" for p, n in presets.items()
    )
    return clips, [n[:-3] for n in names[::6]], how


def run(context):
    data = context.data
    clips, markers, how = _markers(context)
    context.marker_clips = clips
    if clips is None:
        return [f"not run: {how} (skmotion.kinematics.LAYOUTS, or a Layout of your own)"]
    n_markers = len(markers)
    frames = np.concatenate(clips).reshape(-1, n_markers, 6)
    height = {
        name: np.median(frames[:, markers.index(name), 2])
        for name in ("head_top", "head", "pelvis", "left_knee")
        if name in markers
    }
    speed = np.median(np.linalg.norm(frames[:, markers.index("pelvis"), 3:5], axis=1))
    lines = [
        f"{n_markers} markers ({', '.join(markers[:6])}, ...) placed by {how}",
        f"output: {6 * n_markers} channels per frame (px py pz vx vy vz per marker; x forward, "
        "y left, z up; lengths in body heights)",
        "median height over all frames: "
        + ", ".join(f"{k} {v:.2f}" for k, v in height.items())
        + f"; median horizontal pelvis speed {speed:.2f} heights/s",
    ]
    evaluation = evaluation_of(context)
    if evaluation.kind is None:
        return lines + [f"ridge classifier on markers: not run ({evaluation.reason})"]
    model = make_pipeline(
        ResampleClips(n_frames=16), FlattenClips(), StandardScaler(), RidgeClassifier()
    )
    on_markers = evaluation.scores(
        model, clips, data.target, verbose=getattr(context, "verbose", 0), desc="markers CV"
    )
    context.marker_accuracy = on_markers.mean()
    baseline = getattr(context, "baseline_accuracy", None)
    lines.append(
        f"ridge classifier on 16 resampled frames, {evaluation.name}: "
        f"accuracy {on_markers.mean():.3f} +/- {on_markers.std():.3f} on markers"
        + (f" (raw-clip 1-NN baseline {baseline:.3f})" if baseline is not None else "")
    )
    return lines
