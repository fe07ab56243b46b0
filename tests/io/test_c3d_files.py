"""read_c3d on C3D files as labs write them: repeated parameters, NUL-padded or empty units,
headers whose frame range is wrong, analog channels and events; and on the four real files
of the shared data, against ezc3d and the ``c3d`` package."""

import numpy as np
import pytest

from skmotion.io import MotionFileError, read_c3d
from skmotion.io._c3d_parameters import read_metadata
from tests.io.c3d_files import c3d_bytes


def _points(rng, n_frames=30, n_points=3):
    xyz = rng.integers(-2000, 2000, size=(n_frames, n_points, 3)).astype(float)
    residuals = rng.integers(0, 20, size=(n_frames, n_points)).astype(float)
    residuals[4:9, 1] = -1
    return xyz, residuals


def _write(tmp_path, name, *args, **kwargs):
    path = tmp_path / name
    path.write_bytes(c3d_bytes(*args, **kwargs))
    return path


@pytest.mark.parametrize("scale", [-1.0, 0.5])
def test_own_writer_round_trip(tmp_path, rng, scale):
    xyz, residuals = _points(rng)
    xyz = xyz * (0.5 if scale > 0 else 1)
    path = _write(tmp_path, "t.c3d", xyz, residuals, scale=scale, rate=120.0)
    motion = read_c3d(path, units=None)
    gap = residuals < 0
    got = motion.channels.reshape(xyz.shape)
    np.testing.assert_array_equal(np.isnan(got).any(axis=2), gap)
    np.testing.assert_array_equal(got[~gap], xyz[~gap])
    assert motion.frame_rate == 120.0 and motion.units == "mm" and motion.analog is None


def test_a_parameter_defined_twice_keeps_the_last_definition(tmp_path, rng):
    """Plug-in Gait writes PROCESSING:BODYMASS (and its other measurements) more than once."""
    xyz, residuals = _points(rng)
    twice = [("PROCESSING", "BODYMASS", [60.0]), ("PROCESSING", "BODYMASS", [66.5])]
    twice += [("POINT", "UNITS", "cm")]  # after "mm": the last definition, cm, wins
    path = _write(tmp_path, "pig.c3d", xyz, residuals, parameters=twice)
    meta = read_metadata(path, path.read_bytes())
    assert meta.parameters["PROCESSING:BODYMASS"].tolist() == [66.5]
    assert meta.duplicates == ["PROCESSING:BODYMASS", "POINT:UNITS"]  # in file order
    motion = read_c3d(path)
    gap = residuals < 0
    np.testing.assert_allclose(motion.channels.reshape(xyz.shape)[~gap], xyz[~gap] / 100)


@pytest.mark.parametrize("stored", [b"mm\x00\x00", b"  MM  ", b"mm\x00 "])
def test_units_padded_with_nul_bytes_or_spaces(tmp_path, rng, stored):
    xyz, residuals = _points(rng)
    path = _write(tmp_path, "gait.c3d", xyz, residuals, units=stored)
    motion = read_c3d(path)
    gap = residuals < 0
    assert motion.units == "m"
    np.testing.assert_allclose(motion.channels.reshape(xyz.shape)[~gap], xyz[~gap] / 1000)


