"""libigl's biharmonic deformation as a deformbench peer, over the method protocol: the handle
displacements (target - rest) interpolated by igl.harmonic with k = 2 (libigl's cotangent
Laplacian and Voronoi mass matrix), added to the rest positions. The linear baseline of Botsch &
Sorkine's survey ("On Linear Variational Surface Deformation Methods", 2008): no rotations, so a
twist shears. A direct method: every solve starts from the rest shape.

params: k (2; 1 is harmonic, 3 triharmonic).
"""

import importlib.metadata
import os
import sys

os.environ.setdefault("IGL_NUM_THREADS", "1")
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))

import igl  # noqa: E402
import numpy as np  # noqa: E402

import deformbench_method as protocol  # noqa: E402


class LibiglBiharmonic:
    def __init__(self, params):
        self.k = int(params.get("k", 2))

    def precompute(self, V, F):
        self.V, self.F = V, F

    def bind(self, regions):
        self.b = np.concatenate(regions).astype(np.int64)

    def solve(self, constrained, targets):
        displacement = targets - self.V[constrained]
        D = igl.harmonic(self.V, self.F, constrained, displacement, self.k)
        return {"positions": self.V + D, "iterations": 1, "converged": True}


if __name__ == "__main__":
    version = importlib.metadata.version("libigl")
    protocol.serve(LibiglBiharmonic, about=f"libigl {version} k-harmonic (params k, default 2) on the handle displacements")
