"""One meaning of a knot interval everywhere (attribute, operator, OBJ, library):

* a positive finite number is an interval (only ratios matter);
* <= 0, NaN or +-Inf is *unset*, which means 1 (the library reads unset the same way);
* the attribute is float32, so the Set operator refuses, with a message, any value it could not
  store as a positive finite float32 (<= 0, NaN, Inf, below 1.2e-38, 3.4e38 or above) rather
  than store something else; Clear is the way to unset. (Blender's float properties turn Inf
  into 3.4e38 and 1e-300 into 0 before the operator sees them: both are refused.)
"""
import math

import numpy as np

F32_MIN = float(np.finfo(np.float32).tiny)   # smallest normal float32, 1.1754944e-38
F32_MAX = float(np.finfo(np.float32).max)


def is_set(values):
    """Bool mask (or bool) of the values that are intervals (positive and finite)."""
    v = np.asarray(values, dtype=np.float64)
    with np.errstate(invalid="ignore"):
        return np.isfinite(v) & (v > 0)


def effective(values):
    """The interval each value means: itself when set, else 1."""
    v = np.asarray(values, dtype=np.float64)
    return np.where(is_set(v), v, 1.0)


def check_storable(value):
    """None if `value` can be stored as an interval, else the message the operator reports."""
    v = float(value)
    if math.isnan(v):
        return "Knot interval NaN refused: an interval is a positive finite number"
    if v <= 0:
        return ("Knot interval %g refused: it must be > 0 (<= 0 means unset; use Clear to "
                "reset rings to 1)" % v)
    if math.isinf(v) or abs(v) >= F32_MAX:  # Blender's float properties turn Inf into FLT_MAX
        return ("Knot interval %g refused: Inf or outside the float range the attribute stores "
                "(%.3g to %.3g); only ratios matter, so scale it" % (v, F32_MIN, F32_MAX))
    if v < F32_MIN:
        return ("Knot interval %g refused: outside the float range the attribute stores "
                "(%.3g to %.3g); only ratios matter, so scale it" % (v, F32_MIN, F32_MAX))
    return None
