"""Eigenmovements and primitives: the paper's error tables, fit time, PD tracking.

Run: ``python benchmarks/bench_primitives.py``. Writes three results files:

- ``primitives_errors_cmu`` and ``primitives_errors_synthetic``: the eigenmovement
  paper's Tables 1-3 (projection MSE against the number of eigenmovements, clustering
  MSE against the number of clusters, total RMS error) and train-vs-test RMS, for both
  segmentation rules, on the right arm's 4 DOF (the paper's shoulder 3 + elbow): CMU
  subjects 01-03 (``rhumerus`` rx ry rz, ``rradius`` rx; ASF/AMC at 120 Hz, from
  ``../shared/data``) and make_motions (``RightArm`` Z X Y, ``RightForeArm`` X). Both
  readers give radians; the clips are converted to degrees first (CMU angles unwrapped
  in time first), so every error is in degrees as in the paper. Segments are split
  75/25 into train and test at random.
- ``primitives_fit_time``: EigenMovementPCA + KMeansPrimitiveController fitted on
  clips, against sklearn PCA + KMeans fitted on the same segment vectors already
  made (the ratio is the overhead of filtering, segmenting and resampling).
- ``primitives_arm``: tracking error of PD servos on the MuJoCo arm executing the
  primitives, against the gains, and the simulation speed.
"""

import sys
from pathlib import Path

import numpy as np
from sklearn.cluster import KMeans
from sklearn.decomposition import PCA
from threadpoolctl import threadpool_limits

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import SHARED_DATA, interleaved, time_call, write_results  # noqa: E402

from skmotion.control import ArmModel, KMeansPrimitiveController  # noqa: E402
from skmotion.datasets import load_cmu_asfamc, make_motions  # noqa: E402
from skmotion.decomposition import EigenMovementPCA  # noqa: E402
from skmotion.preprocessing import segment_clip  # noqa: E402

N_SAMPLES = 100
MIN_MOVEMENT = 2.0  # degrees: SEG-1's movement threshold, and the same for SEG-2
RULES = {"SEG-1 (zvc)": "zvc", "SEG-2 (energy)": "energy"}


def right_arm_degrees(n_clips_per_class, random_state=0):
    data = make_motions(n_clips_per_class=n_clips_per_class, random_state=random_state)
    sk = data.skeleton
    arm = ArmModel.from_skeleton(
        sk, ["RightArm", "RightForeArm"], dofs=["ZXY", "X"], end="RightHand_end"
    )
    idx = [sk.channel_names.index(n) for n in arm.dof_names]
    return data, arm, [np.degrees(c[:, idx]) for c in data.clips]


def cmu_right_arm_degrees():
    """CMU subjects 01-03, right arm, degrees; None without the shared data."""
    folder = SHARED_DATA / "cmu-asfamc"
    if not folder.is_dir():
        return None
    data = load_cmu_asfamc(folder, SHARED_DATA / "cmu-index.csv", subjects=[1, 2, 3])
    clips = []
    for motion in data.motions:
        names = motion.channel_names
        idx = [
            names.index(n)
            for n in (
                "rhumerus_Xrotation",
                "rhumerus_Yrotation",
                "rhumerus_Zrotation",
                "rradius_Xrotation",
            )
        ]
        clips.append(np.degrees(np.unwrap(motion.channels[:, idx], axis=0)))
    return data, clips


def cut_segments(clips, rule, frame_rate):
    pieces = []
    for clip in clips:
        for start, stop in segment_clip(
            clip, rule=rule, frame_rate=frame_rate, min_movement=MIN_MOVEMENT
        ):
            pieces.append(clip[start:stop])
    return pieces


def _flat(normalised):
    n_segments, n_samples, n_channels = normalised.shape
    return normalised.transpose(0, 2, 1).reshape(n_segments, n_samples * n_channels)


def per_segment_rms(pca, segments, codes):
    """RMS error per sample of each segment rebuilt from ``codes`` (normalised time)."""
    vectors = np.concatenate(pca.segment_vectors(segments))
    rebuilt = np.concatenate([_flat(n) for n in pca.inverse_transform(codes)])
    return np.sqrt(np.mean((vectors - rebuilt) ** 2, axis=1))


