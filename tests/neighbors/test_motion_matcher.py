"""MotionMatcher: its features against a hand-worked circle walk, its search against brute force."""

import pickle

import numpy as np
import pytest
from sklearn.base import clone

from skmotion.datasets import make_walks
from skmotion.io import as_motions
from skmotion.kinematics import get_layout
from skmotion.neighbors import MotionMatcher, floor_frames
from tests.clip_conformance import ClipCase, parametrize_with_clip_checks

KINECT = get_layout("kinect_v1")


def _body_template():
    """Kinect v1 joints of a standing body in its own frame (x forward, y left, z up), metres."""
    where = {
        "HipCenter": (0, 0, 1.0),
        "Spine": (0, 0, 1.2),
        "ShoulderCenter": (0, 0, 1.45),
        "Head": (0, 0, 1.65),
    }
    for side, y in (("Left", 1.0), ("Right", -1.0)):
        where.update(
            {
                f"Shoulder{side}": (0, 0.2 * y, 1.45),
                f"Elbow{side}": (0, 0.25 * y, 1.2),
                f"Wrist{side}": (0, 0.27 * y, 0.95),
                f"Hand{side}": (0, 0.28 * y, 0.88),
                f"Hip{side}": (0, 0.1 * y, 0.95),
                f"Knee{side}": (0.02, 0.1 * y, 0.5),
                f"Ankle{side}": (0, 0.1 * y, 0.08),
                f"Foot{side}": (0.1, 0.1 * y, 0.02),
            }
        )
    return np.array([where[j] for j in KINECT.joints], dtype=float)


def _circle_walk(n_frames, radius, omega, rate):
    """A rigid body walking counter-clockwise on a circle, facing along it; Kinect's y up."""
    t = np.arange(n_frames) / rate
    heading = omega * t + np.pi / 2  # at angle omega t on the circle, facing the tangent
    body = _body_template()
    c, s = np.cos(heading)[:, None], np.sin(heading)[:, None]
    floor_x = radius * np.cos(omega * t)[:, None] + c * body[:, 0] - s * body[:, 1]
    floor_y = radius * np.sin(omega * t)[:, None] + s * body[:, 0] + c * body[:, 1]
    # Floor (x, y) of the planner are world (z, x) for a y-up world.
    world = np.stack([floor_y, np.broadcast_to(body[:, 2], floor_x.shape), floor_x], axis=2)
    return world.reshape(n_frames, -1)


def test_trajectory_features_of_a_circle_walk():
    rate, radius, omega = 30.0, 2.0, 0.5
    take = _circle_walk(200, radius, omega, rate)
    matcher = MotionMatcher(layout="kinect_v1", frame_rate=rate, future=(0.5, 1.0)).fit([take])
    raw = matcher.features_ * matcher.scale_ + matcher.mean_
    cols = raw[:, matcher.groups_["trajectory"]]
    tau = np.array([0.5, 1.0])
    # Seen from the body: ahead R sin(w tau), to the left R (1 - cos(w tau)), turned by w tau.
    expected = np.concatenate(
        [
            radius * np.sin(omega * tau),
            radius * (1 - np.cos(omega * tau)),
            np.cos(omega * tau),
            np.sin(omega * tau),
        ]
    )
    np.testing.assert_allclose(cols, np.broadcast_to(expected, cols.shape), atol=1e-9)
    # The pose in the body frame does not change; the velocities are the rigid turn's.
    pose = raw[:, matcher.groups_["pose"]]
    np.testing.assert_allclose(pose, np.broadcast_to(pose[0], pose.shape), atol=1e-9)
    assert len(matcher.features_) == 200 - 30  # frames with a whole second ahead


def test_floor_frames_follow_the_circle():
    take = _circle_walk(50, 2.0, 0.5, 30.0).reshape(50, KINECT.n_joints, 3)
    hips = [KINECT.index("HipLeft"), KINECT.index("HipRight")]
    origin, yaw = floor_frames(take, root=hips, lefts=[hips[0]], rights=[hips[1]])
    t = np.arange(50) / 30.0
    np.testing.assert_allclose(origin, 2.0 * np.column_stack([np.cos(0.5 * t), np.sin(0.5 * t)]))
    np.testing.assert_allclose(np.cos(yaw - (0.5 * t + np.pi / 2)), 1.0)


