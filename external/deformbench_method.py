"""Serve a deformation method over deformbench's method protocol (version 1) on stdin/stdout.

The protocol (README "Adding a method in another language"): one JSON object per line each way.
The harness sends `hello`, `precompute`, `bind` (per handle set) and `solve` (per edit step), then
`quit`; the method answers each with one line: {"ok": true, ...} or {"ok": false, "error": "..."}.
Positions are JSON numbers, which Python's json writes in shortest round-trip form, so they cross
the pipe exactly. stdout belongs to the protocol: `serve` sends stray prints to stderr, which the
harness keeps in reports/logs/ and quotes when a case fails.

A method is an object with
    precompute(V, F)              V: #V x 3 float64 rest positions, F: #F x 3 int64 faces
    bind(regions)                 regions: list of int64 arrays of vertex indices (disjoint)
    solve(constrained, targets)   int64 array (#C), #C x 3 float64 targets -> dict with
                                  "positions" (#V x 3 array) and optionally "iterations",
                                  "converged", "final_step", "trace" ([{"step", "seconds"}]),
each of which may also return "timings" ({name: seconds}) and "statistics" ({name: count}).
`serve(make_method, about)` calls make_method(params) on `hello`.
"""

import json
import sys
import time
import traceback

import numpy as np

PROTOCOL = "deformbench-method"
VERSION = 1


def serve(make_method, about=""):
    """Answer the harness's requests until `quit` or end of input."""
    protocol_out = sys.stdout
    sys.stdout = sys.stderr
    method = None
    for line in sys.stdin:
        try:
            message = json.loads(line)
            request = message.get("request")
            if request == "quit":
                break
            answer = {}
            if request == "hello":
                if message.get("version") != VERSION:
                    raise ValueError(f"this method speaks protocol version {VERSION}")
                method = make_method(message.get("params", {}))
                answer = {"protocol": PROTOCOL, "version": VERSION, "about": about}
            elif method is None:
                raise ValueError(f"`{request}` before `hello`")
            elif request == "precompute":
                V = np.asarray(message["vertices"], dtype=np.float64).reshape(-1, 3)
                F = np.asarray(message["faces"], dtype=np.int64).reshape(-1, 3)
                answer = method.precompute(V, F) or {}
            elif request == "bind":
                regions = [np.asarray(r, dtype=np.int64) for r in message["regions"]]
                answer = method.bind(regions) or {}
            elif request == "solve":
                constrained = np.asarray(message["constrained"], dtype=np.int64)
                targets = np.asarray(message["targets"], dtype=np.float64).reshape(-1, 3)
                answer = dict(method.solve(constrained, targets))
                answer["positions"] = np.asarray(answer["positions"], dtype=np.float64).tolist()
            else:
                raise ValueError(f"unknown request `{request}`")
            answer["ok"] = True
            # allow_nan=False: a NaN position is an error here, not invalid JSON on the wire.
            text = json.dumps(answer, allow_nan=False)
        except Exception as error:  # noqa: BLE001 - every failure is answered, with its traceback on stderr
            traceback.print_exc(file=sys.stderr)
            text = json.dumps({"ok": False, "error": f"{type(error).__name__}: {error}"})
        protocol_out.write(text + "\n")
        protocol_out.flush()


def bbox_diagonal(V):
    return float(np.linalg.norm(V.max(axis=0) - V.min(axis=0)))


class Stopwatch:
    """`with Stopwatch() as t: ...; t.seconds`."""

    def __enter__(self):
        self.start = time.perf_counter()
        return self

    def __exit__(self, *exc):
        self.seconds = time.perf_counter() - self.start


class DistanceBound:
    """The built-in methods' stopping rule (methods/src/method.rs, `DistanceBound`): after each step
    `s_k` (largest vertex move over the diagonal), the estimated distance to the fixed point is
    `s_k rho / (1 - rho)`, `rho` the largest ratio of successive steps over the last four; until
    four steps are recorded, or while a step grew, `rho` is taken as 0.999. Report the value as the
    answer's `distance` and stop when it falls below the tolerance."""

    WINDOW = 4
    SLOWEST = 0.999

    def __init__(self):
        self.steps = []

    def record(self, step):
        """Record `step`; returns the distance bound after it."""
        if step == 0.0:
            distance = 0.0
        elif not np.isfinite(step):
            distance = float("inf")
        else:
            distance = step * self.SLOWEST / (1.0 - self.SLOWEST)
            if len(self.steps) >= self.WINDOW:
                recent = self.steps[-self.WINDOW:] + [step]
                ratios = [b / a if a > 0.0 else float("inf") for a, b in zip(recent, recent[1:])]
                rho = max(ratios)
                if rho < 1.0:
                    distance = step * rho / (1.0 - rho)
        self.steps = (self.steps + [step])[-(self.WINDOW + 1):]
        return distance
