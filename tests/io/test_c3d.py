"""read_c3d on files the ``c3d`` package writes (int16 and float32 storage, gaps, analog data),
and the point decoding of DEC and MIPS words built from their definitions."""

import warnings

import numpy as np
import pytest

from skmotion.io import MotionFileError, folder_suffixes
from skmotion.io._c3d import _decode_points

c3d = pytest.importorskip("c3d", reason="the optional c3d extra is not installed")

from skmotion.io import read_c3d  # noqa: E402


def _write(path, xyz, residuals, labels, *, scale, rate=100.0, cameras=None, analog=0):
    """A C3D file of points ``xyz`` (n_frames, n_points, 3) in mm; residual < 0 marks a gap."""
    writer = c3d.Writer(point_rate=rate, analog_rate=rate * 2 if analog else 0.0, point_scale=scale)
    writer.set_point_labels(labels)
    if analog:
        writer.set_analog_labels([f"a{k}" for k in range(analog)])
    frames = []
    for f in range(len(xyz)):
        points = np.zeros((xyz.shape[1], 5), np.float32)
        points[:, :3] = xyz[f]
        points[:, 3] = residuals[f]
        points[:, 4] = 0 if cameras is None else cameras[f]
        frames.append((points, np.full((analog, 2), 3.0) if analog else np.zeros((0, 0))))
    writer.add_frames(frames)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with open(path, "wb") as handle:
            writer.write(handle)
    return path


def _data(rng, n_frames, n_points, step):
    """Positions on a grid of ``step`` (exact in int16 storage) and residuals in whole steps."""
    xyz = rng.integers(-4000, 4000, size=(n_frames, n_points, 3)) * step
    residuals = rng.integers(0, 40, size=(n_frames, n_points)) * step
    residuals[3:7, 1] = -1  # a gap of four frames in point 1
    residuals[0, 0] = -1
    return xyz.astype(np.float32), residuals.astype(np.float32)


@pytest.mark.parametrize("scale", [-1.0, -0.25, 0.25, 0.5])  # float32 and int16 storage
def test_read_c3d_gives_back_what_was_written(tmp_path, rng, scale):
    step = abs(scale)
    xyz, residuals = _data(rng, 30, 4, step)
    labels = ["LASI", "RASI", "LPSI", "RPSI"]
    path = _write(tmp_path / "trial.c3d", xyz, residuals, labels, scale=scale, rate=120.0)
    motion = read_c3d(path)
    gap = residuals < 0
    assert motion.kind == "positions" and motion.marker_names == tuple(labels)
    assert motion.frame_rate == 120.0 and motion.units == "m" and motion.source == str(path)
    assert motion.channel_names[:4] == ["LASI_x", "LASI_y", "LASI_z", "RASI_x"]
    positions = motion.channels.reshape(30, 4, 3)
    np.testing.assert_array_equal(np.isnan(positions).any(axis=2), gap)
    np.testing.assert_allclose(
        positions[~gap], xyz[~gap].astype(float) / 1000.0, rtol=0, atol=1e-12
    )
    kept = motion.extras["residuals"]
    assert np.isnan(kept[gap]).all()
    np.testing.assert_allclose(
        kept[~gap], residuals[~gap].astype(float) / 1000.0, rtol=0, atol=1e-12
    )
    in_mm = read_c3d(path, units=None)
    assert in_mm.units == "mm" and in_mm.meters_per_unit == 0.001
    np.testing.assert_allclose(in_mm.channels.reshape(30, 4, 3)[~gap], xyz[~gap], atol=1e-9)
    in_cm = read_c3d(path, units="cm")
    np.testing.assert_allclose(in_cm.channels, in_mm.channels / 10, atol=1e-9)


def test_camera_bits_do_not_leak_into_residuals(tmp_path, rng):
    xyz, residuals = _data(rng, 10, 3, 1.0)
    cameras = rng.integers(0, 127, size=(10, 3))
    path = _write(tmp_path / "c.c3d", xyz, residuals, ["a", "b", "c"], scale=-1.0, cameras=cameras)
    kept = read_c3d(path, units=None).extras["residuals"]
    np.testing.assert_array_equal(kept[residuals >= 0], residuals[residuals >= 0])


def test_analog_samples_between_frames_are_skipped(tmp_path, rng):
    xyz, residuals = _data(rng, 12, 2, 1.0)
    path = _write(tmp_path / "a.c3d", xyz, residuals, ["a", "b"], scale=-1.0, analog=3)
    motion = read_c3d(path, units=None)
    gap = residuals < 0
    np.testing.assert_array_equal(motion.channels.reshape(12, 2, 3)[~gap], xyz[~gap])


def test_labels_empty_and_repeated_get_their_own_names(tmp_path, rng):
    xyz, residuals = _data(rng, 8, 4, 1.0)
    path = _write(tmp_path / "l.c3d", xyz, residuals, ["LASI", "LASI", " ", "RASI"], scale=-1.0)
    assert read_c3d(path).marker_names == ("LASI", "LASI#2", "point3", "RASI")


