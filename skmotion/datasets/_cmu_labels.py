"""Motion classes from free-text trial descriptions (the CMU index) and file names.

The CMU database describes each trial in words ("playground - climb, hang, swing",
"walk on uneven terrain", "run/jog"). A classifier needs a few classes, so each
description is mapped to the class of the **first** keyword it contains, read left to
right, whole words only; a description with none of them is ``"other"``.

The table below is the whole rule. It is kept short on purpose: each class is a kind of
whole-body movement that looks different from the others.

========  ==============================================================================
class     keywords (and their -s, -ing, -ed forms)
========  ==============================================================================
walk      walk, stroll, march, stride, sneak, tiptoe, stagger, limp, wander, amble, step,
          sidestep
run       run, jog, sprint
jump      jump, hop, leap, jumpforward, skip
strike    punch, strike, box, boxing, kick, karate, sword, swordplay, fight, fencing,
          jab, uppercut
climb     climb, ladder
dance     dance, salsa, waltz, ballet, charleston, tango, arabesque, jete, pirouette, lambada
sit       sit, squat, kneel, crouch, lie, laying
reach     reach, pick, scoop, bend, lift, grab, carry
throw     throw, catch, dribble, basketball, golf, swing, soccer, pitch
gesture   wave, signal, signals, point, gesture, gestures, clap, salute
========  ==============================================================================
"""

import re

__all__ = ["CMU_MOTION_CLASSES", "cmu_motion_class", "motion_class_of_name"]

CMU_MOTION_CLASSES = {
    "walk": ("walk", "stroll", "march", "stride", "sneak", "tiptoe", "stagger", "limp", "wander",
             "amble", "step", "sidestep"),
    "run": ("run", "jog", "sprint"),
    "jump": ("jump", "hop", "leap", "jumpforward", "skip"),
    "strike": ("punch", "strike", "box", "boxing", "kick", "karate", "sword", "swordplay", "fight",
               "fencing", "jab", "uppercut"),
    "climb": ("climb", "ladder"),
    "dance": ("dance", "salsa", "waltz", "ballet", "charleston", "tango", "arabesque", "jete",
              "pirouette", "lambada"),
    "sit": ("sit", "squat", "kneel", "crouch", "lie", "laying"),
    "reach": ("reach", "pick", "scoop", "bend", "lift", "grab", "carry"),
    "throw": ("throw", "catch", "dribble", "basketball", "golf", "swing", "soccer", "pitch"),
    "gesture": ("wave", "signal", "signals", "point", "gesture", "gestures", "clap", "salute"),
}  # fmt: skip

_KEYWORD_CLASS = {word: name for name, words in CMU_MOTION_CLASSES.items() for word in words}
_WORD = re.compile(r"[a-z]+")
_SUFFIXES = ("s", "es", "ing", "ed", "d")


def _class_of_word(word):
    if word in _KEYWORD_CLASS:
        return _KEYWORD_CLASS[word]
    for suffix in _SUFFIXES:
        stem = word[: -len(suffix)]
        if word.endswith(suffix) and len(stem) >= 3:
            # "jumping" -> "jump", "running" -> "runn" -> "run" (a doubled last consonant)
            for candidate in (stem, stem[:-1] if stem[-1:] == stem[-2:-1] else None):
                if candidate in _KEYWORD_CLASS:
                    return _KEYWORD_CLASS[candidate]
    return None


def cmu_motion_class(description, *, default="other"):
    """The motion class of a trial description: the class of its first keyword.

    Parameters
    ----------
    description : str
        Free text such as the CMU index's ``Motion Description``.
    default : str, default="other"
        The class of a description without any keyword of
        :data:`CMU_MOTION_CLASSES`.

    Returns
    -------
    label : str
        One of the keys of :data:`CMU_MOTION_CLASSES`, or ``default``.

    Examples
    --------
    >>> from skmotion.datasets import cmu_motion_class
    >>> cmu_motion_class("playground - climb, sit, dangle legs, jump down")
    'climb'
    >>> cmu_motion_class("playground - forward jumps, turn around")
    'jump'
    >>> cmu_motion_class("run/jog"), cmu_motion_class("swordplay"), cmu_motion_class("wash self")
    ('run', 'strike', 'other')
    """
    if not isinstance(description, str):
        raise TypeError(f"description must be a str; got {type(description).__name__}.")
    spaced = re.sub(r"([a-z])([A-Z])", r"\1 \2", description)  # "CoolWalk" -> "Cool Walk"
    for word in _WORD.findall(spaced.lower()):
        found = _class_of_word(word)
        if found is not None:
            return found
    return default


def motion_class_of_name(name):
    """The motion class named by a file or folder name, or None.

    Splits the name at every non-letter and at lower-to-upper case changes
    (``"AV_8Walk_Meredith"`` -> ``av``, ``walk``, ``meredith``) and returns the
    class of the first keyword, as :func:`cmu_motion_class` does for descriptions.

    Parameters
    ----------
    name : str
        A file stem or folder name.

    Returns
    -------
    label : str or None

    Examples
    --------
    >>> from skmotion.datasets import motion_class_of_name
    >>> motion_class_of_name("AV_8Walk_Meredith_HVHA_Rep1"), motion_class_of_name("take_003")
    ('walk', None)
    """
    found = cmu_motion_class(str(name), default="")
    return found or None
