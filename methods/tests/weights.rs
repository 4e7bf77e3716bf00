//! The Laplacian weights (`methods::operators::LaplacianWeights`): the intrinsic Delaunay
//! triangulation's invariants, its agreement with the cotangent Laplacian on Delaunay meshes, the
//! clamped weights, ARAP's rest-shape fixed point for every choice, and an obtuse sliver band where
//! cotangent ARAP folds and the default does not.

mod support;
use support::{dense, entries};

use faer::sparse::SparseColMat;
use meshes::shapes::{generate, ShapeKind};
use meshes::vector::{cross, dot, norm, normalize_or_zero, sub};
use meshes::TriMesh;
use methods::operators::{
    clamped_cotan_laplacian, cotan_laplacian, laplacian, lumped_mass, IntrinsicTriangulation,
    LaplacianWeights, MassKind,
};
use methods::registry::create;
use methods::{HandleRegion, HandleSet, HandleTargets, NoObserver};

const ALL: [LaplacianWeights; 4] = [
    LaplacianWeights::Cotan,
    LaplacianWeights::Clamped,
    LaplacianWeights::IntrinsicDelaunay,
    LaplacianWeights::TuftedDelaunay,
];

fn name(w: LaplacianWeights) -> &'static str {
    match w {
        LaplacianWeights::Cotan => "cotan",
        LaplacianWeights::Clamped => "clamped",
        LaplacianWeights::IntrinsicDelaunay => "intrinsic_delaunay",
        LaplacianWeights::TuftedDelaunay => "tufted_delaunay",
    }
}

/// Smallest off-diagonal entry relative to the largest magnitude (project sign: off-diagonals are
/// the weights, so >= 0 means no negative weight), and the largest |row sum| relative to it.
fn min_offdiagonal_and_row_sum(l: &SparseColMat<usize, f64>) -> (f64, f64) {
    let e = entries(l);
    let scale = e.iter().fold(0.0f64, |m, x| m.max(x.2.abs()));
    let mut rows = vec![0.0; l.nrows()];
    let mut min_off = f64::INFINITY;
    for &(i, j, v) in &e {
        rows[i] += v;
        if i != j {
            min_off = min_off.min(v / scale);
        }
    }
    (min_off, rows.iter().fold(0.0f64, |m, r| m.max(r.abs())) / scale)
}

/// Flat `nx x ny` grid of unit squares in the z = 0 plane, each split along the same diagonal
/// (right isosceles triangles: every edge is Delaunay, the diagonals exactly cocircular).
fn grid(nx: usize, ny: usize) -> TriMesh {
    let idx = |i: usize, j: usize| (j * (nx + 1) + i) as u32;
    let positions = (0..=ny).flat_map(|j| (0..=nx).map(move |i| [i as f64, j as f64, 0.0])).collect();
    let mut triangles = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            triangles.push([idx(i, j), idx(i + 1, j), idx(i + 1, j + 1)]);
            triangles.push([idx(i, j), idx(i + 1, j + 1), idx(i, j + 1)]);
        }
    }
    TriMesh::new(positions, triangles).unwrap()
}

