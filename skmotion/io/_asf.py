"""Reading Acclaim skeleton files (ASF 1.10, as in the CMU database)."""

import numpy as np

from skmotion.io._errors import MotionFileError
from skmotion.io._text import decode_text, is_special, parse_number, read_text
from skmotion.kinematics import Skeleton, euler_to_matrix

__all__ = ["acclaim_order", "read_asf"]

_ROTATION_DOFS = {"rx": "X", "ry": "Y", "rz": "Z"}
_ROOT_DOFS = {
    "tx": "Xposition",
    "ty": "Yposition",
    "tz": "Zposition",
    "rx": "Xrotation",
    "ry": "Yrotation",
    "rz": "Zrotation",
}
_INCH = 0.0254


def acclaim_order(axes):
    """The intrinsic rotation order of an Acclaim axis sequence.

    Acclaim applies the rotations of ``axis XYZ`` (and of a bone's ``dof``
    line) in the order listed, about fixed axes: ``R = Rz @ Ry @ Rx``. That is
    the intrinsic order read backwards, ``"ZYX"``; axes not listed (always at
    zero) are appended.

    Parameters
    ----------
    axes : str
        Axes in the order the file lists them, e.g. ``"XYZ"`` or ``"XZ"``.

    Returns
    -------
    order : str
        An intrinsic order for :func:`skmotion.kinematics.euler_to_matrix`.

    Examples
    --------
    >>> from skmotion.io import acclaim_order
    >>> acclaim_order("XYZ"), acclaim_order("XZ")
    ('ZYX', 'ZXY')
    """
    listed = axes.upper()[::-1]
    return listed + "".join(a for a in "XYZ" if a not in listed)


class _Lines:
    """The file's non-empty lines with their numbers; comments dropped."""

    def __init__(self, path):
        self.path = path
        text = decode_text(read_text(path))
        self.items = []
        for number, line in enumerate(text.split("\n"), start=1):
            words = line.split("#", 1)[0].replace("\t", " ").split(" ")
            words = [w for w in words if w]
            if words:
                self.items.append((number, words))
        self.pos = 0

    def error(self, line, message):
        return MotionFileError(self.path, line, message)

    def peek(self):
        return self.items[self.pos] if self.pos < len(self.items) else (None, None)

    def take(self, what):
        if self.pos >= len(self.items):
            last = self.items[-1][0] if self.items else None
            raise self.error(last, f"file ends where {what} was expected")
        self.pos += 1
        return self.items[self.pos - 1]

    def floats(self, line, words, count, what):
        if len(words) < count:
            raise self.error(line, f"{what} needs {count} values, found {len(words)}")
        try:
            values = [float(w) if is_special(w) else parse_number(w) for w in words[:count]]
        except ValueError:
            bad = next(w for w in words[:count] if not _is_number(w))
            raise self.error(line, f"non-numeric value {bad!r} in {what}") from None
        if not np.isfinite(values).all():
            raise self.error(line, f"non-finite value in {what}")
        return values


def _is_number(word):
    try:
        float(word) if is_special(word) else parse_number(word)
    except ValueError:
        return False
    return True


def _section(lines):
    """Lines up to the next ``:keyword`` line."""
    out = []
    while lines.peek()[1] is not None and not lines.peek()[1][0].startswith(":"):
        out.append(lines.take("a line"))
    return out


def _parse_units(lines, units):
    for line, words in _section(lines):
        if len(words) < 2:
            raise lines.error(line, f"unit {words[0]!r} has no value")
        key = words[0].lower()
        if key == "angle":
            if words[1].lower() not in ("deg", "rad"):
                raise lines.error(line, f"angle unit must be deg or rad, found {words[1]!r}")
            units["angle"] = words[1].lower()
        else:
            units[key] = lines.floats(line, words[1:], 1, f"unit {key!r}")[0]
            if key == "length" and not units[key] > 0:
                raise lines.error(line, "length unit must be positive")


def _parse_root(lines):
    root = {"order": None, "axis": "XYZ", "position": [0.0, 0.0, 0.0], "line": lines.peek()[0]}
    for line, words in _section(lines):
        key = words[0].lower()
        if key == "order":
            dofs = [w.lower() for w in words[1:]]
            unknown = [d for d in dofs if d not in _ROOT_DOFS]
            if unknown or len(set(dofs)) != len(dofs):
                raise lines.error(
                    line, f"root order must list distinct TX TY TZ RX RY RZ, found {words[1:]}"
                )
            root["order"] = dofs
        elif key == "axis":
            root["axis"] = _axis_order(lines, line, words[1] if len(words) > 1 else "")
        elif key == "position":
            root["position"] = lines.floats(line, words[1:], 3, "root position")
        elif key == "orientation":
            if any(v != 0 for v in lines.floats(line, words[1:], 3, "root orientation")):
                raise lines.error(line, "a non-zero root orientation is not supported")
    if root["order"] is None:
        raise lines.error(root["line"], "the :root section has no 'order' line")
    return root


