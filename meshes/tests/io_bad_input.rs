//! Every kind of bad input yields the right error variant, and a message that names the file and the
//! offending line or element.

use std::path::Path;

use meshes::io::{
    read_dmat, read_dmat_column, read_gltf, read_index_list, read_mesh, read_obj, read_off, read_selection,
    read_transform,
};
use meshes::MeshError;

mod fixture;
use fixture::file;

/// The error must be `InFile` for `path`, its message must start with the path and contain every
/// piece of `needles`; returns the inner error.
fn unwrap_in_file<T: std::fmt::Debug>(
    result: Result<T, MeshError>,
    path: &Path,
    needles: &[&str],
) -> MeshError {
    let err = result.expect_err("bad input was accepted");
    let message = err.to_string();
    let file_name = path.file_name().unwrap().to_string_lossy();
    assert!(
        message.starts_with(&path.display().to_string()),
        "message does not start with the path: {message}"
    );
    assert!(message.contains(&*file_name), "message does not name {file_name}: {message}");
    for needle in needles {
        assert!(message.contains(needle), "message lacks '{needle}': {message}");
    }
    match err {
        MeshError::InFile { path: p, error: source } => {
            assert_eq!(p, path);
            *source
        }
        other => panic!("error is not wrapped with the file: {other:?}"),
    }
}

const TRI_HEADER: &str = "OFF\n3 1 0\n";

// ---- OFF ----

#[test]
fn off_malformed_number_names_line_and_vertex() {
    let c = file("bad_number.off", "OFF\n# comment\n3 1 0\n0 0 0\n1 0x 0\n0 1 0\n3 0 1 2\n");
    let e = unwrap_in_file(read_off(&c.path), &c.path, &["line 5", "vertex 1", "'0x'"]);
    assert!(matches!(e, MeshError::Syntax { line: 5, .. }), "{e:?}");
}

#[test]
fn off_too_few_coordinates_names_line() {
    let c = file("few.off", format!("{TRI_HEADER}0 0 0\n1 0\n0 1 0\n3 0 1 2\n"));
    let e = unwrap_in_file(read_off(&c.path), &c.path, &["line 4", "vertex 1", "expected 3 coordinates"]);
    assert!(matches!(e, MeshError::Syntax { line: 4, .. }), "{e:?}");
}

#[test]
fn off_too_few_face_indices_names_line() {
    let c = file("few_idx.off", format!("{TRI_HEADER}0 0 0\n1 0 0\n0 1 0\n3 0 1\n"));
    let e = unwrap_in_file(read_off(&c.path), &c.path, &["line 6", "face 0"]);
    assert!(matches!(e, MeshError::Syntax { line: 6, .. }), "{e:?}");
}

#[test]
fn off_truncated_vertices() {
    let c = file("short_v.off", "OFF\n4 1 0\n0 0 0\n1 0 0\n");
    let e = unwrap_in_file(read_off(&c.path), &c.path, &["4 vertices", "found 2"]);
    assert!(matches!(e, MeshError::Truncated { .. }), "{e:?}");
}

#[test]
fn off_truncated_faces() {
    let c = file("short_f.off", "OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1 2\n");
    let e = unwrap_in_file(read_off(&c.path), &c.path, &["2 faces", "found 1"]);
    assert!(matches!(e, MeshError::Truncated { .. }), "{e:?}");
}

#[test]
fn off_empty_and_header_only_files_are_truncated() {
    let c = file("empty.off", "");
    assert!(matches!(
        unwrap_in_file(read_off(&c.path), &c.path, &["OFF header"]),
        MeshError::Truncated { .. }
    ));
    let c = file("header_only.off", "OFF\n# nothing else\n");
    assert!(matches!(unwrap_in_file(read_off(&c.path), &c.path, &["counts"]), MeshError::Truncated { .. }));
}

#[test]
fn off_out_of_range_index_names_face_and_index() {
    let c = file("range.off", "OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1 2\n3 2 1 7\n");
    let e = unwrap_in_file(read_off(&c.path), &c.path, &["face 1", "index 7"]);
    assert!(matches!(e, MeshError::IndexOutOfRange { face: 1, index: 7, n_vertices: 4 }), "{e:?}");
}

