"""Random byte mutations of motion files, for the reader fuzz test and benchmarks/bench_fuzz.py.

Every mutated file is read with a time limit, and the outcome must be one of:

- ``rejected``: the reader's own :class:`MotionFileError`, naming the file and a line
  inside it (or no line);
- ``agrees``: the file is read, and an independent plain-text parse of the same
  bytes (``tests/bad_input/test_file_mutations.py``) gives the same values;
- ``equal``: a *neutral* mutation (line breaks, a byte-order mark, blanks, blank
  lines) did not change the numbers, and the result equals the original's.

Anything else (another exception type, a hang, a disagreement, a neutral change
that changed the result) is a ``failure`` with its description.
"""

import re
import signal
from dataclasses import dataclass, field

import numpy as np

from skmotion.io import MotionFileError
from tests.bad_input import files
from tests.bad_input.test_file_mutations import CHECKS

CONTROL = [b"\x00", b"\x05", b"\x0b", b"\x0c", b"\x1b", b"\x1f", b"\x7f"]
ODD = [b"_", b"\xa0", b"\xc2\xa0", b"\xc2\xb2", "\u0661".encode(), b"\xef\xbb\xbf", b"\x85"]
PLAIN = [
    b"0",
    b"7",
    b"-",
    b".",
    b"e",
    b"E",
    b"+",
    b"{",
    b"}",
    b" ",
    b"\t",
    b"\n",
    b"\r",
    b"a",
    b":",
]
_NUMBER = re.compile(rb"-?[0-9]+(?:\.[0-9]+)?(?:[eE][-+]?[0-9]+)?")


class Timeout(Exception):
    """A read took longer than the per-case limit."""


def _on_alarm(signum, frame):
    raise Timeout()


def _lines(data):
    return data.split(b"\n")


def mutate(data, rng):
    """(description, mutated bytes, neutral) for one random edit of ``data``."""
    kind = rng.choice(MUTATIONS)
    return MUTATION_FUNCTIONS[kind](data, rng)


def _flip(data, rng):
    i = int(rng.integers(len(data)))
    bit = int(rng.integers(8))
    return (
        f"flip bit {bit} of byte {i}",
        data[:i] + bytes([data[i] ^ (1 << bit)]) + data[i + 1 :],
        False,
    )


def _insert(data, rng):
    pool = CONTROL + ODD + PLAIN
    new = pool[int(rng.integers(len(pool)))]
    i = int(rng.integers(len(data) + 1))
    return f"insert {new!r} at byte {i}", data[:i] + new + data[i:], False


def _inside_number(data, rng):
    spans = [m.span() for m in _NUMBER.finditer(data) if m.end() - m.start() > 1]
    if not spans:
        return _insert(data, rng)
    start, end = spans[int(rng.integers(len(spans)))]
    i = int(rng.integers(start + 1, end))
    new = (CONTROL + [b"_", b"\xc2\xa0", b" ", b"\t"])[int(rng.integers(len(CONTROL) + 4))]
    return f"insert {new!r} inside the number at byte {start}", data[:i] + new + data[i:], False


def _delete(data, rng):
    i = int(rng.integers(len(data)))
    n = int(rng.integers(1, 5))
    return f"delete {n} bytes at {i}", data[:i] + data[i + n :], False


def _truncate(data, rng):
    cut = int(rng.integers(len(data)))
    return f"truncate at byte {cut}", data[:cut], False


def _line_edit(data, rng):
    lines = _lines(data)
    i = int(rng.integers(len(lines)))
    how = ["delete", "duplicate", "swap"][int(rng.integers(3))]
    if how == "delete":
        edited = lines[:i] + lines[i + 1 :]
    elif how == "duplicate":
        edited = lines[: i + 1] + lines[i:]
    else:
        j = int(rng.integers(len(lines)))
        edited = list(lines)
        edited[i], edited[j] = edited[j], edited[i]
    return f"{how} line {i + 1}", b"\n".join(edited), False


def _neutral(data, rng):
    """A change of layout only: the numbers (and the result) must stay the same."""
    how = ["crlf", "cr", "bom", "trailing blanks", "blank lines", "tabs"][int(rng.integers(6))]
    if how == "crlf":
        return "CRLF line breaks", data.replace(b"\n", b"\r\n"), True
    if how == "cr":
        return "CR-only line breaks", data.replace(b"\n", b"\r"), True
    if how == "bom":
        return "UTF-8 byte-order mark", b"\xef\xbb\xbf" + data, True
    lines = _lines(data)
    picked = set(rng.choice(len(lines), size=min(len(lines), 5), replace=False).tolist())
    if how == "trailing blanks":
        lines = [
            line + b" \t " if k in picked and line.strip() else line for k, line in enumerate(lines)
        ]
        return "blanks at the end of some lines", b"\n".join(lines), True
    if how == "blank lines":
        out = []
        for k, line in enumerate(lines):
            out.append(line)
            if k in picked and k + 1 < len(lines):
                out.append(b"  ")
        return "blank lines inserted", b"\n".join(out), True
    lines = [
        re.sub(rb"(?<=[0-9]) (?=[-0-9])", b"\t", line) if k in picked else line
        for k, line in enumerate(lines)
    ]
    return "tabs for spaces between numbers", b"\n".join(lines), True


