"""The compiled part of skmotion: the beam Viterbi's inner loops.

Everything else is in pyproject.toml.
"""

from Cython.Build import cythonize
from setuptools import Extension, setup

# -fopenmp-simd honours the `omp simd` pragmas of _emission.h (vectorised sums) without
# linking OpenMP.
beam = Extension(
    "skmotion.tree._beam",
    ["skmotion/tree/_beam.pyx"],
    depends=[
        "skmotion/tree/_emission.h",
        "skmotion/tree/_emission.pxd",
        "skmotion/tree/_pairs.pxd",
    ],
    extra_compile_args=["-O3", "-fopenmp-simd"],
)
# The causal stream's per-frame update (tree/_online_stream.py), the same flags.
online = Extension(
    "skmotion.tree._online",
    ["skmotion/tree/_online.pyx"],
    depends=[
        "skmotion/tree/_emission.h",
        "skmotion/tree/_emission.pxd",
        "skmotion/tree/_pairs.pxd",
        "skmotion/tree/_online_state.pxd",
    ],
    extra_compile_args=["-O3", "-fopenmp-simd"],
)
# The answers of one update of the causal stream, filled by _online.
online_state = Extension(
    "skmotion.tree._online_state",
    ["skmotion/tree/_online_state.pyx"],
    extra_compile_args=["-O3"],
)
setup(ext_modules=cythonize([beam, online, online_state]))
