"""Every refusal as one JSON shape: ``{"error": {"code": ..., "message": one line}}`` with its
HTTP status, whether the route refused it, the framework's validation or routing did, or the
loop raised."""
from __future__ import annotations

import sys
import traceback

from fastapi import FastAPI, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse
from starlette.exceptions import HTTPException as StarletteHTTPException

from ..loop.outside_loop import EpisodeError


class ApiError(Exception):
    """A refused request: ``status`` (HTTP), ``code`` (a stable word) and a one-line message."""

    def __init__(self, status: int, code: str, message: str):
        super().__init__(message)
        self.status, self.code, self.message = status, code, message


def one_line(text: str) -> str:
    return " ".join(str(text).split())


def error_body(code: str, message: str) -> dict:
    return {"error": {"code": code, "message": one_line(message)}}


def error_response(status: int, code: str, message: str, headers=None) -> JSONResponse:
    return JSONResponse(error_body(code, message), status_code=status, headers=headers)


_HTTP_CODES = {404: "not_found", 405: "method_not_allowed", 413: "body_too_large"}


def _validation(request: Request, exc: RequestValidationError) -> JSONResponse:
    errors = exc.errors()
    if any(e.get("type") == "json_invalid" for e in errors):
        return error_response(400, "malformed_json", "the request body is not valid JSON")
    e = errors[0] if errors else {"loc": (), "msg": "invalid"}
    if tuple(e.get("loc", ())) == ("body",):
        return error_response(422, "invalid_body", "the body must be one JSON object (Content-Type: application/json)")
    where = ".".join(str(p) for p in e.get("loc", ()) if p != "body") or "body"
    return error_response(422, "invalid_body", f"{where}: {e.get('msg')}")


def _http(request: Request, exc: StarletteHTTPException) -> JSONResponse:
    return error_response(exc.status_code, _HTTP_CODES.get(exc.status_code, "http_error"), exc.detail)


def _unexpected(request: Request, exc: Exception) -> JSONResponse:
    traceback.print_exception(type(exc), exc, exc.__traceback__, file=sys.stderr)
    return error_response(500, "internal", f"{type(exc).__name__}: {exc}")


def install(app: FastAPI) -> None:
    """Registers the handlers that shape every error."""
    app.add_exception_handler(ApiError, lambda r, e: error_response(e.status, e.code, e.message))
    app.add_exception_handler(EpisodeError, lambda r, e: error_response(422, "refused", str(e)))
    app.add_exception_handler(RequestValidationError, _validation)
    app.add_exception_handler(StarletteHTTPException, _http)
    app.add_exception_handler(Exception, _unexpected)
