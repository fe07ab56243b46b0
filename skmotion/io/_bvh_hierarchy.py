"""The HIERARCHY block of a BVH file: an iterative, linear-time parser."""

import math
import re

import numpy as np

from skmotion.io._errors import MotionFileError
from skmotion.io._text import NUMBER, is_special, parse_number
from skmotion.kinematics import CHANNEL_KINDS

__all__ = ["parse_hierarchy"]

_CHANNELS = {c.lower(): c for c in CHANNEL_KINDS}
_WORD = re.compile(r"[{}]|[^ \t\n{}]+")
_DIGITS = re.compile(r"[0-9]+")


def _token_lines(path, text, n_words):
    """File line of each word of ``text`` (as ``_WORD`` finds them), computed by NumPy."""
    codes = np.frombuffer(text.encode("utf-32-le"), dtype=np.uint32)
    solid = (codes != 32) & (codes != 9) & (codes != 10)
    brace = (codes == 123) | (codes == 125)
    before = np.r_[False, solid[:-1]]
    brace_before = np.r_[False, brace[:-1]]
    starts = np.flatnonzero(solid & (~before | brace | brace_before))
    if len(starts) != n_words:  # cannot happen for text without control characters
        raise MotionFileError(path, None, "the hierarchy could not be split into words")
    return (np.searchsorted(np.flatnonzero(codes == 10), starts) + 1).tolist()


def _numbers(words):
    """Are ``words[2:5]`` numbers (the values after ``{ OFFSET``)?"""
    match = NUMBER.fullmatch
    return match(words[2]) and match(words[3]) and match(words[4])


