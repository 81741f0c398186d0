"""Progress on stderr for work that says nothing itself (a browser starting, one long planning
step): a line every few seconds while it runs, so no command is silent for long."""
from __future__ import annotations

import threading
import time
from contextlib import contextmanager
from typing import Callable, Optional

#: seconds between the "still working" lines
HEARTBEAT_EVERY = 5.0


@contextmanager
def heartbeat(say: Optional[Callable[[str], None]], what: str, every: Optional[float] = None):
    """While the block runs, ``say("  <what>: N s so far")`` every ``every`` seconds (default
    :data:`HEARTBEAT_EVERY`, read when the block starts). Nothing when ``say`` is None."""
    if say is None:
        yield
        return
    period = HEARTBEAT_EVERY if every is None else every
    stop, start = threading.Event(), time.monotonic()

    def beat():
        while not stop.wait(period):
            say(f"  {what}: {time.monotonic() - start:.0f} s so far")

    t = threading.Thread(target=beat, daemon=True)
    t.start()
    try:
        yield
    finally:
        stop.set()
        t.join()
