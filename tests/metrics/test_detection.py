"""detection_counts and detection_f1 on hand-worked event lists."""

import pytest

from skmotion.metrics import detection_counts, detection_f1


def test_each_point_is_found_once_and_extra_events_are_false():
    points, labels = [[10, 50]], [["kick", "kick"]]
    events = [[(8, "kick", 0.9), (11, "kick", 0.9), (52, "duck", 0.7), (56, "kick", 0.6)]]
    # 10 <- 8 (2 early); 11 is a second event for it: false; 52 has the wrong label: false;
    # 50 <- 56 is 6 late: beyond a latency of 5, so 50 is missed and 56 false
    counts = detection_counts(points, labels, events, latency=5)
    assert counts == {"kick": (1, 2, 1), "duck": (0, 1, 0)}
    assert detection_f1(points, labels, events, latency=5) == pytest.approx(2 / (2 + 3 + 1))
    # with 6 frames of latency 56 finds 50
    assert detection_counts(points, labels, events, latency=6)["kick"] == (2, 1, 0)


def test_early_events_count_only_within_early():
    points, labels, events = [[20]], [["a"]], [[(18, "a", 1.0)]]
    assert detection_f1(points, labels, events, latency=3) == 1.0
    assert detection_f1(points, labels, events, latency=3, early=0) == 0.0
    assert detection_counts(points, labels, events, latency=3, early=1) == {"a": (0, 1, 1)}


def test_takes_are_matched_apart_and_empty_cases():
    points, labels = [[5], [5]], [["a"], ["a"]]
    events = [[], [(5, "a", 1.0)]]  # the second take's event cannot find the first take's point
    assert detection_counts(points, labels, events, latency=2) == {"a": (1, 0, 1)}
    assert detection_f1([[]], [[]], [[]], latency=2) == 0.0
