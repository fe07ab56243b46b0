"""The out-of-core build (.npy files or a dask.array, subtrees on Dask workers) against the
in-memory build on the same frames: the same layers, the same node of every frame."""

import numpy as np
import pytest

from skmotion.tree import MotionTree, build_tree_out_of_core

dask = pytest.importorskip("dask")
da = pytest.importorskip("dask.array")


def _frames(n=6_000, d=5, seed=0):
    """A mixture of correlated clusters of unequal sizes (unbalanced cuts for min_error)."""
    rng = np.random.default_rng(seed)
    centers = rng.normal(size=(6, d)) * 3.0
    which = rng.choice(6, size=n, p=[0.4, 0.25, 0.15, 0.1, 0.07, 0.03])
    return centers[which] + rng.normal(size=(n, d)) @ (rng.normal(size=(d, d)) / 2.0)


def _save(frames, folder, n_files):
    paths = []
    for i, part in enumerate(np.array_split(frames, n_files)):
        paths.append(folder / f"part{i}.npy")
        np.save(paths[-1], part)
    return paths


def _assert_same_tree(tree, memory, frames):
    assert tree.n_nodes.tolist() == memory.n_nodes.tolist()
    for name in ("parent", "left", "right", "depth", "count"):
        assert np.array_equal(getattr(tree, name), getattr(memory, name)), name
    # the same splits up to the rounding of streamed sums and of another frame order
    np.testing.assert_allclose(tree.threshold, memory.threshold, rtol=0, atol=1e-9)
    np.testing.assert_allclose(tree.axis, memory.axis, rtol=0, atol=1e-9)
    np.testing.assert_allclose(tree.mean, memory.mean, rtol=0, atol=1e-9)
    np.testing.assert_allclose(tree.covariance, memory.covariance, rtol=1e-9)
    assert tree.reg == pytest.approx(memory.reg, rel=1e-12)
    for layer in range(tree.n_layers):
        assert np.array_equal(tree.apply(frames, layer), memory.apply(frames, layer))


@pytest.mark.parametrize("split", ["median", "two_means", "min_error"])
@pytest.mark.parametrize("covariance_type", ["diag", "spherical"])
def test_files_give_the_in_memory_tree(tmp_path, split, covariance_type):
    frames = _frames()
    paths = _save(frames, tmp_path, 3)
    params = dict(max_depth=7, split=split, min_samples_leaf=16, covariance_type=covariance_type)
    # a small task budget: several streamed layers before the subtrees (read in small blocks)
    spill = tmp_path / "spill"
    spill.mkdir()
    with dask.config.set(scheduler="synchronous"):
        tree = build_tree_out_of_core(
            paths, max_frames_per_task=900, block_rows=700, spill_dir=spill, **params
        )
    assert list(spill.iterdir()) == []  # the spilled frames are removed
    report = tree.build_report_
    assert report["n_frames"] == len(frames) and report["streamed_nodes"] >= 3
    assert max(s["frames_held"] for s in report["subtrees"]) <= 900
    assert sum(s["frames_held"] for s in report["subtrees"]) + sum(
        tree.count[(tree.left < 0) & (tree.count > 900)]
    ) == len(frames)
    _assert_same_tree(tree, MotionTree.build(frames, **params), frames)


def test_a_dask_array_on_a_local_cluster_gives_the_files_tree(tmp_path):
    distributed = pytest.importorskip("distributed")
    frames = _frames(4_000, d=4, seed=1)
    paths = _save(frames, tmp_path, 2)
    params = dict(max_depth=6, split="two_means", min_samples_leaf=8, max_frames_per_task=1_000)
    with dask.config.set(scheduler="synchronous"):
        from_files = build_tree_out_of_core(paths, **params)
    with (
        distributed.LocalCluster(
            n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None
        ) as cluster,
        distributed.Client(cluster),
    ):
        from_array = build_tree_out_of_core(da.from_array(frames, chunks=(1_500, 2)), **params)
    _assert_same_tree(
        from_array,
        MotionTree.build(frames, max_depth=6, split="two_means", min_samples_leaf=8),
        frames,
    )
    assert np.array_equal(from_array.apply(frames), from_files.apply(frames))


def test_unsplittable_and_tiny_collections(tmp_path):
    same = np.ones((50, 3))
    tree = build_tree_out_of_core(_save(same, tmp_path, 2), max_frames_per_task=10)
    assert tree.n_nodes.tolist() == [1] and np.array_equal(tree.mean[0], [1.0, 1.0, 1.0])
    (tmp_path / "b").mkdir()
    frames = _frames(40, d=3)
    tree = build_tree_out_of_core(_save(frames, tmp_path / "b", 1), min_samples_leaf=4)
    _assert_same_tree(tree, MotionTree.build(frames, min_samples_leaf=4), frames)


def test_bad_input_is_refused_naming_file_row_and_channel(tmp_path):
    frames = _frames(300, d=3)
    frames[123, 2] = np.nan
    paths = _save(frames, tmp_path, 2)
    with pytest.raises(ValueError, match=r"part0\.npy: frames must be finite; row 123, channel 2"):
        build_tree_out_of_core(paths)
    np.save(tmp_path / "wide.npy", np.zeros((10, 4)))
    with pytest.raises(ValueError, match=r"wide\.npy: 4 channels where the first file has 3"):
        build_tree_out_of_core([paths[1], tmp_path / "wide.npy"])
    np.save(tmp_path / "ints.npy", np.zeros((10, 3), dtype=int))
    with pytest.raises(ValueError, match=r"ints\.npy: frames must be a C-ordered float array"):
        build_tree_out_of_core([tmp_path / "ints.npy"])
    with pytest.raises(ValueError, match="does not build covariance_type='full'"):
        build_tree_out_of_core([paths[1]], covariance_type="full")
    with pytest.raises(TypeError, match="non-empty list of .npy files or a 2-D dask.array"):
        build_tree_out_of_core(str(paths[1]))
    with pytest.raises(ValueError, match="min_samples_leaf"):
        build_tree_out_of_core([paths[1]], min_samples_leaf=0)
