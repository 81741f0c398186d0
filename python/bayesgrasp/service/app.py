"""The application (:func:`create_app`) and the server (:func:`serve`: uvicorn, TLS when given a
certificate and key)."""
from __future__ import annotations

import sys

from fastapi import FastAPI

from .. import __version__
from . import errors
from .routes import router
from .security import Guard, load_or_create_token
from .settings import ServiceSettings
from .store import EpisodeStore


def create_app(settings: ServiceSettings, token: str) -> FastAPI:
    """The service's ASGI application: every route behind the token and the body limit."""
    app = FastAPI(title="bayesgrasp", version=__version__,
                  description="Grasp planning under uncertainty: the robot loop of `bayesgrasp episode` as a service.")
    app.state.store = EpisodeStore(settings.episodes, settings.cache_dir, settings.max_warm)
    errors.install(app)
    app.include_router(router)
    app.add_middleware(Guard, token=token, max_body_bytes=settings.max_body_bytes)
    return app


def serve(settings: ServiceSettings) -> int:
    """Runs the service until interrupted; the token is read from (or created in) its file."""
    import uvicorn

    token, created = load_or_create_token(settings.token_path)
    if created:
        print(f"bayesgrasp serve: new token written to {settings.token_path}: {token}", file=sys.stderr)
    if not settings.loopback and not settings.tls:
        print(f"bayesgrasp serve: warning: listening on {settings.host} without TLS: the token crosses the network "
              "in clear text (give --certfile and --keyfile)", file=sys.stderr)
    scheme = "https" if settings.tls else "http"
    print(f"bayesgrasp serve: {scheme}://{settings.host}:{settings.port}/v1 (episodes in {settings.episodes}; "
          f"send 'Authorization: Bearer <the token in {settings.token_path}>')", file=sys.stderr, flush=True)
    uvicorn.run(create_app(settings, token), host=settings.host, port=settings.port, log_level="warning",
                ssl_certfile=settings.certfile, ssl_keyfile=settings.keyfile)
    return 0