def error_tables(clips, frame_rate):
    rng = np.random.default_rng(0)
    rows = []
    n_features = N_SAMPLES * clips[0].shape[1]
    for name, rule in RULES.items():
        segments = cut_segments(clips, rule, frame_rate)
        order = rng.permutation(len(segments))
        n_train = int(round(0.75 * len(segments)))
        train = [segments[i] for i in order[:n_train]]
        test = [segments[i] for i in order[n_train:]]
        for k in (10, 20, 30, 40):
            pca = EigenMovementPCA(k, n_samples=N_SAMPLES, segmentation="none").fit(train)
            test_rms = per_segment_rms(pca, test, pca.transform(test))
            rows.append(
                {
                    "table": "1 projection",
                    "segmentation": name,
                    "n_segments (train/test)": f"{len(train)}/{len(test)}",
                    "eigenvectors": k,
                    "clusters": "-",
                    "MSE (deg^2 per segment)": pca.projection_mse_,
                    "RMS train (deg)": np.sqrt(pca.projection_mse_ / n_features),
                    "RMS test (deg)": float(np.sqrt(np.mean(test_rms**2))),
                }
            )
        pca = EigenMovementPCA(30, n_samples=N_SAMPLES, segmentation="none").fit(train)
        train_codes, test_codes = pca.transform(train), pca.transform(test)
        for n_clusters in (10, 20, 30, 100):
            controller = KMeansPrimitiveController(n_clusters, random_state=0).fit(train_codes)
            total = pca.projection_mse_ + controller.clustering_mse_
            train_rms = per_segment_rms(pca, train, controller.quantize(train_codes))
            test_rms = per_segment_rms(pca, test, controller.quantize(test_codes))
            measured = float(np.mean(train_rms**2) * n_features)
            assert np.isclose(measured, total, rtol=1e-8), (measured, total)
            rows.append(
                {
                    "table": "2-3 clustering, total",
                    "segmentation": name,
                    "n_segments (train/test)": f"{len(train)}/{len(test)}",
                    "eigenvectors": 30,
                    "clusters": n_clusters,
                    "MSE (deg^2 per segment)": controller.clustering_mse_,
                    "RMS train (deg)": float(np.sqrt(total / n_features)),
                    "RMS test (deg)": float(np.sqrt(np.mean(test_rms**2))),
                    "median RMS train/test (deg)": (
                        f"{np.median(train_rms):.2f}/{np.median(test_rms):.2f}"
                    ),
                }
            )
    for row in rows:
        row.setdefault("median RMS train/test (deg)", "-")
    return rows


def fit_times(clips, frame_rate):
    rows = []
    for n_clips in (35, 70, 140, len(clips)):
        subset = clips[:n_clips]
        pca = EigenMovementPCA(30, frame_rate=frame_rate, min_movement=MIN_MOVEMENT).fit(subset)
        vectors = np.concatenate(pca.segment_vectors(subset))
        codes = pca.transform(subset)
        seed = KMeansPrimitiveController(30, random_state=0).fit(codes).kmeans_.random_state

        def skmotion_fit():
            codes = EigenMovementPCA(
                30, frame_rate=frame_rate, min_movement=MIN_MOVEMENT
            ).fit_transform(subset)
            KMeansPrimitiveController(30, n_init=10, random_state=0).fit(codes)

        def sklearn_fit():  # the same K-means start as the controller's
            codes = PCA(30, svd_solver="full").fit_transform(vectors)
            KMeans(30, n_init=10, random_state=seed).fit(codes)

        ours, theirs, prep, eigen, plain = interleaved(
            [
                skmotion_fit,
                sklearn_fit,
                lambda: pca.segment_vectors(subset),
                lambda: EigenMovementPCA(30, frame_rate=frame_rate, min_movement=MIN_MOVEMENT).fit(
                    subset
                ),
                lambda: PCA(30, svd_solver="full").fit(vectors),
            ],
            rounds=7,
        )
        rows.append(
            {
                "clips": n_clips,
                "segments": len(vectors),
                "frames": sum(len(c) for c in subset),
                "skmotion_fit_ms": 1e3 * ours,
                "sklearn_PCA+KMeans_ms": 1e3 * theirs,
                "ratio": ours / theirs,
                "EigenMovementPCA.fit_ms": 1e3 * eigen,
                "sklearn_PCA.fit_ms": 1e3 * plain,
                "filter+segment+resample_ms": 1e3 * prep,
            }
        )
    return rows


