"""Which joint of a humanoid skeleton is which: a matcher over joint-name tokens and topology.

Rigs name the same joints in many ways (``LeftArm``, ``UpperArm_L``,
``l_upperarm``, ``mixamorig:LeftArm``, ``Bip01 L UpperArm``, ``upperarm_l``,
``L_Shoulder``, ``lhumerus``). A name is cut into tokens (namespace, case
changes, separators, digits), the side is read from a ``left``/``l`` or
``right``/``r`` token (or a glued ``l``/``r`` before a known word, as in
CMU's ``lhumerus``), and the rest of the tokens, joined, is looked up in a
small vocabulary of segments. Words mean different joints in different rigs
(``LeftShoulder`` is the clavicle in Mixamo, ``L_Shoulder`` the shoulder
joint in SMPL), so the names only pick the end of each limb; the chain from
the root decides the rest: the wrist's nearest ancestor named like an elbow
(else its parent) is the elbow, the elbow's nearest ancestor named like an
upper arm is the shoulder, and so on. Fingers, twist and roll bones and
helpers never take a role. The trunk comes from the limbs: the chest is
where the two arms branch, the pelvis where the two legs do. When the names
say too little (``bone_07``), the tree alone is read: the first 3-way forks
from the root are the pelvis and the chest, the chest's two longest
branches the arms, the pelvis's two others the legs, and left is up x
forward, forward being the way the feet point in the rest pose.
"""

import re
from dataclasses import dataclass, field

import numpy as np

__all__ = ["JointMatch", "match_joints"]

_LIMBS = {
    "clavicle": {"clavicle", "collar", "collarbone", "shoulder", "scapula"},
    "shoulder": {"upperarm", "arm", "humerus", "uparm", "shoulder"},
    "elbow": {"forearm", "lowerarm", "elbow", "radius", "ulna", "lowarm"},
    "wrist": {"hand", "wrist"},
    "hip": {"upleg", "upperleg", "thigh", "femur", "hip"},
    "knee": {"leg", "lowerleg", "calf", "shin", "knee", "tibia", "lowleg", "shank"},
    "ankle": {"foot", "ankle"},
    "toe": {"toe", "toes", "toebase", "ball"},
}
_CENTRE = {
    "head": {"head"},
    "neck": {"neck", "upperneck", "lowerneck"},
    "spine": {
        "spine",
        "chest",
        "upperchest",
        "torso",
        "back",
        "upperback",
        "lowerback",
        "thorax",
        "abdomen",
        "waist",
    },
    "pelvis": {"hips", "pelvis", "hip", "root"},
}
# Tokens of joints that never take a role, and tokens that carry no meaning.
_SKIP = {
    "index",
    "middle",
    "mid",
    "ring",
    "pinky",
    "little",
    "thumb",
    "finger",
    "fingers",
    "twist",
    "roll",
    "helper",
    "ik",
    "pole",
    "target",
    "nub",
    "end",
    "site",
    "top",
    "metacarpal",
    "carpal",
    "eye",
    "jaw",
    "tongue",
    "brow",
    "ear",
    "prop",
    "weapon",
}
_NOISE = {"bip", "mixamorig", "cc", "base", "def", "jnt", "joint", "bone", "b", "j", "mch", "org"}
_LEFT, _RIGHT = {"left", "l", "lf", "lft"}, {"right", "r", "rt", "rgt"}
_WORDS = set().union(*_LIMBS.values(), *_CENTRE.values())


def _tokens(name):
    name = name.rsplit(":", 1)[-1].rsplit("|", 1)[-1]
    parts = re.findall(r"[A-Z]+(?![a-z])|[A-Z]?[a-z]+|\d+", name)
    return [p.lower() for p in parts]


