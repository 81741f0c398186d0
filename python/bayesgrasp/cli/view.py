"""``bayesgrasp view FILE.json``: any command's JSON output in 3D in the browser (viser): the
object with its parts coloured and the table, the camera's cloud, the registered models with their
weights, and per attempt or round the hand at the grasp (fingers at the read joint angles), the
pre-grasp, the approach and the contacts with their normals, and the arm (a grasp made with
``--robot``) holding the hand; a slider steps through the attempts,
toggles switch the layers. The server listens on localhost (over SSH: ``ssh -L 8080:localhost:8080
HOST``, then open http://localhost:8080); Ctrl-C stops it."""
from __future__ import annotations

import sys
import time

from .. import DEFAULT_HAND
from .args import bounded_int


def add(sub) -> None:
    v = sub.add_parser("view", help="a result in 3D in the browser (viser)", description=__doc__)
    v.add_argument("file", help="a command's --json output, an episode directory's episode.json, `episode show --json`, "
                   "or an experiment's results.sqlite (or its directory) with --series/--object/--run")
    v.add_argument("--port", type=bounded_int(1, 65535), default=8080, help="port (the next free one if busy)")
    v.add_argument("--host", default="127.0.0.1", help="address to listen on")
    v.add_argument("--snapshot", default=None, metavar="FILE.png",
                   help="write a screenshot (headless Chromium) instead of serving until Ctrl-C")
    v.add_argument("--step", type=int, default=None, help="with --snapshot: the attempt or round shown (default: last)")
    v.add_argument("--series", default=None, help="results.sqlite: the stored series, e.g. pub2/stability "
                   "(default: the only one)")
    v.add_argument("--object", default=None, help="results.sqlite: the run's object (default: the only one)")
    v.add_argument("--run", dest="run_index", type=bounded_int(0, 10**9), default=0, help="results.sqlite: the run's index")
    v.add_argument("--hand", default=DEFAULT_HAND, help="results.sqlite: the hand the experiment ran with")
    v.add_argument("--seconds", type=float, default=None, help="stop after this long (default: until Ctrl-C)")
    v.set_defaults(run=run)


def run(args) -> int:
    scene = _scene(args)                                    # refused before a server starts
    if args.snapshot:
        return _snapshot(args, scene)
    _serve_until_stopped(scene, args.file, args.port, args.host, args.seconds)
    return 0


def _scene(args):
    """The scene of a result file, or of one run of an experiment's results.sqlite."""
    from ..viewer import read_result, scene_from_result
    from ..viewer.runs import read_run, results_file, scene_from_run

    if results_file(args.file).suffix in (".sqlite", ".db"):
        return scene_from_run(*read_run(args.file, args.series, args.object, args.run_index), hand=args.hand)
    return scene_from_result(read_result(args.file))


def show_result(args, doc: dict) -> None:
    """A command's ``--view``: its result document in the viewer until Ctrl-C (nothing without it)."""
    if getattr(args, "view", None) is None:
        return
    from ..viewer import scene_from_result

    _serve_until_stopped(scene_from_result(doc), f"this {args.command} result", args.view, "127.0.0.1",
                         getattr(args, "view_seconds", None), stream=sys.stderr)


def _serve_until_stopped(scene, what: str, port: int, host: str, seconds=None, stream=None) -> None:
    from ..viewer.serve import serve, stop

    server, _ = serve(scene, port=port, host=host)
    print(f"viewing {what} ({scene.kind}, {len(scene.steps)} step(s)) at http://{host}:{server.get_port()}"
          " (Ctrl-C stops)", file=stream or sys.stdout, flush=True)
    try:
        deadline = None if seconds is None else time.monotonic() + seconds
        while deadline is None or time.monotonic() < deadline:
            time.sleep(0.2)
    except KeyboardInterrupt:
        print("stopped", file=sys.stderr)
    finally:
        stop(server)


def _snapshot(args, scene) -> int:
    from ..viewer.snapshot import NoBrowser, snapshot
    from .args import CliError, output_file

    png = output_file(args.snapshot, "--snapshot")
    if args.step is not None and not 0 <= args.step < len(scene.steps):
        raise CliError(f"--step: between 0 and {len(scene.steps) - 1}, got {args.step}")
    try:
        snapshot(scene, png, port=args.port, step=args.step)
    except NoBrowser as e:
        raise CliError(f"--snapshot: {e}") from None
    print(f"saved {png}")
    return 0
