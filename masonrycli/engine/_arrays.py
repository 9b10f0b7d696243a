"""Shape and dtype checks shared by the engine's launchers.

The kernels index raw arrays without bounds checks: a wrong shape reads or writes past an array's end
instead of failing. Every public launcher therefore checks its arrays with these functions before calling
its kernel: shape and dtype comparisons only, never a pass over the data.
"""

from __future__ import annotations

import numpy as np

__all__ = ["check_array", "check_vertices"]


def check_array(where: str, name: str, array, shape: tuple, dtype) -> None:
    """Raise ValueError unless ``array`` is a numpy array of ``shape`` and ``dtype``.

    ``shape`` may hold None for a free dimension. The message names the launcher (``where``) and the
    argument, e.g. ``world_vertices: out has shape (3, 2), expected (4, 2) float64``.
    """
    # The message is built only on failure: formatting it every call cost more than the checks.
    if (
        isinstance(array, np.ndarray)
        and array.dtype == dtype
        and array.ndim == len(shape)
        and all(s is None or s == d for s, d in zip(shape, array.shape))
    ):
        return
    expected = f"expected {tuple('any' if s is None else s for s in shape)} {np.dtype(dtype)}"
    if not isinstance(array, np.ndarray):
        raise ValueError(f"{where}: {name} is a {type(array).__name__}, {expected}")
    raise ValueError(f"{where}: {name} has shape {array.shape} {array.dtype}, {expected}")


def check_vertices(where: str, name: str, vertices, body_vert_start) -> tuple[int, int]:
    """Check CSR vertex offsets ``(B+1,) int64`` and the ``(V, 2) float64`` vertex array they index.

    Returns (V, B). Only shapes and dtypes: the offsets' values are checked once per model by
    :func:`masonrycli.engine.contact_key.check_topology`.
    """
    check_array(where, "body_vert_start", body_vert_start, (None,), np.int64)
    if body_vert_start.shape[0] == 0:
        raise ValueError(f"{where}: body_vert_start is empty, expected B+1 offsets")
    vertex_count = int(body_vert_start[-1])
    check_array(where, name, vertices, (vertex_count, 2), np.float64)
    return vertex_count, body_vert_start.shape[0] - 1
