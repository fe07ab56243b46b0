"""Frames too large for memory, read block by block: ``.npy`` files or a ``dask.array``.

A source is a list of *chunks*, each read by a worker as consecutive row blocks of at
most ``rows`` frames, so a task holds one block at a time (plus what it keeps), never a
whole chunk: a ``.npy`` file is read with ``numpy.fromfile`` from its data offset (no
memory map, whose touched pages would count in the worker's memory), a ``dask.array``
chunk is computed by the worker from its own graph. Each block is checked (2-D, the
same channels everywhere, finite) with an error naming the file or chunk, row and
channel.
"""

import os
from pathlib import Path

import numpy as np

__all__ = ["chunk_sources", "read_blocks"]

#: Frames per block a task reads at once (about 30 MB at 60 channels).
BLOCK_ROWS = 1 << 16


def chunk_sources(frames):
    """The chunks of a frame collection, as ``(name, source)`` pairs, and the channel count.

    Parameters
    ----------
    frames : list of str or path-like, or dask.array.Array
        ``.npy`` files of 2-D float arrays (the same number of columns), or a 2-D
        ``dask.array`` (its row chunks; it is rechunked to whole rows if its columns
        are split).

    Returns
    -------
    chunks : list of (str, object)
        A name for messages, and a path or a ``dask.delayed`` block.
    n_channels : int
    """
    if type(frames).__module__.startswith("dask.array"):
        if frames.ndim != 2:
            raise ValueError(f"frames must be a 2-D dask.array; got {frames.ndim} dimensions.")
        if len(frames.chunks[1]) > 1:
            frames = frames.rechunk({1: -1})
        blocks = frames.to_delayed().ravel()
        return [(f"dask.array chunk {i}", block) for i, block in enumerate(blocks)], frames.shape[1]
    if isinstance(frames, (str, os.PathLike)) or not hasattr(frames, "__len__") or not frames:
        raise TypeError(
            "frames must be a non-empty list of .npy files or a 2-D dask.array; got "
            f"{type(frames).__name__}."
        )
    chunks, width = [], None
    for path in frames:
        path = Path(path)
        shape, _, _ = _npy_header(path)
        if len(shape) != 2:
            raise ValueError(f"{path}: frames must be 2-D (n_frames, n_channels); got {shape}.")
        if width is not None and shape[1] != width:
            raise ValueError(f"{path}: {shape[1]} channels where the first file has {width}.")
        width = shape[1]
        chunks.append((str(path), str(path)))
    return chunks, width


def _npy_header(path):
    """Shape, dtype and data offset of a ``.npy`` file (a C-ordered float array)."""
    with open(path, "rb") as file:
        version = np.lib.format.read_magic(file)
        read_header = (
            np.lib.format.read_array_header_1_0
            if version == (1, 0)
            else np.lib.format.read_array_header_2_0
        )
        shape, fortran, dtype = read_header(file)
        offset = file.tell()
    if fortran or dtype.kind != "f":
        raise ValueError(f"{path}: frames must be a C-ordered float array; got {dtype}.")
    return shape, dtype, offset


def read_blocks(name, source, n_channels, rows=BLOCK_ROWS):
    """Yield ``(start, block)``: the chunk's frames as float64 row blocks, checked.

    Parameters
    ----------
    name : str
        The chunk's name, for messages.
    source : str or ndarray
        A ``.npy`` path, or the computed array of a ``dask.array`` chunk.
    n_channels : int
    rows : int, default=BLOCK_ROWS
    """
    if isinstance(source, str):
        shape, dtype, offset = _npy_header(source)
        with open(source, "rb") as file:
            file.seek(offset)
            for start in range(0, shape[0], rows):
                count = min(rows, shape[0] - start) * shape[1]
                block = np.fromfile(file, dtype=dtype, count=count)
                if block.size != count:
                    raise ValueError(f"{name}: the file ends before row {start + rows}.")
                yield start, _checked(name, start, block.reshape(-1, shape[1]), n_channels)
        return
    array = np.asarray(source)
    for start in range(0, len(array), rows):
        yield start, _checked(name, start, array[start : start + rows], n_channels)


def _checked(name, start, block, n_channels):
    block = np.ascontiguousarray(block, dtype=np.float64)
    if block.ndim != 2 or block.shape[1] != n_channels:
        raise ValueError(f"{name}: frames of shape {block.shape}, not (n, {n_channels}).")
    finite = np.isfinite(block)
    if not finite.all():
        row, channel = np.argwhere(~finite)[0]
        raise ValueError(
            f"{name}: frames must be finite; row {start + row}, channel {channel} is "
            f"{block[row, channel]}."
        )
    return block