def arm_tracking(data, arm, clips):
    pca = EigenMovementPCA(30, frame_rate=data.frame_rate, min_movement=MIN_MOVEMENT).fit(clips)
    codes, segments = pca.transform(clips), pca.segment(clips)
    controller = KMeansPrimitiveController(30, random_state=0).fit(codes)
    chosen = [int(np.flatnonzero(data.target == c)[0]) for c in range(len(data.target_names))]
    seconds = sum(len(clips[i]) for i in chosen) / data.frame_rate
    rows = []
    for kp in (25.0, 100.0, 400.0, 1600.0):

        def run(kp=kp):
            return controller.simulate(
                [codes[i] for i in chosen],
                [segments[i] for i in chosen],
                eigenmovements=pca,
                arm=arm,
                frame_rate=data.frame_rate,
                degrees=True,
                kp=kp,
                kd=kp / 10,
            )

        elapsed, _ = time_call(run, repeats=1, warmup=0)
        sims = run()
        errors = np.concatenate([(s.angles - s.desired).ravel() for s in sims])
        worst = max(np.nanmax(np.abs(s.torques)) for s in sims)
        rows.append(
            {
                "kp (N m/rad)": kp,
                "kd (N m s/rad)": kp / 10,
                "RMS tracking error (deg)": float(np.degrees(np.sqrt(np.nanmean(errors**2)))),
                "peak torque (N m)": float(worst),
                "simulated s": seconds,
                "wall s": elapsed,
                "x real time": seconds / elapsed,
            }
        )
    return rows


TABLE_NOTES = (
    "100 samples per channel and segment (400-D vectors); segments with movement above "
    f"{MIN_MOVEMENT} deg; 75/25 random split of the segments. MSE is per segment vector (sum of "
    "the 400 squared errors); RMS is per sample, sqrt(MSE / 400). Table 1 rows: projection only. "
    "Table 2-3 rows: 30 eigenvectors, segments replaced by their cluster centre; RMS train = "
    "sqrt((projection MSE + clustering MSE) / 400), checked against the measured error; the last "
    "column is the median over segments of their RMS (the paper's 19.4 train / 22.3 test degrees)."
)


def main():
    data, arm, clips = right_arm_degrees(30)
    # One thread (BLAS and OpenMP) for skmotion and sklearn alike: on a shared
    # 2-core machine, spinning worker threads make timings meaningless.
    with threadpool_limits(limits=1):
        cmu = cmu_right_arm_degrees()
        if cmu is None:
            print(f"CMU tables skipped: no data at {SHARED_DATA / 'cmu-asfamc'}")
        else:
            cmu_data, cmu_clips = cmu
            write_results(
                "primitives_errors_cmu",
                error_tables(cmu_clips, cmu_data.frame_rate),
                notes=(
                    f"CMU subjects 01-03: {len(cmu_clips)} trials, "
                    f"{sum(len(c) for c in cmu_clips):,} frames at {cmu_data.frame_rate:g} Hz; "
                    "right arm (rhumerus rx ry rz, rradius rx) in degrees. " + TABLE_NOTES
                ),
            )
        write_results(
            "primitives_errors_synthetic",
            error_tables(clips, data.frame_rate),
            notes=(
                f"make_motions(n_clips_per_class=30, random_state=0): {len(clips)} clips at 30 Hz, "
                "right arm (RightArm Z X Y, RightForeArm X) in degrees. " + TABLE_NOTES
            ),
        )
        write_results(
            "primitives_fit_time",
            fit_times(clips, data.frame_rate),
            notes=(
                "Fit on the right-arm clips: skmotion EigenMovementPCA(30, SEG-2) + "
                "KMeansPrimitiveController(30) from clips, against sklearn PCA(30) + KMeans(30) on "
                "the same segment vectors made beforehand (same K-means seed); median of 7 "
                "interleaved rounds, one thread. The last three columns split it: "
                "EigenMovementPCA alone, sklearn PCA alone, and the making of the vectors (filter, "
                "segment, resample)."
            ),
        )
        write_results(
            "primitives_arm",
            arm_tracking(data, arm, clips),
            notes=(
                "One clip of each class, rebuilt from its 30 K-means primitives (30 "
                "eigenmovements), executed on the MuJoCo arm (upper arm 0.29 m, forearm and hand "
                "0.44 m, cylinders of density 1050) by PD servos without gravity compensation, "
                "1 ms steps."
            ),
        )


if __name__ == "__main__":
    main()
