"""read_keypoints on damaged .npy/.npz files: one error type naming the file, and no
allocation that the file's size does not back (a header may claim any shape)."""

import io
import tracemalloc
import zipfile

import numpy as np
import pytest

from skmotion.io import MotionFileError, read_keypoints


def _npy(array):
    buffer = io.BytesIO()
    np.save(buffer, array)
    return buffer.getvalue()


def _forge_shape(data, shape):
    """The .npy bytes with the header's shape replaced (the header keeps its length)."""
    header_len = int.from_bytes(data[8:10], "little")
    header = data[10 : 10 + header_len].decode("latin-1")
    start = header.index("'shape': (") + len("'shape': (")
    end = header.index(")", start)
    new = header[:start] + ", ".join(map(str, shape)) + ("," if len(shape) == 1 else "")
    new = (new + header[end:]).rstrip("\n ")
    assert len(new) < header_len, "the forged header must fit"
    return data[:10] + new.ljust(header_len - 1).encode("latin-1") + b"\n" + data[10 + header_len :]


def _peak(read):
    tracemalloc.start()
    try:
        read()
    except MotionFileError:
        pass
    finally:
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
    return peak


@pytest.fixture
def keypoints(rng):
    return rng.normal(size=(20, 3, 3))


@pytest.mark.parametrize("shape", [(10**6, 3, 3), (2**40, 2**20, 3), (20, 3, 3, 10**9)])
def test_a_header_claiming_a_huge_shape_allocates_nothing(tmp_path, keypoints, shape):
    path = tmp_path / "forged.npy"
    path.write_bytes(_forge_shape(_npy(keypoints), shape))
    with pytest.raises(MotionFileError, match=r"forged\.npy: array: the header announces"):
        read_keypoints(path, frame_rate=30.0)
    assert _peak(lambda: read_keypoints(path, frame_rate=30.0)) < 2 * path.stat().st_size + 65536


def test_a_forged_member_of_an_npz_allocates_nothing(tmp_path, keypoints):
    path = tmp_path / "forged.npz"
    forged = _forge_shape(_npy(keypoints), (10**8, 3, 3))
    with zipfile.ZipFile(path, "w") as archive:
        archive.writestr("keypoints.npy", forged)
    with pytest.raises(MotionFileError, match=r"array 'keypoints': the header announces"):
        read_keypoints(path, frame_rate=30.0)
    assert _peak(lambda: read_keypoints(path, frame_rate=30.0)) < 2 * path.stat().st_size + 65536


def _damaged(tmp_path, keypoints):
    good_npz = io.BytesIO()
    np.savez_compressed(good_npz, keypoints=keypoints, joint_names=np.array(["a", "b", "c"]))
    good_npz = good_npz.getvalue()
    npy = _npy(keypoints)
    header_len = int.from_bytes(npy[8:10], "little")
    cases = {
        "cut.npy": npy[: len(npy) // 2],
        "header_cut.npy": npy[:30],
        "garbled_header.npy": npy[:10] + b"{'descr': '<f8', 'fortran_order': (((" + npy[48:],
        "bad_magic.npy": b"\x93NUMPX" + npy[6:],
        "version9.npy": npy[:6] + b"\x09\x00" + npy[8:],
        "object.npy": _npy(np.array([{"a": 1}, None], dtype=object)),
        "complex.npy": _npy(keypoints.astype(complex)),
        "cut.npz": good_npz[: len(good_npz) // 2],
        "flipped.npz": good_npz[:60] + bytes([good_npz[60] ^ 0xFF]) + good_npz[61:],
        "not_zip.npz": b"PK\x03\x04" + b"\x00" * 40,
        "huge_header_len.npy": npy[:8] + b"\xff\xff" + npy[10:],
    }
    assert header_len > 0
    for name, data in cases.items():
        (tmp_path / name).write_bytes(data)
    return cases


def test_every_damaged_array_file_is_a_motion_file_error(tmp_path, keypoints):
    for name in _damaged(tmp_path, keypoints):
        with pytest.raises(MotionFileError, match=rf"{name.replace('.', '[.]')}: ") as caught:
            read_keypoints(tmp_path / name, "kinect_v1", frame_rate=30.0)
        assert caught.value.path == str(tmp_path / name)


def test_pickles_are_never_loaded(tmp_path, keypoints):
    path = tmp_path / "names.npz"
    np.savez(path, keypoints=keypoints, joint_names=np.array(["a", 1, None], dtype=object))
    with pytest.raises(MotionFileError, match="holds object values, not numbers"):
        read_keypoints(path, frame_rate=30.0)


def test_good_files_still_read(tmp_path, keypoints):
    path = tmp_path / "good.npz"
    np.savez_compressed(path, keypoints=keypoints, joint_names=np.array(["a", "b", "c"]))
    motion = read_keypoints(path, frame_rate=30.0)
    assert motion.marker_names == ("a", "b", "c")
    np.testing.assert_array_equal(motion.channels, keypoints.reshape(20, 9))
    fortran = tmp_path / "fortran.npy"
    np.save(fortran, np.asfortranarray(keypoints))
    np.testing.assert_array_equal(
        read_keypoints(fortran, frame_rate=30.0).channels, keypoints.reshape(20, 9)
    )
