"""libigl's ARAP (Sorkine & Alexa 2007) as a deformbench peer, over the method protocol.

igl.arap_precomputation / igl.arap_solve with the SPOKES energy (libigl's default for triangle
meshes is SPOKES_AND_RIMS; deformbench's `arap` is spokes), libigl's cotangent weights and hard
constraints, no dynamics. libigl's solve runs a fixed number of iterations; this adapter runs one
at a time from the current shape and stops when the estimated distance to the fixed point
(`deformbench_method.DistanceBound`, from the step sequence) falls below `tolerance` x the rest
bounding-box diagonal: the stopping rule of deformbench's `arap`, so both stop near the same fixed
point of the same energy (up to the weights: libigl's plain cotangents, ours intrinsic-Delaunay by
default). The factorization needs the constrained vertices, so it is
timed in `bind`. libigl runs single-threaded here (IGL_NUM_THREADS=1).

params: tolerance (1e-5), max_iterations (20000).
"""

import importlib.metadata
import os
import sys
import time

os.environ.setdefault("IGL_NUM_THREADS", "1")
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))

import igl  # noqa: E402
import numpy as np  # noqa: E402

import deformbench_method as protocol  # noqa: E402


class LibiglArap:
    def __init__(self, params):
        self.tolerance = float(params.get("tolerance", 1e-5))
        self.max_iterations = int(params.get("max_iterations", 20000))

    def precompute(self, V, F):
        self.V, self.F = V, F
        self.current = V.copy()
        self.diagonal = protocol.bbox_diagonal(V)

    def bind(self, regions):
        with protocol.Stopwatch() as t:
            self.data = igl.ARAPData()
            self.data.energy = igl.ARAP_ENERGY_TYPE_SPOKES
            self.data.with_dynamics = False
            self.data.max_iter = 1
            self.b = np.concatenate(regions).astype(np.int64)
            igl.arap_precomputation(self.V, self.F, 3, self.b.astype(np.int32), self.data)
        return {"timings": {"arap_precomputation": t.seconds}}

    def solve(self, constrained, targets):
        if not np.array_equal(constrained, self.b):
            raise ValueError("solve's constrained vertices are not those of the bound regions, in order")
        trace = []
        converged = False
        step = float("inf")
        distance = float("inf")
        rule = protocol.DistanceBound()
        for _ in range(self.max_iterations):
            start = time.perf_counter()
            U = igl.arap_solve(targets, self.data, self.current)
            step = float(np.max(np.linalg.norm(U - self.current, axis=1))) / self.diagonal
            self.current = U
            trace.append({"step": step, "seconds": time.perf_counter() - start})
            distance = rule.record(step)
            if distance < self.tolerance:
                converged = True
                break
        return {
            "positions": self.current,
            "iterations": len(trace),
            "converged": converged,
            "final_step": step,
            "distance": distance,
            "trace": trace,
        }


if __name__ == "__main__":
    version = importlib.metadata.version("libigl")
    protocol.serve(LibiglArap, about=f"libigl {version} arap_solve (SPOKES, cotangent weights), one iteration per call")
