"""Integer arguments on their way into the C++ core.

pybind11 answers a Python int that does not fit the C++ type (2**70 for an ``int``) with a
TypeError listing the function's signatures; these helpers answer it with a ValueError that names
the argument and the range, before the call.
"""
from __future__ import annotations

import operator

INT_MIN, INT_MAX = -(2**31), 2**31 - 1
SEED_MAX = 2**64 - 1


def c_int(value, name: str, lo: int = INT_MIN, hi: int = INT_MAX) -> int:
    """``value`` as an int in [lo, hi] (a C++ ``int`` by default); bools and floats with a
    fractional part are refused, numpy integers accepted."""
    if isinstance(value, bool):
        raise TypeError(f"{name}: expected an integer, got {value!r}")
    try:
        v = operator.index(value)
    except TypeError:
        if isinstance(value, float) and value.is_integer():
            v = int(value)
        else:
            raise TypeError(f"{name}: expected an integer, got {value!r}") from None
    if not lo <= v <= hi:
        raise ValueError(f"{name}: must be in [{lo}, {hi}], got {v}")
    return v


def c_seed(value, name: str = "seed") -> int:
    """A seed for the core's unsigned 64-bit generators: an integer in [0, 2**64 - 1]."""
    return c_int(value, name, 0, SEED_MAX)
