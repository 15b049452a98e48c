"""Argument checks shared by the Python layer: clear ValueErrors naming the argument."""

from __future__ import annotations

import math

import numpy as np


def array(x, shape: tuple[int, ...], name: str) -> np.ndarray:
    """``x`` as a finite float array of exactly ``shape``."""
    try:
        a = np.asarray(x, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: expected numbers of shape {shape}, got {x!r}") from None
    if a.shape != shape:
        raise ValueError(f"{name}: expected shape {shape}, got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name}: expected finite values, got NaN or inf")
    return a


def vector(x, name: str, min_length: int = 0) -> np.ndarray:
    """``x`` as a finite 1-D float array of at least ``min_length`` values."""
    try:
        a = np.asarray(x, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: expected a 1-D sequence of numbers, got {x!r}") from None
    if a.ndim != 1 or a.size < min_length:
        raise ValueError(f"{name}: expected a 1-D sequence of at least {min_length} numbers, got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name}: expected finite values, got NaN or inf")
    return a


def vec3(x, name: str) -> np.ndarray:
    return array(x, (3,), name)


def scalar(x, name: str, *, positive: bool = False, nonnegative: bool = False) -> float:
    try:
        v = float(x)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: expected a number, got {x!r}") from None
    if not math.isfinite(v):
        raise ValueError(f"{name}: expected a finite number, got {v}")
    if positive and not v > 0.0:
        raise ValueError(f"{name}: expected a positive number, got {v}")
    if nonnegative and not v >= 0.0:
        raise ValueError(f"{name}: expected a non-negative number, got {v}")
    return v


def per_coordinate(x, n: int, name: str, *, nonnegative: bool = False) -> list[float]:
    """A scalar (same for every coordinate) or a sequence of ``n`` values."""
    if np.ndim(x) == 0:
        return [scalar(x, name, nonnegative=nonnegative)] * n
    if np.ndim(x) != 1:
        raise ValueError(f"{name}: expected a number or a 1-D sequence of {n} values, got shape {np.shape(x)}")
    values = list(x)
    if len(values) != n:
        raise ValueError(f"{name}: expected a number or {n} values (one per joint coordinate), got {len(values)}")
    return [scalar(v, name, nonnegative=nonnegative) for v in values]
