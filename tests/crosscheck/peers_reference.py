#!/usr/bin/env python3
"""Reference results computed with pymeshlab and open3d for deformbench's cross-check tests.

The companion of igl_reference.py (libigl/scipy): the Rust tests run this script with the interpreter
named by $DEFORMBENCH_PYTHON (set up by scripts/python-env from python/requirements.txt) and
compare against its output. Files are plain text; floats are written with '%.17g' (round-trips an f64).

Mesh input is a triangle OFF file. pymeshlab subcommands load it with pymeshlab's own loader
(MeshSet.load_new_mesh, exact to the digits in the file; checked against this script's reader, below,
so that MeshLab cannot silently triangulate or reorder). open3d subcommands read it with this script's
strict OFF parser (`read_off`) and build an open3d.geometry.TriangleMesh from the arrays, because
open3d.io.read_triangle_mesh parses OFF coordinates inexactly (measured: up to 5e-11 absolute on the
survey bar, whose coordinates have 10 decimals; pymeshlab and libigl read them exactly).

Subcommands and formats
-----------------------
face_measures MESH OUT_DIR
    Per-face measures computed by pymeshlab (MeshLab's filters evaluate in double precision):
    OUT_DIR/faces.txt   pymeshlab's face matrix, `i j k` per face (0-based), so a reader can check that
                        faces and corners are in the file's order.
    OUT_DIR/angles.txt  `a0 a1 a2` per face: the interior angle in radians at corner 0, 1, 2 of the face
                        (corner k is vertex F[f, k]).
    OUT_DIR/areas.txt   one area per face.
    pymeshlab has no per-corner-angle output. Areas come from the filter
    `compute_scalar_by_aspect_ratio_per_face(metric='Area')` (per-face quality); each angle column from
    `compute_scalar_by_function_per_face(q=...)`, MeshLab's muparser evaluating
    atan2(|e1 x e2|, e1 . e2) over the face's corner coordinates x0..z2 (e1, e2 the edges leaving the
    corner); both read back with Mesh.face_scalar_array().

hausdorff A B [--samples N]
    Symmetric Hausdorff distance between the surfaces of meshes A and B with pymeshlab's
    get_hausdorff_distance, run A -> B (points sampled on A, distances to the closest point of B's
    surface) and B -> A. Each direction samples every vertex of the sampled mesh plus max(N, #V) Monte
    Carlo points on its faces (N defaults to 4 x #F of that mesh: about 3.5 s for the 80K-face survey
    plane, 8 s at 10 x #F); no distance cut-off (maxdist is set above the diagonal of the union of both
    bounding boxes). MeshLab's sampler has a fixed seed, so reruns print the same figures. MeshLab
    returns some of the distances rounded to single precision, and two identical meshes give up to
    ~4e-9 x diagonal (closest-point rounding), so read the figures to about 1e-7 relative.
    Prints one JSON object on stdout:
    {"a": path, "b": path, "hausdorff": max of both directions,
     "a_to_b": {"max", "mean", "rms", "n_samples"}, "b_to_a": {...},
     "bbox_diagonal_a": ..., "bbox_diagonal_b": ...}

open3d_arap MESH CONSTRAINTS OUT --iterations N
    CONSTRAINTS: one line per constrained vertex, `index x y z` (target position), as for
    igl_reference.py's `arap`; blank lines and '#' lines are ignored. Runs
    open3d.geometry.TriangleMesh.deform_as_rigid_as_possible with energy Spokes (its default), exactly
    N iterations (open3d has no early exit). OUT: the result as OFF (same faces as MESH).
    What open3d 0.20 does (cpp/open3d/geometry/TriangleMeshDeformation.cpp), where it differs from the
    Sorkine-Alexa spokes ARAP of libigl and deformbench's `arap`:
    - edge weights are the MEAN of the cotangents opposite the edge (ComputeEdgeWeightsCot), clamped
      below at 0: (cot a + cot b) / 2 on interior edges as in libigl's cotmatrix, but cot a (not
      cot a / 2) on boundary edges, and 0 instead of a negative weight;
    - the first local step sees the rest shape itself (constrained vertices not yet moved), so its
      rotations are all identity and iteration 1 is plain Laplacian editing; libigl and deformbench
      move the constrained vertices to their targets before the first local step;
    - rotations by a double-precision 3x3 JacobiSVD; global step by SparseLU on the Laplacian with
      identity rows for the constrained vertices.

geometric_measures MESH
    pymeshlab's get_geometric_measures (MeshLab's "Compute Geometric Measures"): prints one JSON object
    {"surface_area": ..., "mesh_volume": ... or null}; MeshLab reports a volume only for a watertight
    mesh (the divergence theorem over the faces; signed, positive when the faces face outwards).

(open3d's is_self_intersecting is the harness's own check, python/self_intersection.py; measured
about 1 s for the 10K-face survey meshes and 25 s for the 80K-face plane.)

Errors go to stderr naming the file, with exit code 1. Nothing else is printed on stdout.
"""

