"""Draw docs/images/architecture.png: skmotion's packages and who imports whom, from the code.

Run from the repository root: ``python docs/images/draw_architecture.py``. Every
``import`` of ``skmotion/`` is read (at module level and inside functions: the
lazy imports of optional parts count too); a package sits above the packages it
imports, and an arrow goes from a package to each package it imports.
"""

import ast
from collections import defaultdict
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.patches import FancyArrowPatch, FancyBboxPatch  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "skmotion"
# What each package holds, in a few words (the picture's labels).
ROLES = {
    "cli": "the skmotion command",
    "_demo": "skmotion demo",
    "planning": "A* on the transition graph",
    "plotting": "figures (matplotlib)",
    "metrics": "pruning, recall",
    "neighbors": "IntervalIndexNeighbors, MotionMatcher,\nfind_occurrences, psi",
    "recognition": "MotionClassifier",
    "live": "GestureDetector, LinearGestureDetector,\nActivitySegmenter",
    "tree": "MotionTree, MotionTreeHMM,\nMotionTreeEncoder",
    "control": "primitives, arm simulation",
    "decomposition": "SVDFeatureExtractor,\nEigenMovementPCA",
    "estimator_checks": "clip conformance checks",
    "datasets": "synthetic and CMU clips",
    "preprocessing": "clip transformers,\nVirtualMarkerTransform",
    "base": "estimator mixins, versioned pickles",
    "io": "motion files",
    "kinematics": "skeletons, layouts, rotations",
    "utils": "check_clips, containers, parallel",
}
SUBPACKAGES = {"tree": ["_build", "_decoder", "_encoding", "_online", "_growth"]}


def unit_of(path):
    """The package (or top-level module) a file of skmotion/ belongs to."""
    parts = path.relative_to(PACKAGE).parts
    return parts[0] if len(parts) > 1 else Path(parts[0]).stem


def imports():
    """``{unit: {imported unit}}`` over every import of every module."""
    edges = defaultdict(set)
    for path in PACKAGE.rglob("*.py"):
        src = unit_of(path)
        if src not in ROLES:  # __init__, __main__: the entry points, not a layer
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            names = []
            if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
                names = [node.module] + [f"{node.module}.{a.name}" for a in node.names]
            elif isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            for name in names:
                parts = name.split(".")
                if parts[0] == "skmotion" and len(parts) > 1 and parts[1] in ROLES:
                    if parts[1] != src:
                        edges[src].add(parts[1])
    return edges


def levels(edges):
    """Each unit's floor: one above the highest unit it imports (0: imports none)."""
    floor = {}

    def visit(unit, seen=()):
        if unit not in floor:
            below = [visit(u, seen + (unit,)) for u in edges.get(unit, ()) if u not in seen]
            floor[unit] = 1 + max(below, default=-1)
        return floor[unit]

    for unit in ROLES:
        visit(unit)
    return floor


def draw(out):
    edges = imports()
    floor = levels(edges)
    rows = defaultdict(list)
    for unit in ROLES:
        rows[floor[unit]].append(unit)
    width, height = 3.3, 1.05
    place = {}
    n_floors = max(rows) + 1
    for level, units in rows.items():
        units.sort(key=lambda u: list(ROLES).index(u))
        span = len(units) * (width + 0.35)
        for i, unit in enumerate(units):
            place[unit] = (i * (width + 0.35) - span / 2 + width / 2, level * 1.9)
    fig, ax = plt.subplots(figsize=(15, 1.35 * n_floors + 1.2))
    for src, targets in edges.items():
        for dst in targets:
            (x0, y0), (x1, y1) = place[src], place[dst]
            upward = floor[dst] >= floor[src]
            arrow = FancyArrowPatch(
                (x0, y0 - height / 2 if not upward else y0 + height / 2),
                (x1, y1 + height / 2 if not upward else y1 - height / 2),
                arrowstyle="-|>",
                mutation_scale=11,
                color="#c0392b" if upward else "#5d6d7e",
                lw=1.6 if upward else 0.8,
                alpha=0.9 if upward else 0.5,
                connectionstyle="arc3,rad=0.04",
                zorder=1,
            )
            ax.add_patch(arrow)
    for unit, (x, y) in place.items():
        is_module = (PACKAGE / f"{unit}.py").exists()
        box = FancyBboxPatch(
            (x - width / 2, y - height / 2),
            width,
            height,
            boxstyle="round,pad=0.02,rounding_size=0.08",
            facecolor="#fdf2e9" if is_module else "#eaf2f8",
            edgecolor="#2c3e50",
            lw=1.0,
            zorder=2,
        )
        ax.add_patch(box)
        title = f"{unit}.py" if is_module else f"{unit}/"
        ax.text(x, y + 0.25, title, ha="center", va="center", fontsize=10, weight="bold", zorder=3)
        ax.text(x, y - 0.08, ROLES[unit], ha="center", va="center", fontsize=8, zorder=3)
        subs = SUBPACKAGES.get(unit)
        if subs:
            label = "sub-packages " + " ".join(f"{s}/" for s in subs)
            ax.text(x, y - 0.36, label, ha="center", va="center", fontsize=6.5, style="italic")
    xs = [p[0] for p in place.values()]
    ax.set_xlim(min(xs) - width, max(xs) + width)
    ax.set_ylim(-1.0, (n_floors - 1) * 1.9 + 1.0)
    ax.axis("off")
    ax.set_title(
        "skmotion's packages: each sits above what it imports (arrows point to the imported "
        "package; red would be an import that runs up)",
        fontsize=10.5,
    )
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    upward = [(s, d) for s, ts in edges.items() for d in ts if floor[d] >= floor[s]]
    return upward


if __name__ == "__main__":
    found = draw(ROOT / "docs" / "images" / "architecture.png")
    print("imports that run up:", found or "none")