#[test]
fn off_index_beyond_u32_is_out_of_range() {
    let c = file("huge.off", format!("{TRI_HEADER}0 0 0\n1 0 0\n0 1 0\n3 0 1 99999999999\n"));
    let e = unwrap_in_file(read_off(&c.path), &c.path, &["face 0", "99999999999"]);
    assert!(matches!(e, MeshError::IndexOutOfRange { face: 0, index: 99999999999, .. }), "{e:?}");
}

#[test]
fn off_negative_index_names_line() {
    let c = file("neg.off", format!("{TRI_HEADER}0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n"));
    let e = unwrap_in_file(read_off(&c.path), &c.path, &["line 6", "face 0", "negative", "-1"]);
    assert!(matches!(e, MeshError::Syntax { line: 6, .. }), "{e:?}");
}

#[test]
fn off_nan_coordinate_names_vertex() {
    let c = file("nan.off", format!("{TRI_HEADER}0 0 0\n1 0 0\n0 NaN 0\n3 0 1 2\n"));
    let e = unwrap_in_file(read_off(&c.path), &c.path, &["vertex 2", "NaN"]);
    assert!(matches!(e, MeshError::NonFiniteCoordinate { vertex: 2, axis: 1, .. }), "{e:?}");
}

#[test]
fn off_inf_coordinate_names_vertex() {
    let c = file("inf.off", format!("{TRI_HEADER}0 0 0\n1 0 -inf\n0 1 0\n3 0 1 2\n"));
    let e = unwrap_in_file(read_off(&c.path), &c.path, &["vertex 1", "inf"]);
    assert!(matches!(e, MeshError::NonFiniteCoordinate { vertex: 1, axis: 2, .. }), "{e:?}");
}

#[test]
fn off_quad_face_is_not_a_triangle() {
    let c = file("quad.off", "OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n");
    let e = unwrap_in_file(read_off(&c.path), &c.path, &["face 0", "4 corners"]);
    assert!(matches!(e, MeshError::NotATriangle { face: 0, corners: 4 }), "{e:?}");
}

#[test]
fn off_bad_header_counts_and_trailing_content() {
    let c = file("ply.off", "ply\nformat ascii 1.0\n");
    let e = unwrap_in_file(read_off(&c.path), &c.path, &["line 1", "'ply'"]);
    assert!(matches!(e, MeshError::Syntax { line: 1, .. }), "{e:?}");

    let c = file("4off.off", "4OFF\n3 1 0\n");
    assert!(matches!(
        unwrap_in_file(read_off(&c.path), &c.path, &["line 1"]),
        MeshError::Syntax { line: 1, .. }
    ));

    let c = file("counts.off", "OFF\n3 x 0\n");
    let e = unwrap_in_file(read_off(&c.path), &c.path, &["line 2", "face count"]);
    assert!(matches!(e, MeshError::Syntax { line: 2, .. }), "{e:?}");

    let c = file("counts1.off", "OFF\n3\n");
    assert!(matches!(
        unwrap_in_file(read_off(&c.path), &c.path, &["line 2"]),
        MeshError::Syntax { line: 2, .. }
    ));

    let c = file("extra.off", format!("{TRI_HEADER}0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 2 1\n"));
    let e = unwrap_in_file(read_off(&c.path), &c.path, &["line 7", "unexpected content"]);
    assert!(matches!(e, MeshError::Syntax { line: 7, .. }), "{e:?}");
}

#[test]
fn off_huge_announced_counts_fail_cleanly() {
    // A lying header must produce Truncated, not an allocation failure.
    let c = file("liar.off", "OFF\n18446744073709551615 18446744073709551615 0\n0 0 0\n");
    assert!(matches!(unwrap_in_file(read_off(&c.path), &c.path, &[]), MeshError::Truncated { .. }));
}

#[test]
fn off_zero_faces_is_empty() {
    let c = file("nofaces.off", "OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n");
    assert!(matches!(unwrap_in_file(read_off(&c.path), &c.path, &["faces"]), MeshError::Empty("faces")));
}