import json
import os
import sys

import numpy as np

from reference_cli import (
    ArgumentParser,
    UsageError,
    check_file,
    positive_int,
    read_vector_constraints,
    write_matrix,
)

# pymeshlab and open3d are imported by the subcommands that use them (`import open3d` alone takes
# about 1.8 s, most of it its plotly/dash visualizer stack).
pymeshlab = None
o3d = None


def import_pymeshlab():
    global pymeshlab
    import pymeshlab as module

    pymeshlab = module


def import_open3d():
    global o3d
    import open3d as module

    # open3d logs warnings to stdout; only errors are let through so that stdout stays machine-readable.
    module.utility.set_verbosity_level(module.utility.VerbosityLevel.Error)
    o3d = module


# ---------------------------------------------------------------------------------------------
# I/O helpers


def read_off(path):
    """Strict triangle OFF reader -> (V float64 (n, 3), F int32 (m, 3)); comments after '#' ignored."""
    check_file(path, "mesh")
    with open(path) as fh:
        tokens = [t for line in fh for t in line.split("#", 1)[0].split()]
    if not tokens or tokens[0] != "OFF":
        raise UsageError(f"{path}: not an OFF file (first token must be 'OFF')")
    try:
        nv, nf = int(tokens[1]), int(tokens[2])
        pos = 4
        V = np.array(tokens[pos:pos + 3 * nv], dtype=np.float64).reshape(nv, 3)
        pos += 3 * nv
        faces = []
        for f in range(nf):
            if int(tokens[pos]) != 3:
                raise UsageError(f"{path}: face {f} is not a triangle ({tokens[pos]} corners)")
            faces.append([int(t) for t in tokens[pos + 1:pos + 4]])
            pos += 4
    except (IndexError, ValueError) as e:
        raise UsageError(f"{path}: malformed or truncated OFF ({e})")
    F = np.array(faces, dtype=np.int64).reshape(nf, 3)
    if nv == 0 or nf == 0:
        raise UsageError(f"{path}: no vertices or no faces")
    if F.min() < 0 or F.max() >= nv:
        raise UsageError(f"{path}: face vertex index out of range [0, {nv})")
    if not np.all(np.isfinite(V)):
        raise UsageError(f"{path}: non-finite vertex coordinates")
    return V, F.astype(np.int32)


def write_off(path, V, F):
    with open(path, "w") as fh:
        fh.write("OFF\n%d %d 0\n" % (len(V), len(F)))
        for x, y, z in V.tolist():
            fh.write("%.17g %.17g %.17g\n" % (x, y, z))
        for i, j, k in F.tolist():
            fh.write("3 %d %d %d\n" % (i, j, k))


