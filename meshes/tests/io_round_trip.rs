//! Round trips through every writer and reader, and the atomicity of writes.

use std::path::Path;

use meshes::io::{
    atomic_write, encode_glb, read_gltf, read_mesh, read_obj, read_off, read_selection, read_transform,
    write_glb, write_mesh, write_obj, write_off, write_selection, write_transform,
};
use meshes::{AffineTransform, MeshError, TriMesh, VertexStatus};

/// An open 3x2 grid with awkward coordinates: values that print long (1/3), tiny and huge magnitudes,
/// negative zero, so a writer that loses precision or formats badly is caught.
fn awkward_mesh() -> TriMesh {
    let positions = vec![
        [0.0, 0.0, 1.0 / 3.0],
        [0.1, -0.0, 2.0 / 3.0],
        [2.0 + f64::EPSILON * 2.0, 1e-9, 0.2],
        [0.0, 1.0, -7.5e-12],
        [1.0, 1.0, 123456.789],
        [2.0, 1.0, -1.0 / 7.0],
        [3.0e17, 2.0, 1.0], // isolated: no face uses it, readers must keep it anyway
    ];
    let triangles = vec![[0, 1, 4], [0, 4, 3], [1, 2, 5], [1, 5, 4]];
    TriMesh::new(positions, triangles).unwrap()
}

fn assert_bitwise_equal(a: &TriMesh, b: &TriMesh) {
    assert_eq!(a.triangles(), b.triangles());
    assert_eq!(a.n_vertices(), b.n_vertices());
    for (v, (p, q)) in a.positions().iter().zip(b.positions()).enumerate() {
        assert_eq!(p.map(f64::to_bits), q.map(f64::to_bits), "vertex {v}: {p:?} != {q:?}");
    }
}

#[test]
fn off_round_trip_is_exact() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("m.off");
    let mesh = awkward_mesh();
    write_off(&path, &mesh).unwrap();
    assert_bitwise_equal(&read_off(&path).unwrap(), &mesh);
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.starts_with("OFF\n7 4 0\n"), "{text}");
}

#[test]
fn obj_round_trip_is_exact() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("m.obj");
    let mesh = awkward_mesh();
    write_obj(&path, &mesh).unwrap();
    assert_bitwise_equal(&read_obj(&path).unwrap(), &mesh);
}

#[test]
fn write_mesh_and_read_mesh_dispatch_on_extension() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = awkward_mesh();
    for name in ["a.off", "b.OBJ", "c.Off", "f.ply"] {
        let path = dir.path().join(name);
        write_mesh(&path, &mesh).unwrap();
        assert_bitwise_equal(&read_mesh(&path).unwrap(), &mesh);
    }
    let glb = dir.path().join("d.glb");
    write_mesh(&glb, &mesh).unwrap();
    let back = read_mesh(&glb).unwrap();
    assert_eq!(back.triangles(), mesh.triangles());
    // .gltf is readable but not writable
    let err = write_mesh(dir.path().join("e.gltf"), &mesh).unwrap_err();
    assert!(err.to_string().contains("e.gltf") && err.to_string().contains(".glb"), "{err}");
    assert!(!dir.path().join("e.gltf").exists());
}

#[test]
fn obj_reader_handles_slashes_relative_indices_and_ignored_statements() {
    let text = "mtllib x.mtl\no thing\nv 0 0 0\nv 1 0 0 1\nv 0 1 0 0.5 0.5 0.5\nvt 0 0\nvn 0 0 1\n\
                g part\nusemtl red\ns off\nf 1/1/1 2/1/1 3/1/1\nv 1 1 0\nf -3//1 -1//1 -2//1\nl 1 2\n";
    let mesh = meshes::io::parse_obj(text).unwrap();
    assert_eq!(mesh.n_vertices(), 4);
    assert_eq!(mesh.triangles(), &[[0, 1, 2], [1, 3, 2]]);
}

#[test]
fn obj_polygons_are_fan_triangulated() {
    // A quad, a pentagon with corners given out of order and a triangle; vertex 5 defined after use.
    let text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nf 1 2 3 4\nf 2/1 5/1 6/1 7/1 3/1\n\
                v 2 1 0\nv 1.5 1.5 0\nf 4 3 7\n";
    let mesh = meshes::io::parse_obj(text).unwrap();
    assert_eq!(mesh.n_vertices(), 7);
    assert_eq!(mesh.triangles(), &[[0, 1, 2], [0, 2, 3], [1, 4, 5], [1, 5, 6], [1, 6, 2], [3, 2, 6]]);
}

