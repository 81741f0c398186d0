"""`bayesgrasp serve` under load and faults, loopback only, bounded.

Latency: N episodes (--concurrency, e.g. 1,8,32) each sent --steps observations in turn from its
own thread; one observation + the next plan, as the robot's client sees it (HTTP round trip
included), median and 99th percentile. Beside it, the same step through the episode command
(`bayesgrasp episode observe`, a process per step), --cli-steps of them.

Faults: --fault-episodes episodes, --fault-observations observations in all, the server killed
with SIGKILL every --kill-every seconds and restarted; the clients retry each observation with its
request id until answered. Afterwards every episode's steps are compared with what its client was
answered: lost = answered but not in the episode, duplicated = in the episode more than once.

    OMP_NUM_THREADS=1 .venv/bin/python bench/serve_load.py --concurrency 1,8,32
    OMP_NUM_THREADS=1 .venv/bin/python bench/serve_load.py --in-process-only --steps 8   # the step alone

The cylinder with the default models (shipped with the package), stability method.
"""
from __future__ import annotations

import argparse
import hashlib
import json
import os
import signal
import socket
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np

from bayesgrasp.client import Client

TOKEN = "bench-token-0123456789abcdef"
BODY = dict(object="cylinder", estimate=[0.035, -0.04, 0.9], method="stability", seed=3)
# hand readings (rad) of misses, cycled: a believable sequence for the belief to absorb
READINGS = [[0.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0], [0.7854, 1.4316, 1.2102, 1.3176, 1.1722, 1.4873, 1.2288],
            [0.7854, 1.6756, 1.2916, 1.1967, 1.1319, 1.2762, 1.1584]]


def say(msg: str) -> None:
    print(msg, file=sys.stderr, flush=True)


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Server:
    def __init__(self, root: Path, port: int):
        self.root, self.port = root, port
        (root / "token").write_text(TOKEN)
        self.proc = None

    def start(self) -> float:
        t0 = time.perf_counter()
        self.proc = subprocess.Popen([sys.executable, "-m", "bayesgrasp.cli", "serve", "--port", str(self.port),
                                      "--episodes", str(self.root / "episodes"), "--token-file",
                                      str(self.root / "token")], stdout=subprocess.DEVNULL,
                                     stderr=open(self.root / "server.log", "ab"))
        c = Client(f"http://127.0.0.1:{self.port}", TOKEN, timeout=5)
        while True:
            try:
                c.health()
                return time.perf_counter() - t0
            except Exception:
                if self.proc.poll() is not None:
                    raise SystemExit(f"the server died; see {self.root / 'server.log'}")
                time.sleep(0.1)

    def kill(self) -> None:
        self.proc.send_signal(signal.SIGKILL)
        self.proc.wait()

    def stop(self) -> None:
        if self.proc and self.proc.poll() is None:
            self.proc.terminate()
            self.proc.wait()


def pct(values, q) -> float:
    return float(np.percentile(np.asarray(values), q))


def latency(server: Server, n: int, steps: int, tag: str) -> dict:
    """N episodes at once, each `steps` observations in turn: per-observation latency (s)."""
    c = Client(f"http://127.0.0.1:{server.port}", TOKEN, timeout=600)
    ids = [c.new_episode(**BODY, attempts=1000, id=f"{tag}-{i}")["id"] for i in range(n)]
    times: list = []
    lock = threading.Lock()

    def run(eid):
        mine = []
        for k in range(steps):
            t0 = time.perf_counter()
            c.observe(eid, READINGS[k % len(READINGS)], False, request_id=f"{eid}-{k}")
            mine.append(time.perf_counter() - t0)
        with lock:
            times.extend(mine)

    t0 = time.perf_counter()
    threads = [threading.Thread(target=run, args=(e,)) for e in ids]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    wall = time.perf_counter() - t0
    return {"episodes": n, "observations": len(times), "median_ms": 1e3 * statistics.median(times),
            "p99_ms": 1e3 * pct(times, 99), "per_second": len(times) / wall}