def load_meshset(*paths):
    """A pymeshlab MeshSet with each path loaded in order (mesh ids 0, 1, ...). Each file is first read
    by `read_off` (so a non-triangle or malformed OFF is an error, not silently triangulated or
    repaired by MeshLab), and pymeshlab's vertices and faces must equal what it read, exactly."""
    ms = pymeshlab.MeshSet()
    for path in paths:
        V, F = read_off(path)
        try:
            ms.load_new_mesh(path)
        except pymeshlab.PyMeshLabException as e:
            raise UsageError(f"{path}: pymeshlab could not load it: {e}")
        m = ms.current_mesh()
        if not (np.array_equal(m.vertex_matrix(), V) and np.array_equal(m.face_matrix(), F)):
            raise RuntimeError(f"{path}: pymeshlab loaded other vertices or faces than the file's")
    return ms


def bbox_diagonal(V):
    return float(np.linalg.norm(V.max(axis=0) - V.min(axis=0)))


# ---------------------------------------------------------------------------------------------
# face_measures


def corner_angle_expression(k):
    """muparser expression for the angle at corner k: atan2(|e1 x e2|, e1 . e2) with e1 = p(k+1) - pk,
    e2 = p(k+2) - pk, written with MeshLab's per-face variables x0, y0, z0, ..., z2."""
    o, a, b = k, (k + 1) % 3, (k + 2) % 3
    e1 = [f"({c}{a}-{c}{o})" for c in "xyz"]
    e2 = [f"({c}{b}-{c}{o})" for c in "xyz"]
    cross = [
        f"{e1[1]}*{e2[2]}-{e1[2]}*{e2[1]}",
        f"{e1[2]}*{e2[0]}-{e1[0]}*{e2[2]}",
        f"{e1[0]}*{e2[1]}-{e1[1]}*{e2[0]}",
    ]
    cross_norm = "sqrt(" + "+".join(f"({c})^2" for c in cross) + ")"
    dot = "+".join(f"{e1[i]}*{e2[i]}" for i in range(3))
    return f"atan2({cross_norm},{dot})"


def cmd_face_measures(args):
    ms = load_meshset(args.mesh)
    os.makedirs(args.out_dir, exist_ok=True)
    F = ms.current_mesh().face_matrix()

    ms.compute_scalar_by_aspect_ratio_per_face(metric="Area")
    areas = ms.current_mesh().face_scalar_array().copy()

    angles = np.empty((len(F), 3))
    for k in range(3):
        ms.compute_scalar_by_function_per_face(q=corner_angle_expression(k), normalize=False)
        angles[:, k] = ms.current_mesh().face_scalar_array()

    if not (np.all(np.isfinite(areas)) and np.all(np.isfinite(angles))):
        raise RuntimeError(f"{args.mesh}: pymeshlab produced non-finite face measures")
    write_matrix(os.path.join(args.out_dir, "faces.txt"), F, fmt="%d")
    write_matrix(os.path.join(args.out_dir, "angles.txt"), angles)
    write_matrix(os.path.join(args.out_dir, "areas.txt"), areas)


def cmd_geometric_measures(args):
    ms = load_meshset(args.mesh)
    measures = ms.get_geometric_measures()
    volume = measures.get("mesh_volume")
    print(json.dumps({
        "surface_area": float(measures["surface_area"]),
        "mesh_volume": None if volume is None else float(volume),
    }))


# ---------------------------------------------------------------------------------------------
# hausdorff


def one_sided_hausdorff(ms, sampled, target, samples, maxdist):
    m = ms.mesh(sampled)
    n = samples if samples is not None else 4 * m.face_number()
    r = ms.get_hausdorff_distance(
        sampledmesh=sampled,
        targetmesh=target,
        savesample=False,
        samplevert=True,
        sampleedge=False,
        samplefauxedge=False,
        sampleface=True,
        # VertexUniform takes every vertex when samplenum >= #V; Montecarlo takes samplenum face points.
        samplenum=max(n, m.vertex_number()),
        maxdist=pymeshlab.PureValue(maxdist),
    )
    expected = max(n, m.vertex_number()) + m.vertex_number()
    if r["n_samples"] != expected:
        raise RuntimeError(f"get_hausdorff_distance used {r['n_samples']} samples, expected {expected}")
    return {"max": r["max"], "mean": r["mean"], "rms": r["RMS"], "n_samples": r["n_samples"]}


