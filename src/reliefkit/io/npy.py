"""Reading a .npy file's header (shape, order, dtype) before its data, so a loader can
refuse a wrong or oversized array without allocating it."""

from __future__ import annotations

import numpy as np


def npy_header(fh) -> tuple[tuple, bool, np.dtype]:
    """(shape, fortran_order, dtype) of the .npy file open in ``fh`` (binary, at its start);
    leaves ``fh`` at the data. Raises ValueError for a file that is no .npy of version 1 or
    2 (numpy's own message)."""
    version = np.lib.format.read_magic(fh)
    if version == (1, 0):
        return np.lib.format.read_array_header_1_0(fh)
    if version == (2, 0):
        return np.lib.format.read_array_header_2_0(fh)
    raise ValueError(f"unsupported .npy version {version}")
