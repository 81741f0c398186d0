"""Where bayesgrasp keeps what it computes once: ``$BAYESGRASP_CACHE``, else
``~/.cache/bayesgrasp`` (GP models in ``models/``, the lift test's convex decompositions in
``convex_decomposition/``, demonstrated task grasps beside the models), and how it writes and
reads those files safely.

The package ships a read-only cache of the built-in objects' entries (``bayesgrasp/data/cache``,
rebuilt by ``make shipped-cache``: :mod:`bayesgrasp.cache_build`): :func:`load_cached` reads an
entry from the user's cache, else the shipped file of the same name (same key: same mesh, hand and
settings), so a first call on a built-in object builds nothing. ``BAYESGRASP_SHIPPED_CACHE=0``
turns the shipped cache off (a truly empty cache, e.g. to rebuild it).

Every cache file is written atomically: first to a temporary file with a unique name in the same
directory, flushed to disk with fsync, then renamed over the target. So a reader never sees half a
file, and builders of the same key never write into each other's files. Beside each file,
``<name>.sha256`` holds the SHA-256 of its bytes. :func:`checked` tells whether a file matches its
checksum. A missing, truncated, emptied or altered file fails the check, and its caller rebuilds
the entry with a warning instead of failing on every later run.
"""
from __future__ import annotations

import hashlib
import os
import uuid
import warnings
from pathlib import Path
import zipfile
from typing import Callable, Optional, TypeVar, Union

PathLike = Union[str, os.PathLike]
T = TypeVar("T")

#: What reading a damaged file may raise (numpy's .npz reader, json, our own format checks).
READ_ERRORS = (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile)


def cache_root() -> Path:
    """``$BAYESGRASP_CACHE``, else ``~/.cache/bayesgrasp``."""
    return Path(os.environ.get("BAYESGRASP_CACHE") or os.path.join(os.path.expanduser("~"), ".cache", "bayesgrasp"))


def shipped_root() -> Optional[Path]:
    """The package's read-only cache (``bayesgrasp/data/cache``), or None when
    ``$BAYESGRASP_SHIPPED_CACHE`` is ``0`` (or the package has none)."""
    if os.environ.get("BAYESGRASP_SHIPPED_CACHE", "1").strip().lower() in ("0", "false", "no", "off"):
        return None
    root = Path(__file__).resolve().parent / "data" / "cache"
    return root if root.is_dir() else None


def shipped_copy(path: PathLike) -> Optional[Path]:
    """The shipped file standing for cache file ``path`` (the same directory name and file name
    under :func:`shipped_root`), if there is one."""
    root = shipped_root()
    if root is None:
        return None
    path = Path(path)
    p = root / path.parent.name / path.name
    return p if p.is_file() else None


class CacheWarning(UserWarning):
    """A cache file failed its check and is rebuilt."""


def _digest(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def _sidecar(path: Path) -> Path:
    return path.with_name(path.name + ".sha256")


def _replace_synced(tmp: Path, path: Path) -> None:
    with open(tmp, "rb+") as f:
        os.fsync(f.fileno())
    os.replace(tmp, path)


def atomic_write(path: PathLike, write: Callable[[Path], None]) -> None:
    """Writes ``path`` with ``write(tmp)`` (which must create the file ``tmp``, keeping its
    suffix, e.g. ``np.savez``) and then its checksum file; both atomically (see the module)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tag = f"{os.getpid()}.{uuid.uuid4().hex[:8]}"
    tmp = path.with_name(f".{path.stem}.{tag}.tmp{path.suffix}")
    side_tmp = path.with_name(f".{path.name}.{tag}.tmp.sha256")
    try:
        write(tmp)
        digest = _digest(tmp)
        _replace_synced(tmp, path)
        side_tmp.write_text(digest + "\n")
        _replace_synced(side_tmp, _sidecar(path))
    finally:
        for t in (tmp, side_tmp):
            if t.exists():
                t.unlink()


def atomic_write_text(path: PathLike, text: str) -> None:
    """:func:`atomic_write` of a text file."""
    atomic_write(path, lambda tmp: tmp.write_text(text))


def checked(path: PathLike, what: str = "cache file") -> bool:
    """Whether ``path`` exists and matches its checksum file. A file that exists but fails (no
    checksum file, a different digest) gives a :class:`CacheWarning` naming it and ``what``."""
    path = Path(path)
    if not path.is_file():
        return False
    side = _sidecar(path)
    try:
        ok = side.is_file() and side.read_text().strip() == _digest(path)
    except OSError:
        ok = False
    if not ok:
        warnings.warn(f"{what} {path}: damaged or written by another version (checksum does not match); "
                      f"rebuilding it", CacheWarning, stacklevel=3)
    return ok


def load_checked(path: PathLike, what: str, read: Callable[[Path], T]) -> Optional[T]:
    """``read(path)`` if the file exists, passes :func:`checked` and reads without one of
    READ_ERRORS; else None (with a :class:`CacheWarning` unless the file is simply absent): the
    caller rebuilds the entry."""
    path = Path(path)
    if not checked(path, what):
        return None
    try:
        return read(path)
    except READ_ERRORS as e:
        warnings.warn(f"{what} {path}: unreadable ({type(e).__name__}: {e}); rebuilding it", CacheWarning, stacklevel=2)
        return None


def load_cached(path: PathLike, what: str, read: Callable[[Path], T]) -> Optional[T]:
    """:func:`load_checked` of the user's cache file ``path``; if it is absent, of its shipped copy
    (:func:`shipped_copy`). None: build the entry."""
    if not Path(path).is_file():
        ship = shipped_copy(path)
        if ship is not None:
            return load_checked(ship, f"shipped {what}", read)
    return load_checked(path, what, read)


def cached(path: PathLike) -> bool:
    """Whether ``path`` or its shipped copy exists (no checksum read)."""
    return Path(path).is_file() or shipped_copy(path) is not None
