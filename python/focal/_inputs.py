"""Input conversion: every array argument converted at most once to the layout the library views
without copying, with the argument's name in every message."""

from __future__ import annotations

import operator
import warnings
from typing import Any, Optional

import numpy as np

from . import _focal_ext as _ext
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


def _whole(value: Any, name: str, lo: int, hi: int, meaning: str = "") -> int:
    """``value`` as an int in [lo, hi] (an InvalidInputError naming ``name`` otherwise), so that
    no Python int reaches the C++ layer too large for its ``int`` (nanobind's TypeError /
    std::bad_cast)."""
    try:
        v = operator.index(value)
    except TypeError:
        raise InvalidInputError(
            f"{name} must be a whole number, got {type(value).__name__} {value!r}"
        ) from None
    if not lo <= v <= hi:
        raise InvalidInputError(f"{name} must be in [{lo}, {hi}]{meaning}, got {v}")
    return v


def _int32(value: Any, name: str) -> int:
    """``value`` as an int the C++ ``int`` holds (the library checks its own range)."""
    return _whole(value, name, -(2**31), 2**31 - 1)


# C++ int64 range: what _ext.resolve_threads takes (it clamps to kMaxThreads with a warning).
_INT64_MAX = 2**63 - 1


def _threads(threads: Optional[int]) -> int:
    """The thread count for the C++ layer by its one rule (focal::resolve_threads): None or 0
    every CPU (or FOCAL_NUM_THREADS; an InvalidInputError when that is not a number), a count
    above the library's maximum clamped with a warning."""
    if threads is None:
        threads = 0
    try:
        t = operator.index(threads)
    except TypeError:
        raise InvalidInputError(
            f"threads must be None or a whole number >= 0, got {threads!r}"
        ) from None
    if t < 0:
        raise InvalidInputError(f"threads must be None or >= 0, got {threads}")
    count, warning = _ext._resolve_threads(min(t, _INT64_MAX))
    if warning:
        warnings.warn(warning, stacklevel=3)
    return count


def _vector(a: Any, name: str, n: int, dtype: type) -> np.ndarray:
    arr = _array(a, name)
    if arr.shape != (n,):
        raise _shape_error(name, f"({n},)", arr.shape)
    return np.ascontiguousarray(arr, dtype=dtype)



def _usable_normals(N: Optional[np.ndarray], name: str) -> Optional[np.ndarray]:
    """N, or None with a warning when no row of it is a usable normal (every row zero or not
    finite, as CGAL's blobby.xyz: ``x y z 0 0 0``): such normals are read as absent, as the
    command line does, and estimated instead."""
    if N is None or N.shape[0] == 0:
        return N
    lengths = np.einsum("ij,ij->i", N, N)
    if not np.any(np.isfinite(lengths) & (lengths > 0)):
        warnings.warn(
            f"{name}: every normal is zero or not finite: ignored, the normals are estimated "
            "(as without normals)",
            stacklevel=3,
        )
        return None
    return N


def _finite_positions(V: np.ndarray, name: str) -> None:
    """A warning (as the command line's) when rows of V are not finite, and an error when V is
    empty ("no vertices, nothing to compute", as the command line)."""
    if V.shape[0] == 0:
        raise InvalidInputError(f"{name}: no vertices, nothing to compute")
    bad = int(np.count_nonzero(~np.isfinite(V).all(axis=1)))
    if bad:
        warnings.warn(
            f"{name}: {bad} of {V.shape[0]} positions are not finite (NaN or infinite): those "
            "vertices and their neighbours' fits leave them out, and they are undefined",
            stacklevel=3,
        )