/// A strip `n` cells long along x and `2 rows + band` wide, with a band of sliver triangles along
/// its middle: row `A` at `y = 1`, row `B` shifted by half a cell at `y = 1 + delta`. The triangles
/// between them have an angle near `pi` at the vertex opposite each long row edge (the obtuse fan
/// of every band vertex), so those edges get large negative cotangent weights — the pattern decimated
/// real meshes have. Rows 0 (y = 0) and 3 (y = 2 + delta) are regular, aligned with A and B.
fn sliver_strip(n: usize, delta: f64) -> TriMesh {
    let mut positions = Vec::new();
    let rows: [(f64, f64, usize); 4] =
        [(0.0, 0.0, n + 1), (1.0, 0.0, n + 1), (1.0 + delta, 0.5, n), (2.0 + delta, 0.5, n)];
    let mut start = Vec::new();
    for &(y, shift, count) in &rows {
        start.push(positions.len() as u32);
        for i in 0..count {
            positions.push([i as f64 + shift, y, 0.0]);
        }
    }
    let v = |r: usize, i: usize| start[r] + i as u32;
    let mut triangles = Vec::new();
    for i in 0..n {
        // Row 0 -> A: squares.
        triangles.push([v(0, i), v(0, i + 1), v(1, i + 1)]);
        triangles.push([v(0, i), v(1, i + 1), v(1, i)]);
        // A -> B: the sliver band.
        triangles.push([v(1, i), v(1, i + 1), v(2, i)]);
        if i + 1 < n {
            triangles.push([v(1, i + 1), v(2, i + 1), v(2, i)]);
        }
        // B -> row 3: squares.
        if i + 1 < n {
            triangles.push([v(2, i), v(2, i + 1), v(3, i + 1)]);
            triangles.push([v(2, i), v(3, i + 1), v(3, i)]);
        }
    }
    TriMesh::new(positions, triangles).unwrap()
}

fn handles_by(
    mesh: &TriMesh,
    fixed: impl Fn([f64; 3]) -> bool,
    handle: impl Fn([f64; 3]) -> bool,
) -> HandleSet {
    let pick = |f: &dyn Fn([f64; 3]) -> bool| -> Vec<u32> {
        (0..mesh.n_vertices() as u32).filter(|&v| f(mesh.positions()[v as usize])).collect()
    };
    HandleSet::new(
        vec![
            HandleRegion { name: "fixed".into(), vertices: pick(&fixed) },
            HandleRegion { name: "handle".into(), vertices: pick(&handle) },
        ],
        mesh.n_vertices(),
    )
    .unwrap()
}

fn targets_by(mesh: &TriMesh, handles: &HandleSet, f: impl Fn([f64; 3]) -> [f64; 3]) -> HandleTargets {
    HandleTargets::new(handles, handles.constrained().map(|v| f(mesh.positions()[v as usize])).collect())
        .unwrap()
}

fn arap(
    weights: LaplacianWeights,
    mesh: &TriMesh,
    handles: &HandleSet,
    targets: &HandleTargets,
    iterations: usize,
) -> Vec<[f64; 3]> {
    let params: toml::Table =
        format!("weights = \"{}\"\nmax_iterations = {iterations}\ntolerance = 1e-9", name(weights))
            .parse()
            .unwrap();
    let mut m = create("arap", &params).unwrap();
    m.precompute(mesh).unwrap();
    m.bind_handles(handles).unwrap();
    m.solve(targets, &mut NoObserver).unwrap();
    m.positions()
}

/// Largest change (degrees) of the angle between the normals of the two faces of any interior edge:
/// above 90 degrees the surface has folded over that edge.
fn max_dihedral_change(mesh: &TriMesh, deformed: &[[f64; 3]]) -> f64 {
    let topology = meshes::Topology::new(mesh).unwrap();
    let normal = |p: &[[f64; 3]], f: usize| {
        let t = mesh.triangles()[f].map(|i| p[i as usize]);
        normalize_or_zero(cross(sub(t[1], t[0]), sub(t[2], t[0])))
    };
    topology
        .interior_edges()
        .map(|e| {
            let [f0, f1] = topology.edge_faces()[e].map(|f| f as usize);
            let angle = |p: &[[f64; 3]]| dot(normal(p, f0), normal(p, f1)).clamp(-1.0, 1.0).acos();
            (angle(deformed) - angle(mesh.positions())).abs().to_degrees()
        })
        .fold(0.0, f64::max)
}