#[test]
fn off_reader_accepts_comments_blank_lines_counts_on_header_and_extra_columns() {
    let text = "# leading comment\n\nOFF 4 2 0 # counts on the header line\n\
                0 0 0 255 0 0 255\n  1 0 0\n\n# between vertices\n0 1 0 # trailing\n1 1 0\r\n\
                3 0 1 2 0.5 0.5 0.5\n3 2 1 3\n# final comment\n\n";
    let mesh = meshes::io::parse_off(text).unwrap();
    assert_eq!(mesh.n_vertices(), 4);
    assert_eq!(mesh.triangles(), &[[0, 1, 2], [2, 1, 3]]);
    assert_eq!(mesh.positions()[3], [1.0, 1.0, 0.0]);
    // COFF/NOFF only add columns after x y z
    assert!(
        meshes::io::parse_off("COFF\n3 1 0\n0 0 0 1 1 1 1\n1 0 0 1 1 1 1\n0 1 0 1 1 1 1\n3 0 1 2\n").is_ok()
    );
}

fn palette(n: usize) -> Vec<[f32; 3]> {
    (0..n).map(|i| [i as f32 / n as f32, 1.0, 0.25]).collect()
}

#[test]
fn glb_is_valid_gltf_and_round_trips_positions_indices_normals_colors() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("m.glb");
    let mesh = awkward_mesh();
    let colors = palette(mesh.n_vertices());
    write_glb(&path, &mesh, Some(&colors)).unwrap();
    let bytes = std::fs::read(&path).unwrap();

    // GLB container: header, then 4-byte aligned JSON and BIN chunks, declared length = file length.
    let word = |k: usize| u32::from_le_bytes(bytes[4 * k..4 * k + 4].try_into().unwrap());
    assert_eq!(&bytes[..4], b"glTF");
    assert_eq!(word(1), 2);
    assert_eq!(word(2) as usize, bytes.len());
    let json_len = word(3) as usize;
    assert_eq!(json_len % 4, 0);
    assert_eq!(&bytes[16..20], b"JSON");
    let bin_header = 20 + json_len;
    let bin_len = u32::from_le_bytes(bytes[bin_header..bin_header + 4].try_into().unwrap()) as usize;
    assert_eq!(&bytes[bin_header + 4..bin_header + 8], b"BIN\0");
    assert_eq!(bin_len % 4, 0);
    assert_eq!(bin_header + 8 + bin_len, bytes.len());

    // from_slice validates the document (including POSITION min/max, which the spec requires).
    let gltf = gltf::Gltf::from_slice(&bytes).unwrap();
    let json: serde_json::Value = serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
    assert_eq!(json["asset"]["version"], "2.0");
    let buffers = gltf::import_buffers(&gltf.document, None, gltf.blob.clone()).unwrap();
    let g_mesh = gltf.document.meshes().next().unwrap();
    assert_eq!(gltf.document.meshes().count(), 1);
    assert_eq!(g_mesh.primitives().count(), 1);
    let prim = g_mesh.primitives().next().unwrap();
    assert_eq!(prim.mode(), gltf::mesh::Mode::Triangles);
    let reader = prim.reader(|b| Some(&buffers[b.index()].0[..]));

    let positions: Vec<[f32; 3]> = reader.read_positions().unwrap().collect();
    let expected: Vec<[f32; 3]> = mesh.positions().iter().map(|p| p.map(|x| x as f32)).collect();
    assert_eq!(positions, expected);
    let pos_accessor = prim.get(&gltf::Semantic::Positions).unwrap();
    let min: [f32; 3] = serde_json::from_value(pos_accessor.min().unwrap()).unwrap();
    let max: [f32; 3] = serde_json::from_value(pos_accessor.max().unwrap()).unwrap();
    for k in 0..3 {
        assert_eq!(min[k], expected.iter().map(|p| p[k]).fold(f32::INFINITY, f32::min));
        assert_eq!(max[k], expected.iter().map(|p| p[k]).fold(f32::NEG_INFINITY, f32::max));
    }

    let indices: Vec<u32> = reader.read_indices().unwrap().into_u32().collect();
    assert_eq!(indices, mesh.triangles().iter().flatten().copied().collect::<Vec<_>>());

    let normals: Vec<[f32; 3]> = reader.read_normals().unwrap().collect();
    let reference = meshes::geometry::vertex_normals(mesh.positions(), mesh.triangles());
    assert_eq!(normals.len(), mesh.n_vertices());
    for (v, (n, r)) in normals.iter().zip(&reference).enumerate() {
        let len = n.iter().map(|x| x * x).sum::<f32>().sqrt();
        assert!((len - 1.0).abs() < 1e-5, "vertex {v}: normal {n:?} is not unit");
        if *r != [0.0; 3] {
            assert_eq!(*n, r.map(|x| x as f32), "vertex {v}");
        }
    }
    // the isolated vertex has no normal of its own; glTF still needs a unit one
    assert_eq!(normals[6], [0.0, 0.0, 1.0]);

    let read_colors: Vec<[f32; 3]> = reader.read_colors(0).unwrap().into_rgb_f32().collect();
    assert_eq!(read_colors, colors);

    // and through our own reader
    let back = read_gltf(&path).unwrap();
    assert_eq!(back.triangles(), mesh.triangles());
    let widened: Vec<[f64; 3]> = expected.iter().map(|p| p.map(f64::from)).collect();
    assert_eq!(back.positions(), &widened[..]);
}

