"""open3d's TriangleMesh.deform_as_rigid_as_possible as a deformbench peer, over the method
protocol. `energy = "spokes"` (open3d's default: Sorkine & Alexa's energy) or `"smoothed"` (its
smoothed-rotations variant, weight `smoothed_alpha`).

open3d has no initial guess and no early exit: every solve starts from the rest shape and runs
exactly `iterations` iterations, and reports neither a step nor convergence, so its rows cannot be
called unfinished; their distance to deformbench's `arap` (rms_to_arap_over_diag) says how far from
the converged ARAP shape they are. What else differs from libigl and deformbench
(tests/crosscheck/peers_reference.py has the details): clamped mean-cotangent weights, and a first
local step that sees the rest shape.

params: energy ("spokes"), smoothed_alpha (0.01), iterations (1000).
"""

import importlib.metadata
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))

import numpy as np  # noqa: E402
import open3d as o3d  # noqa: E402

import deformbench_method as protocol  # noqa: E402

ENERGIES = {
    "spokes": o3d.geometry.DeformAsRigidAsPossibleEnergy.Spokes,
    "smoothed": o3d.geometry.DeformAsRigidAsPossibleEnergy.Smoothed,
}


class Open3dArap:
    def __init__(self, params):
        energy = params.get("energy", "spokes")
        if energy not in ENERGIES:
            raise ValueError(f"energy must be one of {sorted(ENERGIES)}, not {energy!r}")
        self.energy = ENERGIES[energy]
        self.alpha = float(params.get("smoothed_alpha", 0.01))
        self.iterations = int(params.get("iterations", 1000))

    def precompute(self, V, F):
        self.mesh = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(V), o3d.utility.Vector3iVector(F))
        self.n = len(V)

    def bind(self, regions):
        pass

    def solve(self, constrained, targets):
        out = self.mesh.deform_as_rigid_as_possible(
            o3d.utility.IntVector(constrained.tolist()),
            o3d.utility.Vector3dVector(targets),
            max_iter=self.iterations,
            energy=self.energy,
            smoothed_alpha=self.alpha,
        )
        U = np.asarray(out.vertices)
        if U.shape != (self.n, 3):
            raise RuntimeError(f"open3d returned {U.shape[0]} vertices for {self.n}")
        return {"positions": U, "iterations": self.iterations}


if __name__ == "__main__":
    version = importlib.metadata.version("open3d-cpu")
    protocol.serve(Open3dArap, about=f"open3d {version} deform_as_rigid_as_possible")
