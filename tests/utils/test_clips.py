import numpy as np
import pandas as pd
import pytest
import scipy.sparse as sp
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from skmotion.utils import check_clips, split_frames, stack_clips, to_container


class _Est:
    """A bare object to receive n_features_in_."""


def _frame(clips, labels=None):
    labels = range(len(clips)) if labels is None else labels
    return pd.concat(
        {
            lab: pd.DataFrame(c, columns=[f"m{j}" for j in range(c.shape[1])])
            for lab, c in zip(labels, clips)
        },
        names=["clip", "frame"],
    )


# -- containers --------------------------------------------------------------------


def test_list_tuple_ndarray_dataframe_agree(clips):
    equal = [c[:3] for c in clips]
    forms = [equal, tuple(equal), np.stack(equal), _frame(equal)]
    kinds = ["list", "tuple", "ndarray", "dataframe"]
    for form, kind in zip(forms, kinds):
        out = check_clips(form)
        assert out.container.kind == kind
        assert len(out) == len(equal)
        for a, b in zip(out, equal):
            np.testing.assert_array_equal(a, b)
            assert a.flags.c_contiguous and a.dtype == np.float64


@pytest.mark.parametrize("kind", ["list", "tuple", "ndarray", "dataframe"])
def test_round_trip_keeps_container(kind, clips):
    equal = [c[:3] for c in clips]
    form = {
        "list": equal,
        "tuple": tuple(equal),
        "ndarray": np.stack(equal),
        "dataframe": _frame(equal, "abcde"),
    }[kind]
    checked = check_clips(form)
    back = to_container(list(checked), checked.container)
    if kind == "dataframe":
        pd.testing.assert_frame_equal(back, form)
    elif kind == "ndarray":
        np.testing.assert_array_equal(back, form)
    else:
        assert type(back) is type(form)
        for a, b in zip(back, form):
            np.testing.assert_array_equal(a, b)


def test_dataframe_round_trip_ragged_keeps_labels_and_names(clips):
    df = _frame(clips, labels=["walk_1", "walk_2", "run_1", "run_2", "jump"])
    checked = check_clips(df)
    assert [len(c) for c in checked] == [len(c) for c in clips]
    back = to_container(list(checked), checked.container)
    pd.testing.assert_frame_equal(back, df)


def test_dataframe_output_with_new_channels_gets_given_columns(clips):
    checked = check_clips(_frame(clips))
    out = to_container([c[:, :2] * 2 for c in checked], checked.container, columns=["a", "b"])
    assert list(out.columns) == ["a", "b"]
    np.testing.assert_array_equal(out.loc[3].to_numpy(), clips[3][:, :2] * 2)


def test_ndarray_result_of_unequal_lengths_is_a_list():
    checked = check_clips(np.zeros((2, 5, 3)))
    out = to_container([np.zeros((4, 3)), np.zeros((5, 3))], checked.container)
    assert isinstance(out, list)


def test_to_container_pandas_forces_dataframe(clips):
    checked = check_clips(clips)
    out = to_container(list(checked), "pandas")
    assert isinstance(out, pd.DataFrame)
    assert out.index.names == ["clip", "frame"]
    assert list(out.columns) == ["channel_0", "channel_1", "channel_2", "channel_3"]
    np.testing.assert_array_equal(out.loc[2].to_numpy(), clips[2])


def test_float32_is_kept_and_other_types_converted():
    out = check_clips([np.ones((3, 2), dtype=np.float32), np.ones((3, 2), dtype=np.float32)])
    assert out[0].dtype == np.float32
    out = check_clips([np.ones((3, 2), dtype=int), [[1, 2], [3, 4]]])
    assert out[0].dtype == np.float64 and out[1].dtype == np.float64


def test_views_unless_copy(clips):
    out = check_clips(clips)
    assert np.shares_memory(out[0], clips[0])
    out = check_clips(clips, copy=True)
    assert not np.shares_memory(out[0], clips[0])