@pytest.fixture(scope="module")
def walks():
    data = make_walks(3, turn=1.0, random_state=0)
    held_out = make_walks(1, turn=1.0, random_state=1)
    return (
        as_motions(data.clips, data.skeletons, data.frame_rate),
        as_motions(held_out.clips, held_out.skeletons, held_out.frame_rate),
    )


@pytest.mark.parametrize("algorithm", ["kd_tree", "ball_tree", "brute"])
def test_exact_search_equals_brute_force(walks, algorithm):
    takes, new = walks
    matcher = MotionMatcher(algorithm=algorithm).fit(takes)
    queries = np.concatenate(matcher.frame_features(new))[::7]
    take, frame, distance = matcher.kneighbors(queries, n_neighbors=3)
    full = np.linalg.norm(queries[:, None, :] - matcher.features_[None], axis=2)
    order = np.argsort(full, axis=1)[:, :3]
    np.testing.assert_allclose(distance, np.take_along_axis(full, order, axis=1), atol=1e-9)
    np.testing.assert_array_equal(take, matcher.take_[order])
    np.testing.assert_array_equal(frame, matcher.frame_[order])


def test_hnsw_recall_and_pickle(walks):
    pytest.importorskip("faiss")
    takes, new = walks
    exact = MotionMatcher().fit(takes)
    approx = clone(exact).set_params(algorithm="hnsw").fit(takes)
    queries = np.concatenate(exact.frame_features(new))
    found = approx.kneighbors(queries)[2][:, 0]
    truth = exact.kneighbors(queries)[2][:, 0]
    assert np.mean(np.isclose(found, truth, rtol=1e-5, atol=1e-5)) >= 0.99
    again = pickle.loads(pickle.dumps(approx))
    for a, b in zip(approx.kneighbors(queries), again.kneighbors(queries)):
        np.testing.assert_array_equal(a, b)
    # Built on one thread: a second fit gives the same graph and the same answers.
    np.testing.assert_array_equal(
        clone(approx).fit(takes).kneighbors(queries)[1], approx.kneighbors(queries)[1]
    )


@pytest.mark.parametrize("threads", [1, 2])
def test_hnsw_graph_recall_on_a_made_up_cloud(threads):
    # MotionMatcher's graph (its degree, construction beam and search) on 5,000 points
    # of a noisy 10-dimensional plane in 30 dimensions, against brute force. The beam
    # matters here: one entry finds the nearest point for about 60 % of the queries.
    pytest.importorskip("faiss")
    from skmotion.neighbors._hnsw import faiss_search, hnsw_index
    from skmotion.neighbors._motion_matcher import EF_DEFAULT

    rng = np.random.default_rng(0)
    cloud = rng.normal(size=(5500, 10)) @ rng.normal(size=(10, 30))
    cloud += 0.05 * rng.normal(size=cloud.shape)
    data, queries = cloud[:5000], cloud[5000:]
    truth = np.sqrt(((queries[:, None] - data[None]) ** 2).sum(axis=2).min(axis=1))
    index, _ = hnsw_index(data, threads)
    recall = {}
    for ef in (1, EF_DEFAULT):
        index.hnsw.efSearch = ef
        found = faiss_search(index, queries, 1)[0][:, 0]
        recall[ef] = np.mean(np.isclose(found, truth, rtol=1e-4))
    assert recall[1] < 0.8
    assert recall[EF_DEFAULT] >= 0.99


def test_hnsw_follows_ef_changes_after_fit(walks):
    pytest.importorskip("faiss")
    takes, new = walks
    exact = MotionMatcher().fit(takes)
    approx = MotionMatcher(algorithm="hnsw", ef=1).fit(takes)
    queries = np.concatenate(exact.frame_features(new))[::5]
    truth = exact.kneighbors(queries)[2][:, 0]
    approx.kneighbors(queries)
    # A beam as wide as the collection visits every reachable frame: exact.
    approx.set_params(ef=len(approx.features_))
    np.testing.assert_allclose(approx.kneighbors(queries)[2][:, 0], truth, rtol=1e-5, atol=1e-5)


