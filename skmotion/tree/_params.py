"""The paper's literal settings of MotionTreeHMM, one call away from the measured defaults."""

__all__ = ["PAPER_SETTINGS"]

#: Yamane, Yamaguchi and Nakamura (2011) as published: minimum-error thresholding, no depth
#: limit, at least 16 frames per node, full Gaussian covariances of the frames as given (no
#: standardisation), one transition graph per training clip with the uniform node prior over
#: the nodes that graph's clip visits, and the generation probability at the bottom layer
#: alone, summed over the top few (here 3) node sequences. ``MotionTreeHMM(**PAPER_SETTINGS)``
#: builds it; the defaults differ where measurements on every development data set favoured
#: other settings (see the user guide, ``docs/motion-database.md``).
PAPER_SETTINGS = {
    "split": "min_error",
    "max_depth": None,
    "min_samples_leaf": 16,
    "covariance_type": "full",
    "standardize": False,
    "graph": "clip",
    "node_prior": "graph",
    "score_layers": 1,
    "layer": None,
    "n_paths": 3,
}
