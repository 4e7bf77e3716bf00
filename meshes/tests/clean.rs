//! Mesh cleaning: unreferenced vertices and the map back, exact duplicates, connected components.

use meshes::clean::{connected_components, drop_unreferenced, exact_duplicate_vertices};
use meshes::{MeshError, TriMesh, VertexMap, VertexStatus};

/// A unit square (two triangles) with an unreferenced vertex in the middle of the numbering
/// (vertex 2) and one at the end (vertex 5).
fn square_with_strays() -> TriMesh {
    let positions = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [9.0, 9.0, 9.0], // unreferenced
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
        [7.0, 7.0, 7.0], // unreferenced
    ];
    // TriMesh::new accepts unreferenced vertices: readers keep them, cleaning is a separate step.
    TriMesh::new(positions, vec![[0, 1, 3], [0, 3, 4]]).unwrap()
}

#[test]
fn drop_unreferenced_renumbers_in_input_order() {
    let mesh = square_with_strays();
    let (clean, map) = drop_unreferenced(&mesh);
    assert_eq!(clean.positions(), &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]]);
    assert_eq!(clean.triangles(), &[[0, 1, 2], [0, 2, 3]]);
    assert_eq!(map.kept(), &[0, 1, 3, 4]);
    assert_eq!((map.n_original(), map.n_kept()), (6, 4));
    assert_eq!(map.dropped(), vec![2, 5]);
    assert!(!map.is_identity());
    assert_eq!(map.new_index(3), Some(2));
    assert_eq!(map.new_index(2), None);
    assert_eq!(map.new_index(99), None);
}

#[test]
fn results_go_back_to_the_input_numbering_and_selections_come_over() {
    let mesh = square_with_strays();
    let (clean, map) = drop_unreferenced(&mesh);
    let moved: Vec<[f64; 3]> = clean.positions().iter().map(|p| [p[0] + 10.0, p[1], p[2]]).collect();
    let back = map.to_original(&moved, mesh.positions()).unwrap();
    assert_eq!(
        back,
        vec![
            [10.0, 0.0, 0.0],
            [11.0, 0.0, 0.0],
            [9.0, 9.0, 9.0], // dropped: at rest
            [11.0, 1.0, 0.0],
            [10.0, 1.0, 0.0],
            [7.0, 7.0, 7.0],
        ]
    );
    use VertexStatus::*;
    let selection = [Fixed, Free, Handle, Handle, Free, Fixed];
    assert_eq!(map.restrict(&selection).unwrap(), vec![Fixed, Free, Handle, Free]);

    assert!(matches!(
        map.to_original(&moved[..3], mesh.positions()),
        Err(MeshError::LengthMismatch { got: 3, expected: 4, .. })
    ));
    assert!(matches!(
        map.to_original(&moved, &mesh.positions()[..5]),
        Err(MeshError::LengthMismatch { got: 5, expected: 6, .. })
    ));
    assert!(matches!(
        map.restrict(&selection[..4]),
        Err(MeshError::LengthMismatch { got: 4, expected: 6, .. })
    ));
}

#[test]
fn nothing_to_drop_gives_the_identity() {
    let mesh = TriMesh::new(vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], vec![[0, 1, 2]]).unwrap();
    let (clean, map) = drop_unreferenced(&mesh);
    assert_eq!(clean, mesh);
    assert_eq!(map, VertexMap::identity(3));
    assert!(map.is_identity() && map.dropped().is_empty());
    assert_eq!(map.to_original(clean.positions(), mesh.positions()).unwrap(), mesh.positions());
    assert_eq!(map.restrict(&[1u8, 2, 3]).unwrap(), vec![1, 2, 3]);
}

#[test]
fn exact_duplicates_are_bit_identical_pairs_in_sorted_order() {
    let positions = [
        [1.0, 2.0, 3.0],
        [0.0, 0.0, 0.0],
        [1.0, 2.0, 3.0],
        [-0.0, 0.0, 0.0], // not bit-identical to vertex 1
        [0.0, 0.0, 0.0],
        [1.0, 2.0, 3.0 + f64::EPSILON * 4.0], // close, not equal
        [1.0, 2.0, 3.0],
    ];
    assert_eq!(exact_duplicate_vertices(&positions), vec![(0, 2), (0, 6), (1, 4)]);
    assert!(exact_duplicate_vertices(&positions[..2]).is_empty());
    assert!(exact_duplicate_vertices(&[]).is_empty());
}

#[test]
fn components_are_numbered_by_smallest_vertex() {
    // {0, 2, 4, 7}: triangles 0 2 4 and 4 2 7; it holds vertex 0, so it is component 0.
    // {1, 3, 5, 6, 8, 9}: 1 3 5 and 5 3 6 share an edge, 6 8 9 shares only vertex 6; component 1.
    // Vertex 10 is unreferenced: component 2 on its own. Triangles are listed out of order on purpose.
    let triangles = [[1, 3, 5], [4, 2, 7], [6, 8, 9], [5, 3, 6], [0, 2, 4]];
    let (ids, count) = connected_components(11, &triangles);
    assert_eq!(count, 3);
    assert_eq!(ids, vec![0, 1, 0, 1, 0, 1, 1, 0, 1, 1, 2]);

    let (ids, count) = connected_components(3, &[[0, 1, 2]]);
    assert_eq!((ids, count), (vec![0, 0, 0], 1));
    assert_eq!(connected_components(0, &[]), (vec![], 0));
}

#[test]
fn two_disjoint_bars_are_two_components() {
    let bar = meshes::shapes::generate(meshes::shapes::ShapeKind::Bar, 500).unwrap().mesh;
    let n = bar.n_vertices() as u32;
    let mut positions = bar.positions().to_vec();
    positions.extend(bar.positions().iter().map(|p| [p[0] + 1000.0, p[1], p[2]]));
    let mut triangles = bar.triangles().to_vec();
    triangles.extend(bar.triangles().iter().map(|t| t.map(|v| v + n)));
    let (ids, count) = connected_components(positions.len(), &triangles);
    assert_eq!(count, 2);
    assert!(ids[..n as usize].iter().all(|&c| c == 0) && ids[n as usize..].iter().all(|&c| c == 1));
    // the copy shares no position with the original, and the bar has no duplicates of its own
    assert!(exact_duplicate_vertices(&positions).is_empty());
}
