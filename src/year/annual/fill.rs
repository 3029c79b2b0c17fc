//! A fitted piece's samples with its unlit ones filled in ([`fill_dark`]): the spline is fitted
//! through every node, so a sample where the piece is not lit borrows the nearest lit one.

/// Replaces unlit samples (None) with the nearest lit sample of the same day, then days with no
/// lit sample with the nearest lit day (periodically). None if the surface is never lit.
pub(super) fn fill_dark(samples: &[Option<f64>], days: usize, per_day: usize) -> Option<Vec<f64>> {
    let mut by_day: Vec<Option<Vec<f64>>> = samples.chunks(per_day).map(fill_day).collect();
    let lit: Vec<usize> = (0..days).filter(|&d| by_day[d].is_some()).collect();
    if lit.is_empty() {
        return None;
    }
    for d in 0..days {
        if by_day[d].is_none() {
            let periodic = |a: usize| {
                let diff = a.abs_diff(d);
                diff.min(days - diff)
            };
            let nearest = lit.iter().copied().min_by_key(|&a| periodic(a))?;
            by_day[d] = by_day[nearest].clone();
        }
    }
    Some(by_day.into_iter().flatten().flatten().collect())
}

/// One day's samples with gaps filled from the nearest lit sample (earlier wins ties).
fn fill_day(day: &[Option<f64>]) -> Option<Vec<f64>> {
    let lit: Vec<usize> = (0..day.len()).filter(|&j| day[j].is_some()).collect();
    if lit.is_empty() {
        return None;
    }
    Some(
        (0..day.len())
            .map(|j| {
                let nearest = lit.iter().copied().min_by_key(|&k| k.abs_diff(j)).unwrap_or(j);
                day[nearest].unwrap_or(0.0)
            })
            .collect(),
    )
}
