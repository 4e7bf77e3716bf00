#!/usr/bin/env python3
"""Reference results computed with libigl (and scipy) for deformbench's cross-check tests.

The Rust tests run this script (with the interpreter named by $DEFORMBENCH_PYTHON, set up by
scripts/python-env from python/requirements.txt) and compare the Rust implementations
against its output. Every file written here is plain text, so the Rust side needs no extra crate
to read it. Floats are written with '%.17g' (round-trips an f64 exactly).

Mesh input is an OFF file read with igl.read_triangle_mesh (F as int64).

Subcommands and formats
-----------------------
operators MESH OUT_DIR
    OUT_DIR/cotmatrix.txt        igl.cotmatrix(V, F) as COO triplets, one `i j value` line per
                                 nonzero (after sum_duplicates; entries exactly 0.0 dropped, so a
                                 missing (i, j) means 0; sorted by i then j; 0-based indices).
    OUT_DIR/mass_voronoi.txt     diagonal of igl.massmatrix(V, F, VORONOI), one value per line.
    OUT_DIR/mass_barycentric.txt diagonal of igl.massmatrix(V, F, BARYCENTRIC), one value per line.

intrinsic_delaunay MESH OUT_DIR
    OUT_DIR/intrinsic_delaunay_cotmatrix.txt  L of igl.intrinsic_delaunay_cotmatrix(V, F) as COO
                                 triplets, in the format of `operators`' cotmatrix.txt.

tufted MESH OUT_DIR
    OUT_DIR/tufted_laplacian.txt  -L of robust_laplacian.mesh_laplacian(V, F, mollify_factor=0)
                                 (Sharp & Crane 2020's tufted Laplacian; robust-laplacian's L is
                                 positive semi-definite, so it is negated into the project's
                                 libigl sign), COO triplets in the format of `operators`.
    OUT_DIR/tufted_mass.txt      diagonal of its lumped mass M, one value per line.

arap MESH CONSTRAINTS ITERATIONS OUT
    CONSTRAINTS: one line per constrained vertex, `index x y z` (target position); blank lines
    and lines starting with '#' are ignored. Runs libigl ARAP with the SPOKES energy, dim 3,
    no dynamics, max_iter = ITERATIONS, initial guess U = rest positions V.
    OUT: one line per vertex, `x y z`.

arap_float64 MESH CONSTRAINTS ITERATIONS OUT
    The iteration of `arap` (SPOKES energy, igl.cotmatrix weights, constrained rows moved to their
    targets first, local step then global step) in float64 numpy/scipy, written here: libigl's
    rotation fit is single precision, this one is not, so the Rust side can tell libigl's rounding
    from a difference of its own. Same input and output formats as `arap`.

arap-timing MESH CONSTRAINTS ITERATIONS
    Same set-up as `arap`; times arap_precomputation and arap_solve (max_iter=ITERATIONS; libigl
    has no early exit, so it always runs ITERATIONS iterations), each best of 3 runs, and prints
    one JSON line on stdout (precompute_s in seconds, ms_per_iteration = best solve / ITERATIONS):
    {"mesh": ..., "vertices": n, "precompute_s": ..., "ms_per_iteration": ..., "iterations": ...}

doublearea MESH OUT
    igl.doublearea(V, F): twice the area of every face, one value per line, in face order.

harmonic MESH CONSTRAINTS OUT
    CONSTRAINTS: one line per boundary vertex, `index value`. igl.harmonic with k=1.
    OUT: one value per vertex.

eigs MESH K OUT [--mass barycentric|voronoi]
    Generalized eigenproblem  (-L) x = lambda M x  with L = igl.cotmatrix, M = igl.massmatrix
    (BARYCENTRIC by default, Rong et al. 2008 eq 6; or VORONOI), solved by scipy.sparse.linalg.eigsh in shift-invert mode (sigma slightly negative,
    which='LM', k=K). Eigenvalues ascending, one per line, to OUT; eigenvectors (M-orthonormal,
    columns matching the eigenvalues) to OUT + '.vectors', n lines of K values each.
    Prints {"seconds": <eigsh wall time>} on stdout.

constraints MESH SEL DEF OUT   (helper for tests; not a libigl computation)
    Builds an ARAP CONSTRAINTS file from a Botsch-Sorkine .sel/.def pair: status 0 (fixed) ->
    target = rest position, 2 (handle) -> target = T * (x, y, z, 1) with T the row-major 4x4
    matrix in the .def, 1 (free) -> not constrained.

Errors go to stderr with exit code 1. Nothing else is printed on stdout except the JSON lines of
`arap-timing` and `eigs`.

Threading: the libigl wheel links no OpenMP/TBB/BLAS; its igl::parallel_for uses std::thread
(capped by IGL_NUM_THREADS), but the ARAP path is effectively single-threaded: measured CPU time /
wall time of arap_precomputation and arap_solve is 1.00 on the 2-core machine, with
IGL_NUM_THREADS unset, 1 or 2 alike. This script sets IGL_NUM_THREADS=1 (unless already set) before
importing igl, so `arap-timing` is a strictly single-threaded baseline. (eigsh in `eigs` goes
through scipy's bundled OpenBLAS, which may use several threads.)

Precision caveat: libigl's ARAP local step fits rotations with polar_svd3x3 (McAdams et al.'s
3x3 SVD, computed in single precision). A double-precision SPOKES implementation therefore agrees
with `arap` only to about 1e-7 relative after one iteration (measured: 1e-6 absolute on bar,
whose bounding-box diagonal is 76), with the gap growing slowly over iterations (1.7e-3 absolute
on bar after 20 iterations of its 135-degree twist; 7e-6 on cactus). Compare with tolerances of
that order, not 1e-12.
"""

