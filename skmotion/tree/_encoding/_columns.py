"""The columns of a MotionTreeEncoder: which tree layers it encodes, and their names.

The layer parameters (``layers``, ``transition_layers``, ``residual_layers``,
``pyramid``) are read here, with the errors naming the parameter; the column names
follow the order in which :meth:`MotionTreeEncoder.transform` writes the blocks.
"""

import numpy as np


def _is_all(value):
    return isinstance(value, str) and value == "all"


def _existing(name, values, bottom):
    """The layers of ``values`` that the tree has, sorted, without repeats."""
    return np.array(sorted({v for v in _int_list(name, values) if v <= bottom}), dtype=np.intp)


def _int_list(name, values, low=0):
    values = np.asarray(values).ravel()
    if values.size and (values.dtype.kind not in "iu" or values.min() < low):
        raise ValueError(f"{name} must hold ints >= {low}; got {values.tolist()!r}.")
    return [int(v) for v in values]


def build_depth(max_depth, layers, transition_layers, residual_layers):
    """The deepest layer any block reads (a deeper tree would be built for nothing)."""
    if _is_all(layers):
        return max_depth
    wanted = [
        *_int_list("layers", layers),
        *_int_list("transition_layers", transition_layers),
        *_int_list("residual_layers", residual_layers),
    ]
    return min(max_depth, max(wanted, default=1))


def feature_names(
    blocks, residual_layers, n_nodes, channels, *, second_order, moments, moment_pyramid=(1,)
):
    """The encoder's column names, block after block (see ``get_feature_names_out``).

    ``blocks`` are the occupancy and transition blocks of :func:`feature_blocks`,
    ``n_nodes`` the tree's nodes per layer, ``channels`` the input channel names;
    ``second_order`` whether the residuals' second order follows them.
    """
    names = []
    for kind, layer, parts, width in blocks:
        if kind == "occupancy":
            k = width // parts
            names += [
                f"layer{layer}_node{n}_part{c + 1}of{parts}" for c in range(parts) for n in range(k)
            ]
        else:
            k = int(round(np.sqrt(width)))
            names += [f"layer{layer}_node{a}_to_node{b}" for a in range(k) for b in range(k)]
    for layer in residual_layers:
        names += [f"layer{layer}_node{k}_{c}" for k in range(n_nodes[layer]) for c in channels]
    for layer in residual_layers if second_order else ():
        names += [f"layer{layer}_node{k}_var_{c}" for k in range(n_nodes[layer]) for c in channels]
    if moments:
        for parts in moment_pyramid:
            names += [
                f"mean_{c}" if parts == 1 else f"mean_{c}_part{k + 1}of{parts}"
                for k in range(parts)
                for c in channels
            ]
    if moments >= 2:
        names += [f"rms_{c}" for c in channels]
    return np.asarray(names, dtype=object)
