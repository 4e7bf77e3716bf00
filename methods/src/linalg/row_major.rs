//! Vectorizable kernels on row-major `n x K` blocks of right-hand sides (`x[i * K + q]`), shared by
//! the sparse triangular solves and the eigensolver's block Gram–Schmidt: `K` is a compile-time
//! width so every row is one fixed-size array the compiler keeps in vector registers, and the
//! multiply-add is fused or not by a type parameter ([`Fused`] only inside functions compiled with
//! the `fma` target feature, chosen once at run time).

// The kernels address lanes and block rows by index on purpose (fixed-size arrays the compiler
// keeps in vector registers).
#![allow(clippy::needless_range_loop)]

/// AVX2 and FMA are available (x86-64 only).
pub(crate) fn fma_available() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// `acc + a * b`, fused or not.
pub(crate) trait MulAdd {
    fn mul_add(acc: f64, a: f64, b: f64) -> f64;
}

/// Separate multiply and add (any CPU).
pub(crate) struct Separate;
impl MulAdd for Separate {
    #[inline(always)]
    fn mul_add(acc: f64, a: f64, b: f64) -> f64 {
        acc + a * b
    }
}

/// Fused multiply-add; only used inside functions compiled with the `fma` target feature.
#[cfg(target_arch = "x86_64")]
pub(crate) struct Fused;
#[cfg(target_arch = "x86_64")]
impl MulAdd for Fused {
    #[inline(always)]
    fn mul_add(acc: f64, a: f64, b: f64) -> f64 {
        a.mul_add(b, acc)
    }
}

#[inline(always)]
pub(crate) fn row<const K: usize>(x: &[f64], i: usize) -> &[f64; K] {
    x[i * K..i * K + K].try_into().unwrap()
}

#[inline(always)]
pub(crate) fn row_mut<const K: usize>(x: &mut [f64], i: usize) -> &mut [f64; K] {
    (&mut x[i * K..i * K + K]).try_into().unwrap()
}

/// Sum of `NA` accumulator sets, pairwise in a fixed order.
#[inline(always)]
pub(crate) fn reduce<const K: usize, const NA: usize>(mut acc: [[f64; K]; NA]) -> [f64; K] {
    let mut half = NA;
    while half > 1 {
        half /= 2;
        for u in 0..half {
            for q in 0..K {
                acc[u][q] += acc[u + half][q];
            }
        }
    }
    acc[0]
}

/// `sum_l coef[l] * x[l, :]` for the row-major `coef.len() x K` block `x`, spread over `NA`
/// independent accumulator sets (fixed summation order).
#[inline(always)]
pub(crate) fn combine<const K: usize, const NA: usize, M: MulAdd>(coef: &[f64], x: &[f64]) -> [f64; K] {
    debug_assert_eq!(x.len(), coef.len() * K);
    let mut acc = [[0.0; K]; NA];
    let cs = coef.chunks_exact(NA);
    let xs = x.chunks_exact(NA * K);
    let (c_rest, x_rest) = (cs.remainder(), xs.remainder());
    for (c, xl) in cs.zip(xs) {
        for u in 0..NA {
            for q in 0..K {
                acc[u][q] = M::mul_add(acc[u][q], c[u], xl[u * K + q]);
            }
        }
    }
    for u in 0..NA {
        if u < c_rest.len() {
            for q in 0..K {
                acc[u][q] = M::mul_add(acc[u][q], c_rest[u], x_rest[u * K + q]);
            }
        }
    }
    reduce(acc)
}