import json
import os
import sys
import time

# Single-threaded libigl for comparable timings (must be set before igl is imported; harmless for
# the other subcommands, whose results do not depend on the thread count).
os.environ.setdefault("IGL_NUM_THREADS", "1")

import numpy as np  # noqa: E402
import scipy.sparse as sp  # noqa: E402
import scipy.sparse.linalg as spla  # noqa: E402

import igl  # noqa: E402

from reference_cli import (  # noqa: E402
    ArgumentParser,
    UsageError,
    check_file,
    check_indices,
    positive_int,
    read_rows,
    read_vector_constraints,
    write_matrix,
)


# ---------------------------------------------------------------------------------------------
# I/O helpers


def read_mesh(path):
    check_file(path, "mesh")
    V, F = igl.read_triangle_mesh(path)
    V = np.ascontiguousarray(V, dtype=np.float64)
    F = np.ascontiguousarray(F, dtype=np.int64)
    if V.ndim != 2 or V.shape[0] == 0 or V.shape[1] != 3:
        raise UsageError(f"could not read vertices from {path} (got shape {V.shape})")
    if F.ndim != 2 or F.shape[0] == 0 or F.shape[1] != 3:
        raise UsageError(f"could not read triangles from {path} (got shape {F.shape})")
    return V, F


def read_scalar_constraints(path, n):
    """`index value` lines -> (b int64 array, bc float64 (#b, 1) array)."""
    rows = read_rows(path, 2, "constraints")
    b = np.array([int(r[0]) for r in rows], dtype=np.int64)
    bc = np.array([[float(r[1])] for r in rows], dtype=np.float64)
    check_indices(b, n, path)
    return b, bc


def ensure_dir(path):
    os.makedirs(path, exist_ok=True)


# ---------------------------------------------------------------------------------------------
# operators


def mass_diagonal(V, F, mtype):
    M = igl.massmatrix(V, F, mtype).tocsr()
    offdiag = M - sp.diags(M.diagonal())
    if offdiag.count_nonzero() != 0:
        raise RuntimeError("massmatrix is not diagonal")
    return M.diagonal()


def cmd_operators(args):
    V, F = read_mesh(args.mesh)
    ensure_dir(args.out_dir)

    L = igl.cotmatrix(V, F).tocoo()
    L.sum_duplicates()  # also sorts by (row, col)
    # Entries that are exactly 0.0 (right angles on grid-like meshes give cot = 0 exactly; bar,
    # cylinder and plane have thousands) are dropped: only true nonzeros are written, so readers
    # must treat a missing (i, j) as 0.
    keep = L.data != 0.0
    L = sp.coo_matrix((L.data[keep], (L.row[keep], L.col[keep])), shape=L.shape)
    with open(os.path.join(args.out_dir, "cotmatrix.txt"), "w") as fh:
        for i, j, v in zip(L.row.tolist(), L.col.tolist(), L.data.tolist()):
            fh.write("%d %d %.17g\n" % (i, j, v))

    write_matrix(os.path.join(args.out_dir, "mass_voronoi.txt"),
                 mass_diagonal(V, F, igl.MASSMATRIX_TYPE_VORONOI))
    write_matrix(os.path.join(args.out_dir, "mass_barycentric.txt"),
                 mass_diagonal(V, F, igl.MASSMATRIX_TYPE_BARYCENTRIC))