fn assert_nonnegative(label: &str, mesh: &TriMesh) {
    let t = IntrinsicTriangulation::delaunay(mesh.positions(), mesh.triangles()).unwrap();
    let l = t.cotan_laplacian();
    let (min_off, row_sum) = min_offdiagonal_and_row_sum(&l);
    let (cotan_min, _) = min_offdiagonal_and_row_sum(&cotan_laplacian(mesh.positions(), mesh.triangles()));
    println!(
        "{label}: {} flips; smallest weight / largest: cotan {cotan_min:.3e}, intrinsic {min_off:.3e}",
        t.flips()
    );
    assert!(min_off >= -1e-12, "{label}: intrinsic Delaunay weight {min_off:e} x largest is negative");
    assert!(row_sum <= 1e-12, "{label}: row sum {row_sum:e}");
    // Every interior edge is Delaunay (weights of boundary edges are one cotangent of a triangle
    // whose other angles may be obtuse; they are never flipped).
    for e in t.edges() {
        assert!(e.length > 0.0 && e.length.is_finite(), "{label}: edge {e:?}");
    }
    let area: f64 = meshes::geometry::face_areas(mesh.positions(), mesh.triangles()).iter().sum();
    for kind in [MassKind::Barycentric, MassKind::Voronoi] {
        let total: f64 = t.lumped_mass(kind).iter().sum();
        assert!(
            (total - area).abs() <= 1e-10 * area,
            "{label}: {kind:?} intrinsic mass {total} vs area {area}"
        );
    }
}

#[test]
fn intrinsic_delaunay_equals_cotan_on_a_delaunay_mesh() {
    let mesh = grid(7, 4);
    let t = IntrinsicTriangulation::delaunay(mesh.positions(), mesh.triangles()).unwrap();
    assert_eq!(t.flips(), 0, "a grid of right triangles is Delaunay");
    let (a, b) = (dense(&t.cotan_laplacian()), dense(&cotan_laplacian(mesh.positions(), mesh.triangles())));
    for (ra, rb) in a.iter().zip(&b) {
        for (x, y) in ra.iter().zip(rb) {
            assert!((x - y).abs() <= 1e-14, "intrinsic {x} vs cotan {y}");
        }
    }
    for kind in [MassKind::Barycentric, MassKind::Voronoi] {
        let (x, y) = (t.lumped_mass(kind), lumped_mass(mesh.positions(), mesh.triangles(), kind));
        assert!(x.iter().zip(&y).all(|(x, y)| (x - y).abs() <= 1e-14), "{kind:?} mass");
    }
    // So the three weights give the same operator (clamping removes nothing).
    let c = dense(&clamped_cotan_laplacian(mesh.positions(), mesh.triangles()));
    assert!(c.iter().flatten().zip(b.iter().flatten()).all(|(x, y)| (x - y).abs() <= 1e-14));
}

#[test]
fn sliver_band_flips_to_nonnegative_weights_with_the_flat_metric() {
    let mesh = sliver_strip(12, 0.05);
    let cotan = cotan_laplacian(mesh.positions(), mesh.triangles());
    assert!(min_offdiagonal_and_row_sum(&cotan).0 < -0.05, "the band has negative cotangent weights");
    let t = IntrinsicTriangulation::delaunay(mesh.positions(), mesh.triangles()).unwrap();
    assert!(t.flips() > 0);
    assert_nonnegative("sliver strip", &mesh);
    // The strip is flat, so intrinsic edges are straight segments: their lengths are the distances
    // of their endpoints, and the Laplacian keeps linear precision at interior vertices.
    let p = mesh.positions();
    for e in t.edges() {
        let d = norm(sub(p[e.a as usize], p[e.b as usize]));
        assert!((e.length - d).abs() <= 1e-12 * d, "edge {e:?}: length {} vs distance {d}", e.length);
    }
    let boundary: std::collections::BTreeSet<u32> =
        meshes::Topology::new(&mesh).unwrap().boundary_loops().iter().flatten().copied().collect();
    let l = dense(&t.cotan_laplacian());
    for i in (0..mesh.n_vertices()).filter(|i| !boundary.contains(&(*i as u32))) {
        for a in 0..2 {
            let lx: f64 = (0..mesh.n_vertices()).map(|j| l[i][j] * p[j][a]).sum();
            assert!(lx.abs() <= 1e-12, "vertex {i}: (L x)_{a} = {lx:e}");
        }
    }
    // Clamped: the mesh's pattern, no negative weight, rows sum to 0.
    let (min_off, row_sum) = min_offdiagonal_and_row_sum(&clamped_cotan_laplacian(p, mesh.triangles()));
    assert!(min_off >= 0.0 && row_sum <= 1e-14);
}

