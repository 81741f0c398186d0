"""The requests an episode on disk has taken, by the client's request id: what makes a retried
observation idempotent, also across a restart of the process that serves it.

``requests.json`` beside ``episode.json`` (the episode's own files are unchanged: the CLI reads and
writes the episode as before) maps each request id to the SHA-256 of the request's body, the
number of steps the episode had when the request began, and the reply once it was given. An
observation is recorded *before* it is applied (:meth:`RequestLog.begin`) and its reply after
(:meth:`RequestLog.finish`); so after a crash anywhere in between, the step count tells whether the
observation reached ``episode.json`` (applied: rebuild the reply) or not (apply it now). Every write
is atomic (written, fsynced, renamed, directory fsynced) and checked on read.
"""
from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path
from typing import Optional

from ..cache import atomic_write_text
from .outside_loop import EpisodeError

REQUESTS_FILE = "requests.json"
FORMAT = 1


def body_digest(body: dict) -> str:
    """SHA-256 of a request body as canonical JSON (a retry must send the same body)."""
    return hashlib.sha256(json.dumps(body, sort_keys=True).encode()).hexdigest()


def sync_directory(directory: Path) -> None:
    """fsync a directory, so that the renames into it survive a crash of the machine."""
    fd = os.open(directory, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def _doc_digest(requests: dict) -> str:
    return hashlib.sha256(json.dumps(requests, sort_keys=True).encode()).hexdigest()


class RequestLog:
    """The request ids of the episode in ``directory`` (read once, written through)."""

    def __init__(self, directory):
        self.directory = Path(directory)
        self.path = self.directory / REQUESTS_FILE
        self.requests = self._read()

    def _read(self) -> dict:
        if not self.path.is_file():
            return {}
        try:
            doc = json.loads(self.path.read_text())
            requests, digest = doc["requests"], doc["sha256"]
        except (OSError, ValueError, KeyError, TypeError) as e:
            raise EpisodeError(f"{self.path}: damaged ({type(e).__name__}); the episode's requests cannot be read") \
                from None
        if doc.get("format") != FORMAT or _doc_digest(requests) != digest:
            raise EpisodeError(f"{self.path}: damaged (its checksum or format does not match)")
        return requests

    def _write(self, requests: dict) -> None:
        doc = {"format": FORMAT, "sha256": _doc_digest(requests), "requests": requests}
        atomic_write_text(self.path, json.dumps(doc, indent=1))
        sync_directory(self.directory)
        self.requests = requests

    def get(self, request_id: str) -> Optional[dict]:
        """{"digest", "steps_before", "reply"} of a request seen before, else None."""
        return self.requests.get(request_id)

    def begin(self, request_id: str, digest: str, steps_before: int) -> None:
        """Records a request before it changes the episode."""
        self._write({**self.requests, request_id: {"digest": digest, "steps_before": int(steps_before),
                                                   "reply": None}})

    def finish(self, request_id: str, reply: dict) -> None:
        """Records the reply given to a request (a retry gets it again)."""
        entry = dict(self.requests[request_id], reply=reply)
        self._write({**self.requests, request_id: entry})

    def drop(self, request_id: str) -> None:
        """Forgets a request that changed nothing (it failed): a retry runs it afresh."""
        if request_id in self.requests:
            self._write({k: v for k, v in self.requests.items() if k != request_id})
