"""ShardedIntervalIndex on a real Dask cluster (loopback) answers as one IntervalIndexNeighbors."""

import numpy as np
import pytest

from skmotion.datasets import make_repeated_motions
from skmotion.decomposition import SVDFeatureExtractor
from skmotion.neighbors import IntervalIndexNeighbors, ShardedIntervalIndex

distributed = pytest.importorskip("distributed")
dask = pytest.importorskip("dask")


@pytest.fixture(scope="module")
def client():
    with dask.config.set({"distributed.comm.timeouts.connect": "60s"}):
        cluster = distributed.LocalCluster(
            n_workers=2,
            threads_per_worker=1,
            processes=False,
            protocol="tcp",  # loopback sockets, as to a remote scheduler
            host="127.0.0.1",
            dashboard_address=None,
        )
        try:
            with distributed.Client(cluster) as client:
                client.wait_for_workers(2, timeout=120)
                yield client
        finally:
            cluster.close(timeout=60)


@pytest.fixture(scope="module")
def motions():
    data = make_repeated_motions(n_motions_per_class=3, n_repeats=5, random_state=3)
    clips, labels = data.clips, data.target
    return (
        clips[::5] + clips[1::5] + clips[2::5] + clips[3::5],
        np.tile(labels[::5], 4),
        clips[4::5],
    )


@pytest.mark.parametrize(
    "params",
    [
        {},
        {"epsilon": 0.8, "n_levels": 5},
        {"features": SVDFeatureExtractor(weighting="first_two"), "width_factor": 2.0},
    ],
)
@pytest.mark.parametrize("n_shards", [2, 3])
def test_sharded_answers_equal_the_single_index(client, motions, params, n_shards):
    stored, labels, queries = motions
    single = IntervalIndexNeighbors(random_state=0, **params).fit(stored, labels)
    sharded = ShardedIntervalIndex(
        IntervalIndexNeighbors(random_state=0, **params), client=client, n_shards=n_shards
    ).fit(stored, labels)
    # the widths are reduced over shards in another order: equal up to rounding (~1e-17); the
    # candidates and neighbours below must still be exactly the single index's
    np.testing.assert_allclose(sharded.layout_.radius_, single.radius_, rtol=1e-12, atol=1e-15)
    for got, expected in zip(sharded.candidates(queries), single.candidates(queries)):
        np.testing.assert_array_equal(got, expected)
    for k in (1, 4, len(stored)):  # len(stored): every query falls back to all clips
        distances, ids = sharded.kneighbors(queries, n_neighbors=k)
        expected_distances, expected_ids = single.kneighbors(queries, n_neighbors=k)
        np.testing.assert_array_equal(ids, expected_ids)
        np.testing.assert_allclose(distances, expected_distances, atol=1e-12)


def test_sharded_refuses_psi_pairs_and_bad_k(client, motions):
    stored, labels, queries = motions
    with pytest.raises(ValueError, match='similar="labels" only'):
        ShardedIntervalIndex(IntervalIndexNeighbors(similar="psi"), client=client).fit(
            stored, labels
        )
    sharded = ShardedIntervalIndex(client=client).fit(stored, labels)
    with pytest.raises(ValueError, match="n_neighbors must be an integer from 1 to"):
        sharded.kneighbors(queries, n_neighbors=len(stored) + 1)


def test_shards_are_spread_over_the_workers(client, motions):
    # One shard per worker, so that a query batch is ranked on both in parallel.
    train, labels, _ = motions
    sharded = ShardedIntervalIndex(
        IntervalIndexNeighbors(random_state=0), client=client, n_shards=2
    ).fit(train, labels)
    holders = client.who_has(sharded.shards_)
    workers = [tuple(holders[f.key]) for f in sharded.shards_]
    assert sorted(w for ws in workers for w in ws) == sorted(client.scheduler_info()["workers"])
