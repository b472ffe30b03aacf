"""Comparing renders with reference images made when the kernels read float32 environment
texels (tests/data). The kernels now read half floats (:func:`engine.tracer.tables.environment.
half_texels`): every texel within a relative ``2**-11`` of its float32 value (or ``2**-25`` for
the faintest, stored as subnormals). A pixel is a sum of environment lookups with positive
weights (bilinear weights times branch weights, the same as before when the rays are), so it
moves by at most ``2**-11`` of its own value: a geometry or sampling change moves it by more."""
from __future__ import annotations

import numpy as np

#: What a half float's rounding may move a pixel by: relative, then absolute (subnormal
#: texels, and 1e-10 for the intersectors' last bits, as the references' own tests allow).
HALF_RELATIVE = 2.0 ** -11
HALF_ABSOLUTE = 2.0 ** -25 + 1e-10


def assert_within_half_rounding(img, ref) -> None:
    """``img`` equals the float32-texel reference ``ref`` within the half floats' rounding."""
    img, ref = np.asarray(img, np.float64), np.asarray(ref, np.float64)
    assert img.shape == ref.shape
    excess = np.abs(img - ref) - (HALF_RELATIVE * np.abs(ref) + HALF_ABSOLUTE)
    assert excess.max() <= 0.0, f"{np.count_nonzero(excess > 0)} pixels differ by more than rounding"
