//! Naming a mode by where its kinetic energy lies.

use super::ShapeEntry;

/// The family of a mode from its energy shares (a reading of where the energy lies, the way
/// engineers name modes): the wheelsets' lateral and yaw motion → `wheelset hunting`; the
/// bogie frames' (bolsters, side frames) lateral, yaw and roll with the wheelsets taking part
/// → `bogie hunting`; the carbody → `carbody lower sway` (lateral), `upper sway` (roll), `yaw`,
/// `bounce`, `pitch`; the rails → `rail`; otherwise the dominant body and motion.
pub(super) fn family(shape: &[ShapeEntry], wheelsets: &[&str], carbody: Option<&str>) -> String {
    let is_wheelset = |b: &str| wheelsets.contains(&b);
    let sum = |f: &dyn Fn(&ShapeEntry) -> bool| {
        shape.iter().filter(|s| f(s)).map(|s| s.share).sum::<f64>()
    };
    let ws_hunt = sum(&|s| is_wheelset(&s.body) && (s.dof == "lateral" || s.dof == "yaw"));
    let rails = sum(&|s| s.body.starts_with("rail "));
    let car = sum(&|s| carbody == Some(s.body.as_str()));
    let bogie = sum(&|s| {
        !is_wheelset(&s.body)
            && !s.body.starts_with("rail ")
            && carbody != Some(s.body.as_str())
            && matches!(s.dof, "lateral" | "yaw" | "roll")
    });
    if rails >= 0.5 {
        return "rail".into();
    }
    if ws_hunt >= 0.5 {
        return "wheelset hunting".into();
    }
    if car >= bogie && car >= ws_hunt && car > 0.3 {
        let dof = |d: &str| sum(&|s| carbody == Some(s.body.as_str()) && s.dof == d);
        let by = [
            ("carbody lower sway", dof("lateral")),
            ("carbody upper sway", dof("roll")),
            ("carbody yaw", dof("yaw")),
            ("carbody bounce", dof("vertical")),
            ("carbody pitch", dof("pitch")),
            ("carbody longitudinal", dof("longitudinal")),
        ];
        return by
            .iter()
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .map(|b| b.0.to_string())
            .unwrap_or_default();
    }
    if bogie + ws_hunt >= 0.5 && ws_hunt >= 0.1 {
        return "bogie hunting".into();
    }
    // Otherwise the kind of body (its name without the number and side: `sideframe1l` →
    // `sideframe`) and the motion holding most energy, summed over the bodies of that kind.
    let kind = |b: &str| {
        let side =
            b.len() >= 2 && b.ends_with(['l', 'r']) && b.as_bytes()[b.len() - 2].is_ascii_digit();
        let b = if side { &b[..b.len() - 1] } else { b };
        b.trim_end_matches(|c: char| c.is_ascii_digit()).to_string()
    };
    let mut groups: Vec<(String, &str, f64)> = Vec::new();
    for s in shape {
        let k = kind(&s.body);
        match groups.iter_mut().find(|g| g.0 == k && g.1 == s.dof) {
            Some(g) => g.2 += s.share,
            None => groups.push((k, s.dof, s.share)),
        }
    }
    groups
        .iter()
        .max_by(|a, b| a.2.total_cmp(&b.2))
        .map_or("unnamed".into(), |g| format!("{} {}", g.0, g.1))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn entry(body: &str, dof: &'static str, share: f64) -> ShapeEntry {
        ShapeEntry {
            body: body.into(),
            dof,
            share,
            amplitude: 1.0,
            phase_deg: 0.0,
        }
    }

    /// Modes planted with known energy shares get the families engineers use.
    #[test]
    fn modes_are_named_by_their_energy() {
        let ws = ["wheelset1", "wheelset2"];
        let name = |shape: &[ShapeEntry]| family(shape, &ws, Some("carbody"));
        assert_eq!(
            name(&[
                entry("wheelset1", "lateral", 0.4),
                entry("wheelset2", "yaw", 0.3)
            ]),
            "wheelset hunting"
        );
        assert_eq!(
            name(&[
                entry("bolster1", "yaw", 0.3),
                entry("sideframe1l", "lateral", 0.3),
                entry("wheelset1", "yaw", 0.2),
                entry("carbody", "lateral", 0.2),
            ]),
            "bogie hunting"
        );
        assert_eq!(
            name(&[
                entry("carbody", "lateral", 0.6),
                entry("carbody", "roll", 0.3)
            ]),
            "carbody lower sway"
        );
        assert_eq!(
            name(&[
                entry("carbody", "roll", 0.6),
                entry("carbody", "lateral", 0.3)
            ]),
            "carbody upper sway"
        );
        assert_eq!(name(&[entry("carbody", "yaw", 0.8)]), "carbody yaw");
        assert_eq!(
            name(&[
                entry("rail 1L", "lateral", 0.4),
                entry("rail 1R", "lateral", 0.4)
            ]),
            "rail"
        );
        // Otherwise the kind of body and its motion, summed over bodies of that kind.
        assert_eq!(
            name(&[
                entry("sideframe1l", "yaw", 0.3),
                entry("sideframe2r", "yaw", 0.3),
                entry("bolster1", "vertical", 0.4),
            ]),
            "sideframe yaw"
        );
    }
}
