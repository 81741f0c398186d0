"""Timing helper shared by bench/gp_ours.py and bench/gp_peers.py (either interpreter): median wall
time of repeated calls, with the median process CPU time recorded beside it (shared machines)."""
import time

import numpy as np

CPU = {}  # name -> median process CPU time, s


def median_time(fn, repeat=5, name=None):
    """Median wall time (s) of `repeat` calls of fn; records the median CPU time under `name`."""
    ts, cs = [], []
    for _ in range(repeat):
        t, c = time.perf_counter(), time.process_time()
        fn()
        ts.append(time.perf_counter() - t)
        cs.append(time.process_time() - c)
    if name:
        CPU[name] = float(np.median(cs))
    return float(np.median(ts))
