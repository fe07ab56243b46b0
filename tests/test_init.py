import importlib
import pkgutil
import subprocess
import sys

import pytest

import skmotion

PUBLIC_PACKAGES = [
    name
    for _, name, is_pkg in pkgutil.iter_modules(skmotion.__path__, "skmotion.")
    if is_pkg and not name.split(".")[-1].startswith("_")
]


@pytest.mark.parametrize("package", PUBLIC_PACKAGES)
def test_all_entries_resolve_and_are_sorted(package):
    module = importlib.import_module(package)
    assert module.__all__ == sorted(module.__all__)
    for name in module.__all__:
        assert hasattr(module, name), f"{package}.{name} is in __all__ but missing"


def test_top_level_lists_every_public_subpackage():
    listed = {f"skmotion.{name}" for name in skmotion.__all__ if name != "__version__"}
    assert set(PUBLIC_PACKAGES) <= listed
    for name in skmotion.__all__:
        assert getattr(skmotion, name) is not None


def test_import_is_light_and_loads_no_optional_dependency():
    code = (
        "import sys, skmotion, skmotion.datasets, skmotion.preprocessing, skmotion.kinematics; "
        "heavy = [m for m in ('matplotlib', 'dask', 'distributed', 'mujoco', 'hmmlearn', "
        "'tslearn') if m in sys.modules]; "
        "print(heavy)"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    ).stdout
    assert out.strip() == "[]"
    out = subprocess.run(
        [sys.executable, "-c", "import sys, skmotion; print('sklearn' in sys.modules)"],
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    assert out.strip() == "False"