#[test]
fn glb_without_colors_has_no_color_attribute() {
    let mesh = awkward_mesh();
    let bytes = encode_glb(&mesh, None).unwrap();
    let gltf = gltf::Gltf::from_slice(&bytes).unwrap();
    let prim = gltf.document.meshes().next().unwrap().primitives().next().unwrap();
    assert!(prim.get(&gltf::Semantic::Colors(0)).is_none());
    assert!(prim.get(&gltf::Semantic::Normals).is_some());
}

#[test]
fn glb_rejects_bad_colors() {
    let mesh = awkward_mesh();
    let short = palette(3);
    assert!(matches!(
        encode_glb(&mesh, Some(&short)),
        Err(MeshError::LengthMismatch { got: 3, expected: 7, .. })
    ));
    let mut bad = palette(7);
    bad[5][1] = f32::NAN;
    let err = encode_glb(&mesh, Some(&bad)).unwrap_err();
    assert!(matches!(err, MeshError::Invalid(_)) && err.to_string().contains("vertex 5"), "{err}");
}

/// A `.gltf` with an external `.bin`, u16 indices, a plain instance of the mesh and a mirrored,
/// translated instance two levels down: checks buffer resolution next to the file, node world
/// transforms (parent * child) and the winding flip of mirrored instances.
#[test]
fn gltf_with_external_buffer_applies_node_transforms_and_flips_mirrored_winding() {
    let dir = tempfile::tempdir().unwrap();
    let positions: [[f32; 3]; 4] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.5]];
    let indices: [u16; 6] = [0, 1, 2, 2, 1, 3];
    let mut bin = Vec::new();
    for p in positions {
        for x in p {
            bin.extend_from_slice(&x.to_le_bytes());
        }
    }
    for i in indices {
        bin.extend_from_slice(&i.to_le_bytes());
    }
    std::fs::write(dir.path().join("quad.bin"), &bin).unwrap();
    let json = serde_json::json!({
        "asset": { "version": "2.0" },
        "scene": 0,
        "scenes": [{ "nodes": [0, 1] }],
        "nodes": [
            { "mesh": 0 },
            { "translation": [10.0, 0.0, 0.0], "children": [2] },
            { "scale": [-1.0, 1.0, 1.0], "mesh": 0 },
        ],
        "meshes": [{ "primitives": [{ "attributes": { "POSITION": 0 }, "indices": 1 }] }],
        "buffers": [{ "uri": "quad.bin", "byteLength": bin.len() }],
        "bufferViews": [
            { "buffer": 0, "byteOffset": 0, "byteLength": 48 },
            { "buffer": 0, "byteOffset": 48, "byteLength": 12 },
        ],
        "accessors": [
            { "bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
              "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 0.5] },
            { "bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR" },
        ],
    });
    let path = dir.path().join("scene.gltf");
    std::fs::write(&path, serde_json::to_vec_pretty(&json).unwrap()).unwrap();

    let mesh = read_mesh(&path).unwrap();
    assert_eq!(mesh.n_vertices(), 8);
    let expected_positions: Vec<[f64; 3]> = positions
        .iter()
        .map(|p| p.map(f64::from))
        .chain(positions.iter().map(|p| [10.0 - f64::from(p[0]), f64::from(p[1]), f64::from(p[2])]))
        .collect();
    assert_eq!(mesh.positions(), &expected_positions[..]);
    assert_eq!(mesh.triangles(), &[[0, 1, 2], [2, 1, 3], [4, 6, 5], [6, 7, 5]]);
}

