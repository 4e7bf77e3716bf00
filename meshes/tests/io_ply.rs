//! PLY: the three encodings, property types and names, polygon triangulation, bad input, and the
//! same mesh through OFF, PLY and GLB.

use std::path::Path;

use meshes::io::{
    parse_ply, read_gltf, read_mesh, read_off, read_ply, write_glb, write_mesh, write_off, write_ply,
};
use meshes::shapes::{generate, ShapeKind};
use meshes::{MeshError, TriMesh};

fn assert_bitwise_equal(a: &TriMesh, b: &TriMesh) {
    assert_eq!(a.triangles(), b.triangles());
    assert_eq!(a.n_vertices(), b.n_vertices());
    for (v, (p, q)) in a.positions().iter().zip(b.positions()).enumerate() {
        assert_eq!(p.map(f64::to_bits), q.map(f64::to_bits), "vertex {v}: {p:?} != {q:?}");
    }
}

/// Awkward coordinates (long decimals, tiny and huge magnitudes, negative zero, subnormal) and an
/// isolated vertex that must survive.
fn awkward_mesh() -> TriMesh {
    let positions = vec![
        [0.0, 0.0, 1.0 / 3.0],
        [0.1, -0.0, 2.0 / 3.0],
        [2.0 + f64::EPSILON * 2.0, 1e-9, 0.2],
        [0.0, 1.0, -7.5e-12],
        [1.0, 1.0, 123456.789],
        [2.0, 1.0, -1.0 / 7.0],
        [3.0e17, 5e-324, 1.0],
    ];
    TriMesh::new(positions, vec![[0, 1, 4], [0, 4, 3], [1, 2, 5], [1, 5, 4]]).unwrap()
}

mod fixture;
use fixture::file;

/// The error is `InFile` for `path` and its message names the file and every needle; returns the
/// inner error.
fn in_file<T: std::fmt::Debug>(result: Result<T, MeshError>, path: &Path, needles: &[&str]) -> MeshError {
    let err = result.expect_err("bad input was accepted");
    let message = err.to_string();
    assert!(
        message.starts_with(&path.display().to_string()),
        "message does not start with the path: {message}"
    );
    for needle in needles {
        assert!(message.contains(needle), "message lacks '{needle}': {message}");
    }
    match err {
        MeshError::InFile { path: p, error } => {
            assert_eq!(p, path);
            *error
        }
        other => panic!("error is not wrapped with the file: {other:?}"),
    }
}

#[test]
fn binary_ply_round_trip_is_exact() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = awkward_mesh();
    let path = dir.path().join("m.ply");
    write_ply(&path, &mesh).unwrap();
    assert_bitwise_equal(&read_ply(&path).unwrap(), &mesh);
    let bytes = std::fs::read(&path).unwrap();
    assert!(bytes.starts_with(b"ply\nformat binary_little_endian 1.0\n"));
    // and through the extension dispatch, upper case too
    let path = dir.path().join("n.PLY");
    write_mesh(&path, &mesh).unwrap();
    assert_bitwise_equal(&read_mesh(&path).unwrap(), &mesh);
}

#[test]
fn ascii_ply_with_quads_int_coordinates_extra_properties_and_elements() {
    let text = "ply\nformat ascii 1.0\ncomment a unit cube missing its bottom, as quads\n\
                element vertex 8\nproperty int x\nproperty short y\nproperty float z\n\
                property uchar red\nproperty float nx\n\
                element face 5\nproperty uchar flags\nproperty list uchar int vertex_indices\n\
                element edge 1\nproperty int vertex1\nproperty int vertex2\nend_header\n\
                0 0 0 255 0.5\n1 0 0 255 0.5\n1 1 0 255 0.5\n0 1 0 255 0.5\n\
                0 0 1 255 0.5\n1 0 1 255 0.5\n1 1 1 255 0.5\n0 1 1 255 0.25\n\
                7 4 4 5 6 7\n7 4 0 1 5 4\n7 4 1 2 6 5\n7 4 2 3 7 6\n7 4 3 0 4 7\n0 1\n";
    let mesh = parse_ply(text.as_bytes()).unwrap();
    assert_eq!(mesh.n_vertices(), 8);
    assert_eq!(mesh.positions()[6], [1.0, 1.0, 1.0]);
    assert_eq!(mesh.n_faces(), 10);
    assert_eq!(&mesh.triangles()[..4], &[[4, 5, 6], [4, 6, 7], [0, 1, 5], [0, 5, 4]]);
    // the triangulated quads form a consistently oriented manifold (an open box)
    let topology = meshes::Topology::new(&mesh).unwrap();
    assert_eq!(topology.boundary_loops().len(), 1);
}

