"""Shared fixtures: seeded generators, a small skeleton, ragged clips, real data."""

import os
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, settings

from skmotion.kinematics import Skeleton

# Hypothesis runs the same examples every time (no flaky CI), without deadlines
# (a 2-core CI machine is slower than a laptop).
settings.register_profile(
    "skmotion", derandomize=True, deadline=None, suppress_health_check=[HealthCheck.too_slow]
)
settings.load_profile("skmotion")

SHARED_DATA = Path(
    os.environ.get(
        "SKMOTION_SHARED_DATA", Path(__file__).resolve().parents[1] / ".." / "shared" / "data"
    )
).resolve()


@pytest.fixture
def rng():
    return np.random.default_rng(0)


@pytest.fixture
def skeleton():
    """A 5-joint chain with mixed rotation orders and a 6-channel root."""
    return Skeleton(
        joints=["root", "spine", "neck", "arm", "hand"],
        parents=[-1, 0, 1, 1, 3],
        offsets=[[0, 1, 0], [0, 0.5, 0], [0, 0.4, 0], [0.2, 0.3, 0], [0.3, 0, 0]],
        channels=[
            ["Xposition", "Yposition", "Zposition", "Zrotation", "Xrotation", "Yrotation"],
            ["Xrotation", "Yrotation", "Zrotation"],
            ["Yrotation", "Zrotation"],
            ["Zrotation", "Yrotation", "Xrotation"],
            [],
        ],
        units="m",
        meters_per_unit=1.0,
    )


@pytest.fixture
def clips(rng):
    """Ragged clips of 3 to 40 frames and 4 channels."""
    return [rng.normal(size=(n, 4)) for n in (3, 17, 40, 8, 25)]


@pytest.fixture
def shared_data():
    """The real data in ../shared/data; tests using it skip when it is absent."""
    if not SHARED_DATA.is_dir():
        pytest.skip(f"real motion data not found at {SHARED_DATA} (set SKMOTION_SHARED_DATA)")
    return SHARED_DATA


@pytest.fixture(scope="session")
def demo_report(tmp_path_factory):
    """The output of ``skmotion demo``, run once for every test that reads it."""
    import contextlib
    import io

    from skmotion.cli import main

    buffer = io.StringIO()
    out = tmp_path_factory.mktemp("demo-out")
    with contextlib.redirect_stdout(buffer):
        status = main(["demo", "--quiet", "--out", str(out)])
    assert status == 0
    return buffer.getvalue()


@pytest.fixture(autouse=True)
def _close_figures():
    """Close the figures a test drew (pyplot keeps them, and warns past 20)."""
    yield
    pyplot = sys.modules.get("matplotlib.pyplot")
    if pyplot is not None:
        pyplot.close("all")
