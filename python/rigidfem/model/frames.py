"""Frames: homogeneous transforms built from a translation and ZYX Euler angles.

Imported by both ``model`` and ``beams`` (and re-exported as ``rigidfem.transform`` and
``rigidfem.model.transform``), so that neither has to import the other for it.
"""

from __future__ import annotations

import numpy as np

from ..base import _checks
import rigidfem._core as _core  # the compiled core, by its absolute name


def transform(translation=(0.0, 0.0, 0.0), euler_zyx=(0.0, 0.0, 0.0)) -> np.ndarray:
    """Homogeneous transform Trans(translation) · R3(φ3) R2(φ2) R1(φ1) (4, 4).

    ``translation`` in m, ``euler_zyx = (φ3, φ2, φ1)`` in rad (yaw, pitch, roll).

    Examples
    --------
    >>> import rigidfem as rf
    >>> rf.transform(translation=(1.0, 0.0, 0.0)).round(3)
    array([[1., 0., 0., 1.],
           [0., 1., 0., 0.],
           [0., 0., 1., 0.],
           [0., 0., 0., 1.]])
    """
    r = _checks.vec3(translation, "translation")
    phi = _checks.vec3(euler_zyx, "euler_zyx")
    return _core.homogeneous(_core.euler_zyx(*phi), r)