@pytest.mark.parametrize("k", [1, 3])
def test_hnsw_one_query_per_call_answers_as_the_batch(walks, k, monkeypatch):
    # One row per call takes the fast path (no checks before the search, the answer
    # built from the labels directly); a batch takes the checked path. Same graph:
    # the same neighbours and the same distances, whatever the row's form.
    pytest.importorskip("faiss")
    # Clusters of 100 rows: the graph's storage order is not the rows' here.
    monkeypatch.setattr("skmotion.neighbors._hnsw.ROWS_PER_CLUSTER", 100)
    takes, new = walks
    matcher = MotionMatcher(algorithm="hnsw").fit(takes)
    rng = np.random.default_rng(0)
    queries = np.concatenate(matcher.frame_features(new))[::3]
    queries = np.vstack([queries, rng.normal(scale=2.0, size=(40, queries.shape[1]))])
    batch = matcher.kneighbors(queries, n_neighbors=k)
    # The graph stores its rows in cluster order: the labels must still name the
    # frame whose feature is at the reported distance.
    row_of = {(t, f): i for i, (t, f) in enumerate(zip(matcher.take_, matcher.frame_))}
    rows = np.vectorize(lambda t, f: row_of[t, f])(batch[0], batch[1])
    by_label = np.linalg.norm(matcher.features_[rows] - queries[:, None, :], axis=2)
    np.testing.assert_allclose(batch[2], by_label, rtol=1e-5, atol=1e-5)
    assert not np.array_equal(matcher._graph_order, np.arange(len(matcher.take_)))
    forms = (
        lambda q: q,
        lambda q: q[None],
        lambda q: q.astype(np.float32),
        lambda q: np.asfortranarray(np.tile(q, (2, 1)))[:1],
    )
    for i, q in enumerate(queries):
        for form in forms:
            one = matcher.kneighbors(form(q), n_neighbors=k)
            for a, b in zip(one, batch):
                assert a.shape == (1, k)
                np.testing.assert_array_equal(a[0], b[i])
    # A refit without the graph does not keep searching it.
    matcher.set_params(algorithm="brute").fit(takes)
    take, frame, _ = matcher.kneighbors(queries[0])
    np.testing.assert_array_equal((take, frame), matcher.kneighbors(queries[:1], n_neighbors=1)[:2])
    assert "_graph" not in vars(matcher)


def test_hnsw_one_query_per_call_from_threads(walks):
    # The single-row buffers are per thread: four threads asking one row per call at
    # once each get the batch's answer for their own rows.
    pytest.importorskip("faiss")
    from concurrent.futures import ThreadPoolExecutor

    takes, new = walks
    matcher = MotionMatcher(algorithm="hnsw").fit(takes)
    queries = np.concatenate(matcher.frame_features(new))
    batch = matcher.kneighbors(queries, n_neighbors=2)

    def ask(part):
        return [matcher.kneighbors(queries[i], n_neighbors=2) for i in part]

    parts = [range(j, len(queries), 4) for j in range(4)]
    with ThreadPoolExecutor(4) as pool:
        answers = list(pool.map(ask, parts))
    for part, found in zip(parts, answers):
        for i, one in zip(part, found):
            for a, b in zip(one, batch):
                np.testing.assert_array_equal(a[0], b[i])