MUTATION_FUNCTIONS = {
    "flip": _flip,
    "insert": _insert,
    "inside number": _inside_number,
    "delete": _delete,
    "truncate": _truncate,
    "line": _line_edit,
    "neutral": _neutral,
}
MUTATIONS = list(MUTATION_FUNCTIONS)


def _same(kind, a, b):
    if kind == "asf":
        return a == b
    if kind == "ts":
        same_clips = len(a[0]) == len(b[0]) and all(
            np.array_equal(x, y, equal_nan=True) for x, y in zip(a[0], b[0])
        )
        labels = [None if y is None else list(y) for y in (a[1], b[1])]
        return same_clips and labels[0] == labels[1]
    return a.skeleton == b.skeleton and np.array_equal(a.channels, b.channels)


def _normalised(data):
    """The text as the readers see it (the one text rule), for the reference parsers."""
    if data.startswith(b"\xef\xbb\xbf"):
        data = data[3:]
    return data.replace(b"\r\n", b"\n").replace(b"\r", b"\n").decode("latin-1")


@dataclass
class Tally:
    """Counts of outcomes per reader, and the descriptions of the failures."""

    counts: dict = field(default_factory=dict)
    failures: list = field(default_factory=list)

    def add(self, kind, outcome, description=None):
        row = self.counts.setdefault(
            kind, {"tried": 0, "rejected": 0, "agrees": 0, "equal": 0, "failure": 0}
        )
        row["tried"] += 1
        row[outcome] += 1
        if outcome == "failure":
            self.failures.append(f"{kind}: {description}")


def run_case(path, name, read, data, description, neutral, original, tally, time_limit=5.0):
    """Read one mutated file of source ``name`` (``"written-bvh"``, ...) and record its outcome."""
    kind = name.rsplit("-", 1)[1]
    path.write_bytes(data)
    previous = signal.signal(signal.SIGALRM, _on_alarm)
    signal.setitimer(signal.ITIMER_REAL, time_limit)
    try:
        result = read(path)
    except MotionFileError as error:
        signal.setitimer(signal.ITIMER_REAL, 0)
        lines = data.count(b"\n") + data.count(b"\r") + 1
        inside = error.line is None or 1 <= error.line <= lines
        if str(error).startswith(str(path)) and inside:
            return tally.add(name, "rejected")
        return tally.add(name, "failure", f"{description}: error outside the file: {error}")
    except Timeout:
        return tally.add(name, "failure", f"{description}: no answer within {time_limit} s")
    except Exception as exc:  # noqa: BLE001 - any other type is what the fuzz test looks for
        signal.setitimer(signal.ITIMER_REAL, 0)
        return tally.add(name, "failure", f"{description}: {type(exc).__name__}: {exc}")
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)
    if neutral:
        if _same(kind, result, original):
            return tally.add(name, "equal")
        return tally.add(name, "failure", f"{description}: a layout change changed the result")
    try:
        CHECKS[kind](result, _normalised(data))
    except (ValueError, AttributeError, IndexError, AssertionError) as exc:
        return tally.add(name, "failure", f"{description}: read, but disagrees ({exc!r})")
    return tally.add(name, "agrees")


def sources(folder, shared_data=None):
    """(name, kind, bytes, reader) of every file the fuzzer mutates."""
    asf = files.written_asf()
    out = [
        ("written-bvh", "bvh", files.written_bvh(folder), files.reader_for("bvh", folder)),
        ("written-asf", "asf", asf, files.reader_for("asf", folder)),
        ("written-amc", "amc", files.written_amc(), files.reader_for("amc", folder, asf)),
        ("written-ts", "ts", files.written_ts(), files.reader_for("ts", folder)),
    ]
    if shared_data is not None:
        real_asf = files.real_asf(shared_data)
        out += [
            ("real-bvh", "bvh", files.real_bvh(shared_data), files.reader_for("bvh", folder)),
            ("real-asf", "asf", real_asf, files.reader_for("asf", folder)),
            (
                "real-amc",
                "amc",
                files.real_amc(shared_data),
                files.reader_for("amc", folder / "real", real_asf),
            ),
            ("real-ts", "ts", files.real_ts(shared_data), files.reader_for("ts", folder)),
        ]
    return out


def fuzz(folder, shared_data=None, *, n_cases=100, seed=0, time_limit=5.0):
    """Mutate every source ``n_cases`` times; the Tally of outcomes per source."""
    rng = np.random.default_rng(seed)
    tally = Tally()
    (folder / "real").mkdir(exist_ok=True)
    for name, kind, data, read in sources(folder, shared_data):
        original_path = folder / f"original.{kind}"
        original_path.write_bytes(data)
        original = read(original_path)
        path = folder / f"mutated-{name}.{kind}"
        for _ in range(n_cases):
            description, mutated, neutral = mutate(data, rng)
            run_case(path, name, read, mutated, description, neutral, original, tally, time_limit)
    return tally
