//! The bumpy plane: a 100 x 100 square grid in the xy plane with 13 bumps of height 10, like the
//! survey's `plane.off`.
//!
//! The original is a 201 x 201 grid (vertex `(i, j)` at `(0.5 i, 0.5 j)`, x-major order, each cell
//! split along its `(0, 0)-(1, 1)` diagonal) whose heights are, to 1e-6, the formula used here: a
//! checkerboard of cells of side 100/6 around centres `(100/6) (i, j)`, `1 <= i, j <= 5`, `i + j`
//! even (a 3 x 3 plus an interleaved 2 x 2 pattern), each holding the separable bump
//! `10 [w(dx) w(dy)]^1.5` with `w(d) = (1 + cos(pi d / (100/12))) / 2`. (The original also has traces
//! below 0.003 of bumps centred on the border, left out here.) Same grid layout, diagonal, regions
//! (fixed: x <= 4.25; handle: x >= 96.25) and translation; the grid counts follow the target, kept
//! even so the central peak (z = 10) is a vertex.

use std::f64::consts::PI;

use super::{select, Builder, Generated};
use crate::error::Result;

const SIDE: f64 = 100.0;
const BUMP_HEIGHT: f64 = 10.0;
/// Spacing of the bump lattice; bumps sit on lattice points with an even index sum.
const BUMP_CELL: f64 = SIDE / 6.0;
/// Halfway between the original's last fixed column (x = 4) and first free column (x = 4.5).
const FIXED_MAX_X: f64 = 4.25;
/// Halfway between the original's last free column (x = 96) and first handle column (x = 96.5).
const HANDLE_MIN_X: f64 = 96.25;
/// `plane.def`: translation of the handle edge towards the centre and up.
const TRANSFORM: [[f64; 4]; 4] =
    [[1.0, 0.0, 0.0, -32.299956], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 56.703263], [0.0, 0.0, 0.0, 1.0]];

/// Height of the surface above `(x, y)`.
fn height(x: f64, y: f64) -> f64 {
    let (i, j) = ((x / BUMP_CELL).round(), (y / BUMP_CELL).round());
    let interior = (1.0..=5.0).contains(&i) && (1.0..=5.0).contains(&j);
    if !interior || (i + j) as i64 % 2 != 0 {
        return 0.0;
    }
    let half = BUMP_CELL / 2.0;
    let window = |d: f64| if d.abs() < half { 0.5 * (1.0 + (PI * d / half).cos()) } else { 0.0 };
    BUMP_HEIGHT * (window(x - i * BUMP_CELL) * window(y - j * BUMP_CELL)).powf(1.5)
}

/// Even cell counts `[nx, ny]` with `(nx + 1) (ny + 1)` closest to `target`; the two differ by at
/// most 2, so cells are square up to a few percent at small sizes and exactly at the survey's.
fn grid_for_target(target: usize) -> [usize; 2] {
    let nx = 2 * (((target as f64).sqrt() - 1.0) / 2.0).round().max(1.0) as usize;
    [nx.saturating_sub(2).max(2), nx, nx + 2]
        .into_iter()
        .map(|ny| [nx, ny])
        .min_by_key(|[a, b]| ((a + 1) * (b + 1)).abs_diff(target))
        .unwrap_or([nx, nx])
}

pub(super) fn generate(target: usize) -> Result<Generated> {
    let [nx, ny] = grid_for_target(target);
    let mut b = Builder::with_capacity((nx + 1) * (ny + 1));
    for i in 0..=nx {
        let x = SIDE * i as f64 / nx as f64;
        for j in 0..=ny {
            let y = SIDE * j as f64 / ny as f64;
            b.positions.push([x, y, height(x, y)]);
        }
    }
    b.next_index()?;
    let id = |i: usize, j: usize| (i * (ny + 1) + j) as u32;
    for i in 0..nx {
        for j in 0..ny {
            let [v00, v10, v11, v01] = [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)];
            b.triangles.push([v00, v10, v11]);
            b.triangles.push([v00, v11, v01]);
        }
    }
    let selection = select(&b.positions, |p| p[0] <= FIXED_MAX_X, |p| p[0] >= HANDLE_MIN_X);
    Ok((b.into_mesh()?, selection, TRANSFORM))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Heights of the original `plane.off` at a few grid points (read off the file).
    #[test]
    fn heights_match_the_original() {
        let samples = [
            ([50.0, 50.0], 10.0),
            ([50.0, 52.0], 8.0377721786),
            ([47.0, 50.0], 6.0191264153),
            ([48.0, 52.0], 6.4605774879),
            ([16.5, 16.5], 9.9704303741),
            ([42.0, 50.0], 0.00247561),
            ([41.5, 50.0], 0.0),
            ([25.0, 25.0], 0.0),
            ([2.0, 33.0], 0.0),
        ];
        for ([x, y], z) in samples {
            assert!((height(x, y) - z).abs() < 1e-6, "height({x}, {y}) = {}, expected {z}", height(x, y));
        }
    }

    #[test]
    fn grid_counts() {
        assert_eq!(grid_for_target(40401), [200, 200]);
        for target in [100, 1000, 50_000, 1_000_000] {
            let [nx, ny] = grid_for_target(target);
            assert!(nx % 2 == 0 && ny % 2 == 0);
            let rel = ((nx + 1) * (ny + 1)) as f64 / target as f64;
            assert!((0.9..=1.1).contains(&rel), "target {target}: {nx} x {ny}");
        }
    }
}