@pytest.mark.parametrize("stored", ["", None])
def test_an_empty_unit_needs_units_none(tmp_path, rng, stored, capsys):
    from skmotion.cli import main

    xyz, residuals = _points(rng)
    path = _write(tmp_path, "bts.c3d", xyz, residuals, units=stored)
    with pytest.raises(MotionFileError, match=r"bts\.c3d: POINT:UNITS is empty; pass units=None"):
        read_c3d(path)
    kept = read_c3d(path, units=None)
    assert kept.units == "unknown" and kept.meters_per_unit is None
    np.testing.assert_array_equal(
        kept.channels.reshape(xyz.shape)[residuals >= 0], xyz[residuals >= 0]
    )
    assert main(["info", str(path)]) == 1
    assert "--units none" in capsys.readouterr().err
    assert main(["info", "--units", "none", str(path)]) == 0
    assert "length unit unknown" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("header_frames", "frames_parameter", "expected"),
    [
        ((1, 30), True, 30),  # all agree
        ((1, 0), True, 30),  # header last frame 0: POINT:FRAMES and the data say 30
        ((1, 0), False, 30),  # nothing announced: the data's whole frames, padding left out
        ((2, 30), True, 30),  # header off by one low (29); POINT:FRAMES and the data say 30
        ((1, 31), False, 30),  # truncated by one frame: refused below
    ],
)
def test_frame_count_from_what_the_data_holds(
    tmp_path, rng, header_frames, frames_parameter, expected
):
    xyz, residuals = _points(rng, n_frames=30, n_points=2)
    path = _write(
        tmp_path,
        "f.c3d",
        xyz,
        residuals,
        header_frames=header_frames,
        frames_parameter=frames_parameter,
    )
    if header_frames == (1, 31):
        # 30 frames of 32 bytes fill 960 of the data's two blocks; cut the padding off.
        data = path.read_bytes()
        path.write_bytes(data[: len(data) - 1024 + 30 * 32])
        with pytest.raises(MotionFileError, match=r"truncated: the header announces 31 frames"):
            read_c3d(path)
        return
    motion = read_c3d(path, units=None)
    assert motion.n_frames == expected
    np.testing.assert_array_equal(
        motion.channels.reshape(xyz.shape)[residuals >= 0], xyz[residuals >= 0]
    )


def test_a_count_beyond_the_data_is_not_used_when_another_fits(tmp_path, rng):
    """POINT:FRAMES one too many (the ``c3d`` package's off-by-one) while header and data agree."""
    xyz, residuals = _points(rng, n_frames=40, n_points=4)  # 64-byte frames fill whole blocks
    path = _write(
        tmp_path,
        "g.c3d",
        xyz,
        residuals,
        frames_parameter=False,
        parameters=[("POINT", "FRAMES", [41])],
    )
    assert read_c3d(path, units=None).n_frames == 40


def test_analog_channels_and_events(tmp_path, rng):
    xyz, residuals = _points(rng, n_frames=20)
    per_frame, n_channels = 4, 3
    raw = rng.integers(-2000, 2000, size=(20 * per_frame, n_channels))
    offsets, scales, general = [10, -5, 0], [0.5, 2.0, 1.0], 0.25
    events = [
        ("EVENT", "USED", [2]),
        ("EVENT", "LABELS", ["Foot Strike", "Foot Off"]),
        ("EVENT", "CONTEXTS", ["Left", "Right"]),
        # (minutes, seconds) pairs; the first frame of the motion is trial frame 101 at 100 Hz
        ("EVENT", "TIMES", np.array([[0.0, 1.05], [0.0, 1.20]])),
        ("ANALOG", "RATE", [400.0]),
        ("ANALOG", "LABELS", ["Fz1", "EMG1", ""]),
        ("ANALOG", "UNITS", ["N", "V", "V"]),
        ("ANALOG", "OFFSET", offsets),
        ("ANALOG", "SCALE", scales),
        ("ANALOG", "GEN_SCALE", [general]),
    ]
    path = _write(
        tmp_path,
        "a.c3d",
        xyz,
        residuals,
        analog=raw,
        analog_per_frame=per_frame,
        header_frames=(101, 120),
        parameters=events,
    )
    motion = read_c3d(path)
    analog = motion.analog
    assert analog.rate == 400.0 and analog.labels == ("Fz1", "EMG1", "analog3")
    assert analog.units == ("N", "V", "V") and analog.duration == motion.duration
    expected = (raw - np.array(offsets)) * np.array(scales) * general
    np.testing.assert_allclose(analog.values, expected)
    gap = residuals < 0
    np.testing.assert_allclose(motion.channels.reshape(xyz.shape)[~gap], xyz[~gap] / 1000)
    assert [(e.label, e.context, e.frame) for e in motion.events] == [
        ("Foot Strike", "Left", 5),  # 1.05 s = trial frame 106 = row 5
        ("Foot Off", "Right", 20),  # outside the motion's 20 rows, kept as the file says
    ]
    np.testing.assert_allclose([e.time for e in motion.events], [1.05, 1.20], rtol=1e-6)


