"""Who gets in and what they may send: the bearer token (compared in constant time), the request
body's size limit, and the episode id pattern (an id never names a path)."""
from __future__ import annotations

import hmac
import json
import os
import re
import secrets
from pathlib import Path
from typing import Tuple

from .errors import ApiError, error_body

#: An episode or request id: letters, digits, '_' and '-', starting with a letter or digit; no
#: '.', no '/', so it cannot leave the episodes directory.
ID_PATTERN = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_-]{0,63}$")
TOKEN_MIN_CHARS = 16


def check_id(value: str, what: str = "episode id") -> str:
    if not isinstance(value, str) or not ID_PATTERN.fullmatch(value):
        raise ApiError(400, "invalid_id", f"{what}: 1-64 letters, digits, '_' or '-' (starting with a letter or "
                                          f"digit), got {str(value)[:80]!r}")
    return value


def load_or_create_token(path: Path) -> Tuple[str, bool]:
    """The token in ``path``; a new one (``secrets``, 256 bits) written there with mode 0600 when the
    file is absent. Returns (token, created)."""
    path = Path(path)
    if path.exists():
        token = path.read_text().strip()
        if len(token) < TOKEN_MIN_CHARS or any(c.isspace() for c in token):
            raise ValueError(f"--token-file: {path} must hold one token of at least {TOKEN_MIN_CHARS} characters "
                             "without spaces")
        return token, False
    path.parent.mkdir(parents=True, exist_ok=True)
    token = secrets.token_urlsafe(32)
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
    with os.fdopen(fd, "w") as f:
        f.write(token + "\n")
        f.flush()
        os.fsync(f.fileno())
    return token, True


async def _send_error(send, status: int, code: str, message: str, headers=()) -> None:
    body = json.dumps(error_body(code, message)).encode()
    await send({"type": "http.response.start", "status": status,
                "headers": [(b"content-type", b"application/json"), (b"content-length", str(len(body)).encode()),
                            *headers]})
    await send({"type": "http.response.body", "body": body})


class Guard:
    """ASGI middleware in front of every route: a request without ``Authorization: Bearer
    <token>`` is refused (401), then one whose body exceeds ``max_body_bytes`` (413; the body is
    read here, up to the limit, and handed on whole)."""

    def __init__(self, app, token: str, max_body_bytes: int):
        self.app, self.token, self.max = app, token.encode(), max_body_bytes

    def _authorised(self, scope) -> bool:
        header = dict(scope.get("headers") or []).get(b"authorization", b"")
        scheme, _, given = header.partition(b" ")
        return scheme.lower() == b"bearer" and hmac.compare_digest(given.strip(), self.token)

    async def __call__(self, scope, receive, send):
        if scope["type"] != "http":
            return await self.app(scope, receive, send)
        if not self._authorised(scope):
            return await _send_error(send, 401, "unauthorized", "a valid 'Authorization: Bearer <token>' header "
                                     "is required", [(b"www-authenticate", b"Bearer")])
        length = dict(scope.get("headers") or []).get(b"content-length")
        if length is not None and (not length.isdigit() or int(length) > self.max):
            return await _send_error(send, 413, "body_too_large", f"request bodies are limited to {self.max} bytes")
        chunks, size, more = [], 0, True
        while more:
            message = await receive()
            if message["type"] == "http.disconnect":
                return
            chunks.append(message.get("body", b""))
            size += len(chunks[-1])
            if size > self.max:
                return await _send_error(send, 413, "body_too_large", f"request bodies are limited to {self.max} "
                                                                      "bytes")
            more = message.get("more_body", False)
        body, sent = b"".join(chunks), False

        async def replay():
            nonlocal sent
            if not sent:
                sent = True
                return {"type": "http.request", "body": body, "more_body": False}
            return await receive()

        await self.app(scope, replay, send)
