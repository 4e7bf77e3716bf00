//! Summaries of a list of values that the measures share: root mean square and percentile.

/// The `fraction` percentile (nearest rank) of `values`; 0 for none.
pub fn percentile(mut values: Vec<f64>, fraction: f64) -> f64 {
    if values.is_empty() {
        return 0.0;
    }
    values.sort_by(f64::total_cmp);
    let index = ((fraction * values.len() as f64).ceil() as usize).clamp(1, values.len()) - 1;
    values[index]
}

/// The root mean square of `values`; 0 for none.
pub(crate) fn rms(values: impl Iterator<Item = f64>) -> f64 {
    let (sum, count) = values.fold((0.0, 0usize), |(s, c), v| (s + v * v, c + 1));
    if count == 0 {
        0.0
    } else {
        (sum / count as f64).sqrt()
    }
}
