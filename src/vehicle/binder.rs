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

    /// Upper and lower attachments of a two-point element at the shared point `at` (vehicle
    /// frame, m).
    pub fn pair(
        &self,
        f: &str,
        upper: &str,
        lower: &str,
        at: [f64; 3],
    ) -> Result<(Attachment, Attachment)> {
        if at.iter().any(|v| !v.is_finite()) {
            return Err(self.err(format!("{f}.at"), "must be finite"));
        }
        let u = self.find(format!("{f}.upper"), upper)?;
        let l = self.find(format!("{f}.lower"), lower)?;
        let attach = |body: usize| Attachment {
            body,
            local: Vector3::from(at) - self.bodies[body].position,
        };
        Ok((attach(u), attach(l)))
    }

    /// Checks that every value is finite and ≥ 0.
    pub fn non_negative(&self, field: impl Into<String>, values: &[f64]) -> Result<()> {
        if let Some(v) = values.iter().find(|v| !(v.is_finite() && **v >= 0.0)) {
            return Err(self.err(field, format!("must not be negative, got {v}")));
        }
        Ok(())
    }

    /// Checks that `v` is finite and > 0, and returns it.
    pub fn positive(&self, field: impl Into<String>, v: f64) -> Result<f64> {
        if v.is_finite() && v > 0.0 {
            Ok(v)
        } else {
            Err(self.err(field, format!("must be positive, got {v}")))
        }
    }
}
