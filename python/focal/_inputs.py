"""Input conversion: every array argument converted at most once to the layout the library views
without copying, with the argument's name in every message."""

from __future__ import annotations

from typing import Any, Optional

import numpy as np

from ._errors import InvalidInputError


def _shape_error(name: str, expected: str, got: Any) -> InvalidInputError:
    return InvalidInputError(f"{name} must have shape {expected}, got shape {got}")


# DLPack device type of host memory (dlpack.h, kDLCPU).
_DLPACK_CPU = 1


def _array(a: Any, name: str) -> np.ndarray:
    """``a`` as a NumPy array without copying where its memory allows: ndarrays as they are,
    DLPack producers on the CPU (PyTorch, JAX, ...) through np.from_dlpack, anything else with
    np.asarray (``__array_interface__``, buffers, nested lists). Arrays on a GPU are an error."""
    if isinstance(a, np.ndarray):
        return a
    if hasattr(a, "__dlpack_device__"):
        device_type, device_id = a.__dlpack_device__()
        if int(device_type) != _DLPACK_CPU:
            raise InvalidInputError(
                f"{name} is in device memory (DLPack device type {int(device_type)}, id "
                f"{int(device_id)}); focal takes host arrays: copy it to the CPU first"
            )
        try:
            return np.from_dlpack(a)
        except (TypeError, BufferError, RuntimeError):
            pass  # a dtype DLPack cannot export to NumPy: asarray below
    try:
        return np.asarray(a)
    except (ValueError, TypeError) as e:
        raise InvalidInputError(f"{name} is not an array: {e}") from None


def _as_rows(a: Any, name: str, dtype: type) -> np.ndarray:
    """``a`` as a C-ordered ``(n, 3)`` array of ``dtype``: ``a`` itself when it already is one,
    else one converted copy."""
    arr = _array(a, name)
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise _shape_error(name, "(n, 3)", arr.shape)
    kind = arr.dtype.kind
    if dtype is np.float64:
        if kind not in "fiu":
            raise InvalidInputError(f"{name} must hold numbers, got dtype {arr.dtype}")
    else:
        if kind not in "iu":
            raise InvalidInputError(
                f"{name} must hold integer vertex indices, got dtype {arr.dtype}"
            )
        if arr.dtype != np.int32 and arr.size > 0:
            lo, hi = int(arr.min()), int(arr.max())
            if lo < 0 or hi > np.iinfo(np.int32).max:
                bad = lo if lo < 0 else hi
                raise InvalidInputError(
                    f"{name} holds vertex index {bad}, outside [0, 2^31 - 1]"
                )
    return np.ascontiguousarray(arr, dtype=dtype)


def _mesh_arrays(V: Any, F: Any, N: Any = None):
    Va = _as_rows(V, "V", np.float64)
    Fa = _as_rows(F, "F", np.int32)
    Na = None
    if N is not None:
        Na = _as_rows(N, "N", np.float64)
        if Na.shape[0] != Va.shape[0]:
            raise _shape_error("N", f"({Va.shape[0]}, 3) like V", Na.shape)
    return Va, Fa, Na


def _threads(threads: Optional[int]) -> int:
    if threads is None:
        return 0
    t = int(threads)
    if t < 0:
        raise InvalidInputError(f"threads must be None or >= 0, got {threads}")
    return t


def _vector(a: Any, name: str, n: int, dtype: type) -> np.ndarray:
    arr = _array(a, name)
    if arr.shape != (n,):
        raise _shape_error(name, f"({n},)", arr.shape)
    return np.ascontiguousarray(arr, dtype=dtype)

