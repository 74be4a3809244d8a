//! The local track frame at a distance `s`: origin on the centre line at rail-top level, axes
//! along the track (x), across it to the left in the canted track plane (y), and normal to that
//! plane (z). `R = Rz(heading)·Ry(−atan(gradient))·Rx(cant angle)`.

use crate::track::{RailIrregularity, Track, TrackPoint};
use nalgebra::{Matrix3, Vector3};

/// Track frame and track data at one position.
#[derive(Debug, Clone, Copy)]
pub struct TrackFrame {
    /// Everything the track says here.
    pub point: TrackPoint,
    /// Origin, world, m.
    pub origin: Vector3<f64>,
    /// Axes as columns (x along, y left, z up), world.
    pub axes: Matrix3<f64>,
}

impl TrackFrame {
    /// Frame at `s`.
    pub fn at(track: &Track, s: f64) -> Self {
        let p = track.at(s);
        // The product written out: Rz(ψ) = [cψ −sψ 0; sψ cψ 0; 0 0 1], Ry(−θ) with
        // tan θ = gradient = [cθ 0 −sθ; 0 1 0; sθ 0 cθ], Rx(φ) = [1 0 0; 0 cφ −sφ; 0 sφ cφ].
        let (sh, ch) = p.heading.sin_cos();
        let cg = 1.0 / (1.0 + p.gradient * p.gradient).sqrt();
        let sg = p.gradient * cg;
        let (sc, cc) = p.cant_angle.sin_cos();
        // Ry(−θ)·Rx(φ) = [cθ, −sθ·sφ, −sθ·cφ; 0, cφ, −sφ; sθ, cθ·sφ, cθ·cφ].
        let m = Matrix3::new(cg, -sg * sc, -sg * cc, 0.0, cc, -sc, sg, cg * sc, cg * cc);
        let rz = Matrix3::new(ch, -sh, 0.0, sh, ch, 0.0, 0.0, 0.0, 1.0);
        TrackFrame {
            point: p,
            origin: Vector3::new(p.x, p.y, p.elevation),
            axes: rz * m,
        }
    }

    /// Rail irregularities here.
    pub fn rails(&self) -> &RailIrregularity {
        &self.point.rails
    }

    /// A world vector in track axes.
    #[inline]
    pub fn to_local(&self, v: &Vector3<f64>) -> Vector3<f64> {
        self.axes.transpose() * v
    }
}

/// Improves `s` so that the track point at `s` lies abreast of the world point `p` (Newton on
/// the horizontal along-track offset; two steps from a close guess are plenty).
pub fn project(track: &Track, p: &Vector3<f64>, mut s: f64) -> f64 {
    for _ in 0..3 {
        let (x, y, heading, curvature) = track.centre_line(s);
        let (sh, ch) = heading.sin_cos();
        let along = (p.x - x) * ch + (p.y - y) * sh;
        // 1 − κ·lateral corrects for the curvature of the centre line.
        let lateral = -(p.x - x) * sh + (p.y - y) * ch;
        let ds = along / (1.0 - curvature * lateral);
        s += ds;
        if ds.abs() < 1e-9 {
            break;
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Rotation3;

    /// The written-out product is the rotations' own, on a canted, graded curve.
    #[test]
    fn the_frame_is_the_three_rotations() {
        let track = Track::load("tracks/grade20_L25.toml".as_ref()).unwrap();
        let (mut graded, mut canted) = (false, false);
        for s in (0..40).map(|k| 50.0 * k as f64) {
            let f = TrackFrame::at(&track, s);
            let p = f.point;
            let rot = Rotation3::from_axis_angle(&Vector3::z_axis(), p.heading)
                * Rotation3::from_axis_angle(&Vector3::y_axis(), -p.gradient.atan())
                * Rotation3::from_axis_angle(&Vector3::x_axis(), p.cant_angle);
            assert!((f.axes - rot.into_inner()).amax() < 1e-14, "{s}");
            graded |= p.gradient.abs() > 0.01;
            canted |= p.cant_angle.abs() > 0.01;
        }
        assert!(
            graded && canted,
            "the test track is graded and canted somewhere"
        );
    }
}