#[test]
fn off_invalid_utf8_names_line() {
    let c = file("latin1.off", b"OFF\n3 1 0\n0 0 0\n1 0 0 # caf\xe9\n0 1 0\n3 0 1 2\n");
    let e = unwrap_in_file(read_off(&c.path), &c.path, &["line 4", "UTF-8"]);
    assert!(matches!(e, MeshError::Syntax { line: 4, .. }), "{e:?}");
}

// ---- OBJ ----

#[test]
fn obj_errors_name_line_or_element() {
    let c = file("bad.obj", "v 0 0 0\nv 1 zero 0\nv 0 1 0\nf 1 2 3\n");
    let e = unwrap_in_file(read_obj(&c.path), &c.path, &["line 2", "vertex 1", "'zero'"]);
    assert!(matches!(e, MeshError::Syntax { line: 2, .. }), "{e:?}");

    let c = file("few.obj", "v 0 0\n");
    assert!(matches!(
        unwrap_in_file(read_obj(&c.path), &c.path, &["line 1"]),
        MeshError::Syntax { line: 1, .. }
    ));

    // Quads are triangulated now (see obj_polygons_are_fan_triangulated); a 2-corner face cannot be.
    let c = file("segment.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1/1 2/2\n");
    let e = unwrap_in_file(read_obj(&c.path), &c.path, &["face 1", "2 corners", "triangulated"]);
    assert!(matches!(e, MeshError::Untriangulable { face: 1, corners: 2, .. }), "{e:?}");

    let c = file("pinched.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\nf 1 2 3 3 4\n");
    let e = unwrap_in_file(read_obj(&c.path), &c.path, &["face 1", "repeats vertex 2"]);
    assert!(matches!(e, MeshError::Untriangulable { face: 1, corners: 5, .. }), "{e:?}");

    // The face number is the file's, not the triangle's: face 1 comes after a quad (two triangles).
    let c = file("range_after_quad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\nf 1 2 9\n");
    let e = unwrap_in_file(read_obj(&c.path), &c.path, &["face 1", "index 8"]);
    assert!(matches!(e, MeshError::IndexOutOfRange { face: 1, index: 8, n_vertices: 4 }), "{e:?}");

    let c = file("zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n");
    let e = unwrap_in_file(read_obj(&c.path), &c.path, &["line 4", "face 0", "index 0"]);
    assert!(matches!(e, MeshError::Syntax { line: 4, .. }), "{e:?}");

    let c = file("rel.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n");
    let e = unwrap_in_file(read_obj(&c.path), &c.path, &["line 4", "-4"]);
    assert!(matches!(e, MeshError::Syntax { line: 4, .. }), "{e:?}");

    let c = file("range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 3 2 9\n");
    let e = unwrap_in_file(read_obj(&c.path), &c.path, &["face 1", "index 8"]);
    assert!(matches!(e, MeshError::IndexOutOfRange { face: 1, index: 8, n_vertices: 3 }), "{e:?}");

    let c = file("nan.obj", "v 0 0 0\nv 1 0 0\nv 0 1 nan\nf 1 2 3\n");
    let e = unwrap_in_file(read_obj(&c.path), &c.path, &["vertex 2"]);
    assert!(matches!(e, MeshError::NonFiniteCoordinate { vertex: 2, axis: 2, .. }), "{e:?}");

    let c = file("w.obj", "v 0 0 0 2\n");
    let e = unwrap_in_file(read_obj(&c.path), &c.path, &["line 1", "rational"]);
    assert!(matches!(e, MeshError::Syntax { line: 1, .. }), "{e:?}");

    let c = file("nothing.obj", "# only a comment\nvn 0 0 1\n");
    assert!(matches!(unwrap_in_file(read_obj(&c.path), &c.path, &[]), MeshError::Empty("vertices")));
}

// ---- glTF ----

