"""The header and parameter section of a C3D file, parsed from its bytes.

The layout is the one of the C3D user guide (c3d.org): a 512-byte header
block, then the parameter blocks (a 4-byte preamble whose last byte is the
processor type, then entries), then the data. Each entry starts with the
name length (int8, negative when locked) and the group id (int8: negative
for a group, the id of its group for a parameter), the name, and a signed
16-bit offset to the next entry counted from that offset word (0 on the
last). A parameter goes on with its type (-1 text, 1 byte, 2 int16,
4 float32), its number of dimensions, the dimensions (uint8 each), the
values (first index fastest) and a description.

Every size is checked against the bytes actually present before it is
used, so a damaged section gives :class:`MotionFileError`, never an
allocation from a forged count.
"""

import numpy as np

from skmotion.io._errors import MotionFileError

__all__ = ["C3DMetadata", "dec_to_float", "read_metadata"]

#: Processor byte (83 + type) -> (name, byte order).
_PROCESSORS = {84: ("INTEL", "<"), 85: ("DEC", "<"), 86: ("MIPS", ">")}


def dec_to_float(words):
    """IEEE float32 values of DEC F-floats (uint8 or uint32 little-endian words).

    A DEC F-float keeps the sign, exponent and fraction in the same bit
    positions as IEEE, with its two 16-bit halves swapped and an exponent
    bias larger by two: swap the halves back and divide by 4.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.io._c3d_parameters import dec_to_float
    >>> bits = (np.array([1.5, -20.0], "<f4") * 4).view("<u4")
    >>> dec = ((bits << 16) | (bits >> 16)).astype("<u4")
    >>> dec_to_float(dec.view(np.uint8))
    array([  1.5, -20. ], dtype=float32)
    """
    bits = np.asarray(words).reshape(-1).view("<u4")
    swapped = ((bits << np.uint32(16)) | (bits >> np.uint32(16))).astype("<u4")
    with np.errstate(invalid="ignore"):  # junk words (NaN patterns) are checked by the caller
        return swapped.view("<f4") / np.float32(4.0)


def _int8(byte):
    return byte - 256 if byte > 127 else byte


class C3DMetadata:
    """What the header and parameters of a C3D file say.

    Attributes
    ----------
    processor : {"INTEL", "DEC", "MIPS"}
    order : {"<", ">"}
        Byte order of integers and IEEE floats.
    header : dict
        ``n_points``, ``analog_per_frame`` (samples of all analog channels in
        one point frame), ``first_frame``, ``last_frame``, ``scale``,
        ``data_start`` (512-byte block, 1-based), ``rate``.
    parameters : dict
        ``"GROUP:NAME"`` (upper case) to a 1-D array of numbers or a list of
        strings (NUL bytes and spaces stripped), in file order (first index
        fastest). A parameter defined more than once keeps its last
        definition, as ezc3d does (Vicon Plug-in Gait writes its
        ``PROCESSING`` subject measurements up to three times, the last one
        the final value); the repeated names are in ``duplicates``.
    """

    def __init__(self, processor, order, header, parameters, duplicates):
        self.processor = processor
        self.order = order
        self.header = header
        self.parameters = parameters
        self.duplicates = duplicates

    def number(self, key, default=None, *, unsigned=False):
        """The first value of a numeric parameter (an int16 read as uint16 if ``unsigned``)."""
        values = self.parameters.get(key)
        if values is None or isinstance(values, list) or len(values) == 0:
            return default
        value = values[0]
        if unsigned and isinstance(value, (np.integer, int)) and value < 0:
            return int(value) + 65536
        return value.item() if hasattr(value, "item") else value

    def strings(self, key):
        """A text parameter as a list of strings ([] when absent or numeric)."""
        values = self.parameters.get(key)
        return values if isinstance(values, list) else []


def _header(path, raw, processor, order):
    if len(raw) < 512:
        raise MotionFileError(path, None, "not a C3D file: shorter than its 512-byte header")
    head = bytes(raw[:24])
    words = np.frombuffer(head, dtype=order + "u2")
    floats = np.frombuffer(head[12:16] + head[20:24], np.uint8)
    if processor == "DEC":
        scale, rate = dec_to_float(floats)
    else:
        scale, rate = floats.view(order + "f4")
    return {
        "n_points": int(words[1]),
        "analog_per_frame": int(words[2]),
        "first_frame": int(words[3]),
        "last_frame": int(words[4]),
        "scale": float(scale),
        "data_start": int(words[8]),
        "rate": float(rate),
    }


