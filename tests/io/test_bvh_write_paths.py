"""write_bvh and the paths users give: symlinks, read-only files, missing folders."""

import os

import numpy as np
import pytest

from skmotion.datasets import humanoid_skeleton
from skmotion.io import Motion, read_bvh, write_bvh


@pytest.fixture
def motion(rng):
    sk = humanoid_skeleton()
    return Motion(sk, rng.normal(scale=0.3, size=(5, sk.n_channels)), frame_rate=30.0)


@pytest.mark.skipif(not hasattr(os, "symlink"), reason="needs symlinks")
def test_a_symlink_is_written_through_to_its_target(tmp_path, motion):
    target = tmp_path / "data" / "walk.bvh"
    target.parent.mkdir()
    target.write_text("old")
    link = tmp_path / "walk.bvh"
    link.symlink_to(target)
    write_bvh(motion, link)
    assert link.is_symlink() and os.readlink(link) == str(target)
    np.testing.assert_allclose(read_bvh(target).channels, motion.channels, atol=1e-6)
    assert sorted(os.listdir(target.parent)) == ["walk.bvh"]  # no temporary file left
    dangling = tmp_path / "new.bvh"
    dangling.symlink_to(tmp_path / "data" / "created.bvh")
    write_bvh(motion, dangling)
    assert dangling.is_symlink() and (tmp_path / "data" / "created.bvh").is_file()


def test_a_read_only_file_is_refused_and_kept(tmp_path, motion):
    path = tmp_path / "keep.bvh"
    path.write_text("precious")
    path.chmod(0o444)
    try:
        with pytest.raises(PermissionError, match=r"read-only; not overwritten: '.*keep\.bvh'"):
            write_bvh(motion, path)
        assert path.read_text() == "precious"
        assert os.listdir(tmp_path) == ["keep.bvh"]
    finally:
        path.chmod(0o644)


def test_errors_name_the_users_path(tmp_path, motion):
    missing = tmp_path / "no_such_folder" / "walk.bvh"
    with pytest.raises(FileNotFoundError) as caught:
        write_bvh(motion, missing)
    assert caught.value.filename == str(missing) and ".tmp" not in str(caught.value)
