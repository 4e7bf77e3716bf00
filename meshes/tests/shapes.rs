//! The procedural survey look-alikes (`meshes::shapes`) against facts measured on the survey's
//! originals, and, when the survey data is present (`../shared/deformation-survey` or
//! `DEFORM_SURVEY_DIR`), against the original `.off`/`.sel`/`.def` files themselves.

use std::path::{Path, PathBuf};
use std::time::Instant;

use meshes::geometry::corner_angles;
use meshes::shapes::{default_vertex_count, generate, ShapeKind, TestShape};
use meshes::{Topology, TriMesh, VertexStatus};

/// What is known of an original without reading it (measured once from the survey's files).
struct Original {
    /// Axis-aligned bounding box `[min, max]`.
    bbox: [[f64; 3]; 2],
    /// Euler characteristic `V - E + F`: 2 closed, 1 one boundary loop.
    euler: i64,
    /// Signed volume `sum (a . (b x c)) / 6` about the origin (for the open shapes both the original
    /// and the look-alike miss the same cap, so it is comparable too).
    volume: f64,
    /// Coordinate axis along which the regions are laid out.
    axis: usize,
    /// Largest coordinate of the original's fixed vertices, smallest of its handle vertices.
    fixed_max: f64,
    handle_min: f64,
    /// Spacing of the original's sampling across the region boundaries: a look-alike's boundary
    /// may fall anywhere within it.
    gap: f64,
    /// Smallest corner angle (degrees) accepted in the look-alike.
    min_angle: f64,
}

fn original(kind: ShapeKind) -> Original {
    match kind {
        ShapeKind::Bar => Original {
            bbox: [[-6.0, -6.0, 25.390625], [6.0, 6.0, 100.00666]],
            euler: 1,
            volume: 11961.767,
            axis: 2,
            fixed_max: 29.902,
            handle_min: 95.9375,
            gap: 0.41,
            min_angle: 40.0,
        },
        ShapeKind::Cylinder => Original {
            bbox: [[-1.0, -1.0, 0.0], [1.0, 1.0, 12.0]],
            euler: 2,
            volume: 37.5443,
            axis: 2,
            fixed_max: 0.504202,
            handle_min: 11.4958,
            gap: 0.1008,
            min_angle: 35.0,
        },
        ShapeKind::Cactus => Original {
            bbox: [[0.43942, 0.25380, 0.06887], [0.56068, 0.74597, 0.89169]],
            euler: 2,
            volume: 0.0112903,
            axis: 2,
            fixed_max: 0.15323,
            handle_min: 0.79321,
            gap: 0.0067,
            min_angle: 17.0,
        },
        ShapeKind::BumpyPlane => Original {
            bbox: [[0.0, 0.0, 0.0], [100.0, 100.0, 10.0]],
            euler: 1,
            volume: 6504.641,
            axis: 0,
            fixed_max: 4.0,
            handle_min: 96.5,
            gap: 0.5,
            min_angle: 17.0,
        },
    }
}

/// The cactus's handle is the trunk's top only: the arm tips reach as high but are free.
fn in_cactus_trunk(p: &[f64; 3]) -> bool {
    (0.435..=0.565).contains(&p[0]) && (0.45..=0.59).contains(&p[1])
}

fn bbox(positions: &[[f64; 3]]) -> [[f64; 3]; 2] {
    let mut b = [[f64::INFINITY; 3], [f64::NEG_INFINITY; 3]];
    for p in positions {
        for k in 0..3 {
            b[0][k] = b[0][k].min(p[k]);
            b[1][k] = b[1][k].max(p[k]);
        }
    }
    b
}

fn diagonal(b: &[[f64; 3]; 2]) -> f64 {
    (0..3).map(|k| (b[1][k] - b[0][k]).powi(2)).sum::<f64>().sqrt()
}

fn signed_volume(mesh: &TriMesh) -> f64 {
    let p = mesh.positions();
    mesh.triangles()
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| p[i as usize]);
            let bxc = [b[1] * c[2] - b[2] * c[1], b[2] * c[0] - b[0] * c[2], b[0] * c[1] - b[1] * c[0]];
            (a[0] * bxc[0] + a[1] * bxc[1] + a[2] * bxc[2]) / 6.0
        })
        .sum()
}

fn generated(kind: ShapeKind, target: usize) -> TestShape {
    match generate(kind, target) {
        Ok(shape) => shape,
        Err(e) => panic!("{kind} at {target} vertices: {e}"),
    }
}

