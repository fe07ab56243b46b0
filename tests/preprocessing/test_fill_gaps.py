"""FillGaps: exact on what each method reproduces, errors against true values cut out of clips."""

import numpy as np
import pandas as pd
import pytest
from scipy.spatial.transform import Rotation

from skmotion.datasets import layout_positions, make_position_motions
from skmotion.io import read_amc, read_asf
from skmotion.preprocessing import FillGaps, VirtualMarkerTransform
from skmotion.preprocessing._gaps import gap_runs
from skmotion.utils._clips import check_clips
from tests.clip_conformance import ClipCase, parametrize_with_clip_checks


def _cut(clip, dim, rng, lengths, n_cuts=40):
    """Remove ``n_cuts`` gaps of the given lengths at random interior places; the mask."""
    holed = clip.copy()
    n_frames, n_points = len(clip), clip.shape[1] // dim
    mask = np.zeros((n_frames, n_points), dtype=bool)
    for _ in range(n_cuts):
        length = int(rng.choice(lengths))
        start = int(rng.integers(2, n_frames - length - 2))
        point = int(rng.integers(n_points))
        if mask[start - 1 : start + length + 1, point].any():
            continue  # keep gaps apart so each has the length asked for
        mask[start : start + length, point] = True
    holed.reshape(n_frames, n_points, dim)[mask] = np.nan
    return holed, mask


def _errors(filled, truth, mask, dim):
    diff = (filled - truth).reshape(len(truth), -1, dim)[mask]
    return np.linalg.norm(diff, axis=1)


def test_linear_fills_linear_motion_and_cubic_fills_cubic_motion_exactly():
    t = np.arange(60.0)[:, None]
    line = np.hstack([0.5 + 0.1 * t, 2.0 - 0.03 * t, 0.2 * t])
    cubic = np.hstack([1e-4 * t**3 - 0.01 * t**2 + t, 0.002 * t**3, np.ones_like(t)])
    for clip, method in ((line, "linear"), (cubic, "cubic")):
        holed = clip.copy()
        holed[20:28] = np.nan
        filled = FillGaps(method=method).fit_transform([holed])[0]
        np.testing.assert_allclose(filled, clip, atol=1e-9)


def test_rigid_body_fill_is_exact_for_a_rigid_group_even_at_the_clip_start():
    rng = np.random.default_rng(1)
    body = rng.normal(size=(5, 3))  # 5 points of one rigid segment
    turns = Rotation.from_rotvec(np.cumsum(rng.normal(scale=0.1, size=(80, 3)), axis=0))
    path = np.cumsum(rng.normal(scale=0.05, size=(80, 3)), axis=0)
    clip = (np.einsum("fij,pj->fpi", turns.as_matrix(), body) + path[:, None]).reshape(80, -1)
    holed = clip.copy()
    holed[30:45, 0:3] = np.nan  # point 0, 15 frames, interior
    holed[0:6, 6:9] = np.nan  # point 2, at the start: interpolation cannot reach it
    fill = FillGaps(groups=[[0, 1, 2, 3, 4]], max_gap=20).fit([holed])
    np.testing.assert_allclose(fill.transform([holed])[0], clip, atol=1e-9)
    report = fill.fill_report([holed]).iloc[0]
    assert report[["n_gaps", "n_rigid", "n_interpolated", "n_unfilled"]].tolist() == [2, 21, 0, 0]
    # Without the group the start stays missing; the interior gap is interpolated (not exact).
    plain = FillGaps(max_gap=20).fit([holed])
    out = plain.transform([holed])[0]
    assert np.isnan(out[0:6, 6:9]).all() and not np.isnan(out[30:45, 0:3]).any()
    assert plain.fill_report([holed])["n_unfilled"].item() == 6