def cli_steps(root: Path, steps: int) -> dict:
    """The same step through `bayesgrasp episode observe` (a process each)."""
    d = root / "cli-episode"
    run = [sys.executable, "-m", "bayesgrasp.cli", "episode"]
    subprocess.run(run + ["new", "--object", BODY["object"], "--estimate", ",".join(map(str, BODY["estimate"])),
                          "--method", BODY["method"], "--seed", str(BODY["seed"]), "--attempts", "1000",
                          "--dir", str(d), "--json"], check=True, capture_output=True)
    times = []
    for k in range(steps):
        t0 = time.perf_counter()
        subprocess.run(run + ["observe", str(d), "--joints", ",".join(map(str, READINGS[k % len(READINGS)])),
                              "--lifted", "no", "--json"], check=True, capture_output=True)
        times.append(time.perf_counter() - t0)
    return {"observations": steps, "median_ms": 1e3 * statistics.median(times), "p99_ms": 1e3 * pct(times, 99)}


def in_process(root: Path, steps: int) -> dict:
    """The same step in this process, no HTTP: PoseEpisode.observe (the planner's update and plan,
    the state written), what the service's latency is made of."""
    from bayesgrasp.loop.context import RunContext
    from bayesgrasp.loop.outside_loop import PoseEpisode, particles_digest

    ep = PoseEpisode.new(root / "in-process", BODY["object"], BODY["estimate"], RunContext(), method=BODY["method"],
                         attempts=1000, seed=BODY["seed"])
    times = []
    for k in range(steps):
        t0 = time.perf_counter()
        ep.observe(READINGS[k % len(READINGS)], False)
        times.append(time.perf_counter() - t0)
    b = ep.planner.belief
    return {"observations": steps, "median_ms": 1e3 * statistics.median(times), "p99_ms": 1e3 * pct(times, 99),
            "step_ms": [round(1e3 * t, 1) for t in times],
            "state_sha256": hashlib.sha256(json.dumps(ep.state, sort_keys=True).encode()).hexdigest(),
            "belief_sha256": particles_digest(b.particles, b.weights)}   # a change that keeps results keeps these


