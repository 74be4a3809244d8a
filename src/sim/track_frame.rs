//! The local track frame at a distance `s`: origin on the centre line at rail-top level, axes
//! along the track (x), across it to the left in the canted track plane (y), and normal to that
//! plane (z). `R = Rz(heading)·Ry(−atan(gradient))·Rx(cant angle)`.

use crate::track::{RailIrregularity, Track, TrackPoint};
use nalgebra::{Matrix3, Rotation3, Vector3};

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
        let rot = Rotation3::from_axis_angle(&Vector3::z_axis(), p.heading)
            * Rotation3::from_axis_angle(&Vector3::y_axis(), -p.gradient.atan())
            * Rotation3::from_axis_angle(&Vector3::x_axis(), p.cant_angle);
        TrackFrame {
            point: p,
            origin: Vector3::new(p.x, p.y, p.elevation),
            axes: rot.into_inner(),
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
