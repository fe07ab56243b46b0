"""The command line answers at once: what ``--help`` and ``info`` import (not their wall time).

Importing scikit-learn, pandas and scipy takes seconds on a loaded machine; the
command needs none of them to print its help or describe a BVH file, so it must
not import them (the packages export their names lazily, ``skmotion._lazy``).
"""

import subprocess
import sys

from tests.test_cli_io import bvh_file  # noqa: F401 (the fixture)

HEAVY = ("sklearn", "pandas", "scipy", "matplotlib", "joblib")


def _imported_after(args):
    code = (
        "import sys\n"
        "from skmotion.cli import main\n"
        f"status = main({args!r})\n"
        f"print(status, sorted(m for m in {HEAVY!r} if m in sys.modules), 'numpy' in sys.modules)\n"
    )
    result = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    )
    last = result.stdout.strip().splitlines()[-1]
    status, rest = last.split(" ", 1)
    heavy, numpy = rest.rsplit(" ", 1)
    return int(status), heavy, numpy == "True"


def test_help_imports_nothing_heavy_not_even_numpy():
    status, heavy, numpy = _imported_after([])
    assert status == 2
    assert heavy == "[]"
    assert not numpy


def test_info_on_a_bvh_imports_no_sklearn_pandas_or_scipy(bvh_file):  # noqa: F811
    status, heavy, numpy = _imported_after(["info", str(bvh_file)])
    assert status == 0
    assert heavy == "[]"
    assert numpy
