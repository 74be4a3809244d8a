//! The bodies of a vehicle from its URDF file.

use super::body::Body;
use crate::error::{Error, Result};
use nalgebra::Vector3;
use std::path::Path;

/// The largest principal moment of inertia a vehicle body may have, kg·m² (a loaded C80's
/// carbody yaws with about 10⁶).
const MAX_INERTIA: f64 = 1e8;

/// The farthest a body may sit from the vehicle's origin, m.
const MAX_OFFSET: f64 = 100.0;

/// Reads the bodies of a URDF file: each link with an inertial (mass > 0), placed by the origin
/// of the joint that attaches it to the root (floating joints from a massless reference link).
pub(super) fn read_urdf(path: &Path) -> Result<Vec<Body>> {
    let text = crate::io::read_text(path)?;
    let robot = urdf_rs::read_from_string(&text).map_err(|e| match locate(&text) {
        Some((field, msg)) => Error::config(path, field, msg),
        None => Error::Parse {
            file: path.to_path_buf(),
            message: match e.to_string() {
                m if m.contains("No elements found") => {
                    format!("{m}: the file is empty or cut short")
                }
                m => m,
            },
        },
    })?;
    let mut bodies = Vec::new();
    for link in &robot.links {
        let inertial = &link.inertial;
        let m = inertial.mass.value;
        let is_root = !robot.joints.iter().any(|j| j.child.link == link.name);
        if is_root && m == 0.0 {
            continue; // the massless reference frame the bodies hang from
        }
        let err = |field: &str, msg: String| {
            Error::config(path, format!("link \"{}\".{field}", link.name), msg)
        };
        if !(m.is_finite() && m > 0.0) {
            return Err(err("mass", format!("must be positive, got {m}")));
        }
        crate::bounds::check_value(path, &format!("link \"{}\".mass_kg", link.name), m)?;
        let i = &inertial.inertia;
        for (name, v) in [("ixx", i.ixx), ("iyy", i.iyy), ("izz", i.izz)] {
            if !(v.is_finite() && v > 0.0 && v <= MAX_INERTIA) {
                return Err(err(
                    &format!("inertia.{name}"),
                    format!(
                        "must be positive and at most {MAX_INERTIA:e} kg·m², got {}",
                        crate::bounds::show(v)
                    ),
                ));
            }
        }
        // A rigid body's principal moments obey the triangle inequality (each at most the
        // sum of the other two); a set that does not is no body.
        if i.ixx > i.iyy + i.izz || i.iyy > i.ixx + i.izz || i.izz > i.ixx + i.iyy {
            return Err(err(
                "inertia",
                format!(
                    "({}, {}, {}) kg·m²: one principal moment exceeds the sum of the other two, which no rigid body has",
                    i.ixx, i.iyy, i.izz
                ),
            ));
        }
        if i.ixy != 0.0 || i.ixz != 0.0 || i.iyz != 0.0 {
            return Err(err(
                "inertia",
                "give principal moments (products of inertia 0)".into(),
            ));
        }
        let joint = robot.joints.iter().find(|j| j.child.link == link.name);
        let origin = joint.map(|j| *j.origin.xyz).unwrap_or([0.0; 3]);
        let com = *inertial.origin.xyz;
        for (what, p) in [("joint origin xyz", origin), ("inertial origin xyz", com)] {
            if p.iter().any(|v| !(v.is_finite() && v.abs() <= MAX_OFFSET)) {
                return Err(err(
                    what,
                    format!("{p:?}: every coordinate finite and within ±{MAX_OFFSET} m"),
                ));
            }
        }
        bodies.push(Body {
            name: link.name.clone(),
            mass: m,
            inertia: Vector3::new(i.ixx, i.iyy, i.izz),
            position: Vector3::from(origin) + Vector3::from(com),
        });
    }
    if bodies.is_empty() {
        return Err(Error::Parse {
            file: path.to_path_buf(),
            message: "no link with a positive mass".into(),
        });
    }
    Ok(bodies)
}

/// The link and field behind a URDF the parser refused, where a plain scan finds one: an
/// inertial without its mass or inertia, or a number that does not parse (the parser's own
/// message names neither).
fn locate(text: &str) -> Option<(String, String)> {
    // `name="…"` or `name='…'`, spaces allowed around `=`.
    let attr = |tag: &str, name: &str| -> Option<String> {
        let mut rest = tag;
        loop {
            let at = rest.find(name)?;
            let after = rest[at + name.len()..].trim_start();
            rest = &rest[at + name.len()..];
            if let Some(v) = after.strip_prefix('=') {
                let v = v.trim_start();
                let q = v.chars().next().filter(|c| *c == '"' || *c == '\'')?;
                return Some(v[1..].split(q).next()?.to_string());
            }
        }
    };
    for block in text.split("<link").skip(1) {
        let block = block.split("</link>").next().unwrap_or(block);
        let name = attr(block, "name").unwrap_or_default();
        let Some(inertial) = block.split("<inertial").nth(1) else {
            continue;
        };
        let field = |f: &str| format!("link \"{name}\".{f}");
        for (tag, attrs) in [
            ("<mass", &["value"][..]),
            ("<inertia", &["ixx", "ixy", "ixz", "iyy", "iyz", "izz"][..]),
        ] {
            let Some(t) = inertial.split(tag).nth(1) else {
                return Some((field(&tag[1..]), "missing from the inertial".into()));
            };
            let t = t.split('>').next().unwrap_or(t);
            for a in attrs {
                match attr(t, a) {
                    None if *tag == *"<mass" && !t.contains("value") => {
                        return Some((field("mass"), "has no value".into()));
                    }
                    Some(v) if v.trim().parse::<f64>().is_err() => {
                        let f = if tag == "<mass" {
                            "mass".into()
                        } else {
                            format!("inertia.{a}")
                        };
                        return Some((field(&f), format!("\"{v}\" is not a number")));
                    }
                    _ => {}
                }
            }
        }
    }
    None
}