# The conversion of 1e200 to float32 for faiss warns before the error.
@pytest.mark.filterwarnings("ignore:overflow encountered in cast:RuntimeWarning")
def test_hnsw_one_query_names_nan_and_huge_values(walks):
    # The fast path checks a row by its answer: a NaN or inf row must still be
    # refused by name, and a finite row whose distances overflow float32 (faiss
    # then finds no neighbour, row -1) refused as the batch refuses it, not
    # labelled with the last frame.
    pytest.importorskip("faiss")
    takes, _ = walks
    matcher = MotionMatcher(algorithm="hnsw").fit(takes)
    for bad in (np.nan, np.inf, -np.inf):
        row = matcher.features_[0].copy()
        row[5] = bad
        with pytest.raises(ValueError, match="query 0 holds NaN or inf"):
            matcher.kneighbors(row)
        with pytest.raises(ValueError, match="query 0 holds NaN or inf"):
            matcher.kneighbors(row[None], n_neighbors=2)
    huge = np.full(matcher.features_.shape[1], 1e200)
    with pytest.raises(ValueError, match="query 0: fewer than 1 neighbours found"):
        matcher.kneighbors(huge)
    with pytest.raises(ValueError, match="query 1: fewer than 1 neighbours found"):
        matcher.kneighbors(np.vstack([matcher.features_[:1], huge]))


def test_huge_finite_queries_are_not_refused(walks):
    # The fast finiteness check (one dot product) overflows for these values: the
    # row-wise check behind it must accept them, and still name a NaN row.
    takes, _ = walks
    matcher = MotionMatcher(algorithm="brute").fit(takes)
    huge = np.full((2, matcher.features_.shape[1]), 1e200)
    take, frame, _ = matcher.kneighbors(huge)
    assert take.shape == frame.shape == (2, 1)
    huge[1, 3] = np.nan
    with pytest.raises(ValueError, match="query 1 holds NaN"):
        matcher.kneighbors(huge)


def test_weights_scale_the_groups(walks):
    takes, _ = walks
    base = MotionMatcher().fit(takes)
    heavy = MotionMatcher(trajectory_weight=3.0, velocity_weight=0.0).fit(takes)
    cols = base.groups_["trajectory"]
    np.testing.assert_allclose(heavy.features_[:, cols], 3.0 * base.features_[:, cols])
    assert not heavy.features_[:, base.groups_["velocity"]].any()


def test_pickle_and_clone(walks):
    takes, new = walks
    matcher = MotionMatcher(algorithm="ball_tree").fit(takes)
    queries = np.concatenate(matcher.frame_features(new))[:20]
    again = pickle.loads(pickle.dumps(matcher))
    for a, b in zip(matcher.kneighbors(queries), again.kneighbors(queries)):
        np.testing.assert_array_equal(a, b)
    assert clone(matcher).get_params() == matcher.get_params()


def test_bad_input_is_named(walks):
    takes, _ = walks
    with pytest.raises(TypeError, match="take 1: without a layout"):
        MotionMatcher().fit([takes[0], np.zeros((10, 66))])
    with pytest.raises(ValueError, match="horizon"):
        MotionMatcher(future=(10.0,)).fit(takes[:1])
    with pytest.raises(ValueError, match="frame_rate"):
        MotionMatcher(layout="kinect_v1").fit([np.zeros((40, 60))])
    matcher = MotionMatcher().fit(takes)
    with pytest.raises(ValueError, match="query 1 holds NaN"):
        matcher.kneighbors(np.vstack([matcher.features_[:1], np.full((1, 30), np.nan)]))


def _walk_data():
    data = make_walks(1, random_state=0)
    return as_motions(data.clips, data.skeleton, data.frame_rate), None


_NOT_CLIPS = "the takes are Motions with a skeleton, not channel arrays"


@parametrize_with_clip_checks(
    [
        ClipCase(
            MotionMatcher(),
            _walk_data,
            skip={
                "check_containers_agree": _NOT_CLIPS,
                "check_fitted_attributes": "no n_features_in_: " + _NOT_CLIPS,
                "check_channel_mismatch": _NOT_CLIPS,
                "check_nan_rejected": _NOT_CLIPS,
                "check_too_short": _NOT_CLIPS,
                "check_input_not_modified": _NOT_CLIPS,
                "check_set_output_pandas": "not a transformer",
                "check_cross_val_score": "no score: a search structure",
                "check_grid_search": "no score: a search structure",
                "check_n_jobs": "no n_jobs",
            },
        )
    ]
)
def test_clip_conformance(check):
    check()
