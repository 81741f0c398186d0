"""``bayesgrasp serve``: the robot loop (``bayesgrasp episode``) as an HTTP JSON service, its
episodes warm in memory and on disk in the episode command's format (see bayesgrasp.service)."""
from __future__ import annotations

from .args import CliError, bounded_int



def add(sub) -> None:
    from ..service.settings import ServiceSettings as S

    p = sub.add_parser("serve", help="serve the planning loop over HTTP (JSON) to a robot's stack",
                       description=__doc__ + " Every request needs 'Authorization: Bearer TOKEN' (the token "
                                             "file's content).")
    p.add_argument("--host", default=S.host, help="address to bind (loopback unless told otherwise)")
    p.add_argument("--port", type=bounded_int(1, 65535), default=S.port, help="TCP port")
    p.add_argument("--episodes", default=S.episodes, metavar="DIR", help="directory of the episodes (one "
                                                                          "sub-directory each)")
    p.add_argument("--token-file", default=None, metavar="FILE",
                   help="the bearer token's file; created with a new token (printed) if absent (default: "
                        "DIR/.token)")
    p.add_argument("--certfile", default=None, help="TLS certificate (PEM), with --keyfile: serve HTTPS")
    p.add_argument("--keyfile", default=None, help="TLS private key (PEM), with --certfile")
    p.add_argument("--cache", default=None, help="model cache directory (default: as for the other commands)")
    p.add_argument("--max-body-bytes", type=bounded_int(1024, 1 << 30), default=S.max_body_bytes,
                   help="largest request body accepted")
    p.set_defaults(run=run)


def run(args) -> int:
    from ..service.app import serve
    from ..service.settings import ServiceSettings

    try:
        settings = ServiceSettings(host=args.host, port=args.port, episodes=args.episodes, token_file=args.token_file,
                                   certfile=args.certfile, keyfile=args.keyfile, cache_dir=args.cache,
                                   max_body_bytes=args.max_body_bytes)
    except ValueError as e:
        raise CliError(str(e)) from None
    return serve(settings)