def test_n_features_in_is_set_then_checked(clips):
    est = _Est()
    check_clips(clips, estimator=est, reset=True)
    assert est.n_features_in_ == 4
    check_clips(clips, estimator=est)
    with pytest.raises(ValueError, match="X has 3 channels, but _Est was fitted with 4 channels"):
        check_clips([c[:, :3] for c in clips], estimator=est)


def test_feature_names_are_recorded_and_checked(clips):
    est = _Est()
    check_clips(_frame(clips), estimator=est, reset=True)
    assert list(est.feature_names_in_) == ["m0", "m1", "m2", "m3"]
    renamed = _frame(clips).rename(columns={"m0": "other"})
    with pytest.raises(ValueError, match="channel names differ"):
        check_clips(renamed, estimator=est)
    check_clips(clips, estimator=est, reset=True)
    assert not hasattr(est, "feature_names_in_")


# -- errors ------------------------------------------------------------------------


@pytest.mark.parametrize("empty", [[], (), np.zeros((0, 5, 3))])
def test_empty_collection(empty):
    with pytest.raises(ValueError, match="empty collection"):
        check_clips(empty)


def test_empty_dataframe():
    df = pd.DataFrame({"a": []}, index=pd.MultiIndex.from_arrays([[], []], names=["clip", "frame"]))
    with pytest.raises(ValueError, match="empty collection"):
        check_clips(df)


def test_too_few_clips(clips):
    with pytest.raises(ValueError, match="holds 5 clip.*needs at least 6"):
        check_clips(clips, min_clips=6)


def test_clip_not_2d(clips):
    clips[2] = clips[2][:, 0]
    with pytest.raises(ValueError, match=r"clip 2 is 1-D with shape \(40,\).*reshape\(-1, 1\)"):
        check_clips(clips)
    clips[2] = np.zeros((2, 3, 4))
    with pytest.raises(ValueError, match="clip 2 is 3-D"):
        check_clips(clips)


def test_single_2d_array_is_explained():
    with pytest.raises(ValueError, match=r"2-D array of shape \(10, 3\).*pass \[clip\]"):
        check_clips(np.zeros((10, 3)))


def test_zero_frames_and_zero_channels(clips):
    clips[1] = np.zeros((0, 4))
    with pytest.raises(ValueError, match="clip 1 has no frames"):
        check_clips(clips)
    with pytest.raises(ValueError, match="clip 0 has no channels"):
        check_clips([np.zeros((3, 0))])


def test_fewer_frames_than_minimum(clips):
    with pytest.raises(ValueError, match="clip 0 has 3 frame.*_Est needs at least 5"):
        check_clips(clips, estimator=_Est(), reset=True, min_frames=5)


def test_channel_counts_differ(clips):
    clips[3] = clips[3][:, :2]
    with pytest.raises(ValueError, match="clip 3 has 2 channels, but clip 0 has 4"):
        check_clips(clips)


@pytest.mark.parametrize("value, word", [(np.nan, "NaN"), (np.inf, "inf"), (-np.inf, "-inf")])
def test_non_finite_values_are_located(clips, value, word):
    clips[4][7, 2] = value
    with pytest.raises(ValueError, match=f"clip 4 contains {word} at frame 7, channel 2"):
        check_clips(clips)


def test_nan_allowed_but_inf_never(clips):
    clips[1][2, 0] = np.nan
    out = check_clips(clips, allow_nan=True)
    assert np.isnan(out[1][2, 0])
    clips[1][3, 1] = np.inf
    with pytest.raises(ValueError, match="clip 1 contains inf at frame 3, channel 1"):
        check_clips(clips, allow_nan=True)


def test_non_numeric_data(clips):
    clips[2] = np.array([["a", "b"], ["c", "d"]])
    with pytest.raises(ValueError, match="clip 2 has non-numeric data"):
        check_clips(clips)
    with pytest.raises(ValueError, match="clip 0 has complex values"):
        check_clips([np.ones((2, 2), dtype=complex)])


def test_numeric_strings_and_objects_are_converted():
    out = check_clips(
        [np.array([["1.5", "2"], ["3", "4"]]), np.array([[1, 2], [3, 4]], dtype=object)]
    )
    np.testing.assert_array_equal(out[0], [[1.5, 2], [3, 4]])


