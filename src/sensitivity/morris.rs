//! Morris screening (Morris 1991, with Campolongo, Cariboni & Saltelli 2007's μ*): `r`
//! trajectories through the unit cube on a grid of `p` levels, each moving one parameter at a
//! time by Δ = p / (2(p − 1)); r·(k + 1) runs for k parameters. The elementary effect of
//! parameter i on a trajectory is (y(x + Δeᵢ) − y(x)) / Δ, in the output's unit per unit of
//! the range: the change across the whole range were the output linear in it. μ* (the mean of
//! |EE|) ranks the parameters; σ (their spread) says how far an effect depends on the others
//! or bends.

use rand::seq::SliceRandom;
use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::SeedableRng;
use rand_distr::{Distribution, Uniform};

/// Grid levels of the design (Δ = 2/3: from each level one step up or down fits).
pub const LEVELS: usize = 4;

/// A Morris design: the points, trajectory by trajectory, and which parameter each step moves.
#[derive(Debug, Clone, PartialEq)]
pub struct Design {
    /// Parameters.
    pub k: usize,
    /// Points in the unit cube, r·(k + 1), trajectory after trajectory.
    pub points: Vec<Vec<f64>>,
    /// For point j·(k+1) + s (s ≥ 1): the parameter that step s of trajectory j moved.
    pub moved: Vec<Vec<usize>>,
}

/// One parameter's elementary effects on one output.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Effect {
    /// Mean of the effects (signed).
    pub mu: f64,
    /// Mean of their absolute values: the ranking measure.
    pub mu_star: f64,
    /// Their standard deviation (n − 1).
    pub sigma: f64,
}

impl Design {
    /// `r` trajectories for `k` parameters, from `seed` (the same seed, the same design).
    pub fn new(k: usize, r: usize, seed: u64) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let step = 1.0 / (LEVELS - 1) as f64;
        let delta = LEVELS as f64 / (2.0 * (LEVELS - 1) as f64);
        let level = Uniform::new(0, LEVELS).expect("LEVELS > 0");
        let mut points = Vec::with_capacity(r * (k + 1));
        let mut moved = Vec::with_capacity(r);
        for _ in 0..r {
            let mut x: Vec<f64> = (0..k)
                .map(|_| level.sample(&mut rng) as f64 * step)
                .collect();
            let mut order: Vec<usize> = (0..k).collect();
            order.shuffle(&mut rng);
            points.push(x.clone());
            for &i in &order {
                x[i] = if x[i] + delta <= 1.0 + 1e-12 {
                    x[i] + delta
                } else {
                    x[i] - delta
                };
                points.push(x.clone());
            }
            moved.push(order);
        }
        Design { k, points, moved }
    }

    /// The trajectories.
    pub fn trajectories(&self) -> usize {
        self.moved.len()
    }

    /// The effects of every parameter on an output `y` (one value per point, in order).
    pub fn effects(&self, y: &[f64]) -> Vec<Effect> {
        let k = self.k;
        let mut ee: Vec<Vec<f64>> = vec![Vec::new(); k];
        for (j, order) in self.moved.iter().enumerate() {
            let base = j * (k + 1);
            for (s, &i) in order.iter().enumerate() {
                let (a, b) = (base + s, base + s + 1);
                let dx = self.points[b][i] - self.points[a][i];
                ee[i].push((y[b] - y[a]) / dx);
            }
        }
        ee.iter()
            .map(|e| {
                let n = e.len().max(1) as f64;
                let mu = e.iter().sum::<f64>() / n;
                let mu_star = e.iter().map(|v| v.abs()).sum::<f64>() / n;
                let sigma = if e.len() > 1 {
                    (e.iter().map(|v| (v - mu).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
                } else {
                    0.0
                };
                Effect { mu, mu_star, sigma }
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_step_moves_one_parameter_by_delta_within_the_cube() {
        let d = Design::new(5, 7, 3);
        assert_eq!(d.points.len(), 7 * 6);
        for (j, order) in d.moved.iter().enumerate() {
            let mut seen = order.clone();
            seen.sort_unstable();
            assert_eq!(seen, vec![0, 1, 2, 3, 4]);
            for (s, &i) in order.iter().enumerate() {
                let (a, b) = (&d.points[j * 6 + s], &d.points[j * 6 + s + 1]);
                for m in 0..5 {
                    let diff = (b[m] - a[m]).abs();
                    if m == i {
                        assert!((diff - 2.0 / 3.0).abs() < 1e-12);
                    } else {
                        assert_eq!(diff, 0.0);
                    }
                    assert!((0.0..=1.0).contains(&b[m]));
                }
            }
        }
        assert_eq!(d, Design::new(5, 7, 3), "the same seed, the same design");
    }

    /// A linear function's effects are its coefficients, exactly and with no spread; a
    /// product's spread shows the interaction.
    #[test]
    fn a_linear_output_gives_its_coefficients() {
        let d = Design::new(3, 10, 1);
        let y: Vec<f64> = d
            .points
            .iter()
            .map(|x| 4.0 * x[0] - 2.0 * x[1] + 0.0 * x[2])
            .collect();
        let e = d.effects(&y);
        assert!((e[0].mu - 4.0).abs() < 1e-12 && e[0].sigma < 1e-12);
        assert!((e[1].mu + 2.0).abs() < 1e-12 && (e[1].mu_star - 2.0).abs() < 1e-12);
        assert!(e[2].mu_star < 1e-12);
        let y: Vec<f64> = d.points.iter().map(|x| x[0] * x[1]).collect();
        let e = d.effects(&y);
        assert!(e[0].sigma > 0.1 && e[2].mu_star < 1e-12, "{e:?}");
    }
}
