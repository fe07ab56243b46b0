import pickle

import numpy as np
import pytest

from skmotion.kinematics import Skeleton


def test_structure(skeleton):
    assert skeleton.n_joints == 5
    assert skeleton.n_channels == 14
    assert skeleton.channel_names[:4] == [
        "root_Xposition",
        "root_Yposition",
        "root_Zposition",
        "root_Zrotation",
    ]
    assert skeleton.rotation_orders == ("ZXY", "XYZ", "YZX", "ZYX", "XYZ")
    assert skeleton.children("spine") == (2, 3)
    assert skeleton.end_sites == (4,)  # only "hand" has neither channels nor children
    assert skeleton.depths.tolist() == [0, 1, 2, 2, 3]
    assert skeleton.channel_index("arm", "Xrotation") == 6 + 3 + 2 + 2
    np.testing.assert_allclose(skeleton.rest_positions()[4], [0.5, 1.8, 0])
    assert skeleton.height() == pytest.approx(0.9)


def test_immutable_and_hashable(skeleton):
    with pytest.raises(AttributeError):
        skeleton.joints = ("a",)
    with pytest.raises(ValueError):
        skeleton.offsets[0, 0] = 1.0
    assert skeleton == pickle.loads(pickle.dumps(skeleton))
    assert hash(skeleton) == hash(pickle.loads(pickle.dumps(skeleton)))
    restored = pickle.loads(pickle.dumps(skeleton))
    assert not restored.offsets.flags.writeable


def test_scaled(skeleton):
    big = skeleton.scaled(1.3)
    np.testing.assert_allclose(big.offsets, 1.3 * np.asarray(skeleton.offsets))
    assert big.height() == pytest.approx(1.3 * skeleton.height())
    assert big != skeleton


def test_repr_is_short(skeleton):
    assert (
        repr(skeleton) == "Skeleton(n_joints=5, n_channels=14, root='root', up_axis='y', units='m')"
    )


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(joints=[]), "at least one joint"),
        (dict(joints=["a", "a"], parents=[-1, 0]), "'a' appears twice"),
        (dict(parents=[-1, -1]), "only root"),
        (dict(joints=["a", "b", "c"], parents=[-1, 2, 0]), "listed before their children"),
        (dict(offsets=[[0, 0]] * 2), r"shape \(2, 3\)"),
        (dict(offsets=[[0, 0, np.nan]] * 2), "finite"),
        (dict(channels=[["Xrotaton"], []]), "unknown channel"),
        (dict(channels=[["Xrotation", "Xrotation"], []]), "lists a channel twice"),
        (dict(rotation_orders=["XYZ", "XXY"]), "permutation of 'XYZ'"),
        (dict(axes=np.stack([np.eye(3), 2 * np.eye(3)])), "not a rotation matrix"),
        (dict(up_axis="w"), "up_axis"),
        (dict(meters_per_unit=0.0), "positive"),
    ],
)
def test_invalid_skeletons(kwargs, match):
    base = dict(
        joints=["a", "b"],
        parents=[-1, 0],
        offsets=[[0, 0, 0], [1, 0, 0]],
        channels=[["Xrotation"], []],
    )
    base.update(kwargs)
    if "joints" in kwargs and "parents" not in kwargs:
        base["parents"] = [-1] + [0] * (len(kwargs["joints"]) - 1)
        base["offsets"] = np.zeros((len(kwargs["joints"]), 3))
        base["channels"] = [[] for _ in kwargs["joints"]]
    if "parents" in kwargs and len(kwargs["parents"]) == 3:
        base["offsets"] = np.zeros((3, 3))
        base["channels"] = [[], [], []]
    with pytest.raises(ValueError, match=match):
        Skeleton(**base)


def test_unknown_joint_and_channel(skeleton):
    with pytest.raises(KeyError, match="Unknown joint 'elbow'"):
        skeleton.joint_index("elbow")
    with pytest.raises(KeyError, match="no channel 'Xposition'"):
        skeleton.channel_index("arm", "Xposition")
