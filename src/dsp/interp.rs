//! Catmull–Rom cubic interpolation of samples on a regular grid.

/// Value and derivative (per unit of the grid's axis) of the Catmull–Rom cubic through
/// `v[i−1] … v[i+2]` in interval `i` at fraction `t` ∈ [0, 1], grid step `dx`.
#[inline]
pub fn catmull_rom(v: &[f64], i: usize, t: f64, dx: f64) -> (f64, f64) {
    let (p0, p1, p2, p3) = (v[i - 1], v[i], v[i + 1], v[i + 2]);
    let a = 2.0 * p1;
    let b = p2 - p0;
    let c = 2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3;
    let d = -p0 + 3.0 * p1 - 3.0 * p2 + p3;
    let val = 0.5 * (a + t * (b + t * (c + t * d)));
    let der = 0.5 * (b + t * (2.0 * c + 3.0 * t * d)) / dx;
    (val, der)
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_cubic_is_reproduced_with_its_derivative() {
        // Catmull–Rom reproduces quadratics exactly.
        let f = |x: f64| 0.5 * x * x - x + 2.0;
        let v: Vec<f64> = (0..6).map(|i| f(i as f64 * 0.1)).collect();
        let (y, d) = super::catmull_rom(&v, 2, 0.3, 0.1);
        assert!((y - f(0.23)).abs() < 1e-12 && (d - (0.23 - 1.0)).abs() < 1e-12);
    }
}