def test_damaged_parameter_sections_name_the_file(tmp_path, rng):
    xyz, residuals = _points(rng)
    data = bytearray(c3d_bytes(xyz, residuals))
    section = data[512:1024]
    at = section.find(b"LABELS")
    data[512 + at + 6 + 2 + 1 + 1] = 255  # the label width: 255 x 3 labels past the section
    (tmp_path / "bad.c3d").write_bytes(bytes(data))
    with pytest.raises(MotionFileError, match=r"bad\.c3d: parameter LABELS announces"):
        read_c3d(tmp_path / "bad.c3d")
    data = bytearray(c3d_bytes(xyz, residuals))
    data[512 + 3] = 90
    (tmp_path / "proc.c3d").write_bytes(bytes(data))
    with pytest.raises(MotionFileError, match=r"proc\.c3d: processor type 7"):
        read_c3d(tmp_path / "proc.c3d")


# The four real files: points as a peer reads them. Where the peers disagree (dynamic.C3D,
# whose header announces 6 analog samples per frame and whose ANALOG group has no RATE),
# ezc3d reads the analog words as points; the c3d package and read_c3d skip them, and the
# file's size (296 frames of 34 points and 6 analog words, exactly) says they are right.
REAL = {
    "Gait.c3d": ("ezc3d", 487, 33, 28),
    "PiG_Motion-FlatFoot-One.c3d": ("ezc3d", 255, 193, 38),
    "PiG_Motion3_noFF.c3d": ("ezc3d", 293, 97, 34),
    "dynamic.C3D": ("c3d", 296, 34, 6),
}


def _peer_points(peer, path):
    if peer == "ezc3d":
        ezc3d = pytest.importorskip("ezc3d", reason="ezc3d (a benchmark peer) is not installed")
        points = ezc3d.c3d(str(path))["data"]["points"][:3]
        return points.transpose(2, 1, 0)
    import warnings

    c3d = pytest.importorskip("c3d", reason="the c3d package is not installed")
    with open(path, "rb") as handle, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        frames = [p.copy() for _, p, _ in c3d.Reader(handle).read_frames(copy=False)]
    frames = np.array(frames)
    xyz = frames[:, :, :3].astype(float)
    xyz[frames[:, :, 3] < 0] = np.nan
    return xyz


@pytest.mark.parametrize("name", sorted(REAL))
def test_the_real_files_read_as_a_peer_reads_them(shared_data, name):
    path = shared_data / "c3d" / name
    peer, n_frames, n_points, n_analog = REAL[name]
    motion = read_c3d(path, units=None)
    assert motion.channels.shape == (n_frames, 3 * n_points)
    assert motion.analog is not None and len(motion.analog.labels) == n_analog
    expected = _peer_points(peer, path)
    got = motion.channels.reshape(n_frames, n_points, 3)
    np.testing.assert_array_equal(np.isnan(got), np.isnan(expected))
    np.testing.assert_allclose(got, expected, rtol=1e-6, atol=1e-6)


def test_real_plug_in_gait_events_fall_on_their_frames(shared_data):
    """Foot strikes and toe-offs lie inside the trial, in time order, alternating sides."""
    motion = read_c3d(shared_data / "c3d" / "PiG_Motion3_noFF.c3d")
    assert len(motion.events) == 12
    frames = [e.frame for e in motion.events]
    assert frames == sorted(frames) and 0 <= frames[0] and frames[-1] < motion.n_frames
    strikes = [e.context for e in motion.events if e.label == "Foot Strike"]
    assert strikes == ["Right", "Left"] * 3
    # A heel marker is lowest and slowest near its own foot strike.
    heel = motion.channels[:, 3 * motion.marker_names.index("RHEE") + 2]
    for event in motion.events:
        if event.label == "Foot Strike" and event.context == "Right":
            window = heel[max(event.frame - 15, 0) : event.frame + 15]
            assert heel[event.frame] - np.nanmin(window) < 0.02  # within 2 cm of the lowest