def test_long_gaps_stay_missing_or_raise_naming_clip_point_and_frames():
    data = make_position_motions("kinect_v1", n_clips_per_class=1, classes=["walk"], random_state=0)
    clip = data.clips[0].copy()
    clip[20:35, 3:6] = np.nan  # Spine, 15 frames
    kept = FillGaps(max_gap=10, layout="kinect_v1").fit_transform([clip])[0]
    assert np.isnan(kept[20:35, 3:6]).all() and np.isfinite(np.delete(kept, [3, 4, 5], 1)).all()
    with pytest.raises(ValueError, match="clip 0, point 'Spine': frames 20-34 .* longer than max"):
        FillGaps(max_gap=10, layout="kinect_v1", unfilled="raise").fit_transform([clip])
    # 0.5 s at 30 Hz is 15 frames: filled.
    seconds = FillGaps(max_gap=0.5, max_gap_unit="seconds", frame_rate=30.0).fit([clip])
    assert seconds.max_gap_frames_ == 15 and np.isfinite(seconds.transform([clip])[0]).all()


def test_zero_frames_zero_points_and_low_confidence_are_missing():
    data = make_position_motions("coco17", n_clips_per_class=1, classes=["wave"], random_state=0)
    clip = data.clips[0]
    n = len(clip)
    lost = clip.copy()
    lost[10:13] = 0.0  # the tracker lost the body for 3 frames
    filled = FillGaps(zeros="frame", layout="coco17").fit_transform([lost])[0]
    assert np.abs(filled[10:13] - clip[10:13]).max() < 15.0  # pixels; 1 m is ~170 px here
    assert np.array_equal(FillGaps(layout="coco17").fit_transform([lost])[0], lost)
    undetected = clip.copy()
    undetected[40:42, 18:20] = 0.0  # OpenPose writes 0, 0 for an undetected keypoint
    out = FillGaps(zeros="point", layout="coco17").fit_transform([undetected])[0]
    assert np.abs(out[40:42, 18:20] - clip[40:42, 18:20]).max() < 5.0
    # x, y, confidence per keypoint: low confidence values are replaced, the channel dropped.
    confidence = np.ones((n, 17))
    confidence[50:53, 9] = 0.1
    noisy = clip.reshape(n, 17, 2).copy()
    noisy[50:53, 9] += 80.0  # a wrong detection, flagged by its confidence
    with_c = np.concatenate([noisy, confidence[..., None]], axis=2).reshape(n, -1)
    fill = FillGaps(confidence_threshold=0.3, layout="coco17").fit([with_c])
    out = fill.transform([with_c])[0]
    assert out.shape == clip.shape and np.abs(out - clip).max() < 5.0
    assert fill.get_feature_names_out()[:3].tolist() == ["nose_x", "nose_y", "left_eye_x"]


def test_fill_report_counts_by_hand_and_transform_keeps_no_state():
    clip = np.tile(np.arange(20.0)[:, None], (1, 6))  # 2 points, linear in time
    clip[3:5, 0:3] = np.nan  # point 0: a 2-frame gap
    clip[0:2, 3:6] = np.nan  # point 1: at the start, unfillable without a group
    clip[10:19, 3:6] = np.nan  # point 1: 9 frames, longer than max_gap=5
    fill = FillGaps(max_gap=5, method="linear").fit([clip])
    state = dict(vars(fill))
    report = fill.fill_report([clip, clip[5:]])
    expected = [[13, 3, 9, 0, 2, 11], [9, 1, 9, 0, 0, 9]]
    assert report.values.tolist() == expected
    assert list(report.columns) == [
        "n_missing",
        "n_gaps",
        "longest_gap",
        "n_rigid",
        "n_interpolated",
        "n_unfilled",
    ]
    fill.transform([clip])
    assert vars(fill).keys() == state.keys()


def test_gap_runs_against_a_loop():
    rng = np.random.default_rng(3)
    missing = rng.random((200, 7)) < 0.3
    expected = []
    for j in range(7):
        f = 0
        while f < 200:
            if missing[f, j]:
                g = f
                while g < 200 and missing[g, j]:
                    g += 1
                expected.append((j, f, g))
                f = g
            else:
                f += 1
    assert list(zip(*(a.tolist() for a in gap_runs(missing)))) == expected