def _parse(name):
    """(side or None, the joined segment word, skipped) of a joint name."""
    tokens = [t for t in _tokens(name) if not t.isdigit() and t not in _NOISE]
    side = None
    words = []
    for t in tokens:
        if t in _LEFT or t in _RIGHT:
            side = "left" if t in _LEFT else "right"
        elif t[0] in "lr" and t[1:] in _WORDS and t not in _WORDS:
            side = "left" if t[0] == "l" else "right"  # CMU: lhumerus, rfemur
            words.append(t[1:])
        else:
            words.append(t)
    skipped = bool(set(words) & _SKIP)
    # The longest run of tokens that is a known word ("Character1_LeftUpLeg" -> "upleg").
    runs = ["".join(words[i:j]) for i in range(len(words)) for j in range(i + 1, len(words) + 1)]
    known = [r for r in runs if r in _WORDS]
    return side, max(known, key=len) if known else "".join(words), skipped


@dataclass
class JointMatch:
    """The joints of a humanoid skeleton found by :func:`match_joints`.

    Attributes
    ----------
    roles : dict of str to str
        Role (``"head"``, ``"neck"``, ``"chest"``, ``"spine"``, ``"pelvis"``,
        ``"head_end"``, ``"left_shoulder"``, ``"right_knee"``, ... with
        ``clavicle``, ``shoulder``, ``elbow``, ``wrist``, ``hand_end``,
        ``hip``, ``knee``, ``ankle``, ``toe`` per side) to joint name.
    how : dict of str to str
        Per role, ``"name"`` (the joint's name says it) or ``"topology"``
        (its place in the chain from the root does).
    up_axis : {"x", "y", "z"}
        The axis along which the rest pose's head is farthest from its feet.
    missing : list of str
        Roles no joint took (a clavicle on a rig without one, ...).
    """

    roles: dict
    how: dict
    up_axis: str
    missing: list = field(default_factory=list)

    def report(self):
        """One line per role: the joint and how it was found.

        Returns
        -------
        text : str
        """
        lines = [f"{role:<16} {joint:<28} ({self.how[role]})" for role, joint in self.roles.items()]
        lines += [f"{role:<16} -" for role in self.missing]
        return "\n".join(lines + [f"up axis: {self.up_axis} (head above feet in the rest pose)"])


class _Tree:
    def __init__(self, skeleton):
        self.names = list(skeleton.joints)
        self.parents = list(skeleton.parents)
        self.children = [[] for _ in self.names]
        for j, p in enumerate(self.parents):
            if p >= 0:
                self.children[p].append(j)
        self.parsed = [_parse(n) for n in self.names]
        self.is_end = [not c for c in skeleton.channels]

    def ancestors(self, j):
        out = []
        while self.parents[j] >= 0:
            j = self.parents[j]
            out.append(j)
        return out

    def is_(self, j, words, side=None):
        s, word, skipped = self.parsed[j]
        return not skipped and word in words and (side is None or s == side)

    def depth(self, j):
        return len(self.ancestors(j))


def _limb_end(tree, side, words, avoid=()):
    """The root-most joint of ``side`` named by ``words`` (the top of a limb's end part)."""
    found = [j for j in range(len(tree.names)) if tree.is_(j, words, side) and j not in avoid]
    return min(found, key=tree.depth) if found else None


def _up_chain(tree, start, words, side, how, role, roles):
    """The nearest ancestor of ``start`` named by ``words``, else its parent (topology)."""
    for a in tree.ancestors(start):
        if tree.is_(a, words, side):
            roles[role], how[role] = a, "name"
            return a
    parent = tree.parents[start]
    if parent >= 0 and tree.parsed[parent][0] in (side, None):
        roles[role], how[role] = parent, "topology"
        return parent
    return None


def _limb(tree, side, roles, how, end, middle):
    """A limb's end joint (found by name) and the joint above it: ``(None, None)`` without one."""
    joint = _limb_end(tree, side, _LIMBS[end])
    if joint is None:
        return None, None
    roles[f"{side}_{end}"], how[f"{side}_{end}"] = joint, "name"
    return joint, _up_chain(tree, joint, _LIMBS[middle], side, how, f"{side}_{middle}", roles)


