#!/usr/bin/env python3
"""open3d's `TriangleMesh.is_self_intersecting` of triangle OFF meshes, for the harness's
`--self-intersections` (harness/src/self_intersection.rs). Run with the project's Python
($DEFORMBENCH_PYTHON, made by scripts/python-env from python/requirements.txt).

    self_intersection.py MESH...    prints `path,true|false` per mesh, in order

The OFF files are the harness's own (`meshes::io::write_off`); they are still read strictly, and a
malformed one is an error naming the file (exit code 1).
"""

import sys

import numpy as np


def read_off(path):
    """Triangle OFF -> (V float64 (n, 3), F int32 (m, 3)); text after '#' ignored."""
    with open(path) as fh:
        tokens = [t for line in fh for t in line.split("#", 1)[0].split()]
    if not tokens or tokens[0] != "OFF":
        raise ValueError(f"{path}: not an OFF file")
    try:
        nv, nf = int(tokens[1]), int(tokens[2])
        V = np.array(tokens[4:4 + 3 * nv], dtype=np.float64).reshape(nv, 3)
        rows = np.array(tokens[4 + 3 * nv:4 + 3 * nv + 4 * nf], dtype=np.int64).reshape(nf, 4)
    except (IndexError, ValueError) as e:
        raise ValueError(f"{path}: malformed or truncated OFF ({e})")
    if nf and (rows[:, 0] != 3).any():
        raise ValueError(f"{path}: a face is not a triangle")
    F = rows[:, 1:]
    if nf and (F.min() < 0 or F.max() >= nv):
        raise ValueError(f"{path}: face vertex index out of range [0, {nv})")
    return V, F.astype(np.int32)


def main(paths):
    if not paths:
        print("usage: self_intersection.py MESH...", file=sys.stderr)
        return 1
    import open3d as o3d

    # open3d logs warnings to stdout; only errors pass, so stdout stays the answer.
    o3d.utility.set_verbosity_level(o3d.utility.VerbosityLevel.Error)
    try:
        for path in paths:
            V, F = read_off(path)
            mesh = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(V), o3d.utility.Vector3iVector(F))
            print(f"{path},{'true' if mesh.is_self_intersecting() else 'false'}")
    except (OSError, ValueError) as e:
        print(f"self_intersection.py: error: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
