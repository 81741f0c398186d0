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


def with_fields(cls, options=None, fields=None, validate: bool = True):
    """A copy of ``options`` (an instance of the bound option class ``cls``; None: its defaults)
    with ``fields`` set (a None value keeps the field as it is), each converted to the type of the
    field's current value (ints range-checked, ``seed`` as an unsigned 64-bit seed), then validated
    (``validate=False``: the caller validates once it has set everything). ValueError naming an
    unknown field or a bad value; the ``options`` given is never changed."""
    if options is None:
        out = cls()
    elif isinstance(options, cls):
        out = options.__copy__()
    else:
        raise ValueError(f"options: expected a {cls.__name__}, got {type(options).__name__}")
    for name, value in (fields or {}).items():
        if name not in cls.fields:
            raise ValueError(f"{name}: not a field of {cls.__name__} (fields: {', '.join(cls.fields)})")
        if value is None:
            continue
        current = getattr(out, name)
        if isinstance(current, bool):
            value = bool(value)
        elif isinstance(current, int):
            value = c_seed(value, name) if name == "seed" else c_int(value, name)
        elif isinstance(current, float):
            value = float(value)
        setattr(out, name, value)
    if validate and hasattr(out, "validate"):
        out.validate()
    return out