def _value(path, body, at, order, processor, name):
    """The values of one parameter entry whose type byte is at ``body[at]``."""
    if at + 2 > len(body):
        raise MotionFileError(path, None, f"parameter {name} is cut short")
    kind = _int8(body[at])
    n_dims = body[at + 1]
    dims = [int(d) for d in body[at + 2 : at + 2 + n_dims]]
    start = at + 2 + n_dims
    if kind not in (-1, 1, 2, 4) or len(dims) != n_dims:
        raise MotionFileError(path, None, f"parameter {name} has type {kind}, not -1, 1, 2 or 4")
    size = abs(kind) * int(np.prod(dims, dtype=np.int64))
    if start + size > len(body):
        raise MotionFileError(
            path, None, f"parameter {name} announces {size} bytes past the parameter section"
        )
    data = body[start : start + size]
    if kind == -1:
        width = dims[0] if dims else 1
        count = size // width if width else 0
        texts = [data[i * width : (i + 1) * width] for i in range(count)]
        return [t.decode("latin-1").strip("\x00 ").strip() for t in texts]
    if kind == 1:
        return np.frombuffer(data, np.int8).astype(np.int64)
    if kind == 2:
        return np.frombuffer(data, order + "i2").astype(np.int64)
    if processor == "DEC":
        return dec_to_float(np.frombuffer(data, np.uint8)).astype(np.float64)
    return np.frombuffer(data, order + "f4").astype(np.float64)


def _entries(path, body, order, processor):
    """``{"GROUP:NAME": values}`` of every parameter, and the names defined twice."""
    groups, found, at = {}, [], 0
    while at + 4 <= len(body):
        n_chars, group_id = _int8(body[at]), _int8(body[at + 1])
        if n_chars == 0 or group_id == 0:
            break
        name_end = at + 2 + abs(n_chars)
        name = body[at + 2 : name_end].decode("latin-1").strip("\x00 ").upper()
        if name_end + 2 > len(body):
            break
        step = int(np.frombuffer(body[name_end : name_end + 2], order + "i2")[0])
        if group_id < 0:
            groups[-group_id] = name
        else:
            found.append((group_id, name, _value(path, body, name_end + 2, order, processor, name)))
        if step <= 0:  # 0 marks the last entry; a negative offset would loop
            break
        at = name_end + step
    parameters, duplicates = {}, []
    for group_id, name, values in found:
        key = f"{groups.get(group_id, group_id)}:{name}"
        if key in parameters and key not in duplicates:
            duplicates.append(key)
        parameters[key] = values  # the last definition wins, as in ezc3d
    return parameters, duplicates


def read_metadata(path, raw):
    """Parse the header and parameter section of the C3D bytes ``raw``.

    Parameters
    ----------
    path : str or path-like
        The file, for messages.
    raw : bytes or memoryview
        The file's bytes (at least the header and parameter blocks).

    Returns
    -------
    metadata : C3DMetadata

    Raises
    ------
    MotionFileError
        Not a C3D file, an unknown processor type, or a parameter whose
        announced size runs past the section.
    """
    raw = memoryview(raw).cast("B")
    if len(raw) < 512 or raw[1] != 0x50:
        raise MotionFileError(path, None, "not a C3D file: the header's key byte is not 0x50")
    start = (raw[0] - 1) * 512
    if raw[0] < 2 or start + 4 > len(raw):
        raise MotionFileError(path, None, f"the parameter section (block {raw[0]}) is missing")
    n_blocks, kind = raw[start + 2], raw[start + 3]
    if kind not in _PROCESSORS:
        raise MotionFileError(
            path, None, f"processor type {kind - 83} is not 1 (Intel), 2 (DEC) or 3 (MIPS)"
        )
    processor, order = _PROCESSORS[kind]
    body = bytes(raw[start + 4 : start + 512 * max(n_blocks, 1)])
    parameters, duplicates = _entries(path, body, order, processor)
    return C3DMetadata(
        processor, order, _header(path, raw, processor, order), parameters, duplicates
    )