def _axis_order(lines, line, word):
    if sorted(word.upper()) != ["X", "Y", "Z"]:
        raise lines.error(line, f"axis order must be a permutation of XYZ, found {word!r}")
    return word.upper()


def _parse_bone(lines, opened):
    bone = {"line": opened, "dof": []}
    while True:
        line, words = lines.take(f"'end' of the bone opened at line {opened}")
        key = words[0].lower()
        if key == "end":
            break
        if key == "begin" or key.startswith(":"):
            raise lines.error(line, f"the bone opened at line {opened} has no 'end'")
        if key == "name":
            bone["name"] = words[1] if len(words) > 1 else ""
        elif key == "direction":
            bone["direction"] = lines.floats(line, words[1:], 3, "direction")
        elif key == "length":
            bone["length"] = lines.floats(line, words[1:], 1, "length")[0]
        elif key == "axis":
            angles = lines.floats(line, words[1:], 3, "axis")
            bone["axis"] = (angles, _axis_order(lines, line, words[4] if len(words) > 4 else ""))
        elif key == "dof":
            dofs = [w.lower() for w in words[1:]]
            bad = [d for d in dofs if d not in _ROTATION_DOFS]
            if bad:
                raise lines.error(
                    line, f"dof {bad[0]!r} is not supported on a bone (only rx, ry, rz)"
                )
            if len(set(dofs)) != len(dofs):
                raise lines.error(line, f"dof lists an axis twice: {words[1:]}")
            bone["dof"] = dofs
    for needed in ("name", "direction", "length", "axis"):
        if needed not in bone:
            raise lines.error(opened, f"the bone opened here has no {needed!r}")
    return bone


def _parse_bones(lines):
    bones = {}
    while lines.peek()[1] is not None and not lines.peek()[1][0].startswith(":"):
        line, words = lines.take("a bone")
        if words[0].lower() != "begin":
            raise lines.error(line, f"expected 'begin' of a bone, found {words[0]!r}")
        bone = _parse_bone(lines, line)
        if bone["name"] in bones or bone["name"] == "root":
            raise lines.error(line, f"bone name {bone['name']!r} appears twice")
        bones[bone["name"]] = bone
    return bones


def _parse_hierarchy(lines, bones):
    children = {}
    parents = {}
    opened, words = lines.take("'begin' of the hierarchy")
    if words[0].lower() != "begin":
        raise lines.error(opened, f"expected 'begin' after :hierarchy, found {words[0]!r}")
    while True:
        line, words = lines.take(f"'end' of the hierarchy opened at line {opened}")
        if words[0].lower() == "end":
            return children
        if words[0].startswith(":"):
            raise lines.error(line, f"the hierarchy opened at line {opened} has no 'end'")
        for name in words:
            if name != "root" and name not in bones:
                raise lines.error(line, f"unknown bone {name!r} in the hierarchy")
        for child in words[1:]:
            if child in parents or child == "root":
                raise lines.error(line, f"bone {child!r} is given a second parent")
            parents[child] = words[0]
        children.setdefault(words[0], []).extend(words[1:])


def _build(lines, units, root, bones, children):
    """The Skeleton: one joint per bone, at the bone's start."""
    to_rad = np.pi / 180.0 if units.get("angle", "deg") == "deg" else 1.0
    names, parents, offsets, channels, orders, axes = [], [], [], [], [], []

    def add(name, parent, offset, chans, order, axis):
        names.append(name)
        parents.append(parent)
        offsets.append(offset)
        channels.append(chans)
        orders.append(order)
        axes.append(axis)

    add(
        "root",
        -1,
        root["position"],
        [_ROOT_DOFS[d] for d in root["order"]],
        acclaim_order(root["axis"]),
        np.eye(3),
    )
    stack = [(child, 0) for child in reversed(children.get("root", []))]
    vectors = {}
    while stack:
        name, parent = stack.pop()
        bone = bones[name]
        direction = np.asarray(bone["direction"], dtype=float)
        scale = np.abs(direction).max()
        if not scale > 0:
            raise lines.error(bone["line"], f"bone {name!r} has a zero direction")
        # Scaled to at most 1 before the norm, so 1e308 or 1e-308 components give the right unit.
        direction = direction / scale
        # A bone's joint sits at the end of its parent bone; the root's bones start at the root.
        offset = vectors.get(names[parent], np.zeros(3))
        vectors[name] = bone["length"] * direction / np.linalg.norm(direction)
        with np.errstate(over="ignore"):
            overflow = not np.isfinite(offset + vectors[name]).all()
        if overflow:
            raise lines.error(
                bone["line"], f"bone {name!r}: its length {bone['length']:g} overflows a float"
            )
        angles, axis_order = bone["axis"]
        # The three values are the x, y, z angles; the letters say in which order they apply.
        by_axis = dict(zip("XYZ", angles))
        order = acclaim_order(axis_order)
        axis = euler_to_matrix(np.array([by_axis[a] for a in order]) * to_rad, order)
        dof_axes = "".join(_ROTATION_DOFS[d] for d in bone["dof"])
        index = len(names)
        add(name, parent, offset, [f"{a}rotation" for a in dof_axes], acclaim_order(dof_axes), axis)
        kids = children.get(name, [])
        if not kids:
            add(f"{name}_end", index, vectors[name], [], "XYZ", np.eye(3))
        stack.extend((child, index) for child in reversed(kids))
    missing = sorted(set(bones) - set(names))
    if missing:
        raise lines.error(None, f"bones {missing} are not connected to the root in the hierarchy")
    length = units.get("length")
    try:
        return _skeleton(names, parents, offsets, channels, orders, axes, length)
    except ValueError as exc:
        raise lines.error(None, f"the bones do not make a valid skeleton: {exc}") from None