def test_a_long_file_is_read_whole(tmp_path, rng):
    xyz = np.repeat(rng.normal(scale=500, size=(1, 40, 3)), 5000, axis=0).astype(np.float32)
    xyz[:, :, 0] += np.arange(5000, dtype=np.float32)[:, None]
    path = _write(
        tmp_path / "long.c3d", xyz, np.zeros((5000, 40)), list(map(str, range(40))), scale=-1
    )
    motion = read_c3d(path, units=None)
    np.testing.assert_allclose(motion.channels.reshape(5000, 40, 3), xyz, rtol=0, atol=0)


def test_broken_files_name_the_file(tmp_path, rng):
    xyz, residuals = _data(rng, 20, 2, 1.0)
    path = _write(tmp_path / "cut.c3d", xyz, residuals, ["a", "b"], scale=-1.0)
    data = path.read_bytes()
    header_and_params = len(data) - 512  # the data block is the last 512-byte block here
    path.write_bytes(data[: header_and_params + 100])
    with pytest.raises(MotionFileError, match=r"cut\.c3d: truncated: the header announces 20"):
        read_c3d(path)
    junk = tmp_path / "junk.c3d"
    junk.write_bytes(bytes(range(256)) * 4)
    with pytest.raises(MotionFileError, match=r"junk\.c3d"):
        read_c3d(junk)
    with pytest.raises(FileNotFoundError):
        read_c3d(tmp_path / "missing.c3d")
    with pytest.raises(ValueError, match="units must be None or one of"):
        read_c3d(path, units="furlong")


def _fourth_word(residual_steps, cameras, invalid):
    word = (cameras.astype(np.int32) << 8) | residual_steps.astype(np.int32)
    return np.where(invalid, -1, word)


def _words(rng, n_frames=6, n_points=3):
    xyz = rng.integers(-3000, 3000, size=(n_frames, n_points, 3)).astype(np.float64)
    steps = rng.integers(0, 200, size=(n_frames, n_points))
    cameras = rng.integers(0, 100, size=(n_frames, n_points))
    invalid = rng.random((n_frames, n_points)) < 0.2
    last = _fourth_word(steps, cameras, invalid)
    return xyz, steps, invalid, np.concatenate([xyz, last[:, :, None]], axis=2)


@pytest.mark.parametrize("processor", ["INTEL", "MIPS", "DEC"])
@pytest.mark.parametrize("storage", ["float", "int16"])
def test_point_words_of_every_processor(rng, processor, storage):
    """Decode words written as each processor stores them: little- or big-endian IEEE/int16,
    and DEC F-floats (the IEEE bits of 4x the value with their two 16-bit halves swapped)."""
    xyz, steps, invalid, words = _words(rng)
    scale = -0.5 if storage == "float" else 0.5
    if storage == "int16":
        values = np.concatenate([xyz / 0.5, words[:, :, 3:]], axis=2).astype(np.int16)
        raw = values.astype(">i2" if processor == "MIPS" else "<i2").tobytes()
    elif processor == "DEC":
        bits = (words * 4).astype("<f4").view("<u4")
        raw = ((bits >> 16) | (bits << 16)).astype("<u4").tobytes()
    else:
        raw = words.astype(">f4" if processor == "MIPS" else "<f4").tobytes()
    block = np.frombuffer(raw, dtype=np.uint8).reshape(len(words), -1)
    got_xyz, residuals, got_invalid = _decode_points(block, processor, scale, words.shape[1])
    np.testing.assert_array_equal(got_invalid, invalid)
    np.testing.assert_allclose(got_xyz[~invalid], xyz[~invalid], rtol=0, atol=1e-9)
    np.testing.assert_allclose(residuals[~invalid], steps[~invalid] * 0.5, rtol=0, atol=1e-12)


def test_folder_loaders_and_info_know_c3d(tmp_path, rng, capsys):
    from skmotion.cli import main
    from skmotion.datasets import load_motion_folder

    assert ".c3d" in folder_suffixes()
    for label, n in (("walk", 2), ("jump", 1)):
        (tmp_path / label).mkdir()
        for k in range(n):
            xyz, residuals = _data(rng, 10 + k, 3, 1.0)
            _write(tmp_path / label / f"t{k}.C3D", xyz, residuals, ["a", "b", "c"], scale=-1.0)
    data = load_motion_folder(tmp_path, verbose=1)
    assert "reading motion files" in capsys.readouterr().err
    assert data.target_names[data.target].tolist() == ["jump", "walk", "walk"]
    assert [len(c) for c in data.clips] == [10, 10, 11] and data.frame_rate == 100.0
    assert all(m.kind == "positions" for m in data.motions) and data.layout.tolist() == [0, 0, 0]
    assert main(["info", str(tmp_path / "walk" / "t0.C3D")]) == 0
    out = capsys.readouterr().out
    assert "format: C3D" in out and "markers: 3 (3-D, length unit m): a, b, c" in out
    assert "frames: 10 at 100 Hz, duration 0.10 s" in out
    assert "missing: 16.7% of marker positions; 0 markers never seen" in out  # 5 of 30
