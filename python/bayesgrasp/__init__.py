"""bayesgrasp: grasp planning under uncertainty.

The C++ core lives in :mod:`bayesgrasp._core`; the Python modules here orchestrate it.
Units are metres, radians, kilograms and newtons; frames are z up with the table top at z = 0.
"""
import os as _os

# Development hook: a CMake build tree outside scikit-build puts _core in
# <build>/bayesgrasp_core; point BAYESGRASP_CORE_DIR there to use it from the source tree.
_dev_core = _os.environ.get("BAYESGRASP_CORE_DIR")
if _dev_core:
    __path__.append(_dev_core)  # noqa: F821 (module __path__)

__version__ = "0.1.0"

#: The hand every command and function takes when none is named: the Barrett BH8 (the thesis's).
DEFAULT_HAND = "barrett_bh8"
