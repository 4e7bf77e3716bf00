//! Time the sparse Cholesky back-substitution on a mesh: `cholesky_solve_timing MESH [K...]`.
//!
//! Builds `-cotan_laplacian + 1e-6 * lumped_mass` (on the diagonal), factorizes it with
//! [`SparseCholesky`] and, for each number of right-hand-side columns `K` (default 1 3 8 32),
//! prints the milliseconds per right-hand-side vector of `SparseCholesky::solve_in_place` next to
//! faer's own supernodal/simplicial `LltRef` solve on the same factorization, and their largest
//! relative difference (the "faer" columns are what `solve_in_place` cost before it got its own kernels).
//! `BUDGET` (seconds per measurement, default 1) trades time for stabler numbers. Run with
//! `cargo run --release -p methods --example cholesky_solve_timing -- MESH [K...]`.

use std::time::Instant;

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::sparse::linalg::cholesky::{factorize_symbolic_cholesky, LltRef, SymbolicCholeskyRaw};
use faer::{Conj, Mat, Par, Side};
use methods::linalg::sparse_cholesky::{add_to_diagonal, SparseCholesky};
use methods::operators::{cotan_laplacian, lumped_mass, MassKind};

/// Best and median milliseconds per call of `f`, repeated for about `budget` seconds.
fn time(mut f: impl FnMut(), budget: f64) -> (f64, f64) {
    f();
    let mut samples = Vec::new();
    let start = Instant::now();
    while samples.len() < 5 || (start.elapsed().as_secs_f64() < budget && samples.len() < 2000) {
        let t = Instant::now();
        f();
        samples.push(t.elapsed().as_secs_f64() * 1e3);
    }
    samples.sort_by(f64::total_cmp);
    (samples[0], samples[samples.len() / 2])
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let [_, mesh_path, rest @ ..] = args.as_slice() else {
        return Err("usage: cholesky_solve_timing MESH [K...]".into());
    };
    let ks: Vec<usize> = if rest.is_empty() {
        vec![1, 3, 8, 32]
    } else {
        rest.iter().map(|k| k.parse()).collect::<Result<_, _>>()?
    };
    let budget: f64 = std::env::var("BUDGET").ok().map(|b| b.parse()).transpose()?.unwrap_or(1.0);

    let mesh = meshes::io::read_mesh(mesh_path)?;
    let mut a = cotan_laplacian(mesh.positions(), mesh.triangles());
    a.val_mut().iter_mut().for_each(|v| *v = -*v);
    let d: Vec<f64> =
        lumped_mass(mesh.positions(), mesh.triangles(), MassKind::Voronoi).iter().map(|m| 1e-6 * m).collect();
    let a = add_to_diagonal(a.as_ref(), &d);
    let n = a.nrows();

    let t = Instant::now();
    let mut chol = SparseCholesky::new(a.as_ref())?;
    let factor_ms = t.elapsed().as_secs_f64() * 1e3;

    // faer's own solve on an identical factorization, as the reference.
    let symbolic =
        factorize_symbolic_cholesky(a.symbolic(), Side::Lower, Default::default(), Default::default())?;
    let kind = match symbolic.raw() {
        SymbolicCholeskyRaw::Simplicial(_) => "simplicial",
        SymbolicCholeskyRaw::Supernodal(_) => "supernodal",
    };
    let mut values = vec![0.0; symbolic.len_val()];
    let mut buf = MemBuffer::new(symbolic.factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default()));
    symbolic.factorize_numeric_llt(
        &mut values,
        a.as_ref(),
        Side::Lower,
        LltRegularization::default(),
        Par::Seq,
        MemStack::new(&mut buf),
        Default::default(),
    )?;
    let llt = LltRef::new(&symbolic, &values);
    println!(
        "{mesh_path}: n = {n}, nnz(A) = {}, nnz(L) = {} ({kind}), factorize {factor_ms:.1} ms",
        a.compute_nnz(),
        chol.factor_nnz()
    );
    println!(
        "{:>4} {:>14} {:>14} {:>14} {:>14} {:>10}",
        "k", "ours best", "ours median", "faer best", "faer median", "rel diff"
    );
    for &k in &ks {
        let b = Mat::from_fn(n, k, |i, j| (((i * 7919 + j * 104729) % 1000) as f64 / 500.0) - 1.0);
        let mut x = b.clone();
        let (ours_best, ours_med) = time(
            || {
                x.copy_from(&b);
                chol.solve_in_place(x.as_mut());
            },
            budget,
        );
        let mut y = b.clone();
        let mut stack = MemBuffer::new(symbolic.solve_in_place_scratch::<f64>(k, Par::Seq));
        let (faer_best, faer_med) = time(
            || {
                y.copy_from(&b);
                llt.solve_in_place_with_conj(Conj::No, y.as_mut(), Par::Seq, MemStack::new(&mut stack));
            },
            budget,
        );
        let diff = (&x - &y).norm_max() / y.norm_max();
        let kf = k as f64;
        println!(
            "{k:>4} {:>14.4} {:>14.4} {:>14.4} {:>14.4} {diff:>10.1e}",
            ours_best / kf,
            ours_med / kf,
            faer_best / kf,
            faer_med / kf
        );
    }
    Ok(())
}