#[test]
fn ply_face_list_named_vertex_index_with_unsigned_types() {
    let text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty double x\nproperty double y\n\
                property double z\nelement face 1\nproperty list ushort uint vertex_index\nend_header\n\
                0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    assert_eq!(parse_ply(text.as_bytes()).unwrap().triangles(), &[[0, 1, 2]]);
}

/// A binary big endian file with `float` positions, `uchar`-counted `int` lists and a pentagon.
#[test]
fn big_endian_binary_ply_with_float_positions_and_a_pentagon() {
    let positions: [[f32; 3]; 5] =
        [[0.0, 0.0, 0.1], [1.0, 0.0, 0.2], [1.5, 1.0, 0.3], [0.5, 1.5, 0.4], [-0.5, 1.0, 0.5]];
    let mut bytes = b"ply\nformat binary_big_endian 1.0\nelement vertex 5\nproperty float x\n\
                      property float y\nproperty float z\nelement face 1\n\
                      property list uchar int vertex_indices\nend_header\n"
        .to_vec();
    for p in positions {
        for x in p {
            bytes.extend_from_slice(&x.to_be_bytes());
        }
    }
    bytes.push(5);
    for i in [0i32, 1, 2, 3, 4] {
        bytes.extend_from_slice(&i.to_be_bytes());
    }
    let mesh = parse_ply(&bytes[..]).unwrap();
    let widened: Vec<[f64; 3]> = positions.iter().map(|p| p.map(f64::from)).collect();
    assert_eq!(mesh.positions(), &widened[..]);
    assert_eq!(mesh.triangles(), &[[0, 1, 2], [0, 2, 3], [0, 3, 4]]);
}

const TRI_HEADER: &str = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                          property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n";

#[test]
fn ply_two_corner_face_is_an_error_naming_the_face() {
    let c = file("segment.ply", format!("{TRI_HEADER}0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n2 0 1\n"));
    let e = in_file(read_ply(&c.path), &c.path, &["segment.ply", "face 1", "2 corners"]);
    assert!(matches!(e, MeshError::Untriangulable { face: 1, corners: 2, .. }), "{e:?}");

    let c = file("pinched.ply", format!("{TRI_HEADER}0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n4 0 1 1 2\n"));
    let e = in_file(read_ply(&c.path), &c.path, &["face 1", "repeats vertex 1"]);
    assert!(matches!(e, MeshError::Untriangulable { face: 1, corners: 4, .. }), "{e:?}");
}

#[test]
fn ply_bad_indices_name_the_face() {
    let c = file("range.ply", format!("{TRI_HEADER}0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 2 1 3\n"));
    let e = in_file(read_ply(&c.path), &c.path, &["face 1", "index 3"]);
    assert!(matches!(e, MeshError::IndexOutOfRange { face: 1, index: 3, n_vertices: 3 }), "{e:?}");

    let c = file("negative.ply", format!("{TRI_HEADER}0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 2 -1 0\n"));
    let e = in_file(read_ply(&c.path), &c.path, &["face 1", "-1", "negative"]);
    assert!(matches!(e, MeshError::Format(_)), "{e:?}");
}

