"""The episodes the service holds: one sub-directory of the episodes directory per id (the
format ``bayesgrasp episode`` writes), kept warm in memory with their planners, each behind its
own lock (an episode's observations one after another; different episodes in parallel).

A warm episode is reopened from disk when its ``episode.json`` changed under it (another process,
e.g. ``bayesgrasp episode observe``, continued it) or after it was dropped from memory (the least
recently used beyond ``max_warm``) or the service restarted."""
from __future__ import annotations

import os
import threading
from collections import OrderedDict
from dataclasses import dataclass
from pathlib import Path
from typing import Optional

from ..loop.outside_loop import STATE_FILE, DiskEpisode
from ..loop.outside_loop_category import open_episode
from ..loop.outside_requests import RequestLog
from .errors import ApiError
from .security import check_id


def _stamp(directory: Path):
    """What changes whenever episode.json is replaced (atomic renames give a new inode)."""
    st = os.stat(directory / STATE_FILE)
    return st.st_ino, st.st_mtime_ns, st.st_size


@dataclass
class Warm:
    """One episode in memory: its planner-holding object, its request log, the file it was read from."""

    episode: DiskEpisode
    log: RequestLog
    stamp: tuple

    def written(self) -> None:
        """After the episode wrote its state: remember the file as ours."""
        self.stamp = _stamp(self.episode.directory)


class EpisodeStore:
    def __init__(self, root, cache_dir: Optional[str] = None, max_warm: int = 256):
        self.root = Path(root)
        self.root.mkdir(parents=True, exist_ok=True)
        self.cache_dir, self.max_warm = cache_dir, max_warm
        self._guard = threading.Lock()          # over the two dicts below
        self._locks: dict = {}
        self._warm: "OrderedDict[str, Warm]" = OrderedDict()
        self.creating = threading.Lock()        # new episodes one at a time (first model loads are shared)

    def directory(self, eid: str) -> Path:
        return self.root / check_id(eid)

    def exists(self, eid: str) -> bool:
        return (self.directory(eid) / STATE_FILE).is_file()

    def lock(self, eid: str) -> threading.Lock:
        """The episode's own lock: hold it around every use of :meth:`get`."""
        check_id(eid)
        with self._guard:
            return self._locks.setdefault(eid, threading.Lock())

    def get(self, eid: str) -> Warm:
        """The episode, warm (reopened from disk if it changed there or was not in memory)."""
        d = self.directory(eid)
        if not (d / STATE_FILE).is_file():
            raise ApiError(404, "no_such_episode", f"no episode {eid!r}")
        with self._guard:
            warm = self._warm.get(eid)
        if warm is None or warm.stamp != _stamp(d):
            stamp = _stamp(d)
            warm = Warm(open_episode(d), RequestLog(d), stamp)
        self.put(eid, warm)
        return warm

    def put(self, eid: str, warm: Warm) -> None:
        with self._guard:
            self._warm[eid] = warm
            self._warm.move_to_end(eid)
            while len(self._warm) > self.max_warm:
                self._warm.popitem(last=False)

    def warm_count(self) -> int:
        with self._guard:
            return len(self._warm)
