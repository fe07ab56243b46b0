"""The compiled parts of skmotion: the motion database's decoders, the online stream,
the body frame of point trajectories, the similarity search's eigenpairs and psi, and the
occurrence search's sliding statistics and subsequence DTW.

Everything else is in pyproject.toml.
"""

from Cython.Build import cythonize
from setuptools import Extension, setup


def tree_modules(package, names, pxd):
    """Compiled modules of a tree sub-package: the loops of _decoder/_emission.h, the same flags.

    ``pxd``: the declarations they share (their structs and cimported functions), on which
    each module depends as on _emission.h.
    """
    shared = [
        f"skmotion/tree/_decoder/{file}" for file in ("_emission.h", "_emission.pxd", "_pairs.pxd")
    ]
    return [
        Extension(
            f"skmotion.tree.{package}.{name}",
            [f"skmotion/tree/{package}/{name}.pyx"],
            depends=shared + [f"skmotion/tree/{package}/{file}" for file in pxd],
            include_dirs=["skmotion/tree/_decoder"],  # _emission.h, for _online's modules too
            extra_compile_args=["-O3", "-fopenmp-simd"],
        )
        for name in names
    ]


def module(name, *flags):
    """The compiled module ``name`` (dotted) from its ``.pyx`` file, at -O3 and ``flags``."""
    return Extension(name, [name.replace(".", "/") + ".pyx"], extra_compile_args=["-O3", *flags])


# -fopenmp-simd honours the `omp simd` pragmas of _emission.h (vectorised sums) without
# linking OpenMP. The compiled decoder (tree/_decoder/): the beam search itself (_beam), a
# layer's candidates and emissions (_beam_candidates), its memory (_beam_memory) and the
# scoring passes (_beam_passes), over the structs of _beam_structs.pxd.
beam = tree_modules(
    "_decoder",
    ["_beam", "_beam_candidates", "_beam_memory", "_beam_passes"],
    ["_beam_structs.pxd", "_beam_candidates.pxd", "_beam_memory.pxd", "_beam_passes.pxd"],
)
# The causal stream's per-frame update (tree/_online/, used by its _causal.py): the kernel
# (_kernel), its per-frame work (_step) and answers (_answers) over the C state of
# _structs.pxd, and the answers object it fills (_state).
online = tree_modules(
    "_online",
    ["_kernel", "_answers", "_state", "_step"],
    ["_structs.pxd", "_answers.pxd", "_state.pxd", "_step.pxd"],
)
# The body frame of point trajectories, one pass over the frames (preprocessing/_position_frame).
position_frame = module("skmotion.preprocessing._position_frame_loops")
# Leading eigenpairs of each clip's Gram matrix (decomposition/_clip_svd.py): SciPy's
# BLAS/LAPACK through the pointers SciPy exports, so no build-time SciPy.
leading = module("skmotion.decomposition._leading")
# psi distances of a leaf's queries to its candidates (neighbors/_ranking.py).
psi_rank = module("skmotion.neighbors._psi_rank")
# A leaf's items filtered by the levels the interval index does not materialise, and
# Euclidean distances of a leaf's queries to its candidates (neighbors/_interval_index.py,
# neighbors/_stored_clips.py).
leaf_kernels = module("skmotion.neighbors._leaf_kernels")
# Sliding window statistics and subsequence DTW of the occurrence search
# (neighbors/_occurrences.py); no errno from sqrt and no trapping comparisons, so the
# distance loop's selects are branch-free and the loop is vectorised.
occurrence_loops = module(
    "skmotion.neighbors._occurrence_loops", "-fno-math-errno", "-fno-trapping-math"
)
# Weighted sums of rows per group, in row order (utils/_group_sums, the tree encoder's
# per-clip sums); no contraction, so each product is rounded before it is added, as SciPy's
# sparse product rounds it (the same doubles).
group_sums = module("skmotion.utils._group_sums", "-ffp-contract=off")
# A node's rows reordered in place along the permutation's cycles (tree/_build/_permute):
# the build keeps no second copy of the frames.
permute = module("skmotion.tree._build._permute")
# A tree node's moments (centred in cached chunks, one dsyrk each) and the partition of its
# rows at a cut, in place and without the GIL (tree/_build/_node_passes, the build's passes).
node_passes = module("skmotion.tree._build._node_passes")
# Frames walked down a motion tree, each on its own path (one dot product per layer), one
# compiled loop instead of array operations per layer (tree/_encoding/_routing, the router).
walk = module("skmotion.tree._encoding._walk")
# The encoder's residuals, moments and magnitude check, one pass over each clip's frames
# (tree/_encoding/_histograms); no contraction: the doubles of the NumPy expressions.
readout_passes = module("skmotion.tree._encoding._readout_passes", "-ffp-contract=off")
# Frame features and window scores of the linear gesture detector, one frame at a time
# (live/_linear_detector.py).
live_window = module("skmotion.live._window_kernel")
# The best label path of a long take under a switch penalty (live/_segmenter.py).
live_path = module("skmotion.live._switch_path")
# Forward kinematics, one pass over frames and joints (kinematics/_forward.py).
forward_loops = module("skmotion.kinematics._forward_loops")
# Each clip's channel covariance, its triangle row by row, one dsyrk per clip
# (recognition/_motion_classifier.clip_covariances).
covariance_rows = module("skmotion.recognition._covariance_rows")
# SciPy's BLAS and LAPACK functions looked up through the pointers SciPy exports, for the
# modules above that call them (_leading, _node_passes, _covariance_rows): no build-time SciPy.
scipy_blas = module("skmotion.utils._scipy_blas")
setup(
    ext_modules=cythonize(
        [
            *beam,
            *online,
            position_frame,
            leading,
            psi_rank,
            leaf_kernels,
            occurrence_loops,
            group_sums,
            permute,
            node_passes,
            walk,
            readout_passes,
            live_window,
            live_path,
            forward_loops,
            covariance_rows,
            scipy_blas,
        ]
    )
)
