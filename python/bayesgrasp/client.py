"""A small client of ``bayesgrasp serve`` (standard library only, so a robot's environment needs
nothing else): start an episode, send each observation, read the episode back.

    from bayesgrasp.client import Client
    c = Client("http://127.0.0.1:8765", token=open("episodes/.token").read().strip())
    ep = c.new_episode(object="cylinder", estimate=[0.035, -0.04, 0.9], method="stability")
    while ep["next"] is not None:
        joints, lifted = robot.execute(ep["next"]["grasp"])       # your robot
        ep = c.observe(ep["id"], joints, lifted)

:meth:`Client.observe` gives each observation a request id and retries it with the same id when the
connection fails or the server is restarting: the service applies it once and answers the retry
with the same reply."""
from __future__ import annotations

import json
import ssl
import time
import urllib.error
import urllib.request
import uuid
from typing import Optional, Sequence


class ServiceError(Exception):
    """The service refused a request: ``status`` (HTTP), ``code`` and ``message`` from its JSON error."""

    def __init__(self, status: int, code: str, message: str):
        super().__init__(f"{status} {code}: {message}")
        self.status, self.code, self.message = status, code, message


class Client:
    """``base_url``: e.g. ``http://127.0.0.1:8765``; ``token``: the server's bearer token;
    ``cafile``: the certificate to trust for an HTTPS server with a self-signed one; ``retries``,
    ``backoff``, ``max_backoff``: how often to retry an observation that got no answer, and how
    long to wait before each retry (s, doubling from ``backoff`` up to ``max_backoff``)."""

    def __init__(self, base_url: str, token: str, timeout: float = 60.0, cafile: Optional[str] = None,
                 retries: int = 5, backoff: float = 0.5, max_backoff: float = 5.0):
        if retries < 0 or not 0 < backoff <= max_backoff:
            raise ValueError(f"retries >= 0 and 0 < backoff <= max_backoff, got {retries}, {backoff}, {max_backoff}")
        self.base = base_url.rstrip("/") + "/v1"
        self.token, self.timeout, self.retries = token, timeout, retries
        self.backoff, self.max_backoff = backoff, max_backoff
        self.context = ssl.create_default_context(cafile=cafile) if cafile else None

    def _call(self, method: str, path: str, body: Optional[dict] = None) -> dict:
        data = None if body is None else json.dumps(body).encode()
        req = urllib.request.Request(self.base + path, data=data, method=method,
                                     headers={"Authorization": f"Bearer {self.token}",
                                              "Content-Type": "application/json"})
        try:
            with urllib.request.urlopen(req, timeout=self.timeout, context=self.context) as r:
                return json.loads(r.read())
        except urllib.error.HTTPError as e:
            try:
                err = json.loads(e.read())["error"]
            except (ValueError, KeyError, TypeError):
                err = {"code": "http_error", "message": str(e)}
            raise ServiceError(e.code, err.get("code", "http_error"), err.get("message", "")) from None

    def health(self) -> dict:
        return self._call("GET", "/health")

    def new_episode(self, **options) -> dict:
        """``POST /v1/episodes``: the options of ``bayesgrasp episode new`` (object, estimate, method,
        attempts, seed, hand, models, planner; or category, task and a view) -> {id, next, ...}."""
        return self._call("POST", "/episodes", options)

    def observe(self, episode_id: str, joints: Sequence[float], lifted: bool,
                request_id: Optional[str] = None) -> dict:
        """``POST /v1/episodes/{id}/observations``: the joints read after executing ``next`` and the
        lift verdict -> the next grasp (``next`` None: the episode ended). Retried with the same
        request id while the server cannot be reached."""
        body = {"joints": [float(v) for v in joints], "lifted": bool(lifted),
                "request_id": request_id or uuid.uuid4().hex}
        for i in range(self.retries + 1):
            try:
                return self._call("POST", f"/episodes/{episode_id}/observations", body)
            except (urllib.error.URLError, ConnectionError, TimeoutError):
                if i == self.retries:
                    raise
                time.sleep(min(self.backoff * 2 ** i, self.max_backoff))

    def episode(self, episode_id: str) -> dict:
        """``GET /v1/episodes/{id}``: the history and the belief."""
        return self._call("GET", f"/episodes/{episode_id}")

    def plan(self, **options) -> dict:
        """``POST /v1/plan``: the first grasp for an object at an estimate (``{next}``), or with
        category and task the task grasp as ``bayesgrasp category --json`` prints it; no episode kept."""
        return self._call("POST", "/plan", options)
