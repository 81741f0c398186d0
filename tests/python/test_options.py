"""Every option class the core binds (OptionClass in cpp/bindings/options.hpp) is one kind of
thing: defaults that validate, a 'name : type' docstring per field, a keyword constructor that
names an unknown keyword, and a validate() that names a NaN float field."""
import copy
import math

import pytest

from bayesgrasp import _core
from bayesgrasp._args import with_fields

SUBMODULES = [getattr(_core, n) for n in dir(_core) if type(getattr(_core, n)).__name__ == "module"]
OPTION_CLASSES = sorted({cls for mod in SUBMODULES for cls in vars(mod).values()
                         if isinstance(cls, type) and isinstance(getattr(cls, "fields", None), tuple)},
                        key=lambda c: c.__name__)


def test_the_option_classes_are_found():
    names = {c.__name__ for c in OPTION_CLASSES}
    for expected in ["PSOOptions", "TrustRegionOptions", "RegistrationOptions", "SegmentationOptions", "NoiseModel",
                     "Intrinsics", "Table"]:
        assert expected in names


@pytest.mark.parametrize("cls", OPTION_CLASSES, ids=lambda c: c.__name__)
def test_defaults_validate_and_every_field_is_documented(cls):
    cls().validate()
    assert cls.fields and len(set(cls.fields)) == len(cls.fields)
    for name in cls.fields:
        doc = getattr(cls, name).__doc__ or ""
        assert doc.startswith(f"{name} : ") and len(doc.split("\n", 1)[-1].strip()) > 3, (cls.__name__, name, doc)


@pytest.mark.parametrize("cls", OPTION_CLASSES, ids=lambda c: c.__name__)
def test_validate_names_a_nan_in_each_float_field(cls):
    floats = [n for n in cls.fields if type(getattr(cls(), n)) is float]
    for name in floats:
        o = cls()
        setattr(o, name, math.nan)
        with pytest.raises(ValueError, match=name):
            o.validate()


@pytest.mark.parametrize("cls", OPTION_CLASSES, ids=lambda c: c.__name__)
def test_keyword_constructor_copies_and_repr(cls):
    name = cls.fields[0]
    value = getattr(cls(), name)
    o = cls(**{name: value})
    assert repr(o).startswith(cls.__name__ + "(")
    with pytest.raises(ValueError, match="not_a_field"):
        cls(not_a_field=1)
    c = copy.deepcopy(o)
    assert repr(c) == repr(o) and c is not o


def test_with_fields_converts_validates_and_leaves_the_given_options_alone():
    pso = _core.optim.PSOOptions
    given = pso(n_particles=10)
    out = with_fields(pso, given, {"n_particles": 12.0, "seed": 2**63, "max_iter": None})
    assert (out.n_particles, out.seed, out.max_iter) == (12, 2**63, 200) and given.n_particles == 10
    with pytest.raises(ValueError, match="inertia"):
        with_fields(pso, given, {"inertia": math.nan})
    with pytest.raises(ValueError, match="swarm"):
        with_fields(pso, None, {"swarm": 3})
    assert given.n_particles == 10