/// Sizes every shape is checked at: the original's, and about 1K and 50K vertices.
fn targets(kind: ShapeKind) -> [usize; 3] {
    [default_vertex_count(kind), 1000, 50_000]
}

fn survey_dir() -> Option<PathBuf> {
    let dir = match std::env::var_os("DEFORM_SURVEY_DIR") {
        Some(dir) => PathBuf::from(dir),
        None => Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/deformation-survey"),
    };
    dir.join("bar.off").is_file().then_some(dir)
}

/// Numbers of a survey text file, without `#` comment lines (and without the `OFF` keyword).
fn numbers(path: &Path) -> Vec<f64> {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    text.lines()
        .filter(|l| !l.trim_start().starts_with('#'))
        .flat_map(|l| l.split_whitespace())
        .filter(|w| *w != "OFF")
        .map(|w| w.parse::<f64>().unwrap_or_else(|e| panic!("{}: '{w}': {e}", path.display())))
        .collect()
}

/// Positions of an OFF file (`#V x 3`).
fn off_positions(path: &Path) -> Vec<[f64; 3]> {
    let n = numbers(path);
    let n_vertices = n[0] as usize;
    n[3..3 + 3 * n_vertices].chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect()
}

/// Named `shapes` so that `cargo test -p meshes shapes` selects these with the unit tests.
mod shapes {
    use super::*;

    #[test]
    fn vertex_counts_follow_the_target() {
        for kind in ShapeKind::ALL {
            for target in [100, 250, 1000, 3000, default_vertex_count(kind), 50_000, 200_000] {
                let shape = generated(kind, target);
                let n = shape.mesh.n_vertices();
                assert!(
                    n.abs_diff(target) as f64 <= 0.15 * target as f64,
                    "{kind}: {n} vertices for {target}"
                );
                assert_eq!(shape.selection.len(), n, "{kind}: one role per vertex");
                assert!(shape.label.contains(&target.to_string()) && shape.label.contains(&n.to_string()));
            }
        }
    }

    #[test]
    fn topology_matches_the_originals() {
        for kind in ShapeKind::ALL {
            let orig = original(kind);
            for target in targets(kind) {
                let shape = generated(kind, target);
                let mesh = &shape.mesh;
                let topology = Topology::new(mesh).unwrap_or_else(|e| panic!("{kind} at {target}: {e}"));
                let euler = mesh.n_vertices() as i64 - topology.edges().len() as i64 + mesh.n_faces() as i64;
                assert_eq!(euler, orig.euler, "{kind} at {target}: Euler characteristic");
                assert_eq!(topology.is_closed(), orig.euler == 2, "{kind} at {target}");
                assert!(topology.boundary_loops().len() <= 1, "{kind} at {target}");
                let used = {
                    let mut used = vec![false; mesh.n_vertices()];
                    mesh.triangles().iter().flatten().for_each(|&v| used[v as usize] = true);
                    used
                };
                assert!(used.iter().all(|&u| u), "{kind} at {target}: unreferenced vertices");
            }
        }
    }

    #[test]
    fn open_boundaries_are_where_the_originals_are() {
        for (kind, on_rim) in [
            (ShapeKind::Bar, (|p: &[f64; 3]| (p[2] - 25.390625).abs() < 1e-9) as fn(&[f64; 3]) -> bool),
            (ShapeKind::BumpyPlane, |p: &[f64; 3]| {
                p[2] == 0.0 && [p[0], p[1]].iter().any(|&c| c.abs() < 1e-9 || (c - 100.0).abs() < 1e-9)
            }),
        ] {
            for target in targets(kind) {
                let shape = generated(kind, target);
                let topology = Topology::new(&shape.mesh).unwrap_or_else(|e| panic!("{kind}: {e}"));
                let rim = &topology.boundary_loops()[0];
                let positions = shape.mesh.positions();
                assert!(rim.iter().all(|&v| on_rim(&positions[v as usize])), "{kind} at {target}: boundary");
                let n_on_rim = positions.iter().filter(|p| on_rim(p)).count();
                assert_eq!(rim.len(), n_on_rim, "{kind} at {target}: every rim vertex is on the boundary");
            }
        }
    }