def _arm(tree, side, roles, how):
    wrist, elbow = _limb(tree, side, roles, how, "wrist", "elbow")
    if elbow is None:
        return
    shoulder = _up_chain(tree, elbow, _LIMBS["shoulder"], side, how, f"{side}_shoulder", roles)
    if shoulder is None:
        return
    parent = tree.parents[shoulder]
    if parent >= 0 and tree.parsed[parent][0] == side and not tree.parsed[parent][2]:
        roles[f"{side}_clavicle"] = parent
        how[f"{side}_clavicle"] = "name" if tree.is_(parent, _LIMBS["clavicle"]) else "topology"
    children = tree.children[wrist]
    if children:
        # The hand's end: a child named like a hand (CMU's lhand), else the middle finger.
        named = [c for c in children if tree.parsed[c][1] == "hand"]
        middle = [c for c in children if "mid" in tree.names[c].lower()]
        end = (named or middle or children)[0]
        roles[f"{side}_hand_end"], how[f"{side}_hand_end"] = end, "topology"


def _leg(tree, side, roles, how):
    ankle, knee = _limb(tree, side, roles, how, "ankle", "knee")
    if ankle is None:
        return
    if knee is not None:
        _up_chain(tree, knee, _LIMBS["hip"], side, how, f"{side}_hip", roles)
    toes = [j for j in _descendants(tree, ankle) if tree.is_(j, _LIMBS["toe"])]
    if toes:
        roles[f"{side}_toe"], how[f"{side}_toe"] = toes[0], "name"
    elif tree.children[ankle]:
        roles[f"{side}_toe"], how[f"{side}_toe"] = tree.children[ankle][0], "topology"


def _descendants(tree, j):
    out, queue = [], list(tree.children[j])
    while queue:
        k = queue.pop(0)
        out.append(k)
        queue += tree.children[k]
    return out


def _common_ancestor(tree, a, b):
    chain = [a, *tree.ancestors(a)]
    for j in [b, *tree.ancestors(b)]:
        if j in chain:
            return j
    return None


def _trunk(tree, roles, how, rest):
    """Chest, pelvis, spine, neck and head from where the limbs branch, and the names."""
    arms = [roles.get(f"{s}_clavicle", roles.get(f"{s}_shoulder")) for s in ("left", "right")]
    legs = [roles.get(f"{s}_hip") for s in ("left", "right")]
    if None not in arms:
        roles["chest"], how["chest"] = _common_ancestor(tree, *arms), "topology"
    if None not in legs:
        roles["pelvis"], how["pelvis"] = _common_ancestor(tree, *legs), "topology"
    named_pelvis = [j for j in range(len(tree.names)) if tree.is_(j, _CENTRE["pelvis"], None)]
    if "pelvis" not in roles and named_pelvis:
        roles["pelvis"], how["pelvis"] = min(named_pelvis, key=tree.depth), "name"
    heads = [j for j in range(len(tree.names)) if tree.is_(j, _CENTRE["head"], None)]
    if heads:
        head = min(heads, key=tree.depth)
        roles["head"], how["head"] = head, "name"
    elif "chest" in roles and "head" not in roles:
        # The longest chain from the chest that holds no arm: its last joint with children.
        arm_joints = {j for s in ("left", "right") for j in [roles.get(f"{s}_shoulder")] if j}
        best = None
        for leaf in _descendants(tree, roles["chest"]):
            path = [leaf, *tree.ancestors(leaf)]
            if tree.children[leaf] or arm_joints & set(path):
                continue
            if best is None or len(path) > len(best):
                best = path
        if best is not None and len(best) > 1:
            roles["head"], how["head"] = (best[1] if len(best) > 2 else best[0]), "topology"
    if "head" in roles:
        head = roles["head"]
        if tree.children[head]:
            roles["head_end"], how["head_end"] = tree.children[head][0], "topology"
        neck = [a for a in tree.ancestors(head) if tree.is_(a, _CENTRE["neck"], None)]
        if neck:
            roles["neck"], how["neck"] = neck[0], "name"
    if "chest" in roles and "head" in roles:
        above = tree.ancestors(roles["head"])
        if roles["chest"] in above:
            # The base of the neck: the chest's child on the way to the head.
            below = [roles["head"], *above[: above.index(roles["chest"])]]
            roles["neck_base"], how["neck_base"] = below[-1], "topology"
    if "chest" in roles and "pelvis" in roles:
        path = [roles["chest"], *tree.ancestors(roles["chest"])]
        if roles["pelvis"] in path:
            path = path[: path.index(roles["pelvis"]) + 1]
            middle = 0.5 * (rest[roles.get("neck_base", roles["chest"])] + rest[roles["pelvis"]])
            spine = min(path, key=lambda j: np.linalg.norm(rest[j] - middle))
            roles["spine"], how["spine"] = spine, "topology"