def _skeleton(names, parents, offsets, channels, orders, axes, length):
    return Skeleton(
        joints=names,
        parents=parents,
        offsets=offsets,
        channels=channels,
        rotation_orders=orders,
        axes=axes,
        units="unknown" if length is None else f"1/{length:g} inch",
        meters_per_unit=None if length is None else _INCH / length,
        up_axis="y",
    )


def read_asf(path):
    """Read an Acclaim skeleton (ASF) file as a Skeleton.

    Each bone becomes a joint located at the bone's start (the end of its
    parent bone; the root's bones start at the root), rotating by
    ``C @ M @ C.T`` with ``C`` the bone's ``axis`` frame and ``M`` the rotation
    of its ``dof`` values; a leaf bone gets an end site ``<bone>_end`` at its
    tip. Acclaim rotations (``axis XYZ`` and ``dof rx ry rz``) are applied in
    the listed order about fixed axes, ``Rz @ Ry @ Rx``: intrinsic ``"ZYX"``
    (see :func:`acclaim_order`). Lengths stay in the file's unit:
    ``:units length 0.45`` means one unit is 1/0.45 inch, recorded in
    ``meters_per_unit``. Acclaim skeletons are Y-up.

    Parameters
    ----------
    path : str or path-like
        The ``.asf`` file.

    Returns
    -------
    skeleton : Skeleton
        The root joint ``root`` carries the channels of the root's ``order``
        line; each bone carries one rotation channel per ``dof`` entry, in
        the ``dof`` line's order (the column order of an AMC line).

    Raises
    ------
    MotionFileError
        For a malformed file (a bone without ``end``, unknown bones in the
        hierarchy, non-numeric values, unsupported dofs); the message names
        the file and line.

    See Also
    --------
    read_amc : the motion of an ASF skeleton.

    Examples
    --------
    >>> import os, tempfile
    >>> from skmotion.io import read_asf
    >>> text = '''
    ... :units
    ...   length 0.45
    ...   angle deg
    ... :root
    ...   order TX TY TZ RX RY RZ
    ...   axis XYZ
    ...   position 0 0 0
    ...   orientation 0 0 0
    ... :bonedata
    ...   begin
    ...     id 1
    ...     name femur
    ...     direction 0 -1 0
    ...     length 18
    ...     axis 0 0 20 XYZ
    ...     dof rx ry rz
    ...   end
    ...   begin
    ...     id 2
    ...     name tibia
    ...     direction 0 -1 0
    ...     length 17
    ...     axis 0 0 20 XYZ
    ...     dof rx
    ...   end
    ... :hierarchy
    ...   begin
    ...     root femur
    ...     femur tibia
    ...   end
    ... '''
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = os.path.join(folder, "leg.asf")
    ...     _ = open(path, "w").write(text)
    ...     skeleton = read_asf(path)
    >>> skeleton.joints
    ('root', 'femur', 'tibia', 'tibia_end')
    >>> skeleton.channel_names[6:]
    ['femur_Xrotation', 'femur_Yrotation', 'femur_Zrotation', 'tibia_Xrotation']
    >>> skeleton.rest_positions()[3].tolist(), round(skeleton.meters_per_unit, 6)
    ([0.0, -35.0, 0.0], 0.056444)
    """
    lines = _Lines(path)
    units, root, bones, children = {}, None, None, None
    while lines.peek()[1] is not None:
        line, words = lines.take("a section")
        keyword = words[0].lower()
        if keyword == ":units":
            _parse_units(lines, units)
        elif keyword == ":root":
            root = _parse_root(lines)
        elif keyword == ":bonedata":
            bones = _parse_bones(lines)
        elif keyword == ":hierarchy":
            if bones is None:
                raise lines.error(line, ":hierarchy comes before :bonedata")
            children = _parse_hierarchy(lines, bones)
        elif keyword.startswith(":"):
            _section(lines)  # :version, :name, :documentation, :skin: nothing to read
        else:
            raise lines.error(line, f"expected a ':section' keyword, found {words[0]!r}")
    for what, value in ((":root", root), (":bonedata", bones), (":hierarchy", children)):
        if value is None:
            raise MotionFileError(path, None, f"no {what} section: not an ASF file")
    return _build(lines, units, root, bones, children)
