//! Why `read_obj` does not use `tobj`: tobj renumbers an OBJ file's vertices, and our per-vertex files
//! (`.sel`, `.dmat` selections) index the file's vertices in file order.
//!
//! The file below defines five vertices up front, then two objects whose faces use them out of order,
//! share two of them across the `o` boundary, and leave vertex 4 (0-based) unused. With the options
//! the design named (`triangulate: true, single_index: false`), tobj emits one model per object, each
//! with its own positions in order of first use by that model's faces, and drops the unused vertex.
//! This test pins that behaviour down; if a tobj release ever keeps the file's order, it fails, and
//! the hand-written reader could be replaced.

use std::io::Cursor;

const FILE: &str = "\
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 5 5 5
o first
f 3 2 1
o second
f 1 3 4
";

fn tobj_models(text: &str) -> Vec<tobj::Model> {
    let options = tobj::LoadOptions { triangulate: true, single_index: false, ..Default::default() };
    let (models, _materials) =
        tobj::load_obj_buf(&mut Cursor::new(text), &options, |_| Err(tobj::LoadError::OpenFileFailed))
            .unwrap();
    models
}

#[test]
fn tobj_renumbers_vertices_per_object_in_order_of_first_use() {
    // `g` groups split models exactly like `o` objects.
    for text in [FILE.to_string(), FILE.replace("o ", "g ")] {
        check_renumbered(&tobj_models(&text));
    }
}

fn check_renumbered(models: &[tobj::Model]) {
    assert_eq!(models.len(), 2, "one model per `o`/`g`");

    // Model "first": its face `f 3 2 1` makes file vertex 2 its vertex 0, file vertex 1 its vertex 1, ...
    let first = &models[0].mesh;
    assert_eq!(first.positions, vec![1.0, 1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
    assert_eq!(first.indices, vec![0, 1, 2]);

    // Model "second" starts again at 0: file vertices 0 and 2 are duplicated, not shared with "first".
    let second = &models[1].mesh;
    assert_eq!(second.positions, vec![0.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0]);
    assert_eq!(second.indices, vec![0, 1, 2]);

    // 3 + 3 positions for 4 used vertices, and the unused vertex (5, 5, 5) is gone.
    let all: Vec<f64> = models.iter().flat_map(|m| m.mesh.positions.iter().copied()).collect();
    assert_eq!(all.len(), 18);
    assert!(!all.contains(&5.0));
}

#[test]
fn read_obj_keeps_the_file_order_and_shares_vertices_across_objects() {
    let mesh = meshes::io::parse_obj(FILE).unwrap();
    assert_eq!(
        mesh.positions(),
        &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0], [5.0, 5.0, 5.0]]
    );
    assert_eq!(mesh.triangles(), &[[2, 1, 0], [0, 2, 3]]);
}