class _Parser:
    """A stack of open joints instead of recursion; sets for names; slices of words.

    A joint's name is the rest of its ``ROOT``/``JOINT`` line, kept verbatim but for
    the surrounding blanks and a final ``{`` (3ds Max writes ``JOINT Bip01 Neck``).
    The common layout (``{``, ``OFFSET x y z``, ``CHANNELS n ...`` in order) is
    read by slicing the word list; anything else goes through ``expect``, which
    names what was expected and where.
    """

    def __init__(self, path, text):
        self.path = path
        self.text_lines = text.split("\n")
        self.words = _WORD.findall(text)
        self.line_of = _token_lines(path, text, len(self.words))
        self.pos = 0
        self.joints, self.parents, self.offsets, self.channels = [], [], [], []
        self.names = set()

    def error(self, message, line=None):
        if line is None:
            at = min(self.pos, len(self.words) - 1)
            line = self.line_of[at] if self.words else 1
        return MotionFileError(self.path, line, message)

    def next(self, what):
        if self.pos >= len(self.words):
            raise self.error(f"file ends where {what} was expected")
        self.pos += 1
        return self.words[self.pos - 1], self.line_of[self.pos - 1]

    def expect(self, keyword, context):
        word, line = self.next(f"{keyword!r}")
        if word.upper() != keyword.upper():
            raise self.error(f"expected {keyword!r} {context}, found {word!r}", line)
        return line

    def offset(self, context):
        values = []
        for _ in range(3):
            word, line = self.next(f"a number ({context})")
            try:
                value = float(word) if is_special(word) else parse_number(word)
            except ValueError:
                raise self.error(f"non-numeric value {word!r} in {context}", line) from None
            if not math.isfinite(value):
                raise self.error(f"non-finite value {word!r} in {context}", line)
            values.append(value)
        return values

    def parse(self):
        self.expect("HIERARCHY", "at the start of a BVH file")
        self.expect("ROOT", "after HIERARCHY")
        words, n_words = self.words, len(self.words)
        stack = [self.joint(parent=-1)]
        while stack:
            if self.pos >= n_words:
                index, opened = stack[-1]
                raise self.error(
                    f"file ends where '}}' closing joint {self.joints[index]!r} (opened at line "
                    f"{opened}) was expected"
                )
            word = words[self.pos]
            self.pos += 1
            if word == "}":
                stack.pop()
                continue
            key = word.upper()
            if key == "JOINT":
                stack.append(self.joint(stack[-1][0]))
            elif key == "END":
                self.end_site(stack[-1][0])
            else:
                index, opened = stack[-1]
                raise self.error(
                    f"expected JOINT, End Site or '}}' in joint {self.joints[index]!r} (opened "
                    f"at line {opened}), found {word!r}",
                    self.line_of[self.pos - 1],
                )
        if self.pos < n_words:
            word, line = words[self.pos], self.line_of[self.pos]
            if word.upper() == "ROOT":
                raise self.error(
                    "a second ROOT: files with several hierarchies are not supported", line
                )
            raise self.error(f"unexpected {word!r} after the hierarchy (a '}}' too many?)", line)

    def joint_name(self):
        """The rest of the keyword's line; its words are consumed (but a final '{')."""
        line_of, keyword = self.line_of, self.pos - 1
        line = line_of[keyword]
        first = keyword
        while first > 0 and line_of[first - 1] == line:
            first -= 1
        text = self.text_lines[line - 1]
        if first == keyword:  # the usual layout: the keyword opens its line
            rest = text.lstrip(" \t")[len(self.words[keyword]) :].strip(" \t")
        else:
            found = _WORD.finditer(text)
            for _ in range(keyword - first):
                next(found)
            rest = text[next(found).end() :].strip(" \t")
        end = self.pos
        while end < len(line_of) and line_of[end] == line:
            end += 1
        if rest.endswith("{") and end > self.pos:
            rest, end = rest[:-1].rstrip(" \t"), end - 1  # the brace opens the joint
        self.pos = end
        if not rest:
            raise self.error("a joint without a name", line)
        if "{" in rest or "}" in rest:
            raise self.error(f"joint name {rest!r} contains a brace", line)
        return rest, line

    def joint(self, parent):
        name, line = self.joint_name()
        if name in self.names:
            raise self.error(f"joint name {name!r} appears twice", line)
        self.names.add(name)
        self.joints.append(name)
        self.parents.append(parent)
        pos = self.pos
        head = self.words[pos : pos + 5]
        if len(head) == 5 and head[0] == "{" and head[1].upper() == "OFFSET" and _numbers(head):
            opened, offset = self.line_of[pos], [float(head[2]), float(head[3]), float(head[4])]
            self.pos += 5
        else:
            opened = self.expect("{", f"after joint {name!r}")
            self.expect("OFFSET", f"in joint {name!r}")
            offset = self.offset(f"OFFSET of {name!r}")
        if not all(map(math.isfinite, offset)):
            raise self.error(f"non-finite value in OFFSET of {name!r}", opened)
        self.offsets.append(offset)
        self.channels.append(self.channel_list(name))
        return len(self.joints) - 1, opened

    def channel_list(self, name):
        self.expect("CHANNELS", f"in joint {name!r}")
        word, line = self.next("the channel count")
        if not _DIGITS.fullmatch(word):
            raise self.error(
                f"channel count of joint {name!r} must be an integer, found {word!r}", line
            )
        count = int(word)
        listed = self.words[self.pos : self.pos + count] if count <= 6 else []
        channels = [_CHANNELS.get(w.lower()) for w in listed]
        if len(channels) == count and None not in channels and len(set(channels)) == count:
            self.pos += count
            return channels
        channels = []  # something is wrong: find what, word by word
        for _ in range(count):
            word, line = self.next(f"a channel name of joint {name!r}")
            channel = _CHANNELS.get(word.lower())
            if channel is None:
                raise self.error(
                    f"unknown channel {word!r} of joint {name!r} (expected one of "
                    f"{list(CHANNEL_KINDS)})",
                    line,
                )
            if channel in channels:
                raise self.error(f"joint {name!r} lists channel {word!r} twice", line)
            channels.append(channel)
        raise self.error(f"joint {name!r} lists more than six channels", line)

    def end_site(self, parent):
        parent_name = self.joints[parent]
        name, suffix = f"{parent_name}_end", 2
        while name in self.names:
            name, suffix = f"{parent_name}_end{suffix}", suffix + 1
        site = self.words[self.pos : self.pos + 7]  # Site { OFFSET x y z }
        if (
            len(site) == 7
            and site[0].upper() == "SITE"
            and site[1] == "{"
            and site[2].upper() == "OFFSET"
            and site[6] == "}"
            and _numbers(site[1:])
        ):
            offset = [float(site[3]), float(site[4]), float(site[5])]
            self.pos += 7
        else:
            self.expect("Site", "after 'End'")
            opened = self.expect("{", "after End Site")
            self.expect("OFFSET", "in End Site")
            offset = self.offset(f"OFFSET of the End Site of {parent_name!r}")
            self.expect("}", f"closing the End Site opened at line {opened}")
        if not all(map(math.isfinite, offset)):
            raise self.error(f"non-finite value in the End Site OFFSET of {parent_name!r}")
        self.names.add(name)
        self.joints.append(name)
        self.parents.append(parent)
        self.offsets.append(offset)
        self.channels.append([])


def parse_hierarchy(path, text):
    """Joints, parents, offsets and channel lists of a BVH HIERARCHY block.

    Parameters
    ----------
    path : str or path-like
        For error messages.
    text : str
        The file's text up to its MOTION line (LF line breaks, no control characters).

    Returns
    -------
    joints, parents, offsets, channels : list
        One entry per joint, in file order; End Sites are joints ``<parent>_end``
        without channels.

    Examples
    --------
    >>> from skmotion.io._bvh_hierarchy import parse_hierarchy
    >>> text = "HIERARCHY\\nROOT Bip01 Pelvis\\n{\\n OFFSET 0 0 0\\n CHANNELS 3 Zrotation"
    >>> text += " Xrotation Yrotation\\n End Site\\n {\\n  OFFSET 0 1 0\\n }\\n}\\n"
    >>> parse_hierarchy("a.bvh", text)[0]
    ['Bip01 Pelvis', 'Bip01 Pelvis_end']
    """
    parser = _Parser(path, text)
    parser.parse()
    return parser.joints, parser.parents, parser.offsets, parser.channels
