"""The compiled part of skmotion: the beam Viterbi's inner loops.

Everything else is in pyproject.toml.
"""

from Cython.Build import cythonize
from setuptools import Extension, setup

# -fopenmp-simd honours the `omp simd` pragmas of _emission.h (vectorised sums) without
# linking OpenMP. The search is four modules sharing the structs of _beam_structs.pxd: the
# search itself (_beam), a layer's candidates and emissions (_beam_candidates), its memory
# (_beam_memory) and the scoring passes (_beam_passes).
beam_depends = [
    "skmotion/tree/_beam_structs.pxd",
    "skmotion/tree/_beam_candidates.pxd",
    "skmotion/tree/_beam_memory.pxd",
    "skmotion/tree/_beam_passes.pxd",
    "skmotion/tree/_emission.h",
    "skmotion/tree/_emission.pxd",
    "skmotion/tree/_pairs.pxd",
]
beam = [
    Extension(
        f"skmotion.tree.{name}",
        [f"skmotion/tree/{name}.pyx"],
        depends=beam_depends,
        extra_compile_args=["-O3", "-fopenmp-simd"],
    )
    for name in ("_beam", "_beam_candidates", "_beam_memory", "_beam_passes")
]
# The causal stream's per-frame update (tree/_online_stream.py), the same flags: the kernel
# (_online), its per-frame work (_online_step) and answers (_online_answers) over the C state of
# _online_structs.pxd, and the answers object it fills (_online_state).
online_depends = [
    "skmotion/tree/_online_structs.pxd",
    "skmotion/tree/_online_answers.pxd",
    "skmotion/tree/_online_state.pxd",
    "skmotion/tree/_online_step.pxd",
    "skmotion/tree/_emission.h",
    "skmotion/tree/_emission.pxd",
    "skmotion/tree/_pairs.pxd",
]
online = [
    Extension(
        f"skmotion.tree.{name}",
        [f"skmotion/tree/{name}.pyx"],
        depends=online_depends,
        extra_compile_args=["-O3", "-fopenmp-simd"],
    )
    for name in ("_online", "_online_answers", "_online_state", "_online_step")
]
# The body frame of point trajectories, one pass over the frames (preprocessing/_position_frame).
position_frame = Extension(
    "skmotion.preprocessing._position_frame_loops",
    ["skmotion/preprocessing/_position_frame_loops.pyx"],
    extra_compile_args=["-O3"],
)
# Leading eigenpairs of each clip's Gram matrix (decomposition/_clip_svd.py): SciPy's
# BLAS/LAPACK through the pointers SciPy exports, so no build-time SciPy.
leading = Extension(
    "skmotion.decomposition._leading",
    ["skmotion/decomposition/_leading.pyx"],
    extra_compile_args=["-O3"],
)
# psi distances of a leaf's queries to its candidates (neighbors/_interval_neighbors.py).
psi_rank = Extension(
    "skmotion.neighbors._psi_rank",
    ["skmotion/neighbors/_psi_rank.pyx"],
    extra_compile_args=["-O3"],
)
setup(ext_modules=cythonize([*beam, *online, position_frame, leading, psi_rank]))