    #[test]
    fn faces_point_outward() {
        for kind in ShapeKind::ALL {
            for target in targets(kind) {
                let mesh = generated(kind, target).mesh;
                match kind {
                    // Open at z = 25.39: the volume about a point of that plane is the enclosed one.
                    ShapeKind::Bar => {
                        let shifted: Vec<[f64; 3]> =
                            mesh.positions().iter().map(|p| [p[0], p[1], p[2] - 25.390625]).collect();
                        let shifted = mesh.with_positions(shifted).expect("same size");
                        assert!(signed_volume(&shifted) > 0.0, "{kind} at {target}");
                    }
                    ShapeKind::BumpyPlane => {
                        let normals = meshes::geometry::face_normals(mesh.positions(), mesh.triangles());
                        assert!(normals.iter().all(|n| n[2] > 0.0), "{kind} at {target}: faces point up");
                    }
                    _ => assert!(signed_volume(&mesh) > 0.0, "{kind} at {target}"),
                }
            }
        }
    }

    #[test]
    fn triangles_are_well_shaped() {
        for kind in ShapeKind::ALL {
            let orig = original(kind);
            for target in targets(kind) {
                let mesh = generated(kind, target).mesh;
                mesh.check_nondegenerate().unwrap_or_else(|e| panic!("{kind} at {target}: {e}"));
                let min_angle = corner_angles(mesh.positions(), mesh.triangles())
                    .iter()
                    .flatten()
                    .fold(f64::INFINITY, |m, &a| m.min(a.to_degrees()));
                assert!(
                    min_angle > orig.min_angle,
                    "{kind} at {target}: smallest angle {min_angle:.1} degrees"
                );
            }
        }
    }

    #[test]
    fn bounding_boxes_match_the_originals() {
        for kind in ShapeKind::ALL {
            let orig = original(kind);
            let tolerance = 0.01 * diagonal(&orig.bbox);
            for target in targets(kind) {
                let b = bbox(generated(kind, target).mesh.positions());
                for (side, k) in (0..2).flat_map(|s| (0..3).map(move |k| (s, k))) {
                    let (got, want) = (b[side][k], orig.bbox[side][k]);
                    assert!(
                        (got - want).abs() < tolerance,
                        "{kind} at {target}: bbox[{side}][{k}] {got} vs {want}"
                    );
                }
            }
        }
    }

    #[test]
    fn volumes_match_the_originals() {
        for kind in ShapeKind::ALL {
            let orig = original(kind);
            let volume = signed_volume(&generated(kind, default_vertex_count(kind)).mesh);
            let rel = volume / orig.volume - 1.0;
            assert!(rel.abs() < 0.02, "{kind}: volume {volume} vs the original's {}", orig.volume);
        }
    }

    #[test]
    fn regions_lie_where_the_originals_are() {
        for kind in ShapeKind::ALL {
            let orig = original(kind);
            for target in targets(kind) {
                let shape = generated(kind, target);
                let mut counts = [0usize; 3];
                for (p, &status) in shape.mesh.positions().iter().zip(&shape.selection) {
                    counts[status.code() as usize] += 1;
                    let c = p[orig.axis];
                    let handle_here =
                        c >= orig.handle_min + orig.gap && (kind != ShapeKind::Cactus || in_cactus_trunk(p));
                    let (fixed_ok, handle_ok) =
                        (c <= orig.fixed_max + orig.gap, c >= orig.handle_min - orig.gap);
                    match status {
                        VertexStatus::Fixed => assert!(fixed_ok, "{kind} at {target}: fixed vertex at {p:?}"),
                        VertexStatus::Handle => {
                            assert!(handle_ok, "{kind} at {target}: handle vertex at {p:?}");
                            if kind == ShapeKind::Cactus {
                                assert!(
                                    in_cactus_trunk(p),
                                    "{kind} at {target}: handle vertex on an arm {p:?}"
                                );
                            }
                        }
                        VertexStatus::Free => {
                            assert!(
                                c > orig.fixed_max - orig.gap,
                                "{kind} at {target}: {p:?} should be fixed"
                            );
                            assert!(!handle_here, "{kind} at {target}: {p:?} should be the handle");
                        }
                    }
                }
                assert!(counts.iter().all(|&c| c > 0), "{kind} at {target}: region sizes {counts:?}");
            }
        }
    }

