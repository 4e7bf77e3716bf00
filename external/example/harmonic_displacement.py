#!/usr/bin/env python3
"""A deformation method in one file, for deformbench's method protocol (version 1).

Harmonic displacement interpolation: the handles' displacements (target - rest) spread over the
free vertices by solving the cotangent Laplace equation L d = 0 with d fixed on the handles, then
added to the rest positions. Linear, no rotations (a twisted handle shears its neighbourhood): a
baseline, and a template. It needs numpy and scipy.

The protocol, as this file speaks it: one JSON object per line on stdin, one answer per line on
stdout; stderr is for logs (the harness keeps it in reports/logs/ and quotes it when a case fails).
  {"request": "hello", "version": 1, "params": {...}}        -> {"ok": true, "protocol": "deformbench-method", "version": 1}
  {"request": "precompute", "vertices": [[x,y,z],...], "faces": [[i,j,k],...]}  -> {"ok": true}
  {"request": "bind", "regions": [[i,...], ...]}                -> {"ok": true}
  {"request": "solve", "constrained": [i,...], "targets": [[x,y,z],...]}
                                                     -> {"ok": true, "positions": [[x,y,z],...]}
  {"request": "quit"}                                           -> (exit)
Any failure: {"ok": false, "error": "what went wrong"}.
"""

import json
import sys

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla


def cotangent_laplacian(V, F):
    """#V x #V cotangent Laplacian (positive semi-definite: sum_j w_ij (x_i - x_j))."""
    rows, cols, weights = [], [], []
    for k in range(3):
        i, j, o = F[:, (k + 1) % 3], F[:, (k + 2) % 3], F[:, k]
        a, b = V[i] - V[o], V[j] - V[o]
        cot = np.einsum("ij,ij->i", a, b) / np.linalg.norm(np.cross(a, b), axis=1)
        rows += [i, j]
        cols += [j, i]
        weights += [0.5 * cot, 0.5 * cot]
    W = sp.csr_matrix((np.concatenate(weights), (np.concatenate(rows), np.concatenate(cols))), shape=(len(V),) * 2)
    return sp.diags(np.asarray(W.sum(axis=1)).ravel()) - W


class HarmonicDisplacement:
    def precompute(self, V, F):
        self.V = V
        self.L = cotangent_laplacian(V, F).tocsr()

    def bind(self, regions):
        n = len(self.V)
        self.constrained = np.concatenate(regions)
        self.free = np.setdiff1d(np.arange(n), self.constrained)
        # Factor once per handle set; every solve is two back-substitutions per coordinate.
        self.solver = spla.splu(self.L[self.free][:, self.free].tocsc())
        self.coupling = self.L[self.free][:, self.constrained]

    def solve(self, constrained, targets):
        d_constrained = targets - self.V[constrained]
        d_free = self.solver.solve(-(self.coupling @ d_constrained))
        U = self.V.copy()
        U[constrained] = targets
        U[self.free] += d_free
        return U


def main():
    out = sys.stdout
    sys.stdout = sys.stderr  # a stray print must not break the protocol stream
    method = HarmonicDisplacement()
    for line in sys.stdin:
        message = json.loads(line)
        request = message["request"]
        try:
            if request == "quit":
                break
            if request == "hello":
                answer = {"protocol": "deformbench-method", "version": 1, "about": "harmonic displacement (numpy/scipy)"}
            elif request == "precompute":
                method.precompute(np.array(message["vertices"], dtype=float), np.array(message["faces"], dtype=int))
                answer = {}
            elif request == "bind":
                method.bind([np.array(r, dtype=int) for r in message["regions"]])
                answer = {}
            elif request == "solve":
                U = method.solve(np.array(message["constrained"], dtype=int), np.array(message["targets"], dtype=float))
                answer = {"positions": U.tolist(), "iterations": 1, "converged": True}
            else:
                raise ValueError(f"unknown request {request!r}")
            answer["ok"] = True
            text = json.dumps(answer, allow_nan=False)
        except Exception as error:
            print(f"harmonic_displacement: {request}: {error!r}", file=sys.stderr)
            text = json.dumps({"ok": False, "error": f"{type(error).__name__}: {error}"})
        out.write(text + "\n")
        out.flush()


if __name__ == "__main__":
    main()