#[test]
fn binary_ply_nan_coordinate_names_the_vertex() {
    let dir = tempfile::tempdir().unwrap();
    let full = dir.path().join("full.ply");
    write_ply(&full, &awkward_mesh()).unwrap();
    let mut bytes = std::fs::read(&full).unwrap();
    let header_len = bytes.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
    let y_of_vertex_2 = header_len + (2 * 3 + 1) * 8;
    bytes[y_of_vertex_2..y_of_vertex_2 + 8].copy_from_slice(&f64::NAN.to_le_bytes());
    let c = file("nan.ply", &bytes);
    let e = in_file(read_ply(&c.path), &c.path, &["vertex 2", "NaN"]);
    assert!(matches!(e, MeshError::NonFiniteCoordinate { vertex: 2, axis: 1, .. }), "{e:?}");
}

#[test]
fn truncated_binary_ply_is_an_error_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let full = dir.path().join("full.ply");
    write_ply(&full, &awkward_mesh()).unwrap();
    let bytes = std::fs::read(&full).unwrap();
    let header_len = bytes.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
    // inside the faces, inside the vertices, and right after the header
    for (cut, needle) in [(bytes.len() - 5, "face"), (header_len + 100, "vertex"), (header_len, "vertex")] {
        let c = file("cut.ply", &bytes[..cut]);
        let e = in_file(read_ply(&c.path), &c.path, &["cut.ply", needle, "announced"]);
        assert!(matches!(e, MeshError::Truncated { .. }), "{e:?}");
    }
    // inside the header: after a complete line it is truncated, within a line that line is malformed
    let c = file("cut_header.ply", &bytes[..b"ply\nformat binary_little_endian 1.0\n".len()]);
    let e = in_file(read_ply(&c.path), &c.path, &["cut_header.ply", "header"]);
    assert!(matches!(e, MeshError::Truncated { .. }), "{e:?}");
    let c = file("cut_line.ply", &bytes[..30]);
    let e = in_file(read_ply(&c.path), &c.path, &["cut_line.ply", "line 2", "header"]);
    assert!(matches!(e, MeshError::Syntax { line: 2, .. }), "{e:?}");
    // and an ASCII file with fewer faces than announced
    let c = file("short.ply", format!("{TRI_HEADER}0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"));
    let e = in_file(read_ply(&c.path), &c.path, &["2 'face' elements", "found 1"]);
    assert!(matches!(e, MeshError::Truncated { .. }), "{e:?}");
}

#[test]
fn ply_without_x_y_z_or_faces_is_an_error() {
    let c = file(
        "noz.ply",
        "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n0 0\n",
    );
    let e = in_file(read_ply(&c.path), &c.path, &["noz.ply", "'vertex'", "no property 'z'"]);
    assert!(matches!(e, MeshError::Format(_)), "{e:?}");

    let c = file("nov.ply", "ply\nformat ascii 1.0\nelement point 1\nproperty float x\nend_header\n0\n");
    let e = in_file(read_ply(&c.path), &c.path, &["no 'vertex' element"]);
    assert!(matches!(e, MeshError::Format(_)), "{e:?}");

    let c = file(
        "listx.ply",
        "ply\nformat ascii 1.0\nelement vertex 1\nproperty list uchar float x\nproperty float y\n\
         property float z\nend_header\n1 0 0 0\n",
    );
    let e = in_file(read_ply(&c.path), &c.path, &["'x' is a list"]);
    assert!(matches!(e, MeshError::Format(_)), "{e:?}");

    let c = file(
        "floatidx.ply",
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
         element face 1\nproperty list uchar float vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
    );
    let e = in_file(read_ply(&c.path), &c.path, &["vertex_indices", "list of integers"]);
    assert!(matches!(e, MeshError::Format(_)), "{e:?}");

    let c = file(
        "nolist.ply",
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
         element face 1\nproperty list uchar int corners\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
    );
    let e = in_file(read_ply(&c.path), &c.path, &["'vertex_indices' or 'vertex_index'"]);
    assert!(matches!(e, MeshError::Format(_)), "{e:?}");

    let c = file(
        "points.ply",
        "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n\
         end_header\n0 0 0\n",
    );
    assert!(matches!(in_file(read_ply(&c.path), &c.path, &["faces"]), MeshError::Empty("faces")));
}

