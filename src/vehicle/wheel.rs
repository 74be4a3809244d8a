//! Wheel names: `1L`, `1R`, `2L`, … from the front, left/right facing the running direction.

/// Name of wheel `k` (0 → `1L`, 1 → `1R`, 2 → `2L`, …).
pub fn wheel_name(k: usize) -> String {
    format!(
        "{}{}",
        k / 2 + 1,
        if k.is_multiple_of(2) { 'L' } else { 'R' }
    )
}

/// Parses a wheel name like `1L` into an index `2·(n−1) + side`.
pub fn parse_wheel(s: &str, n_wheelsets: usize) -> Option<usize> {
    let s = s.trim().to_ascii_uppercase();
    let (num, side) = s.split_at(s.len().checked_sub(1)?);
    let n: usize = num.parse().ok()?;
    let side = match side {
        "L" => 0,
        "R" => 1,
        _ => return None,
    };
    (1..=n_wheelsets).contains(&n).then_some(2 * (n - 1) + side)
}
