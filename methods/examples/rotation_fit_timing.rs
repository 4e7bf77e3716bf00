//! Time the local step's rotation fit: `rotation_fit_timing [flat]`.
//!
//! For 200,000 random 3x3 matrices `m` (entries in [-1, 1); `flat` scales their third column by
//! 1e-3, as the covariances of nearly planar one-rings), each perturbed by 1e-3 as from one ARAP
//! iteration to the next, prints the nanoseconds per call of `closest_rotation_warm` (the Jacobi
//! SVD warm-started from the last singular frames) and of `closest_rotation_near` (Newton on the
//! rotation group from the last rotation), three rounds each. Run with
//! `cargo run --release -p methods --example rotation_fit_timing`.

use std::time::Instant;

use methods::rotation_fit::{closest_rotation, closest_rotation_near, closest_rotation_warm, Mat3, IDENTITY};

fn main() {
    let n = 200_000;
    let flat = std::env::args().nth(1).as_deref() == Some("flat");
    let mut state = 12345u64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    let last: Vec<Mat3> = (0..n)
        .map(|_| {
            let mut m: Mat3 = std::array::from_fn(|_| std::array::from_fn(|_| next()));
            if flat {
                m.iter_mut().for_each(|row| row[2] *= 1e-3);
            }
            m
        })
        .collect();
    let last_rotations: Vec<Mat3> = last.iter().map(closest_rotation).collect();
    let mut last_frames = vec![IDENTITY; n];
    for (m, frame) in last.iter().zip(&mut last_frames) {
        closest_rotation_warm(m, frame);
    }
    let current: Vec<Mat3> = last
        .iter()
        .map(|m| std::array::from_fn(|i| std::array::from_fn(|j| m[i][j] + 1e-3 * next())))
        .collect();
    let mut checksum = 0.0;
    for _ in 0..3 {
        let mut frames = last_frames.clone();
        let t = Instant::now();
        for (m, frame) in current.iter().zip(&mut frames) {
            checksum += closest_rotation_warm(m, frame)[0][0];
        }
        let warm = t.elapsed().as_secs_f64() / n as f64 * 1e9;
        let mut frames = last_frames.clone();
        let t = Instant::now();
        for ((m, frame), previous) in current.iter().zip(&mut frames).zip(&last_rotations) {
            checksum += closest_rotation_near(m, previous, frame)[0][0];
        }
        let near = t.elapsed().as_secs_f64() / n as f64 * 1e9;
        println!(
            "closest_rotation_warm {warm:.0} ns, closest_rotation_near {near:.0} ns (checksum {checksum:.3})"
        );
    }
}
