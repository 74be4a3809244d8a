//! Track: design geometry (horizontal alignment, cant, vertical profile) and irregularities.
//!
//! A [`Track`] is built from a track file ([`TrackSpec`]) and answers, for any distance `s`
//! along the centre line, a [`TrackPoint`]: position and heading in the plane, curvature,
//! cant, elevation and gradient, and the irregular offsets of both rails.

mod alignment;
pub mod check;
pub mod discrete;
mod file;
pub mod irregularity;
mod profile;
pub mod short_wave;
mod support;

pub use alignment::{Alignment, Section, SectionKind, Turn, cant_deficiency_acceleration};
pub use file::{MAX_CANT_MM, MAX_GRADIENT_PERMILLE, RAIL_SUPPORT_MODELS, TrackSpec};
pub use irregularity::{
    Channel, FraClass, GermanSpectrum, Irregularities, IrregularitySpec, RailIrregularity, Spectrum,
};
pub use profile::{Grade, VerticalProfile};
pub use support::{RailSupport, Support};

use crate::error::{Error, Result};
use std::path::Path;

/// Everything the track says at one position.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct TrackPoint {
    /// Distance along the centre line, m.
    pub s: f64,
    /// Plane position of the centre line, m (x along the initial direction, y to its left).
    pub x: f64,
    /// See `x`.
    pub y: f64,
    /// Heading, rad (positive turning left).
    pub heading: f64,
    /// Signed curvature, 1/m (positive for a left-hand curve).
    pub curvature: f64,
    /// Signed cant, m: height of the left rail over the right.
    pub cant: f64,
    /// Signed cant angle `asin(cant / rail_spacing)`, rad: roll of the track plane about the
    /// running direction (positive raises the left rail).
    pub cant_angle: f64,
    /// Elevation of the centre line, m.
    pub elevation: f64,
    /// Gradient dz/ds (positive uphill).
    pub gradient: f64,
    /// Vertical curvature d²z/ds², 1/m (positive in a sag).
    pub vertical_curvature: f64,
    /// Irregular offsets of both rails.
    pub rails: RailIrregularity,
}

/// A track ready to be queried.
#[derive(Debug, Clone)]
pub struct Track {
    spec: TrackSpec,
    alignment: Alignment,
    irregularities: Option<Irregularities>,
    short_waves: Option<short_wave::ShortWaves>,
}

impl Track {
    /// Loads a track file and builds the track with the file's irregularity seed.
    pub fn load(path: &Path) -> Result<Self> {
        Ok(Self::new(TrackSpec::load(path)?, None))
    }

    /// Builds a track; `seed` overrides the irregularity seed of the file (and the
    /// roughness's, which is drawn on its own stream of the same seed).
    pub fn new(mut spec: TrackSpec, seed: Option<u64>) -> Self {
        if let (Some(irr), Some(seed)) = (spec.irregularity.as_mut(), seed) {
            irr.seed = seed;
        }
        if let (Some(r), Some(seed)) = (
            spec.short_waves.as_mut().and_then(|w| w.roughness.as_mut()),
            seed,
        ) {
            r.seed = seed;
        }
        let alignment = Alignment::new(&spec.sections);
        let irregularities = spec
            .irregularity
            .map(|irr| Irregularities::synthesize(irr, spec.length()));
        let short_waves = spec
            .short_waves
            .map(|w| short_wave::ShortWaves::synthesize(w, spec.length()));
        Track {
            spec,
            alignment,
            irregularities,
            short_waves,
        }
    }

    /// The validated description the track was built from.
    pub fn spec(&self) -> &TrackSpec {
        &self.spec
    }

    /// Total length, m.
    pub fn length(&self) -> f64 {
        self.spec.length()
    }

    /// Horizontal alignment.
    pub fn alignment(&self) -> &Alignment {
        &self.alignment
    }

    /// Irregularity samples, if the track has irregularities.
    pub fn irregularities(&self) -> Option<&Irregularities> {
        self.irregularities.as_ref()
    }

    /// Rail roughness and weld dips, if the track has them.
    pub fn short_waves(&self) -> Option<&short_wave::ShortWaves> {
        self.short_waves.as_ref()
    }

    /// Everything the track says at `s` (clamped to the track).
    pub fn at(&self, s: f64) -> TrackPoint {
        let s = s.clamp(0.0, self.length());
        let (x, y, heading, curvature, cant) = self.alignment.at(s);
        let (elevation, gradient, vertical_curvature) = self.spec.profile.at(s);
        TrackPoint {
            s,
            x,
            y,
            heading,
            curvature,
            cant,
            cant_angle: crate::angle::asin(cant / self.spec.rail_spacing),
            elevation,
            gradient,
            vertical_curvature,
            rails: self.rails_at(s),
        }
    }

    /// The irregular offsets of both rails at `s`: the geometry's, and under each wheel's
    /// running surface the short waves' heights.
    fn rails_at(&self, s: f64) -> RailIrregularity {
        let mut r = self
            .irregularities
            .as_ref()
            .map(|irr| irr.rails_at(s))
            .unwrap_or_default();
        if let Some(w) = &self.short_waves {
            let [zl, dl, zr, dr] = w.at(s);
            r.left_z += zl;
            r.left_z_ds += dl;
            r.right_z += zr;
            r.right_z_ds += dr;
        }
        r
    }

    /// Centre-line position `(x, y)`, heading and curvature at `s` only (cheaper than
    /// [`Track::at`]: no profile, cant or irregularities).
    pub fn centre_line(&self, s: f64) -> (f64, f64, f64, f64) {
        let s = s.clamp(0.0, self.length());
        let (x, y, heading, curvature, _) = self.alignment.at(s);
        (x, y, heading, curvature)
    }

    /// Like [`Track::at`] but fails outside the track, for callers that must not run off it.
    pub fn try_at(&self, s: f64) -> Result<TrackPoint> {
        if !(0.0..=self.length()).contains(&s) {
            return Err(Error::Domain(format!(
                "position {s:.2} m is off the track '{}' (0 to {:.2} m)",
                self.spec.name,
                self.length()
            )));
        }
        Ok(self.at(s))
    }

    /// Writes the geometry and irregularities every `step` metres as CSV (SI units, header
    /// names carry the unit), atomically.
    pub fn write_csv(&self, path: &Path, step: f64) -> Result<()> {
        if !(step.is_finite() && step > 0.0) {
            return Err(Error::Domain(format!(
                "the sampling step must be positive, got {step} m"
            )));
        }
        let n = crate::bounds::count_of((self.length() / step).floor(), "track samples")?;
        crate::io::write_atomic(path, |w| {
            writeln!(
                w,
                "s_m,x_m,y_m,heading_rad,curvature_1pm,cant_m,cant_angle_rad,elevation_m,gradient,vertical_curvature_1pm,left_y_m,left_z_m,right_y_m,right_z_m"
            )?;
            for i in 0..=n {
                let p = self.at(i as f64 * step);
                let r = p.rails;
                writeln!(
                    w,
                    "{:.4},{:.6},{:.6},{:.9},{:.9},{:.6},{:.9},{:.6},{:.9},{:.9},{:.9},{:.9},{:.9},{:.9}",
                    p.s,
                    p.x,
                    p.y,
                    p.heading,
                    p.curvature,
                    p.cant,
                    p.cant_angle,
                    p.elevation,
                    p.gradient,
                    p.vertical_curvature,
                    r.left_y,
                    r.left_z,
                    r.right_y,
                    r.right_z
                )?;
            }
            Ok(())
        })
    }
}