def write_coo(path, L):
    """COO triplets of a sparse matrix, as `operators` writes cotmatrix.txt."""
    L = L.tocoo()
    L.sum_duplicates()
    keep = L.data != 0.0
    with open(path, "w") as fh:
        for i, j, v in zip(L.row[keep].tolist(), L.col[keep].tolist(), L.data[keep].tolist()):
            fh.write("%d %d %.17g\n" % (i, j, v))


def cmd_intrinsic_delaunay(args):
    V, F = read_mesh(args.mesh)
    ensure_dir(args.out_dir)
    L, _l_intrinsic, _F_intrinsic = igl.intrinsic_delaunay_cotmatrix(V, F)
    write_coo(os.path.join(args.out_dir, "intrinsic_delaunay_cotmatrix.txt"), L)


def cmd_tufted(args):
    import robust_laplacian  # only this subcommand needs it

    V, F = read_mesh(args.mesh)
    ensure_dir(args.out_dir)
    L, M = robust_laplacian.mesh_laplacian(V, F, mollify_factor=0.0)
    write_coo(os.path.join(args.out_dir, "tufted_laplacian.txt"), -L)
    with open(os.path.join(args.out_dir, "tufted_mass.txt"), "w") as fh:
        for v in M.diagonal().tolist():
            fh.write("%.17g\n" % v)


# ---------------------------------------------------------------------------------------------
# ARAP


def arap_setup(V, F, b, iterations):
    """Precomputes libigl ARAP (SPOKES energy, dim 3, no dynamics)."""
    data = igl.ARAPData()
    # Default energy is ARAP_ENERGY_TYPE_DEFAULT, which libigl resolves to SPOKES_AND_RIMS for
    # triangle meshes in 3D: SPOKES must be set explicitly. Checked when this was written: with
    # SPOKES the result differs from DEFAULT/SPOKES_AND_RIMS (0.9 max on bar) and from ELEMENTS,
    # and matches an independent numpy SPOKES implementation up to libigl's single-precision
    # rotation fit (see the module docstring).
    data.energy = igl.ARAP_ENERGY_TYPE_SPOKES
    data.with_dynamics = False
    data.max_iter = iterations
    if data.energy != igl.ARAP_ENERGY_TYPE_SPOKES or data.max_iter != iterations:
        raise RuntimeError("ARAPData fields did not take the values set")
    # The binding wants b as int32 (see igl.arap_precomputation.__doc__).
    igl.arap_precomputation(V, F, 3, b.astype(np.int32), data)
    return data


def arap_solve(data, bc, V):
    # arap_solve uses U as the initial guess (after writing bc into the constrained rows) and
    # returns the solution as a new array.
    return igl.arap_solve(bc, data, V.copy())


def cmd_arap(args):
    V, F = read_mesh(args.mesh)
    b, bc = read_vector_constraints(args.constraints, V.shape[0])
    data = arap_setup(V, F, b, args.iterations)
    U = arap_solve(data, bc, V)
    if not np.all(np.isfinite(U)):
        raise RuntimeError("ARAP produced non-finite positions")
    write_matrix(args.out, U)


