"""Loaders of motion-file folders and the CMU fetcher (cache path, offline error; no network)."""

import io
import shutil
import urllib.error

import numpy as np
import pytest

from skmotion.datasets import (
    _fetch,
    fetch_cmu_mocap,
    load_bvh_folder,
    load_cmu_asfamc,
    load_motion_folder,
    make_motions,
    read_cmu_index,
)
from skmotion.io import as_motions, read_amc, read_asf, write_bvh
from tests.io.test_asf_amc import ASF, _amc, _frames

INDEX = (
    "Subject,Trial #,Motion Description,framerate\n"
    '5,1,"walk, then turn",120\n'
    "5,2,jump - high,60\n"
    "6,1,walk,120\n"
)


def _cmu_tree(root, rng):
    """A CMU-style folder: subjects 05 (two trials) and 06 (one), sharing the toy skeleton."""
    for subject, trials in (("05", 2), ("06", 1)):
        folder = root / subject
        folder.mkdir(parents=True)
        (folder / f"{subject}.asf").write_text(ASF)
        for t in range(1, trials + 1):
            (folder / f"{subject}_{t:02d}.amc").write_text(_amc(_frames(rng, n=4 + t)))
    (root / "index.csv").write_text(INDEX)
    return root


def test_read_cmu_index(tmp_path):
    (tmp_path / "i.csv").write_text(INDEX)
    index = read_cmu_index(tmp_path / "i.csv")
    assert list(index.index) == ["05_01", "05_02", "06_01"]
    assert (
        index.loc["05_02", "frame_rate"] == 60
        and index.loc["05_01", "description"] == "walk, then turn"
    )
    (tmp_path / "bad.csv").write_text("a,b\n1,2\n")
    with pytest.raises(ValueError, match="not a CMU index"):
        read_cmu_index(tmp_path / "bad.csv")


def test_load_cmu_asfamc(tmp_path, rng):
    root = _cmu_tree(tmp_path / "cmu", rng)
    data = load_cmu_asfamc(root, root / "index.csv")
    assert data.trials.tolist() == ["05_01", "05_02", "06_01"]
    assert data.description.tolist() == ["walk, then turn", "jump - high", "walk"]
    assert data.subject_names.tolist() == ["05", "06"] and data.groups.tolist() == [0, 0, 1]
    assert data.target_names[data.target].tolist() == ["walk", "jump", "walk"]
    assert [m.frame_rate for m in data.motions] == [120.0, 60.0, 120.0] and data.frame_rate is None
    assert [len(c) for c in data.clips] == [5, 6, 5]
    reference = read_amc(root / "05" / "05_02.amc", read_asf(root / "05" / "05.asf"))
    np.testing.assert_array_equal(data.clips[1], reference.channels)
    only = load_cmu_asfamc(root, subjects=[6])
    assert (
        only.trials.tolist() == ["06_01"]
        and only.description.tolist() == [""]
        and only.frame_rate == 120.0
    )
    with pytest.raises(FileNotFoundError, match="No .amc trials"):
        load_cmu_asfamc(root, subjects=[7])


def test_load_bvh_folder_labels_by_subfolder(tmp_path):
    data = make_motions(
        n_clips_per_class=2, classes=["kick", "wave"], duration=(0.5, 0.6), random_state=0
    )
    for k, motion in enumerate(as_motions(data.clips, data.skeletons, data.frame_rate)):
        folder = tmp_path / str(data.target_names[data.target[k]])
        folder.mkdir(exist_ok=True)
        write_bvh(motion, folder / f"take{k}.bvh")
    loaded = load_bvh_folder(tmp_path)
    assert loaded.target_names.tolist() == ["kick", "wave"] and loaded.target.tolist() == [
        0,
        0,
        1,
        1,
    ]
    for clip, original in zip(loaded.clips, data.clips):
        np.testing.assert_allclose(clip, original, atol=1e-12)
    (tmp_path / "empty").mkdir()
    with pytest.raises(FileNotFoundError, match="No .bvh files"):
        load_bvh_folder(tmp_path / "empty")


def test_load_motion_folder_mixes_formats_and_finds_the_index(tmp_path, rng):
    root = _cmu_tree(tmp_path / "data" / "asfamc", rng)
    shutil.move(root / "index.csv", tmp_path / "data" / "cmu-index.csv")
    data = make_motions(n_clips_per_class=1, classes=["wave"], duration=(0.5, 0.5), random_state=0)
    (tmp_path / "data" / "waves").mkdir()
    write_bvh(
        as_motions(data.clips, data.skeletons, 30.0)[0], tmp_path / "data" / "waves" / "w.bvh"
    )
    loaded = load_motion_folder(tmp_path / "data")
    assert loaded.filenames[0].endswith("w.bvh")
    assert loaded.target_names[loaded.target].tolist() == ["waves", "walk", "jump", "walk"]
    assert loaded.subject_names[loaded.groups].tolist() == ["waves", "05", "05", "06"]
    assert len({m.skeleton.n_channels for m in loaded.motions}) == 2