@pytest.mark.parametrize(
    "bad, error",
    [
        ({"a": np.zeros((2, 2))}, TypeError),
        (sp.csr_matrix(np.eye(3)), TypeError),
        ([sp.csr_matrix(np.eye(3))], TypeError),
        ("clips", TypeError),
        (pd.DataFrame(np.zeros((3, 2))), ValueError),
    ],
)
def test_unsupported_collections(bad, error):
    with pytest.raises(error):
        check_clips(bad)


def test_dataframe_clip_rows_must_be_contiguous(clips):
    df = _frame(clips[:3])
    shuffled = pd.concat([df.loc[[0]], df.loc[[1]], df.loc[[0]].iloc[:0], df.loc[[2]]])
    check_clips(shuffled)
    interleaved = pd.concat([df.iloc[:2], df.loc[[1]], df.iloc[2:3]])
    with pytest.raises(ValueError, match="rows of clip 0 are not contiguous"):
        check_clips(interleaved)


def test_dataframe_frames_must_increase(clips):
    df = _frame(clips[:2])
    swapped = df.iloc[[0, 2, 1] + list(range(3, len(df)))]
    with pytest.raises(ValueError, match="frames of clip 0 are not strictly increasing"):
        check_clips(swapped)


# -- stacking -------------------------------------------------------------------------


def test_stack_and_split(clips):
    frames, offsets = stack_clips(clips)
    assert frames.shape == (sum(len(c) for c in clips), 4)
    assert offsets.tolist() == [0, 3, 20, 60, 68, 93]
    for a, b in zip(split_frames(frames, offsets), clips):
        np.testing.assert_array_equal(a, b)
    labels = split_frames(np.arange(len(frames)), offsets)
    assert [len(lab) for lab in labels] == [3, 17, 40, 8, 25]


@pytest.mark.parametrize("offsets", [[0, 2], [1, 5], [0, 3, 2, 5], [0.0, 5.0], [[0, 5]]])
def test_split_rejects_bad_offsets(offsets):
    with pytest.raises(ValueError, match="offsets must increase"):
        split_frames(np.zeros((5, 2)), offsets)


clip_lists = st.lists(
    st.integers(1, 12).flatmap(
        lambda n: hnp.arrays(np.float64, (n, 3), elements=st.floats(-1e6, 1e6, allow_nan=False))
    ),
    min_size=1,
    max_size=8,
)


@given(clip_lists)
def test_stack_split_round_trip_property(clip_list):
    frames, offsets = stack_clips(clip_list)
    back = split_frames(frames, offsets)
    assert len(back) == len(clip_list)
    for a, b in zip(back, clip_list):
        np.testing.assert_array_equal(a, b)


@given(clip_lists)
def test_dataframe_round_trip_property(clip_list):
    df = to_container(clip_list, "pandas")
    checked = check_clips(df)
    for a, b in zip(checked, clip_list):
        np.testing.assert_array_equal(a, b)


def test_empty_clips_only_when_min_frames_is_zero():
    # Sequences of segment codes: a clip without segments is a (0, k) array.
    codes = [np.zeros((0, 3)), np.ones((2, 3))]
    clips = check_clips(codes, min_frames=0)
    assert clips.lengths.tolist() == [0, 2] and clips.n_channels == 3
    with pytest.raises(ValueError, match="clip 0 has no frames"):
        check_clips(codes)


def test_min_frames_defaults_to_the_estimators_tags():
    from skmotion.base import ClipEstimatorMixin, MotionTags

    class NeedsFive(ClipEstimatorMixin):
        _motion_tags = MotionTags(min_frames=5)

    clips = [np.zeros((6, 2)), np.zeros((4, 2))]
    with pytest.raises(ValueError, match="clip 1 has 4 frame"):
        check_clips(clips, estimator=NeedsFive())
    # an explicit minimum wins over the tags; without an estimator the minimum is 1
    assert len(check_clips(clips, estimator=NeedsFive(), min_frames=4)) == 2
    with pytest.raises(ValueError, match="clip 0 has no frames"):
        check_clips([np.zeros((0, 2))])