@pytest.mark.parametrize("layout", ["kinect_v2", "mediapipe_pose33"])
def test_error_by_gap_length_on_synthetic_clips_at_120_hz(layout):
    """Gaps cut into complete clips: median error below 1 cm up to 10 frames, then growing."""
    data = make_position_motions(
        layout, n_clips_per_class=1, frame_rate=120.0, noise=0.0, duration=(2.0, 2.5),
        random_state=0,
    )  # fmt: skip
    rng = np.random.default_rng(0)
    medians = {}
    for lengths in ((1, 2, 3), (4, 6, 8, 10), (20, 30)):
        errors = []
        for clip in data.clips:
            holed, mask = _cut(clip, 3, rng, lengths)
            filled = FillGaps(max_gap=30, layout=layout).fit_transform([holed])[0]
            errors.append(_errors(filled, clip, mask, 3))
        medians[lengths] = np.median(np.concatenate(errors))
    assert medians[(1, 2, 3)] < 0.001 and medians[(4, 6, 8, 10)] < 0.01  # metres
    assert medians[(20, 30)] > medians[(4, 6, 8, 10)]


def test_error_by_gap_length_on_real_cmu_clips(shared_data):
    asf = shared_data / "cmu-asfamc" / "02"
    skeleton = read_asf(asf / "02.asf")
    motion = read_amc(asf / "02_01.amc", skeleton)
    clip = layout_positions(skeleton, motion.channels, "kinect_v2")
    cm_per_unit = 2.54 / 0.45  # CMU ASF lengths are in 1/0.45 inch
    rng = np.random.default_rng(0)
    for lengths, limit in (((1, 2, 3, 4, 5), 0.2), ((6, 8, 10), 1.0)):
        holed, mask = _cut(clip, 3, rng, lengths, n_cuts=200)
        filled = FillGaps(max_gap=10, layout="kinect_v2").fit_transform([holed])[0]
        assert np.median(_errors(filled, clip, mask, 3)) * cm_per_unit < limit


def test_filled_clips_feed_the_virtual_markers():
    data = make_position_motions("kinect_v2", n_clips_per_class=1, classes=["walk"], random_state=0)
    holed = data.clips[0].copy()
    holed[5:9, :] = np.nan  # every joint lost for 4 frames
    with pytest.raises(ValueError, match="fill gaps first"):
        VirtualMarkerTransform(layout="kinect_v2", frame_rate=30).fit([holed])
    filled = FillGaps(layout="kinect_v2").fit_transform([holed])
    VirtualMarkerTransform(layout="kinect_v2", frame_rate=30).fit_transform(filled)


def test_parameter_errors_name_what():
    clip = np.zeros((10, 7))
    with pytest.raises(ValueError, match="not a multiple of 3 channels per point"):
        FillGaps().fit([clip])
    with pytest.raises(ValueError, match="needs frame_rate"):
        FillGaps(max_gap=0.2, max_gap_unit="seconds").fit([np.zeros((10, 6))])
    with pytest.raises(ValueError, match="point 2 is out of range for 2 points"):
        FillGaps(groups=[[0, 1, 2, 5]]).fit([np.zeros((10, 6))])
    with pytest.raises(ValueError, match="layout 'coco17' has 17 joints"):
        FillGaps(layout="coco17").fit([np.zeros((10, 6))])


def _holed_case():
    data = make_position_motions(
        "kinect_v1", n_clips_per_class=3, classes=["walk", "wave"], duration=(0.6, 0.9),
        random_state=0,
    )  # fmt: skip
    clips = [c.copy() for c in data.clips]
    for c in clips:
        c[5:8, 0:3] = np.nan
    return clips, data.target


@parametrize_with_clip_checks([ClipCase(FillGaps(layout="kinect_v1"), _holed_case)])
def test_conformance(check):
    check()


def test_pandas_output_keeps_layout_names():
    clips, _ = _holed_case()
    out = FillGaps(layout="kinect_v1").set_output(transform="pandas").fit_transform(clips)
    assert isinstance(out, pd.DataFrame) and list(out.columns[:2]) == ["HipCenter_x", "HipCenter_y"]
    assert len(check_clips(out)) == len(clips)