def cmd_hausdorff(args):
    ms = load_meshset(args.a, args.b)
    Va, Vb = ms.mesh(0).vertex_matrix(), ms.mesh(1).vertex_matrix()
    both = np.vstack([Va, Vb])
    # No sample may be dropped by the cut-off: no two points of the meshes are farther apart than this.
    maxdist = 2.0 * bbox_diagonal(both) + 1.0
    a_to_b = one_sided_hausdorff(ms, 0, 1, args.samples, maxdist)
    b_to_a = one_sided_hausdorff(ms, 1, 0, args.samples, maxdist)
    print(json.dumps({
        "a": args.a,
        "b": args.b,
        "hausdorff": max(a_to_b["max"], b_to_a["max"]),
        "a_to_b": a_to_b,
        "b_to_a": b_to_a,
        "bbox_diagonal_a": bbox_diagonal(Va),
        "bbox_diagonal_b": bbox_diagonal(Vb),
    }))


# ---------------------------------------------------------------------------------------------
# open3d


def open3d_mesh(V, F):
    return o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(V), o3d.utility.Vector3iVector(F))


def cmd_open3d_arap(args):
    V, F = read_off(args.mesh)
    idx, pos = read_vector_constraints(args.constraints, len(V))
    mesh = open3d_mesh(V, F)
    out = mesh.deform_as_rigid_as_possible(
        o3d.utility.IntVector(idx.tolist()),
        o3d.utility.Vector3dVector(pos),
        max_iter=args.iterations,
        energy=o3d.geometry.DeformAsRigidAsPossibleEnergy.Spokes,
    )
    U = np.asarray(out.vertices)
    if U.shape != V.shape or not np.array_equal(np.asarray(out.triangles), F):
        raise RuntimeError(f"{args.mesh}: open3d returned a mesh of another size or connectivity")
    if not np.all(np.isfinite(U)):
        raise RuntimeError(f"{args.mesh}: open3d ARAP produced non-finite positions")
    write_off(args.out, U, F)


# ---------------------------------------------------------------------------------------------


def build_parser():
    p = ArgumentParser(description="pymeshlab/open3d reference results for deformbench.")
    sub = p.add_subparsers(dest="command", required=True, parser_class=ArgumentParser)

    s = sub.add_parser("face_measures", help="per-face corner angles and areas (pymeshlab)")
    s.add_argument("mesh")
    s.add_argument("out_dir")
    s.set_defaults(func=cmd_face_measures, needs=import_pymeshlab)

    s = sub.add_parser("geometric_measures", help="surface area and enclosed volume (pymeshlab)")
    s.add_argument("mesh")
    s.set_defaults(func=cmd_geometric_measures, needs=import_pymeshlab)

    s = sub.add_parser("hausdorff", help="symmetric Hausdorff distance (pymeshlab)")
    s.add_argument("a")
    s.add_argument("b")
    s.add_argument("--samples", type=positive_int, default=None,
                   help="face samples per direction (default 4 x #F of the sampled mesh)")
    s.set_defaults(func=cmd_hausdorff, needs=import_pymeshlab)

    s = sub.add_parser("open3d_arap", help="open3d deform_as_rigid_as_possible (Spokes)")
    s.add_argument("mesh")
    s.add_argument("constraints")
    s.add_argument("out")
    s.add_argument("--iterations", type=positive_int, required=True)
    s.set_defaults(func=cmd_open3d_arap, needs=import_open3d)

    return p


def main(argv=None):
    args = build_parser().parse_args(argv)
    args.needs()
    errors = (UsageError, RuntimeError, OSError, ValueError)
    if pymeshlab is not None:
        errors += (pymeshlab.PyMeshLabException,)
    try:
        args.func(args)
    except errors as e:
        print(f"peers_reference.py {args.command}: error: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
