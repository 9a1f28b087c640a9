"""Array helpers shared by the physics modules."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.floating[Any]]


def reflected_cumsum(increments: ArrayLike, initial: float = 0.0) -> FloatArray:
    """Running sum held at or above zero: ``w_k = max(0, w_{k-1} + x_k)``, ``w_0 = initial``.

    Vectorised through Lindley's identity ``w_k = S_k − min(−w_0, min_{j≤k} S_j)`` with
    ``S_k = x_1 + … + x_k`` (Lindley 1952), so no Python loop per step. Used for the heat stored
    in a cargo box above its set-point and for a battery that cannot charge beyond full.

    Parameters
    ----------
    increments
        x_1 … x_n, in any unit.
    initial
        w_0 >= 0, in the same unit.

    Returns
    -------
    numpy.ndarray
        w_1 … w_n.
    """
    s = np.cumsum(np.asarray(increments, dtype=float))
    return s - np.minimum(np.minimum.accumulate(s), -initial) if s.size else s
