"""The compiled parts of skmotion: the motion database's decoders, the online stream,
the body frame of point trajectories, the similarity search's eigenpairs and psi, and the
occurrence search's sliding statistics and subsequence DTW.

Everything else is in pyproject.toml.
"""

from Cython.Build import cythonize
from setuptools import Extension, setup


def tree_modules(names, pxd):
    """Compiled modules of the tree decoders: the loops of _emission.h, the same flags.

    ``pxd``: the declarations they share (their structs and cimported functions), on which
    each module depends as on _emission.h.
    """
    shared = ["_emission.h", "_emission.pxd", "_pairs.pxd", *pxd]
    return [
        Extension(
            f"skmotion.tree.{name}",
            [f"skmotion/tree/{name}.pyx"],
            depends=[f"skmotion/tree/{file}" for file in shared],
            extra_compile_args=["-O3", "-fopenmp-simd"],
        )
        for name in names
    ]


# -fopenmp-simd honours the `omp simd` pragmas of _emission.h (vectorised sums) without
# linking OpenMP. The beam search: the search itself (_beam), a layer's candidates and
# emissions (_beam_candidates), its memory (_beam_memory) and the scoring passes
# (_beam_passes), over the structs of _beam_structs.pxd.
beam = tree_modules(
    ["_beam", "_beam_candidates", "_beam_memory", "_beam_passes"],
    ["_beam_structs.pxd", "_beam_candidates.pxd", "_beam_memory.pxd", "_beam_passes.pxd"],
)
# The causal stream's per-frame update (tree/_online_stream.py): the kernel (_online), its
# per-frame work (_online_step) and answers (_online_answers) over the C state of
# _online_structs.pxd, and the answers object it fills (_online_state).
online = tree_modules(
    ["_online", "_online_answers", "_online_state", "_online_step"],
    ["_online_structs.pxd", "_online_answers.pxd", "_online_state.pxd", "_online_step.pxd"],
)
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
# psi distances of a leaf's queries to its candidates (neighbors/_ranking.py).
psi_rank = Extension(
    "skmotion.neighbors._psi_rank",
    ["skmotion/neighbors/_psi_rank.pyx"],
    extra_compile_args=["-O3"],
)
# Sliding window statistics and subsequence DTW of the occurrence search
# (neighbors/_occurrences.py).
occurrence_loops = Extension(
    "skmotion.neighbors._occurrence_loops",
    ["skmotion/neighbors/_occurrence_loops.pyx"],
    extra_compile_args=["-O3"],
)
setup(ext_modules=cythonize([*beam, *online, position_frame, leading, psi_rank, occurrence_loops]))
