"""Where bayesgrasp keeps what it computes once: ``$BAYESGRASP_CACHE``, else
``~/.cache/bayesgrasp`` (GP models in ``models/``, the lift test's convex decompositions in
``convex_decomposition/``)."""
from __future__ import annotations

import os
from pathlib import Path


def cache_root() -> Path:
    """``$BAYESGRASP_CACHE``, else ``~/.cache/bayesgrasp``."""
    return Path(os.environ.get("BAYESGRASP_CACHE") or os.path.join(os.path.expanduser("~"), ".cache", "bayesgrasp"))
