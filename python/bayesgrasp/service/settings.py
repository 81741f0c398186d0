"""The service's options, with their defaults and checks in one place."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Optional

LOOPBACK = ("127.0.0.1", "::1", "localhost")


@dataclass(frozen=True)
class ServiceSettings:
    """host: the address to bind (loopback by default: nobody else reaches it); port: the TCP port;
    episodes: the directory holding one sub-directory per episode; token_file: the bearer token's
    file (None: ``<episodes>/.token``; created with a new token if absent); certfile, keyfile: TLS
    certificate and key (PEM; both or neither); cache_dir: the model cache (None: the default one);
    max_body_bytes: the largest request body taken; max_warm: episodes kept in memory at most (the
    least recently used are dropped and reopened from disk when asked for)."""

    host: str = "127.0.0.1"
    port: int = 8765
    episodes: str = "episodes"
    token_file: Optional[str] = None
    certfile: Optional[str] = None
    keyfile: Optional[str] = None
    cache_dir: Optional[str] = None
    max_body_bytes: int = 1 << 20
    max_warm: int = 256

    def __post_init__(self):
        if not (isinstance(self.port, int) and 1 <= self.port <= 65535):
            raise ValueError(f"--port: an integer in [1, 65535], got {self.port!r}")
        if (self.certfile is None) != (self.keyfile is None):
            raise ValueError("--certfile, --keyfile: give both (TLS) or neither")
        for option, path in (("--certfile", self.certfile), ("--keyfile", self.keyfile)):
            if path is not None and not Path(path).is_file():
                raise ValueError(f"{option}: no such file {path}")
        if not 1024 <= self.max_body_bytes <= 1 << 30:
            raise ValueError(f"--max-body-bytes: between 1024 and 2^30, got {self.max_body_bytes}")
        if self.max_warm < 1:
            raise ValueError(f"--max-warm: at least 1, got {self.max_warm}")

    @property
    def token_path(self) -> Path:
        return Path(self.token_file) if self.token_file else Path(self.episodes) / ".token"

    @property
    def tls(self) -> bool:
        return self.certfile is not None

    @property
    def loopback(self) -> bool:
        return self.host in LOOPBACK