#[test]
fn intrinsic_delaunay_is_deterministic_and_symmetric() {
    let mesh = generate(ShapeKind::Cactus, 3000).unwrap().mesh;
    let a = IntrinsicTriangulation::delaunay(mesh.positions(), mesh.triangles()).unwrap();
    let b = IntrinsicTriangulation::delaunay(mesh.positions(), mesh.triangles()).unwrap();
    assert_eq!(a.triangles(), b.triangles());
    assert_eq!(entries(&a.cotan_laplacian()), entries(&b.cotan_laplacian()));
    let l = a.cotan_laplacian();
    let d = dense(&l);
    for (i, j, v) in entries(&l) {
        assert_eq!(v.to_bits(), d[j][i].to_bits().min(u64::MAX), "L is not exactly symmetric at ({i}, {j})");
    }
}

#[test]
fn intrinsic_delaunay_weights_are_nonnegative_on_the_procedural_shapes() {
    for kind in ShapeKind::ALL {
        let shape = generate(kind, 3000).unwrap();
        assert_nonnegative(&format!("{kind:?}"), &shape.mesh);
    }
}

/// The survey meshes (`$DEFORM_SURVEY_DIR`) and the real meshes (`$DEFORM_REAL_MESHES_DIR`), when set.
#[test]
fn intrinsic_delaunay_weights_are_nonnegative_on_the_survey_and_real_meshes() {
    let mut files = Vec::new();
    if let Some(dir) = std::env::var_os("DEFORM_SURVEY_DIR").map(std::path::PathBuf::from) {
        files.extend(["cylinder", "bar", "cactus", "plane"].map(|n| dir.join(format!("{n}.off"))));
    }
    if let Some(dir) = std::env::var_os("DEFORM_REAL_MESHES_DIR").map(std::path::PathBuf::from) {
        files.extend(["decimated-knight.off", "bunny.off", "decimated-max.obj"].map(|n| dir.join(n)));
    }
    if files.is_empty() {
        eprintln!("SKIPPED: neither DEFORM_SURVEY_DIR nor DEFORM_REAL_MESHES_DIR is set");
    }
    for file in files {
        let mesh = meshes::io::read_mesh(&file).unwrap();
        assert_nonnegative(&file.display().to_string(), &mesh);
    }
}

#[test]
fn bad_meshes_are_errors_not_panics() {
    let degenerate = TriMesh::new(
        vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        vec![[0, 1, 2], [0, 1, 3]],
    );
    if let Ok(mesh) = degenerate {
        assert!(laplacian(LaplacianWeights::IntrinsicDelaunay, mesh.positions(), mesh.triangles()).is_err());
    }
    let p = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 1.0]];
    let fan = [[0, 1, 2], [0, 1, 3], [0, 1, 4]];
    assert!(IntrinsicTriangulation::delaunay(&p, &fan).is_err(), "an edge with three faces");
    assert!(IntrinsicTriangulation::delaunay(&p, &[[0, 1, 2], [0, 1, 3]]).is_err(), "misoriented");
    assert!(IntrinsicTriangulation::delaunay(&p, &[[0, 1, 7]]).is_err(), "vertex out of range");
}

