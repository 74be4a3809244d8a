//! Binds the names and numbers of a vehicle file to the bodies of its URDF: every force element
//! reads its own table of the file through this (see each element's `bind`), so a misspelt link
//! or a negative stiffness is reported with the file and the field.

use super::body::{Attachment, Body};
use crate::error::{Error, Result};
use nalgebra::Vector3;
use std::path::Path;

/// The vehicle file being read and the bodies its elements attach to.
pub(crate) struct Binder<'a> {
    /// The vehicle TOML file (for messages).
    pub path: &'a Path,
    /// The URDF file (for messages).
    pub urdf: &'a Path,
    /// Bodies read from the URDF.
    pub bodies: &'a [Body],
}

impl Binder<'_> {
    /// A configuration error at `field` of the vehicle file.
    pub fn err(&self, field: impl Into<String>, msg: impl Into<String>) -> Error {
        Error::config(self.path, field.into(), msg.into())
    }

    /// Index of the body called `name`.
    pub fn find(&self, field: impl Into<String>, name: &str) -> Result<usize> {
        self.bodies
            .iter()
            .position(|b| b.name == name)
            .ok_or_else(|| {
                self.err(
                    field,
                    format!(
                        "unknown link \"{name}\" (not in {}; links: {})",
                        self.urdf.display(),
                        self.bodies
                            .iter()
                            .map(|b| b.name.as_str())
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                )
            })
    }

    /// Upper and lower attachments of a two-point element: `upper_at` on the upper body and
    /// `lower_at` on the lower one (vehicle frame, m, static loaded position), and the rest
    /// offset `lower_at − upper_at` the element measures its displacement from. The one-point
    /// `at` of older files is refused with what to write instead: an element acting at one
    /// point for both bodies put the side frames' pads and nests at the wrong heights
    /// (assets/docs/physics.md §2). Each point must lie on its body (within its inertia box grown by
    /// [`Self::REACH`]) and the two no more than [`Self::SPAN`] apart.
    pub fn pair(
        &self,
        f: &str,
        (upper, lower): (&str, &str),
        at: Option<[f64; 3]>,
        (upper_at, lower_at): (Option<[f64; 3]>, Option<[f64; 3]>),
    ) -> Result<(Attachment, Attachment, Vector3<f64>)> {
        let u = self.find(format!("{f}.upper"), upper)?;
        let l = self.find(format!("{f}.lower"), lower)?;
        if let Some(p) = at {
            return Err(self.err(
                format!("{f}.at"),
                format!(
                    "one point for both bodies is no longer read: write `upper_at` (where the element meets \"{upper}\") and `lower_at` (where it meets \"{lower}\"), e.g. upper_at = {p:?} and lower_at = {p:?} if they truly meet there (assets/docs/file-formats.md, vehicle files)"
                ),
            ));
        }
        let point = |field: &str, p: Option<[f64; 3]>, body: usize| -> Result<Vector3<f64>> {
            let p = p.ok_or_else(|| {
                self.err(
                    format!("{f}.{field}"),
                    format!(
                        "missing: where the element meets \"{}\" (vehicle frame, m)",
                        self.bodies[body].name
                    ),
                )
            })?;
            if p.iter().any(|v| !v.is_finite()) {
                return Err(self.err(format!("{f}.{field}"), "must be finite"));
            }
            let p = Vector3::from(p);
            let b = &self.bodies[body];
            let half = b.half_extents();
            let rel = p - b.position;
            if (0..3).any(|k| rel[k].abs() > half[k] + Self::REACH) {
                return Err(self.err(
                    format!("{f}.{field}"),
                    format!(
                        "{:?} does not lie on \"{}\": {:.2} m from its centre of gravity at {:?}, beyond its extent (±{:.2}, ±{:.2}, ±{:.2} m from its inertia, plus {} m)",
                        [p.x, p.y, p.z],
                        b.name,
                        rel.norm(),
                        [b.position.x, b.position.y, b.position.z],
                        half.x,
                        half.y,
                        half.z,
                        Self::REACH
                    ),
                ));
            }
            Ok(p)
        };
        let pu = point("upper_at", upper_at, u)?;
        let pl = point("lower_at", lower_at, l)?;
        let rest = pl - pu;
        if rest.norm() > Self::SPAN {
            return Err(self.err(
                format!("{f}.lower_at"),
                format!(
                    "{:.2} m from upper_at: the two points of one element lie at most {} m apart",
                    rest.norm(),
                    Self::SPAN
                ),
            ));
        }
        let attach = |body: usize, p: Vector3<f64>| Attachment {
            body,
            local: p - self.bodies[body].position,
        };
        Ok((attach(u, pu), attach(l, pl), rest))
    }

    /// How far beyond its inertia box (the uniform box of the body's mass and principal
    /// inertias) an attachment point may lie, m: the box is a rough size (a bolster's ends
    /// reach past the box of its inertia).
    pub const REACH: f64 = 0.3;

    /// The largest distance between the two points of one element, m.
    pub const SPAN: f64 = 1.0;

    /// Checks that every value is finite, ≥ 0 and within the physical bound its field
    /// declares ([`crate::bounds::element_bound`]).
    pub fn non_negative(&self, field: impl Into<String>, values: &[f64]) -> Result<()> {
        let field = field.into();
        if let Some(v) = values.iter().find(|v| !(v.is_finite() && **v >= 0.0)) {
            return Err(self.err(
                field,
                format!("must not be negative, got {}", crate::bounds::show(*v)),
            ));
        }
        for &v in values {
            self.within_bound(&field, v)?;
        }
        Ok(())
    }

    /// Checks that `v` is finite, > 0 and within its field's physical bound, and returns it.
    pub fn positive(&self, field: impl Into<String>, v: f64) -> Result<f64> {
        let field = field.into();
        if v.is_finite() && v > 0.0 {
            self.within_bound(&field, v)?;
            Ok(v)
        } else {
            Err(self.err(
                field,
                format!("must be positive, got {}", crate::bounds::show(v)),
            ))
        }
    }

    fn within_bound(&self, field: &str, v: f64) -> Result<()> {
        match crate::bounds::element_bound(field) {
            Some((max, what)) if v.abs() > max => Err(self.err(
                field,
                format!(
                    "{} is beyond the physical bound of {} for {what}",
                    crate::bounds::show(v),
                    crate::bounds::show(max)
                ),
            )),
            _ => Ok(()),
        }
    }
}