    // The expected values are computed from the .def files' six-digit numbers.
    #[allow(clippy::approx_constant)]
    #[test]
    fn transforms_are_the_surveys() {
        let cases: [(ShapeKind, [f64; 3], [f64; 3]); 4] = [
            // 135 degrees about z.
            (ShapeKind::Bar, [1.0, 0.0, 50.0], [-0.707107, 0.707107, 50.0]),
            // The cylinder's top centre goes to (-5.196, 0, 3): bent over by 120 degrees about y.
            (ShapeKind::Cylinder, [0.0, 0.0, 12.0], [5.196152 - 0.866025 * 12.0, 0.0, 9.0 - 6.0]),
            (ShapeKind::Cactus, [0.0, 0.0, 0.0], [-0.019322, -0.134331, 0.821073]),
            (ShapeKind::BumpyPlane, [100.0, 50.0, 0.0], [67.700044, 50.0, 56.703263]),
        ];
        for (kind, p, want) in cases {
            let got = generated(kind, 1000).transform.apply(p);
            for k in 0..3 {
                assert!((got[k] - want[k]).abs() < 1e-9, "{kind}: {p:?} -> {got:?}, expected {want:?}");
            }
        }
    }

    #[test]
    fn generation_is_deterministic() {
        for kind in ShapeKind::ALL {
            let (a, b) = (generated(kind, 2000), generated(kind, 2000));
            assert_eq!(a.mesh, b.mesh, "{kind}");
            assert_eq!(a.selection, b.selection, "{kind}");
        }
    }

    #[test]
    fn targets_out_of_range_are_errors() {
        for kind in ShapeKind::ALL {
            for target in [0, 10, 99, 20_000_001, usize::MAX] {
                assert!(generate(kind, target).is_err(), "{kind} at {target}");
            }
        }
    }

    /// A million vertices are generated quickly (the bound is loose: machines are shared) and stay valid.
    #[test]
    fn million_vertex_shapes() {
        for kind in ShapeKind::ALL {
            let start = Instant::now();
            let shape = generated(kind, 1_000_000);
            let elapsed = start.elapsed();
            assert!(elapsed.as_secs_f64() < 5.0, "{kind}: {elapsed:?} for a million vertices");
            let n = shape.mesh.n_vertices();
            assert!(n.abs_diff(1_000_000) <= 150_000, "{kind}: {n} vertices");
            let topology = Topology::new(&shape.mesh).unwrap_or_else(|e| panic!("{kind}: {e}"));
            assert_eq!(topology.is_closed(), original(kind).euler == 2, "{kind}");
        }
    }

    #[test]
    fn look_alikes_match_the_original_files() {
        let Some(dir) = survey_dir() else {
            eprintln!("survey data not found (set DEFORM_SURVEY_DIR): skipped");
            return;
        };
        for kind in ShapeKind::ALL {
            let name = kind.name();
            let positions = off_positions(&dir.join(format!("{name}.off")));
            let codes = numbers(&dir.join(format!("{name}.sel")));
            let rows = numbers(&dir.join(format!("{name}.def")));
            assert_eq!(positions.len(), default_vertex_count(kind), "{name}: vertex count");
            assert_eq!(codes.len(), positions.len(), "{name}: one role per vertex");

            let shape = generated(kind, positions.len());
            let orig_bbox = bbox(&positions);
            let tolerance = 0.01 * diagonal(&orig_bbox);
            let close = |a: &[[f64; 3]; 2], b: &[[f64; 3]; 2], tol: f64| {
                (0..2).all(|s| (0..3).all(|k| (a[s][k] - b[s][k]).abs() < tol))
            };
            let ours = bbox(shape.mesh.positions());
            assert!(close(&ours, &orig_bbox, tolerance), "{name}: bbox {ours:?} vs {orig_bbox:?}");

            // Each region's bounding box, to within two of the original's sampling steps across it.
            let region_tolerance = tolerance.max(2.0 * original(kind).gap);
            for status in [VertexStatus::Fixed, VertexStatus::Free, VertexStatus::Handle] {
                let theirs: Vec<[f64; 3]> = positions
                    .iter()
                    .zip(&codes)
                    .filter(|(_, &c)| c == f64::from(status.code()))
                    .map(|(p, _)| *p)
                    .collect();
                let mine: Vec<[f64; 3]> = shape
                    .mesh
                    .positions()
                    .iter()
                    .zip(&shape.selection)
                    .filter(|(_, &s)| s == status)
                    .map(|(p, _)| *p)
                    .collect();
                let (a, b) = (bbox(&mine), bbox(&theirs));
                assert!(close(&a, &b, region_tolerance), "{name} {status:?}: region bbox {a:?} vs {b:?}");
            }

            let transform = shape.transform.rows();
            for (k, want) in rows.iter().enumerate() {
                let got = transform[k / 4][k % 4];
                assert!(
                    (got - want).abs() < 1e-9,
                    "{name}: transform entry {k} is {got}, the .def says {want}"
                );
            }
        }
    }
}