def _leaves(tree, j):
    return [k for k in [j, *_descendants(tree, j)] if not tree.children[k]]


def _fork(tree, j):
    """The first joint from ``j`` down a chain of single children with 3 or more children."""
    while len(tree.children[j]) == 1:
        j = tree.children[j][0]
    return j if len(tree.children[j]) >= 3 else None


def _chain_end(tree, branch, rest, origin):
    """(end joint, its end site or None) of a limb: where its leaves meet, or its far leaf."""
    leaves = _leaves(tree, branch)
    far = max(leaves, key=lambda k: np.linalg.norm(rest[k] - rest[origin]))
    if len(leaves) > 1:  # fingers or toes: the limb ends where they branch
        end = far
        while not set(leaves) <= {end, *_descendants(tree, end)}:
            end = tree.parents[end]
        below = [c for c in tree.children[end] if far in (c, *_descendants(tree, c))]
        return end, below[0]
    parent = tree.parents[far]
    return (parent, far) if tree.is_end[far] and parent != origin else (far, None)


def _by_topology(tree, rest, roles, how):
    """Roles from the tree alone (joints named ``j1``, ``bone_07``): the pelvis and chest are
    the 3-way forks, the arms the chest's two far-reaching branches, the legs the pelvis's
    two others; left is up x forward, with forward the way the feet point."""
    pelvis = _fork(tree, 0)
    if pelvis is None:
        return False
    kids = sorted(tree.children[pelvis], key=lambda c: len(_leaves(tree, c)), reverse=True)
    chest = _fork(tree, kids[0])
    if chest is None or len(kids) < 3:
        return False

    def reach(k, origin):
        """The longest bone path from ``origin`` into branch ``k`` (arms are long even
        when they hang beside the trunk)."""
        longest = 0.0
        for leaf in _leaves(tree, k):
            length, j = 0.0, leaf
            while j != origin:
                length += np.linalg.norm(rest[j] - rest[tree.parents[j]])
                j = tree.parents[j]
            longest = max(longest, length)
        return longest

    legs = sorted(kids[1:], key=lambda c: reach(c, pelvis), reverse=True)[:2]
    branches = sorted(tree.children[chest], key=lambda c: reach(c, chest), reverse=True)
    arms, head_branch = branches[:2], branches[2]
    head, head_end = _chain_end(tree, head_branch, rest, chest)
    ankles = []
    for leg in legs:
        toe, _ = _chain_end(tree, leg, rest, pelvis)
        ankles.append((tree.parents[toe], toe))
    up = rest[head] - np.mean([rest[a] for a, _ in ankles], axis=0)
    forward = np.mean([rest[t] - rest[a] for a, t in ankles], axis=0)
    forward -= up * (forward @ up) / (up @ up)
    left = np.cross(up, forward)
    if np.linalg.norm(forward) < 1e-9 * np.linalg.norm(up):
        return False  # feet that point nowhere: no facing, so no side
    sides = {}
    for group, origin in ((arms, chest), (legs, pelvis)):
        ordered = sorted(group, key=lambda c: (rest[c] - rest[origin]) @ left, reverse=True)
        sides.update({ordered[0]: "left", ordered[1]: "right"})
    for arm in arms:
        s = sides[arm]
        wrist, hand_end = _chain_end(tree, arm, rest, chest)
        elbow = tree.parents[wrist]
        shoulder = tree.parents[elbow]
        found = {"wrist": wrist, "elbow": elbow, "shoulder": shoulder, "hand_end": hand_end}
        if tree.parents[shoulder] != chest:
            found["clavicle"] = tree.parents[shoulder]
        roles.update({f"{s}_{k}": v for k, v in found.items() if v is not None})
    for leg, (ankle, toe) in zip(legs, ankles):
        s = sides[leg]
        knee = tree.parents[ankle]
        roles.update(
            {
                f"{s}_toe": toe,
                f"{s}_ankle": ankle,
                f"{s}_knee": knee,
                f"{s}_hip": tree.parents[knee],
            }
        )
    roles["head"] = head
    if head_end is not None:
        roles["head_end"] = head_end
    how.update(dict.fromkeys(roles, "topology"))
    return True