# -- fetch_cmu_mocap: a fake server ----------------------------------------------------------------


class FakeServer:
    def __init__(self, files):
        self.files = files
        self.requests = []

    def __call__(self, url, timeout):
        self.requests.append(url)
        name = url.rsplit("/", 1)[1]
        if name not in self.files:
            raise urllib.error.HTTPError(url, 404, "Not Found", {}, None)
        body = io.BytesIO(self.files[name].encode())
        body.headers = {"Content-Length": str(len(body.getvalue()))}  # as a real server states
        return body


def test_fetch_downloads_then_reuses_the_cache(tmp_path, rng, monkeypatch):
    server = FakeServer(
        {"05.asf": ASF, "05_01.amc": _amc(_frames(rng, 3)), "05_02.amc": _amc(_frames(rng, 4))}
    )
    monkeypatch.setattr(_fetch, "_urlopen", server)
    data = fetch_cmu_mocap(5, data_home=tmp_path)
    assert data.trials.tolist() == ["05_01", "05_02"]
    assert server.requests == [
        "https://mocap.cs.cmu.edu/subjects/05/05.asf",
        "https://mocap.cs.cmu.edu/subjects/05/05_01.amc",
        "https://mocap.cs.cmu.edu/subjects/05/05_02.amc",
        "https://mocap.cs.cmu.edu/subjects/05/05_03.amc",
    ]
    assert sorted(p.name for p in (tmp_path / "cmu-asfamc" / "05").iterdir() if p.suffix) == [
        "05.asf",
        "05_01.amc",
        "05_02.amc",
    ]
    # Second time: everything from the cache, no request at all.
    server.requests.clear()
    again = fetch_cmu_mocap([5], data_home=tmp_path)
    assert server.requests == []
    np.testing.assert_array_equal(again.clips[1], data.clips[1])
    only = fetch_cmu_mocap(5, trials=[2], data_home=tmp_path)
    assert only.trials.tolist() == ["05_02"] and server.requests == []
    with pytest.raises(ValueError, match="CMU has no trial 05_07"):
        fetch_cmu_mocap(5, trials=[7], data_home=tmp_path)


def test_fetch_uses_local_files_without_network(tmp_path, rng, monkeypatch):
    root = _cmu_tree(tmp_path / "home" / "cmu-asfamc", rng)

    def offline(url, timeout):
        raise urllib.error.URLError("network is unreachable")

    monkeypatch.setattr(_fetch, "_urlopen", offline)
    data = fetch_cmu_mocap(
        [5], trials=[1, 2], data_home=tmp_path / "home", index=root / "index.csv"
    )
    assert data.trials.tolist() == ["05_01", "05_02"] and data.description[1] == "jump - high"
    with pytest.raises(
        ConnectionError,
        match=r"Could not download https://mocap.cs.cmu.edu/subjects/05/05_03.amc "
        r"\(network is unreachable\).*place the files in .*05",
    ):
        fetch_cmu_mocap([5], trials=[3], data_home=tmp_path / "home")
    with pytest.raises(ConnectionError, match="subjects/09/09.asf"):
        fetch_cmu_mocap(9, data_home=tmp_path / "home")
    assert not list((tmp_path / "home" / "cmu-asfamc" / "09").glob("*.part"))


def test_shared_data_loaders(shared_data):
    data = load_cmu_asfamc(shared_data / "cmu-asfamc", shared_data / "cmu-index.csv", subjects=[2])
    assert len(data.clips) == 10 and data.frame_rate == 120.0
    assert data.description[data.trials == "02_03"].tolist() == ["run/jog"]
    # 07_01.bvh has another skeleton (306 channels) than 07_02-12 (303): refused, then allowed.
    with pytest.raises(ValueError, match=r"306 channels .* 1 files: 07_01.bvh\n  303 channels"):
        load_bvh_folder(shared_data / "cmu-bvh")
    bvh = load_bvh_folder(shared_data / "cmu-bvh", channel_layouts="any")
    assert bvh.layout.tolist() == [0] + [1] * 11
    assert [len(c) for c in bvh.layout_channels] == [306, 303]
    assert len(bvh.clips) == 12 and bvh.frame_rate == 60.0 and bvh.target_names.tolist() == ["07"]