def arap_float64(V, F, b, bc, iterations):
    """SPOKES ARAP in float64: E = sum_i sum_j w_ij |(u_i - u_j) - R_i (v_i - v_j)|^2 with w_ij
    igl.cotmatrix's off-diagonal entries; local step R_i = polar(S_i), S_i = sum_j w_ij e0_ij e_ij^T
    (reflections fixed by flipping the last singular vector); global step -L u = sum_j w_ij / 2
    (R_i + R_j)(v_i - v_j) on the free rows, constrained rows at bc."""
    import scipy.sparse as sp
    import scipy.sparse.linalg as spl

    L = sp.csr_matrix(igl.cotmatrix(V, F))
    n = V.shape[0]
    free = np.setdiff1d(np.arange(n), b)
    solve = spl.factorized(-L[free][:, free].tocsc())
    L_fb = L[free][:, b]
    coo = L.tocoo()
    off = coo.row != coo.col
    rows, cols, w = coo.row[off], coo.col[off], coo.data[off]
    rest_edges = V[cols] - V[rows]
    U = V.copy()
    U[b] = bc
    for _ in range(iterations):
        edges = U[cols] - U[rows]
        S = np.zeros((n, 3, 3))
        np.add.at(S, rows, w[:, None, None] * rest_edges[:, :, None] * edges[:, None, :])
        left, _, right_t = np.linalg.svd(S)
        flip = np.linalg.det(np.einsum("nij,njk->nki", left, right_t)) < 0
        left[flip, :, 2] *= -1
        R = np.einsum("nij,njk->nki", left, right_t)  # R_i = V U^T of S_i = U s V^T
        rhs = np.zeros((n, 3))
        np.add.at(rhs, rows, (w[:, None] / 2) * np.einsum("nij,nj->ni", R[rows] + R[cols], -rest_edges))
        for k in range(3):
            U[free, k] = solve(rhs[free, k] + L_fb @ bc[:, k])
        U[b] = bc
    return U


def cmd_arap_float64(args):
    V, F = read_mesh(args.mesh)
    b, bc = read_vector_constraints(args.constraints, V.shape[0])
    U = arap_float64(V, F, b, bc, args.iterations)
    if not np.all(np.isfinite(U)):
        raise RuntimeError("float64 ARAP produced non-finite positions")
    write_matrix(args.out, U)


def cmd_arap_timing(args):
    V, F = read_mesh(args.mesh)
    b, bc = read_vector_constraints(args.constraints, V.shape[0])
    repeats = 3

    pre = []
    data = None
    for _ in range(repeats):
        t0 = time.perf_counter()
        data = arap_setup(V, F, b, args.iterations)
        pre.append(time.perf_counter() - t0)

    solve = []
    for _ in range(repeats):
        U0 = V.copy()
        t0 = time.perf_counter()
        U = igl.arap_solve(bc, data, U0)
        solve.append(time.perf_counter() - t0)
    if not np.all(np.isfinite(U)):
        raise RuntimeError("ARAP produced non-finite positions")

    print(json.dumps({
        "mesh": os.path.basename(args.mesh),
        "vertices": int(V.shape[0]),
        "precompute_s": min(pre),
        "ms_per_iteration": 1000.0 * min(solve) / args.iterations,
        "iterations": args.iterations,
    }))


# ---------------------------------------------------------------------------------------------
# harmonic


def cmd_doublearea(args):
    V, F = read_mesh(args.mesh)
    write_matrix(args.out, igl.doublearea(V, F).reshape(-1))


def cmd_harmonic(args):
    V, F = read_mesh(args.mesh)
    b, bc = read_scalar_constraints(args.constraints, V.shape[0])
    W = igl.harmonic(V, F, b, bc, 1)
    W = np.asarray(W).reshape(V.shape[0], -1)[:, 0]
    if not np.all(np.isfinite(W)):
        raise RuntimeError("harmonic produced non-finite values")
    write_matrix(args.out, W)


# ---------------------------------------------------------------------------------------------
# eigs


def cmd_eigs(args):
    V, F = read_mesh(args.mesh)
    n = V.shape[0]
    if args.k >= n:
        raise UsageError(f"K={args.k} must be smaller than the vertex count {n}")
    L = igl.cotmatrix(V, F).tocsc()
    mass_type = {"voronoi": igl.MASSMATRIX_TYPE_VORONOI, "barycentric": igl.MASSMATRIX_TYPE_BARYCENTRIC}[args.mass]
    M = igl.massmatrix(V, F, mass_type).tocsc()
    A = (-L).tocsc()
    # Deterministic start vector so reruns give the same (sign of the) eigenvectors. Not the constant
    # vector: that is an eigenvector, and a Krylov method started from it breaks down at once.
    v0 = np.random.default_rng(12345).uniform(-1.0, 1.0, n)
    t0 = time.perf_counter()
    vals, vecs = spla.eigsh(A, k=args.k, M=M, sigma=-1e-8, which="LM", v0=v0)
    seconds = time.perf_counter() - t0
    order = np.argsort(vals)
    vals = vals[order]
    vecs = vecs[:, order]
    write_matrix(args.out, vals)
    write_matrix(args.out + ".vectors", vecs)
    print(json.dumps({"seconds": seconds}))