def faults(server: Server, n: int, total: int, kill_every: float, max_kills: int) -> dict:
    """`total` observations over `n` episodes while the server is killed every `kill_every` s (at
    most `max_kills` times: the run stays bounded even when restarts outlast the interval)."""
    c = Client(f"http://127.0.0.1:{server.port}", TOKEN, timeout=120, retries=60, backoff=0.25, max_backoff=2.0)
    ids = [c.new_episode(**BODY, attempts=1000, id=f"fault-{i}")["id"] for i in range(n)]
    answered = {e: [] for e in ids}
    waits: list = []                  # s from sending an observation to its answer, retries included
    per = [total // n + (1 if i < total % n else 0) for i in range(n)]
    errors: dict = {}                 # episode -> why its client gave up (its last observation unanswered)
    done = threading.Event()

    def run(eid, count):
        try:
            for k in range(count):
                t0 = time.perf_counter()
                reply = c.observe(eid, READINGS[k % len(READINGS)], False, request_id=f"{eid}-{k}")
                waits.append(time.perf_counter() - t0)
                assert reply["attempts_made"] == k + 1, (eid, k, reply["attempts_made"])
                answered[eid].append(k)
        except Exception as e:   # counted: an observation the client gave up on
            errors[eid] = f"{type(e).__name__}: {e}"

    kills, restarts = 0, []

    def killer():
        nonlocal kills
        while kills < max_kills and not done.wait(kill_every):
            server.kill()
            kills += 1
            restarts.append(server.start())

    threads = [threading.Thread(target=run, args=(e, k)) for e, k in zip(ids, per)]
    k_thread = threading.Thread(target=killer)
    t0 = time.perf_counter()
    for t in threads:
        t.start()
    k_thread.start()
    for t in threads:
        t.join()
    done.set()
    k_thread.join()
    wall = time.perf_counter() - t0
    lost = dup = 0
    for eid in ids:
        steps = c.episode(eid)["steps"]
        sent = len(answered[eid])
        lost += max(0, sent - len(steps))
        dup += max(0, len(steps) - sent - (eid in errors))   # an unanswered one may have been applied
        for k, s in enumerate(steps[:sent]):     # each step is the reading sent as observation k
            if s["joints"] != READINGS[k % len(READINGS)]:
                dup += 1
    return {"episodes": n, "observations": sum(len(a) for a in answered.values()), "kills": kills,
            "restart_s_median": statistics.median(restarts) if restarts else None, "lost": lost,
            "duplicated": dup, "client_errors": len(errors),
            "answer_s_median": statistics.median(waits) if waits else None, "answer_s_max": max(waits, default=None), "wall_s": wall, "errors": list(errors.values())[:3]}


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--concurrency", default="1,8,32", help="episodes at once, comma-separated")
    p.add_argument("--steps", type=int, default=6, help="observations per episode in the latency runs")
    p.add_argument("--cli-steps", type=int, default=3, help="steps through `bayesgrasp episode observe`")
    p.add_argument("--fault-episodes", type=int, default=32)
    p.add_argument("--fault-observations", type=int, default=500)
    p.add_argument("--kill-every", type=float, default=20.0, help="seconds between SIGKILLs of the server")
    p.add_argument("--max-kills", type=int, default=10, help="kills at most (the fault run stays bounded)")
    p.add_argument("--no-faults", action="store_true")
    p.add_argument("--no-latency", action="store_true")
    p.add_argument("--in-process-only", action="store_true",
                   help="only the step in this process (PoseEpisode.observe, no server): --steps of them")
    a = p.parse_args()
    out = {"cpu_count": os.cpu_count()}
    if a.in_process_only:
        with tempfile.TemporaryDirectory(prefix="serve-load-") as tmp:
            out["in_process"] = in_process(Path(tmp), a.steps)
        say(f"in process (PoseEpisode.observe): median {out['in_process']['median_ms']:.1f} ms")
        print(json.dumps(out, indent=1))
        return 0
    with tempfile.TemporaryDirectory(prefix="serve-load-") as tmp:
        root = Path(tmp)
        server = Server(root, free_port())
        try:
            out["server_start_s"] = server.start()
            say(f"server up in {out['server_start_s']:.1f} s")
            Client(f"http://127.0.0.1:{server.port}", TOKEN).new_episode(**BODY, id="warm-up")  # models loaded
            out["latency"] = []
            for n in [] if a.no_latency else [int(v) for v in a.concurrency.split(",")]:
                r = latency(server, n, a.steps, f"load{n}")
                out["latency"].append(r)
                say(f"{n} episode(s): median {r['median_ms']:.1f} ms, p99 {r['p99_ms']:.1f} ms, "
                    f"{r['per_second']:.1f} observations/s")
            if not a.no_latency:
                out["in_process"] = in_process(root, a.steps)
                say(f"in process (PoseEpisode.observe): median {out['in_process']['median_ms']:.1f} ms")
                out["cli"] = cli_steps(root, a.cli_steps)
                say(f"episode command: median {out['cli']['median_ms']:.0f} ms per step")
            if not a.no_faults:
                out["faults"] = faults(server, a.fault_episodes, a.fault_observations, a.kill_every,
                                       a.max_kills)
                f = out["faults"]
                say(f"faults: {f['observations']} observations, {f['kills']} kills, lost {f['lost']}, "
                    f"duplicated {f['duplicated']}, client errors {f['client_errors']}")
        finally:
            server.stop()
    print(json.dumps(out, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