#[test]
fn ascii_ply_errors_name_the_line_and_element() {
    let c = file("word.ply", format!("{TRI_HEADER}0 0 0\n1 zero 0\n0 1 0\n3 0 1 2\n3 0 2 1\n"));
    let e = in_file(read_ply(&c.path), &c.path, &["line 11", "vertex 1"]);
    assert!(matches!(e, MeshError::Syntax { line: 11, .. }), "{e:?}");

    // ply-rs-bw's ASCII grammar has no `nan`: a syntax error on the line
    let c = file("nan.ply", format!("{TRI_HEADER}0 0 0\n1 0 0\n0 nan 0\n3 0 1 2\n3 0 2 1\n"));
    let e = in_file(read_ply(&c.path), &c.path, &["line 12", "vertex 2"]);
    assert!(matches!(e, MeshError::Syntax { line: 12, .. }), "{e:?}");

    let c = file("header.ply", "ply\nformat ascii 1.0\nelement vertex three\nend_header\n");
    let e = in_file(read_ply(&c.path), &c.path, &["line 3"]);
    assert!(matches!(e, MeshError::Syntax { line: 3, .. }), "{e:?}");

    let c = file("notply.ply", "OFF\n3 1 0\n");
    let e = in_file(read_ply(&c.path), &c.path, &["line 1"]);
    assert!(matches!(e, MeshError::Syntax { line: 1, .. }), "{e:?}");

    let c = file("empty.ply", "");
    assert!(matches!(in_file(read_ply(&c.path), &c.path, &["header"]), MeshError::Truncated { .. }));

    // a lying count must fail cleanly, not allocate
    let c = file(
        "liar.ply",
        "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\n\
         property float y\nproperty float z\nend_header\n\0\0\0\0",
    );
    assert!(matches!(in_file(read_ply(&c.path), &c.path, &[]), MeshError::Truncated { .. }));

    let missing = c.path.with_file_name("missing.ply");
    let e = in_file(read_ply(&missing), &missing, &["missing.ply"]);
    assert!(matches!(e, MeshError::Io(ref io) if io.kind() == std::io::ErrorKind::NotFound), "{e:?}");
}

/// The procedural bar through OFF, binary PLY and GLB. OFF (text, round-trip precision) and PLY
/// (binary doubles) must give the bar itself to the last bit. `write_glb` stores `f32` positions
/// (glTF has no `f64` POSITION), so the GLB read is compared with an OFF written from that same
/// GLB-read mesh: what is checked there is that the readers agree on one file content (the same
/// `f32`-exact positions, widened exactly, and the same triangles in the same order), and that the
/// GLB positions are the bar's rounded to `f32`.
#[test]
fn the_bar_reads_the_same_from_off_ply_and_glb() {
    let dir = tempfile::tempdir().unwrap();
    let bar = generate(ShapeKind::Bar, 2000).unwrap().mesh;

    let off = dir.path().join("bar.off");
    let ply = dir.path().join("bar.ply");
    write_off(&off, &bar).unwrap();
    write_ply(&ply, &bar).unwrap();
    let from_off = read_off(&off).unwrap();
    let from_ply = read_ply(&ply).unwrap();
    assert_bitwise_equal(&from_off, &bar);
    assert_bitwise_equal(&from_ply, &from_off);

    let glb = dir.path().join("bar.glb");
    write_glb(&glb, &bar, None).unwrap();
    let from_glb = read_gltf(&glb).unwrap();
    assert_eq!(from_glb.triangles(), bar.triangles());
    for (p, q) in from_glb.positions().iter().zip(bar.positions()) {
        assert_eq!(*p, q.map(|x| f64::from(x as f32)));
    }
    let glb_off = dir.path().join("bar-from-glb.off");
    let glb_ply = dir.path().join("bar-from-glb.ply");
    write_off(&glb_off, &from_glb).unwrap();
    write_ply(&glb_ply, &from_glb).unwrap();
    assert_bitwise_equal(&read_off(&glb_off).unwrap(), &from_glb);
    assert_bitwise_equal(&read_ply(&glb_ply).unwrap(), &from_glb);
}
