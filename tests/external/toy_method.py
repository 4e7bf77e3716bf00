"""A toy external method for the tests of the protocol, standard library only.

usage: toy_method.py MODE [PID_FILE]

MODE `ok` is a well-behaved method: every vertex stays at rest except the constrained ones, which
go to their targets (three reported iterations). Every other mode breaks the protocol in one way,
at the request it names:
  crash-in-solve   writes a traceback to stderr and exits with status 3
  malformed        answers `precompute` with a line that is not JSON
  wrong-count      answers `solve` with one position too few
  nan              answers `solve` with a NaN coordinate (Python's json writes `NaN`)
  error            answers `bind` with {"ok": false, "error": ...}
  old-protocol     answers `hello` with version 0
  hang             starts a grandchild (`sleep 600`, its pid written to PID_FILE) and never answers `solve`
  ignore-stdin     starts a grandchild likewise and never reads its input again
  exit-at-start    exits with status 7 before reading anything
  random           well-behaved but for one free vertex moved by a random amount (non-deterministic)
  silent           well-behaved but says nothing of iterations or convergence (as open3d's ARAP)
"""

import json
import subprocess
import sys
import time

mode = sys.argv[1]
pid_file = sys.argv[2] if len(sys.argv) > 2 else None


def grandchild():
    child = subprocess.Popen(["sleep", "600"])
    with open(pid_file, "w") as f:
        f.write(str(child.pid))


def answer(obj):
    sys.stdout.write(json.dumps(obj) + "\n")
    sys.stdout.flush()


if mode == "exit-at-start":
    print("toy: giving up at once", file=sys.stderr)
    sys.exit(7)

rest = []
for line in sys.stdin:
    message = json.loads(line)
    request = message["request"]
    print(f"toy: {request}", file=sys.stderr, flush=True)
    if request == "quit":
        break
    if request == "hello":
        version = 0 if mode == "old-protocol" else 1
        answer({"ok": True, "protocol": "deformbench-method", "version": version, "about": f"toy {mode}"})
    elif request == "precompute":
        rest = message["vertices"]
        if mode == "malformed":
            sys.stdout.write("precomputed, thank you\n")
            sys.stdout.flush()
        elif mode == "ignore-stdin":
            grandchild()
            time.sleep(600)
        else:
            answer({"ok": True, "timings": {"toy_precompute": 0.001}})
    elif request == "bind":
        if mode == "error":
            answer({"ok": False, "error": "toy: this handle set is not for me"})
        else:
            answer({"ok": True})
    elif request == "solve":
        positions = [list(p) for p in rest]
        for v, t in zip(message["constrained"], message["targets"]):
            positions[v] = t
        if mode == "crash-in-solve":
            print("Traceback (most recent call last):\n  ZeroDivisionError: toy division by zero", file=sys.stderr)
            sys.stderr.flush()
            sys.exit(3)
        if mode == "random":
            import random

            free = next(v for v in range(len(positions)) if v not in set(message["constrained"]))
            positions[free] = [c + random.random() * 1e-9 for c in positions[free]]
        if mode == "wrong-count":
            positions = positions[:-1]
        if mode == "nan":
            positions[0][1] = float("nan")
        if mode == "hang":
            grandchild()
            time.sleep(600)
        trace = [{"step": 0.1, "seconds": 0.001}, {"step": 0.01, "seconds": 0.001}, {"step": 0.0, "seconds": 0.001}]
        if mode == "silent":
            answer({"ok": True, "positions": positions})
        else:
            answer({"ok": True, "positions": positions, "iterations": 3, "converged": True, "trace": trace})
