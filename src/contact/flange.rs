//! A wheel profile's flange: where its tip lies and how high it stands over the tape circle,
//! and the check that a profile read from a file rises toward the gauge side, as the
//! convention has it.

use super::Profile;

/// A wheel's flange.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Flange {
    /// Lateral position of the tip, m (the internal convention: negative, toward the gauge
    /// side).
    pub tip_y: f64,
    /// Height of the tip over the tape circle (`y = 0`), m (S1002: 28 mm).
    pub height: f64,
}

/// The lowest flange a railway wheel profile may have, m: tram wheels stand about 20 mm, S1002
/// 28 mm (a limit chosen below both; a profile under it has lost its flange, cut short).
pub const MIN_FLANGE_HEIGHT: f64 = 15e-3;

impl Flange {
    /// The highest point of `wheel` over its tape circle, sampled at 2 000 points.
    pub fn of(wheel: &Profile) -> Flange {
        let (lo, hi) = wheel.range();
        let (tip_y, tip) = (0..=2000)
            .map(|i| {
                let y = lo + (hi - lo) * i as f64 / 2000.0;
                (y, wheel.eval(y).0)
            })
            .fold((0.0, f64::MIN), |a, b| if b.1 > a.1 { b } else { a });
        Flange {
            tip_y,
            height: tip - wheel.eval(0.0).0,
        }
    }

    /// Refuses a wheel profile whose highest point lies on the field side (+y: a mirrored
    /// file), saying so. A profile without a flange (a pure cone, as the textbook checks use)
    /// passes; [`Flange::is_flangeless`] tells a caller to say so.
    pub fn check(wheel: &Profile) -> Result<Flange, String> {
        let f = Flange::of(wheel);
        if f.tip_y > 0.0 {
            return Err(format!(
                "its highest point lies at y = {:+.1} mm, on the field side: the file's y runs the other way (mirror it: wheel_profile_mirror_y = true)",
                f.tip_y * 1e3
            ));
        }
        Ok(f)
    }

    /// Lower than [`MIN_FLANGE_HEIGHT`]: no flange (a cone, or a file cut short).
    pub fn is_flangeless(&self) -> bool {
        self.height < MIN_FLANGE_HEIGHT
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::profile::s1002;

    #[test]
    fn s1002_has_a_28_mm_flange_on_the_gauge_side_a_mirror_is_refused_a_cut_one_flangeless() {
        let f = Flange::check(&s1002()).unwrap();
        assert!((f.height - 0.028).abs() < 3e-4 && f.tip_y < -0.03, "{f:?}");
        let pts: Vec<(f64, f64)> = (0..=600)
            .rev()
            .map(|i| {
                let y = -0.0695 + 0.1295 * i as f64 / 600.0;
                (-y, s1002().eval(y).0)
            })
            .collect();
        let mirrored = Profile::from_points("mirrored", &pts).unwrap();
        assert!(Flange::check(&mirrored).unwrap_err().contains("field side"));
        let tread: Vec<(f64, f64)> = (0..=300)
            .map(|i| {
                let y = 0.06 * i as f64 / 300.0 - 0.01;
                (y, s1002().eval(y).0)
            })
            .collect();
        let cut = Profile::from_points("cut", &tread).unwrap();
        assert!(Flange::check(&cut).unwrap().is_flangeless());
    }
}
