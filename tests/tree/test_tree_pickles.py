"""MotionTree and TransitionGraphs pickles carry skmotion's version, refused when incompatible."""

import pickle

import numpy as np
import pytest

import skmotion
from skmotion.base import IncompatibleVersionError
from skmotion.tree import MotionTree, TransitionGraphs


@pytest.fixture(scope="module")
def structures():
    rng = np.random.default_rng(2)
    frames = np.vstack([rng.normal(c, 1.0, size=(40, 3)) for c in (0.0, 5.0)])
    tree = MotionTree.build(frames, max_depth=3, min_samples_leaf=8)
    graphs = TransitionGraphs.count(
        list(tree.iter_apply(frames)), tree.n_nodes, offsets=[0, 40, 80], graph_of_clip=[0, 1]
    )
    return frames, tree, graphs


def _same(kind, a, b, frames):
    if kind == "tree":
        np.testing.assert_array_equal(a.apply(frames, 2), b.apply(frames, 2))
        np.testing.assert_array_equal(a.log_likelihood(frames, -1), b.log_likelihood(frames, -1))
    else:
        for layer in range(a.n_layers):
            np.testing.assert_array_equal(a.matrix(layer, 1), b.matrix(layer, 1))


@pytest.mark.parametrize("kind", ["tree", "graphs"])
def test_a_round_trip_keeps_the_structure(structures, kind):
    frames, tree, graphs = structures
    obj = tree if kind == "tree" else graphs
    loaded = pickle.loads(pickle.dumps(obj))
    _same(kind, obj, loaded, frames)
    assert "_skmotion_version" not in vars(loaded)


@pytest.mark.parametrize("kind", ["tree", "graphs"])
def test_a_tampered_version_is_refused(structures, kind):
    obj = structures[1] if kind == "tree" else structures[2]
    version = skmotion.__version__.encode()
    data = pickle.dumps(obj)
    assert data.count(version) == 1
    major, minor = map(int, skmotion.__version__.split(".")[:2])
    newer = f"{major}.{minor + 1}.0".encode().ljust(len(version), b"0")[: len(version)]
    name = type(obj).__name__
    with pytest.raises(
        IncompatibleVersionError, match=rf"{name} was saved by skmotion {major}\.{minor + 1}\.0"
    ):
        pickle.loads(data.replace(version, newer))


def test_a_patch_release_loads_and_a_newer_minor_refuses(structures, monkeypatch):
    frames, tree, graphs = structures
    data = pickle.dumps((tree, graphs))
    major, minor, *_ = skmotion.__version__.split(".")
    monkeypatch.setattr(skmotion, "__version__", f"{major}.{minor}.99")
    loaded_tree, loaded_graphs = pickle.loads(data)
    _same("tree", tree, loaded_tree, frames)
    _same("graphs", graphs, loaded_graphs, frames)
    monkeypatch.setattr(skmotion, "__version__", f"{major}.{int(minor) + 1}.0")
    with pytest.raises(IncompatibleVersionError, match="MotionTree was saved"):
        pickle.loads(data)


def test_a_pickle_without_a_version_is_refused(structures):
    tree = structures[1]
    state = tree.__getstate__()
    del state["_skmotion_version"]
    with pytest.raises(IncompatibleVersionError, match="unknown skmotion version"):
        MotionTree.__new__(MotionTree).__setstate__(state)