#[test]
fn selection_and_transform_round_trip() {
    let dir = tempfile::tempdir().unwrap();
    let sel_path = dir.path().join("e.sel");
    let selection = vec![VertexStatus::Fixed, VertexStatus::Handle, VertexStatus::Free, VertexStatus::Free];
    write_selection(&sel_path, &selection).unwrap();
    assert_eq!(read_selection(&sel_path, 4).unwrap(), selection);

    let def_path = dir.path().join("e.def");
    let t = AffineTransform::rotation_about([0.3, -1.0, 0.2], 2.0, [1.0 / 3.0, 5.0, -7.0])
        .compose(&AffineTransform::translation([1e-7, 0.1, 3e5]));
    write_transform(&def_path, &t).unwrap();
    let back = read_transform(&def_path).unwrap();
    assert_eq!(back.rows().map(|r| r.map(f64::to_bits)), t.rows().map(|r| r.map(f64::to_bits)));
}

fn entries(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn write_into_missing_directory_fails_and_creates_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("no-such-dir");
    let mesh = awkward_mesh();
    for name in ["m.off", "m.obj", "m.ply", "m.glb"] {
        let path = missing.join(name);
        let err = write_mesh(&path, &mesh).unwrap_err();
        match &err {
            MeshError::InFile { path: p, error: source } => {
                assert_eq!(p, &path);
                assert!(matches!(**source, MeshError::Io(ref e) if e.kind() == std::io::ErrorKind::NotFound));
            }
            other => panic!("expected InFile(Io), got {other:?}"),
        }
        assert!(err.to_string().contains(name), "{err}");
    }
    assert!(!missing.exists());
    assert!(entries(dir.path()).is_empty());
}

#[test]
fn failing_write_keeps_the_previous_file_and_leaves_no_temporary() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("keep.off");
    let mesh = awkward_mesh();
    write_off(&path, &mesh).unwrap();
    let before = std::fs::read(&path).unwrap();

    // fails after writing part of the data
    let err = atomic_write(&path, |w| {
        w.write_all(b"OFF\n1000 1000 0\n0 0 0\n")?;
        Err(MeshError::Invalid("simulated failure mid-way".into()))
    })
    .unwrap_err();
    assert!(err.to_string().contains("keep.off") && err.to_string().contains("simulated"), "{err}");
    assert_eq!(std::fs::read(&path).unwrap(), before);
    assert_eq!(entries(dir.path()), vec!["keep.off".to_string()]);

    // fails by panicking mid-way
    let panicked = std::panic::catch_unwind(|| {
        let _ = atomic_write(&path, |w| {
            w.write_all(b"partial")?;
            panic!("simulated panic");
        });
    });
    assert!(panicked.is_err());
    assert_eq!(std::fs::read(&path).unwrap(), before);
    assert_eq!(entries(dir.path()), vec!["keep.off".to_string()]);

    // fails before writing (bad colors): the existing file is untouched
    let glb = dir.path().join("keep.glb");
    write_glb(&glb, &mesh, None).unwrap();
    let glb_before = std::fs::read(&glb).unwrap();
    assert!(write_glb(&glb, &mesh, Some(&palette(2))).is_err());
    assert_eq!(std::fs::read(&glb).unwrap(), glb_before);

    // a successful write replaces the file
    let other = TriMesh::new(vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], vec![[0, 1, 2]]).unwrap();
    write_off(&path, &other).unwrap();
    assert_eq!(read_off(&path).unwrap(), other);
    assert_eq!(entries(dir.path()), vec!["keep.glb".to_string(), "keep.off".to_string()]);
}

#[test]
fn writing_onto_a_directory_fails_and_cleans_up() {
    let dir = tempfile::tempdir().unwrap();
    let target = dir.path().join("taken.off");
    std::fs::create_dir(&target).unwrap();
    assert!(write_off(&target, &awkward_mesh()).is_err());
    assert!(target.is_dir());
    assert_eq!(entries(dir.path()), vec!["taken.off".to_string()]);
}
