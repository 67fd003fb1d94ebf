"""Error against time: the Pareto front of a series of (time, error)
points and the time at which it reaches a given error, shared by the
peer benchmarks' drivers (`peer/bench_peer.py`, `renderpark/bench_renderpark.py`).
Standard library only."""

import math


def pareto(points):
    """(time, error) points, sorted by time, each better than every faster one."""
    front, best = [], float("inf")
    for t, e in sorted(points):
        if e < best:
            front.append((t, e))
            best = e
    return front


def time_to_error(points, target):
    """Smallest time at which the error reaches `target`, log-log between
    the Pareto neighbours; None where never reached."""
    front = pareto(points)
    for i, (t, e) in enumerate(front):
        if e <= target:
            if i == 0 or e == target:
                return t
            t0, e0 = front[i - 1]
            f = (math.log(target) - math.log(e0)) / (math.log(e) - math.log(e0))
            return math.exp(math.log(t0) + f * (math.log(t) - math.log(t0)))
    return None
