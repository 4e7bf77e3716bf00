//! libigl's tutorial meshes and selections (not part of the repository). Looked up in
//! `$DEFORM_REAL_MESHES_DIR`, else `../shared/real-meshes` from the workspace root; each test passes
//! with a `SKIPPED:` message when the data is absent.

use std::path::PathBuf;

use meshes::io::{read_dmat, read_dmat_column, read_mesh};

fn real_meshes_dir() -> Option<PathBuf> {
    let dir = match std::env::var_os("DEFORM_REAL_MESHES_DIR") {
        Some(d) => PathBuf::from(d),
        None => PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/real-meshes"),
    };
    if dir.is_dir() {
        Some(dir)
    } else {
        eprintln!("SKIPPED: real meshes not found at {} (set DEFORM_REAL_MESHES_DIR)", dir.display());
        None
    }
}

/// Number of vertices with each value -1, 0, 1, 2, ... of a selection column.
fn histogram(selection: &[i64]) -> Vec<usize> {
    let max = selection.iter().copied().max().unwrap_or(-1);
    let mut counts = vec![0; (max + 2) as usize];
    for &s in selection {
        counts[(s + 1) as usize] += 1;
    }
    counts
}

#[test]
fn knight_selection_matches_the_knight() {
    let Some(dir) = real_meshes_dir() else { return };
    let mesh = read_mesh(dir.join("decimated-knight.off")).unwrap();
    assert_eq!(mesh.n_vertices(), 502);
    let path = dir.join("decimated-knight-selection.dmat");
    let matrix = read_dmat(&path).unwrap();
    assert_eq!((matrix.rows(), matrix.cols()), (502, 1));
    let selection = read_dmat_column(&path, mesh.n_vertices()).unwrap();
    assert_eq!(selection.len(), 502);
    assert_eq!(selection[..10], [-1, -1, -1, -1, -1, -1, -1, -1, 1, -1]);
    // the integer and the f64 reading agree
    assert!(selection.iter().zip(matrix.column(0)).all(|(&s, &x)| s as f64 == x));
    let counts = histogram(&selection);
    assert!(counts.len() >= 3 && counts[1..].iter().all(|&c| c > 0), "regions: {counts:?}");
    // against the wrong mesh size, the error names the file and both counts
    let err = read_dmat_column(&path, 501).unwrap_err().to_string();
    assert!(
        err.contains("decimated-knight-selection.dmat") && err.contains("502") && err.contains("501"),
        "{err}"
    );
}

#[test]
fn max_selection_matches_the_obj_bust() {
    let Some(dir) = real_meshes_dir() else { return };
    let mesh = read_mesh(dir.join("decimated-max.obj")).unwrap();
    assert_eq!(mesh.n_vertices(), 5272);
    let selection = read_dmat_column(dir.join("decimated-max-selection.dmat"), mesh.n_vertices()).unwrap();
    assert_eq!(selection.len(), 5272);
    let counts = histogram(&selection);
    assert!(counts.len() >= 2 && counts.iter().all(|&c| c > 0), "values -1, 0, ...: {counts:?}");
    eprintln!("decimated-max selection: vertices per value -1, 0, 1, ...: {counts:?}");
}