# ---------------------------------------------------------------------------------------------
# constraints (helper)


def cmd_constraints(args):
    V, _ = read_mesh(args.mesh)
    status = []
    with open(args.sel) as fh:
        for line in fh:
            s = line.strip()
            if s and not s.startswith("#"):
                status.append(int(s))
    if len(status) != V.shape[0]:
        raise UsageError(f"{args.sel}: {len(status)} entries for {V.shape[0]} vertices")
    with open(args.deform) as fh:
        nums = [float(x) for line in fh if not line.strip().startswith("#") for x in line.split()]
    if len(nums) != 16:
        raise UsageError(f"{args.deform}: expected a 4x4 matrix, got {len(nums)} numbers")
    T = np.array(nums).reshape(4, 4)
    with open(args.out, "w") as fh:
        for i, s in enumerate(status):
            if s == 0:
                p = V[i]
            elif s == 2:
                p = (T @ np.append(V[i], 1.0))[:3]
            elif s == 1:
                continue
            else:
                raise UsageError(f"{args.sel}: unknown status {s} for vertex {i}")
            fh.write("%d %.17g %.17g %.17g\n" % (i, p[0], p[1], p[2]))


# ---------------------------------------------------------------------------------------------


def build_parser():
    p = ArgumentParser(description="libigl/scipy reference results for deformbench.")
    sub = p.add_subparsers(dest="command", required=True, parser_class=ArgumentParser)

    s = sub.add_parser("operators", help="cotangent Laplacian and mass matrix diagonals")
    s.add_argument("mesh")
    s.add_argument("out_dir")
    s.set_defaults(func=cmd_operators)

    s = sub.add_parser("intrinsic_delaunay", help="igl.intrinsic_delaunay_cotmatrix")
    s.add_argument("mesh")
    s.add_argument("out_dir")
    s.set_defaults(func=cmd_intrinsic_delaunay)

    s = sub.add_parser("tufted", help="robust_laplacian.mesh_laplacian (tufted Laplacian), unmollified")
    s.add_argument("mesh")
    s.add_argument("out_dir")
    s.set_defaults(func=cmd_tufted)

    s = sub.add_parser("arap", help="libigl ARAP (SPOKES) deformation")
    s.add_argument("mesh")
    s.add_argument("constraints")
    s.add_argument("iterations", type=positive_int)
    s.add_argument("out")
    s.set_defaults(func=cmd_arap)

    s = sub.add_parser("arap_float64", help="the same SPOKES ARAP iteration in float64 numpy")
    s.add_argument("mesh")
    s.add_argument("constraints")
    s.add_argument("iterations", type=positive_int)
    s.add_argument("out")
    s.set_defaults(func=cmd_arap_float64)

    s = sub.add_parser("arap-timing", help="time libigl ARAP precomputation and iterations")
    s.add_argument("mesh")
    s.add_argument("constraints")
    s.add_argument("iterations", type=positive_int)
    s.set_defaults(func=cmd_arap_timing)

    s = sub.add_parser("doublearea", help="igl.doublearea: twice the face areas")
    s.add_argument("mesh")
    s.add_argument("out")
    s.set_defaults(func=cmd_doublearea)

    s = sub.add_parser("harmonic", help="igl.harmonic with k=1")
    s.add_argument("mesh")
    s.add_argument("constraints")
    s.add_argument("out")
    s.set_defaults(func=cmd_harmonic)

    s = sub.add_parser("eigs", help="smallest generalized eigenpairs of (-L, M)")
    s.add_argument("mesh")
    s.add_argument("k", type=positive_int)
    s.add_argument("out")
    s.add_argument("--mass", choices=["barycentric", "voronoi"], default="barycentric")
    s.set_defaults(func=cmd_eigs)

    s = sub.add_parser("constraints", help="ARAP constraints file from a .sel/.def pair")
    s.add_argument("mesh")
    s.add_argument("sel")
    s.add_argument("deform", metavar="def")
    s.add_argument("out")
    s.set_defaults(func=cmd_constraints)
    return p


def main(argv=None):
    args = build_parser().parse_args(argv)
    try:
        args.func(args)
    except (UsageError, RuntimeError, OSError, ValueError) as e:
        print(f"igl_reference.py {args.command}: error: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