#[test]
fn gltf_garbage_and_truncated_glb_are_format_errors() {
    let c = file("garbage.glb", b"this is not a glb file at all");
    assert!(matches!(unwrap_in_file(read_gltf(&c.path), &c.path, &["glTF"]), MeshError::Format(_)));

    let mesh =
        meshes::TriMesh::new(vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], vec![[0, 1, 2]]).unwrap();
    let bytes = meshes::io::encode_glb(&mesh, None).unwrap();
    let c = file("cut.glb", &bytes[..bytes.len() - 8]);
    assert!(matches!(unwrap_in_file(read_gltf(&c.path), &c.path, &["glTF"]), MeshError::Format(_)));

    let c = file("broken.gltf", "{ \"asset\": { \"version\": \"2.0\" ");
    assert!(matches!(unwrap_in_file(read_mesh(&c.path), &c.path, &["glTF"]), MeshError::Format(_)));
}

#[test]
fn gltf_out_of_range_index_and_oversized_accessor_are_format_errors() {
    let positions: [[f32; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let mut bin = Vec::new();
    for x in positions.iter().flatten() {
        bin.extend_from_slice(&x.to_le_bytes());
    }
    for i in [0u32, 1, 5] {
        bin.extend_from_slice(&i.to_le_bytes());
    }
    let uri = format!("data:application/octet-stream;base64,{}", base64(&bin));
    let doc = |count: usize| {
        serde_json::json!({
            "asset": { "version": "2.0" },
            "meshes": [{ "primitives": [{ "attributes": { "POSITION": 0 }, "indices": 1 }] }],
            "buffers": [{ "uri": uri, "byteLength": bin.len() }],
            "bufferViews": [
                { "buffer": 0, "byteOffset": 0, "byteLength": 36 },
                { "buffer": 0, "byteOffset": 36, "byteLength": 12 },
            ],
            "accessors": [
                { "bufferView": 0, "componentType": 5126, "count": count, "type": "VEC3",
                  "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 0.0] },
                { "bufferView": 1, "componentType": 5125, "count": 3, "type": "SCALAR" },
            ],
        })
        .to_string()
    };
    let c = file("index.gltf", doc(3));
    let e = unwrap_in_file(read_mesh(&c.path), &c.path, &["mesh 0", "primitive 0", "index 5"]);
    assert!(matches!(e, MeshError::Format(_)), "{e:?}");

    let c = file("oversized.gltf", doc(1000));
    let e = unwrap_in_file(read_mesh(&c.path), &c.path, &["mesh 0", "POSITION", "1000"]);
    assert!(matches!(e, MeshError::Format(_)), "{e:?}");
}

/// Minimal standard base64 for building `data:` URIs in tests.
fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for chunk in bytes.chunks(3) {
        let b = [chunk[0], *chunk.get(1).unwrap_or(&0), *chunk.get(2).unwrap_or(&0)];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(ALPHABET[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

// ---- .sel ----

#[test]
fn selection_with_wrong_length() {
    let c = file("short.sel", "# per vertex status\n# 4 vertices\n0\n1\n2\n");
    let e = unwrap_in_file(read_selection(&c.path, 4), &c.path, &["selection", "3 entries", "4 vertices"]);
    assert!(matches!(e, MeshError::LengthMismatch { got: 3, expected: 4, .. }), "{e:?}");
    let e = unwrap_in_file(read_selection(&c.path, 2), &c.path, &["3 entries"]);
    assert!(matches!(e, MeshError::LengthMismatch { got: 3, expected: 2, .. }), "{e:?}");
}

#[test]
fn selection_with_code_3_names_line_and_vertex() {
    let c = file("code3.sel", "# comment\n0\n1\n3\n2\n");
    let e = unwrap_in_file(read_selection(&c.path, 4), &c.path, &["line 4", "vertex 2", "status 3"]);
    assert!(matches!(e, MeshError::Syntax { line: 4, .. }), "{e:?}");
}

#[test]
fn selection_with_non_integer_names_line() {
    let c = file("float.sel", "# comment\n0\n1.0\n");
    let e = unwrap_in_file(read_selection(&c.path, 2), &c.path, &["line 3", "'1.0'"]);
    assert!(matches!(e, MeshError::Syntax { line: 3, .. }), "{e:?}");
    let c = file("neg.sel", "0\n-1\n");
    let e = unwrap_in_file(read_selection(&c.path, 2), &c.path, &["line 2", "-1"]);
    assert!(matches!(e, MeshError::Syntax { line: 2, .. }), "{e:?}");
}

// ---- .dmat ----

#[test]
fn dmat_errors_name_the_file_and_line() {
    let c = file("header.dmat", "1\n0\n");
    let e = unwrap_in_file(read_dmat(&c.path), &c.path, &["line 1", "'#columns #rows'", "'1'"]);
    assert!(matches!(e, MeshError::Syntax { line: 1, .. }), "{e:?}");
    let c = file("neg.dmat", "1 -3\n0\n");
    assert!(matches!(
        unwrap_in_file(read_dmat(&c.path), &c.path, &["line 1"]),
        MeshError::Syntax { line: 1, .. }
    ));

    let c = file("word.dmat", "1 3\n0\n1\ntwo\n");
    let e = unwrap_in_file(read_dmat(&c.path), &c.path, &["line 4", "row 2", "'two'", "not a number"]);
    assert!(matches!(e, MeshError::Syntax { line: 4, .. }), "{e:?}");
    let e = unwrap_in_file(read_dmat_column(&c.path, 3), &c.path, &["line 4", "'two'", "integer"]);
    assert!(matches!(e, MeshError::Syntax { line: 4, .. }), "{e:?}");

    let c = file("few.dmat", "1 4\n0\n1\n");
    let e = unwrap_in_file(read_dmat(&c.path), &c.path, &["4 values", "found 2"]);
    assert!(matches!(e, MeshError::Truncated { .. }), "{e:?}");
    let c = file("many.dmat", "1 2\n0\n1\n\n2\n");
    let e = unwrap_in_file(read_dmat(&c.path), &c.path, &["line 5", "'2'", "2 values"]);
    assert!(matches!(e, MeshError::Syntax { line: 5, .. }), "{e:?}");

    let c = file("sel.dmat", "1 3\n-1\n0\n1\n");
    let e = unwrap_in_file(read_dmat_column(&c.path, 4), &c.path, &["sel.dmat", "3 entries", "4 vertices"]);
    assert!(matches!(e, MeshError::LengthMismatch { got: 3, expected: 4, .. }), "{e:?}");
    let c = file("wide.dmat", "2 2\n0 0\n0 0\n");
    let e = unwrap_in_file(read_dmat_column(&c.path, 2), &c.path, &["one column", "2 columns"]);
    assert!(matches!(e, MeshError::Invalid(_)), "{e:?}");

    let c = file("empty.dmat", "");
    assert!(matches!(unwrap_in_file(read_dmat(&c.path), &c.path, &["header"]), MeshError::Truncated { .. }));
    let c =
        file("binary.dmat", b"0 0\n1 2\n\x00\x00\x00\x00\x00\x00\xf0\xbf\x00\x00\x00\x00\x00\x00\xf0\xff");
    let e = unwrap_in_file(read_dmat(&c.path), &c.path, &["binary .dmat", "not supported"]);
    assert!(matches!(e, MeshError::Format(_)), "{e:?}");
}

// ---- vertex-id lists ----

#[test]
fn index_list_errors_name_the_file_and_line() {
    let c = file("ids.txt", "# handle\n1 2\n3 x4\n");
    let e = unwrap_in_file(read_index_list(&c.path), &c.path, &["ids.txt", "line 3", "entry 3", "'x4'"]);
    assert!(matches!(e, MeshError::Syntax { line: 3, .. }), "{e:?}");
    let c = file("neg.txt", "1\n-2\n");
    let e = unwrap_in_file(read_index_list(&c.path), &c.path, &["line 2", "'-2'", "non-negative"]);
    assert!(matches!(e, MeshError::Syntax { line: 2, .. }), "{e:?}");
    let c = file("ok.txt", "5 # trailing\n\n0\n");
    assert_eq!(read_index_list(&c.path).unwrap(), vec![5, 0]);
}

// ---- .def ----

const ROW: &str = "1 0 0 0\n";

#[test]
fn transform_with_three_rows() {
    let c = file("three.def", format!("# 4x4 handle transformation matrix\n{ROW}{ROW}{ROW}"));
    let e = unwrap_in_file(read_transform(&c.path), &c.path, &["line 4", "3 rows"]);
    assert!(matches!(e, MeshError::Syntax { line: 4, .. }), "{e:?}");
}

#[test]
fn transform_with_five_number_row_names_line() {
    let c =
        file("wide.def", format!("# 4x4 handle transformation matrix\n{ROW}0 1 0 0 7\n0 0 1 0\n0 0 0 1\n"));
    let e = unwrap_in_file(read_transform(&c.path), &c.path, &["line 3", "row 2", "found 5"]);
    assert!(matches!(e, MeshError::Syntax { line: 3, .. }), "{e:?}");
}

#[test]
fn transform_with_three_number_row_or_extra_row() {
    let c = file("narrow.def", format!("# m\n{ROW}0 1 0\n0 0 1 0\n0 0 0 1\n"));
    let e = unwrap_in_file(read_transform(&c.path), &c.path, &["line 3", "found 3"]);
    assert!(matches!(e, MeshError::Syntax { line: 3, .. }), "{e:?}");

    let c = file("five.def", format!("# m\n{ROW}0 1 0 0\n0 0 1 0\n0 0 0 1\n0 0 0 1\n"));
    let e = unwrap_in_file(read_transform(&c.path), &c.path, &["line 6", "fifth row"]);
    assert!(matches!(e, MeshError::Syntax { line: 6, .. }), "{e:?}");
}

#[test]
fn transform_with_bad_number_or_not_affine() {
    let c = file("word.def", format!("# m\n{ROW}0 one 0 0\n0 0 1 0\n0 0 0 1\n"));
    let e = unwrap_in_file(read_transform(&c.path), &c.path, &["line 3", "'one'"]);
    assert!(matches!(e, MeshError::Syntax { line: 3, .. }), "{e:?}");

    let c = file("projective.def", format!("# m\n{ROW}0 1 0 0\n0 0 1 0\n0 0 1 1\n"));
    let e = unwrap_in_file(read_transform(&c.path), &c.path, &["not affine"]);
    assert!(matches!(e, MeshError::Invalid(_)), "{e:?}");

    let c = file("nan.def", format!("# m\n{ROW}0 1 0 NaN\n0 0 1 0\n0 0 0 1\n"));
    let e = unwrap_in_file(read_transform(&c.path), &c.path, &["(1, 3)"]);
    assert!(matches!(e, MeshError::Invalid(_)), "{e:?}");
}

// ---- dispatch and missing files ----

#[test]
fn unknown_or_missing_extension() {
    // .ply is a mesh format now; .stl is not
    let c = file("mesh.stl", "solid x\n");
    let e = unwrap_in_file(read_mesh(&c.path), &c.path, &["'.stl'", ".off", ".ply"]);
    assert!(matches!(e, MeshError::Invalid(_)), "{e:?}");
    let c = file("mesh", "OFF\n");
    let e = unwrap_in_file(read_mesh(&c.path), &c.path, &["no extension"]);
    assert!(matches!(e, MeshError::Invalid(_)), "{e:?}");
}

#[test]
fn missing_files_are_io_not_found_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let is_not_found =
        |e: &MeshError| matches!(e, MeshError::Io(io) if io.kind() == std::io::ErrorKind::NotFound);
    for name in ["gone.off", "gone.obj", "gone.ply", "gone.glb", "gone.gltf"] {
        let path = dir.path().join(name);
        let e = unwrap_in_file(read_mesh(&path), &path, &[]);
        assert!(is_not_found(&e), "{name}: {e:?}");
    }
    let path = dir.path().join("gone.sel");
    assert!(is_not_found(&unwrap_in_file(read_selection(&path, 3), &path, &[])));
    let path = dir.path().join("gone.def");
    assert!(is_not_found(&unwrap_in_file(read_transform(&path), &path, &[])));
}