#[test]
fn weights_parse_from_the_method_tables() {
    for w in ALL {
        for method in ["laplacian", "arap", "isolines", "isolines_t1", "spectral_mhb", "scale_aware"] {
            let params: toml::Table = format!("weights = \"{}\"", name(w)).parse().unwrap();
            assert!(create(method, &params).is_ok(), "{method}: weights = {}", name(w));
        }
    }
    let params: toml::Table = "weights = \"delaunay\"".parse().unwrap();
    assert!(matches!(create("arap", &params), Err(methods::MethodError::Parameters { .. })));
}

#[test]
fn arap_rest_shape_is_a_fixed_point_for_every_weight() {
    let bar = generate(ShapeKind::Bar, 1500).unwrap();
    let status = |s| meshes::edit::vertices_with_status(&bar.selection, s);
    let bar_handles = HandleSet::new(
        vec![
            HandleRegion { name: "fixed".into(), vertices: status(meshes::VertexStatus::Fixed) },
            HandleRegion { name: "handle".into(), vertices: status(meshes::VertexStatus::Handle) },
        ],
        bar.mesh.n_vertices(),
    )
    .unwrap();
    let bar = bar.mesh;
    let strip = sliver_strip(20, 0.05);
    for (label, mesh, weights) in [
        ("bar", &bar, &ALL[..]),
        (
            "sliver strip",
            &strip,
            &[
                LaplacianWeights::Clamped,
                LaplacianWeights::IntrinsicDelaunay,
                LaplacianWeights::TuftedDelaunay,
            ][..],
        ),
    ] {
        let (lo, hi) = (mesh.bbox().0[0], mesh.bbox().1[0]);
        let handles = if label == "bar" {
            bar_handles.clone()
        } else {
            handles_by(mesh, |p| p[0] < lo + 1.6, |p| p[0] > hi - 1.6)
        };
        let targets = targets_by(mesh, &handles, |p| p);
        for &w in weights {
            let x = arap(w, mesh, &handles, &targets, 20);
            let d = methods::method::max_displacement(&x, mesh.positions()) / mesh.bbox_diagonal();
            println!("{label} {}: rest shape moved by {d:.2e} x diagonal", name(w));
            assert!(d < 1e-12, "{label} {}: the rest shape moved by {d:e} x diagonal", name(w));
        }
    }
}

#[test]
fn cotan_arap_folds_the_sliver_band_and_the_delaunay_weights_do_not() {
    let mesh = sliver_strip(20, 0.05);
    let handles = handles_by(&mesh, |p| p[0] < 1.6, |p| p[0] > 18.4);
    // Push the handle end 6 cells towards the fixed end, in the plane; and twist it by 2 radians
    // about the strip's axis.
    let compress = targets_by(&mesh, &handles, |p| [p[0] - 6.0, p[1], p[2]]);
    let twist = targets_by(&mesh, &handles, |p| {
        let (s, c) = 2.0f64.sin_cos();
        let y = p[1] - 1.0;
        [p[0] - 2.0, 1.0 + c * y, s * y]
    });
    for (label, targets) in [("compress", &compress), ("twist", &twist)] {
        let fold = |w| max_dihedral_change(&mesh, &arap(w, &mesh, &handles, targets, 500));
        let (cotan, intrinsic) = (fold(LaplacianWeights::Cotan), fold(LaplacianWeights::IntrinsicDelaunay));
        let tufted = fold(LaplacianWeights::TuftedDelaunay);
        println!(
            "{label}: largest dihedral change cotan {cotan:.1} deg, intrinsic_delaunay {intrinsic:.1} deg, \
             tufted_delaunay {tufted:.1} deg"
        );
        assert!(tufted < 30.0, "{label}: tufted Delaunay ARAP changed a dihedral angle by {tufted} deg");
        assert!(cotan > 90.0, "{label}: expected cotan ARAP to fold the sliver band, got {cotan} deg");
        assert!(
            intrinsic < 30.0,
            "{label}: intrinsic Delaunay ARAP changed a dihedral angle by {intrinsic} deg"
        );
    }
}