ROLES = ["head", "head_end", "neck", "neck_base", "chest", "spine", "pelvis"] + [
    f"{s}_{p}"
    for s in ("left", "right")
    for p in ("clavicle", "shoulder", "elbow", "wrist", "hand_end", "hip", "knee", "ankle", "toe")
]
#: Roles without which no marker set is built.
REQUIRED = tuple(
    ["head", "pelvis", "chest"]
    + [
        f"{s}_{p}"
        for s in ("left", "right")
        for p in ("shoulder", "elbow", "wrist", "hip", "knee", "ankle")
    ]
)


def match_joints(skeleton):
    """Find the head, trunk and limb joints of a humanoid skeleton by name and topology.

    Parameters
    ----------
    skeleton : Skeleton

    Returns
    -------
    match : JointMatch
        ``roles`` maps each role found to its joint; ``up_axis`` is the axis
        of the largest rest-pose distance from the mean of the ankles to the
        head (or, without a head, the chest).

    Raises
    ------
    ValueError
        When a role of :data:`REQUIRED` is found nowhere; the message lists
        what was found and what was not.

    Examples
    --------
    >>> from skmotion.datasets import humanoid_skeleton
    >>> from skmotion.kinematics._joint_matching import match_joints
    >>> match = match_joints(humanoid_skeleton())
    >>> match.roles["left_shoulder"], match.roles["right_knee"], match.up_axis
    ('LeftArm', 'RightLeg', 'y')
    """
    tree = _Tree(skeleton)
    roles, how = {}, {}
    for side in ("left", "right"):
        _arm(tree, side, roles, how)
        _leg(tree, side, roles, how)
    rest = skeleton.rest_positions()
    _trunk(tree, roles, how, rest)
    missing = [r for r in REQUIRED if r not in roles]
    if missing:  # the names say too little: the tree alone
        topology_roles, topology_how = {}, {}
        if _by_topology(tree, rest, topology_roles, topology_how):
            _trunk(tree, topology_roles, topology_how, rest)
            if all(r in topology_roles for r in REQUIRED):
                roles, how, missing = topology_roles, topology_how, []
    named = {r: tree.names[j] for r, j in roles.items()}
    if missing:
        found = ", ".join(f"{r}={n}" for r, n in named.items()) or "nothing"
        raise ValueError(
            f"No humanoid found in this skeleton (root {tree.names[0]!r}, {len(tree.names)} "
            f"joints): no joint for {missing}; found {found}. Define the markers with a MarkerSet."
        )
    top = rest[roles["head"]]
    feet = rest[[roles["left_ankle"], roles["right_ankle"]]].mean(axis=0)
    up_axis = "xyz"[int(np.argmax(np.abs(top - feet)))]
    ordered = {r: named[r] for r in ROLES if r in named}
    return JointMatch(
        ordered, {r: how[r] for r in ordered}, up_axis, [r for r in ROLES if r not in named]
    )
