"""Engines that execute an experiment's runs: local worker processes (the default) or Ray tasks.

An engine maps a module-level function over items and yields ``(item, result)`` pairs as they
finish, in any order; the runner stores each result as it arrives (the store lives only in the
calling process, so a worker that dies loses nothing and writes nothing twice).

* :class:`LocalEngine` - ``workers`` processes of this machine (spawned, not forked: a forked
  child inherits OpenMP's thread pool in a broken state and hangs in its first parallel region);
  one worker runs everything in this process.
* :class:`RayEngine` - every item a Ray task (``max_retries`` retries when the worker process
  or its node dies), on a local Ray instance started for the experiment (``workers`` CPUs) or on
  an existing cluster (``address``). Every node needs bayesgrasp installed and, for the models
  to be built once, the model cache (``--cache`` / ``BAYESGRASP_CACHE``) on storage all nodes
  share: the per-object model builds are tasks of their own that write the cache, and the runs
  read it (each worker process loads an object's models once). The cache rather than Ray's
  object store, because it is already atomic and checksummed, survives the sweep (a resume or
  the next sweep builds nothing), and a worker keeps the models it loaded for all its later runs
  instead of fetching them per task.
"""
from __future__ import annotations

import multiprocessing
import os
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from typing import Callable, Iterable, Iterator, Optional, Tuple

ENGINES = ("local", "ray")


def _die_with_parent(parent_pid: int, interval: float = 0.5) -> None:
    """Worker initializer: a daemon thread ends this worker once its parent is gone (a parent
    killed by SIGKILL cannot tell its pool to stop, and the workers would run on indefinitely;
    when the last of them ends, multiprocessing's resource tracker sees its pipe close and ends
    too)."""
    import threading
    import time

    def watch():
        while True:
            if os.getppid() != parent_pid:
                os._exit(1)
            time.sleep(interval)

    threading.Thread(target=watch, name="bayesgrasp-parent-watchdog", daemon=True).start()


def _call(fn, item):
    return item, fn(item)


class LocalEngine:
    """Runs on this machine: in this process (``workers`` 1) or in spawned worker processes."""

    name = "local"

    def __init__(self, workers: int = 1):
        if int(workers) < 1:
            raise ValueError(f"workers: must be at least 1, got {workers}")
        self.workers = int(workers)

    def map(self, fn: Callable, items: Iterable) -> Iterator[Tuple[object, object]]:
        items = list(items)
        if self.workers == 1 or len(items) <= 1:
            for item in items:
                yield item, fn(item)
            return
        with ProcessPoolExecutor(max_workers=min(self.workers, len(items)),
                                 mp_context=multiprocessing.get_context("spawn"),
                                 initializer=_die_with_parent, initargs=(os.getpid(),)) as pool:
            pending = {pool.submit(_call, fn, item) for item in items}
            try:
                while pending:
                    finished, pending = wait(pending, return_when=FIRST_COMPLETED)
                    for fut in finished:
                        yield fut.result()
            finally:
                for fut in pending:
                    fut.cancel()

    def close(self) -> None:
        pass


class RayEngine:
    """Runs every item as a Ray task: a local instance with ``workers`` CPUs (started here, shut
    down by :meth:`close`) or the cluster at ``address`` ("HOST:PORT", or "auto")."""

    name = "ray"

    def __init__(self, workers: Optional[int] = None, address: Optional[str] = None, max_retries: int = 3):
        try:
            import ray
        except ImportError:
            raise ValueError("engine 'ray': the ray package is not installed (pip install 'ray>=2.9')") from None
        if workers is not None and int(workers) < 1:
            raise ValueError(f"workers: must be at least 1, got {workers}")
        if int(max_retries) < 0:
            raise ValueError(f"max_retries: must be >= 0, got {max_retries}")
        self._ray = ray
        self.workers, self.address, self.max_retries = workers, address, int(max_retries)
        self._started = False
        if not ray.is_initialized():
            kw = dict(include_dashboard=False, log_to_driver=False, logging_level="ERROR", configure_logging=False)
            if address:
                check_address(address)                  # one line within seconds, not Ray's minutes of retries
            try:
                if address:
                    ray.init(address=address, **kw)
                else:
                    ray.init(num_cpus=workers, **kw)
            except (ConnectionError, RuntimeError, ValueError) as e:
                raise ValueError(f"engine 'ray': cannot {'reach ' + address if address else 'start Ray'}: {e}") from None
            self._started = True
        self._remote = ray.remote(num_cpus=1, max_retries=self.max_retries, retry_exceptions=False)(_call)

    def map(self, fn: Callable, items: Iterable) -> Iterator[Tuple[object, object]]:
        ray = self._ray
        fn_ref = ray.put(fn)
        pending = [self._remote.remote(fn_ref, item) for item in items]
        try:
            while pending:
                done, pending = ray.wait(pending, num_returns=1)
                for ref in done:
                    yield ray.get(ref)
        finally:
            for ref in pending:
                ray.cancel(ref, force=True)

    def close(self) -> None:
        if self._started and self._ray.is_initialized():
            self._ray.shutdown()
        self._started = False


#: seconds to wait for a Ray head's port before the address is declared unreachable
ADDRESS_TIMEOUT = 5.0


def check_address(address: str, timeout: float = ADDRESS_TIMEOUT) -> None:
    """Checks that a Ray head listens at ``address`` ("HOST:PORT") by opening a TCP connection to
    it within ``timeout`` seconds (Ray's own client retries for minutes). "auto" and
    "ray://..." addresses are left to Ray. ValueError "address: ..." naming the address."""
    import socket

    if address == "auto" or "://" in address:
        return
    host, sep, port = address.rpartition(":")
    if not sep or not host or not port.isdigit() or not 0 < int(port) < 65536:
        raise ValueError(f"address: expected HOST:PORT (e.g. 10.0.0.5:6379) or auto, got {address!r}")
    try:
        with socket.create_connection((host, int(port)), timeout=timeout):
            pass
    except socket.gaierror as e:
        raise ValueError(f"address: cannot resolve host {host!r} of {address} ({e.strerror or e})") from None
    except OSError as e:
        why = "no answer" if isinstance(e, socket.timeout) else (e.strerror or str(e))
        raise ValueError(f"address: no Ray head at {address} ({why} within {timeout:g} s); "
                         f"start one there with `ray start --head --port {port}`") from None


def check_engine(name: str = "local", workers: int = 1, address: Optional[str] = None, reach: bool = True) -> None:
    """The engine's settings checked before anything starts: the name, ``address`` only for Ray
    and not with ``workers``, then (``reach``) the address answering (:func:`check_address`).
    ValueError "FIELD: ..." naming the field at fault."""
    if name not in ENGINES:
        raise ValueError(f"engine: one of {', '.join(ENGINES)}; got {name!r}")
    if address and name != "ray":
        raise ValueError("address: only for engine 'ray'")
    if address and workers != 1:
        raise ValueError(f"workers: the cluster at {address} has its own CPUs; workers {workers} would be ignored")
    if address and reach:
        check_address(address)


def make_engine(name: str = "local", workers: int = 1, address: Optional[str] = None):
    """An engine by name: "local" (``workers`` processes) or "ray" (a local instance of
    ``workers`` CPUs, or the cluster at ``address``)."""
    check_engine(name, workers, address, reach=False)          # RayEngine checks the address itself
    if name == "local":
        return LocalEngine(workers)
    return RayEngine(workers=None if address else workers, address=address)
