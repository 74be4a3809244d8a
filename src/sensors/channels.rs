//! Channel names, units and kinds. Every recorded run has the axis channels (`time_s`,
//! `s_m`), the paper's 21 inputs (vehicles with a sensor layout), the forces and contact
//! quantities of every wheel (`w1l_force_y` …), body signals (`carbody_acc_y` …) and the
//! deflections of the suspension elements (`nest_sideframe1l_z` …, see
//! [`crate::vehicle::elements::Element::gauges`]).

use serde::{Deserialize, Serialize};

/// Names of the paper's 21 input channels, in order X1 … X21 (assets/docs/physics.md §5). The three
/// creepages and the angle of attack are those of the label wheel (1L in the paper).
pub const PAPER_CHANNELS: [&str; 21] = [
    "frame_l_acc_y",
    "frame_r_acc_y",
    "frame_l_acc_z",
    "frame_r_acc_z",
    "bolster_acc_y",
    "bolster_acc_z",
    "ws1_acc_y",
    "ws1_acc_z",
    "ws1_y_rel",
    "ws1_yaw",
    "ws1_roll",
    "body_roll_rate",
    "body_pitch_rate",
    "body_yaw_rate",
    "ws1_roll_rate",
    "ws1_pitch_rate",
    "ws1_yaw_rate",
    "ws1_attack_angle",
    "w1l_creep_y",
    "w1l_creep_x",
    "w1l_creep_spin",
];

/// Units of [`PAPER_CHANNELS`].
pub const PAPER_UNITS: [&str; 21] = [
    "m/s2", "m/s2", "m/s2", "m/s2", "m/s2", "m/s2", "m/s2", "m/s2", "m", "rad", "rad", "rad/s",
    "rad/s", "rad/s", "rad/s", "rad/s", "rad/s", "rad", "1", "1", "1/m",
];

/// Suffix of the noised copy of an input channel.
pub const NOISY_SUFFIX: &str = "_noisy";

/// `<channel>_noisy`.
pub fn noisy_name(channel: &str) -> String {
    format!("{channel}{NOISY_SUFFIX}")
}

/// Whether a name is a noised copy.
pub fn is_noisy(name: &str) -> bool {
    name.ends_with(NOISY_SUFFIX)
}

/// The clean channel a name refers to (`x_noisy` → `x`).
pub fn clean_name(name: &str) -> &str {
    name.strip_suffix(NOISY_SUFFIX).unwrap_or(name)
}

/// Lateral and vertical force channels of a wheel named `1L` … `4R`: the labels FL and FQ.
pub fn label_channels(wheel: &str) -> [String; 2] {
    let w = wheel.to_ascii_lowercase();
    [format!("w{w}_force_y"), format!("w{w}_force_z")]
}

/// The vehicle's total mass, t: a constant of each run that an operator knows without a
/// sensor (the weighbridge ticket, the consist list), recorded so a model may read it beside
/// the signals (assets/docs/learning.md §4.6). Never a feature-selection candidate.
pub const VEHICLE_MASS: &str = "vehicle_mass_t";

/// Prefixes of the suspension-deflection channels (one per element kind that has a gauge).
/// The prefix of the train's channels (`coupler_front_force`, …): [`ChannelKind::Train`].
pub const TRAIN_PREFIX: &str = "coupler_";

/// Channel-name prefixes of suspension deflections.
pub const DEFLECTION_PREFIXES: [&str; 4] = ["nest_", "pad_", "sidebearer_", "centreplate_"];

/// Body signals a sensor on board can measure (accelerometers, gyroscopes, track-relative
/// displacement and angle references); see `sim::output`.
const BODY_MEASURABLE: [&str; 10] = [
    "acc_x",
    "acc_y",
    "acc_z",
    "roll_rate",
    "pitch_rate",
    "yaw_rate",
    "y_rel",
    "z_rel",
    "roll",
    "yaw",
];

/// What a channel is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ChannelKind {
    /// Time or distance.
    Axis,
    /// One of the paper's 21 inputs.
    Input,
    /// A noised copy of an input.
    InputNoisy,
    /// A force of the label wheel (FL, FQ).
    Label,
    /// A quantity of one wheel (force, contact, creepage, the rail's deflection under it): not
    /// measurable on board.
    Wheel,
    /// A body signal (acceleration, rate, track-relative position or angle).
    Body,
    /// The deflection of a suspension element (displacement transducer).
    Deflection,
    /// A constant of the run known without a sensor ([`VEHICLE_MASS`]).
    Known,
    /// A quantity of the train around the wagon (coupler force and angle): recorded in a
    /// run with a consist, measured by no wagon, never an input candidate.
    Train,
}

impl ChannelKind {
    /// Kind of `name`, given the two label channels.
    pub fn of(name: &str, labels: &[String; 2]) -> ChannelKind {
        if name == "time_s" || name == "s_m" {
            return ChannelKind::Axis;
        }
        if name == VEHICLE_MASS {
            return ChannelKind::Known;
        }
        if is_noisy(name) {
            return ChannelKind::InputNoisy;
        }
        if PAPER_CHANNELS.contains(&name) {
            return ChannelKind::Input;
        }
        if labels.iter().any(|l| l == name) {
            return ChannelKind::Label;
        }
        if name.starts_with(TRAIN_PREFIX) {
            return ChannelKind::Train;
        }
        if DEFLECTION_PREFIXES.iter().any(|p| name.starts_with(p)) {
            return ChannelKind::Deflection;
        }
        let b = name.as_bytes();
        if b.len() > 4 && b[0] == b'w' && b[1].is_ascii_digit() && b[3] == b'_' {
            return ChannelKind::Wheel;
        }
        ChannelKind::Body
    }

    /// Manifest name.
    pub fn name(self) -> &'static str {
        match self {
            ChannelKind::Axis => "axis",
            ChannelKind::Input => "input",
            ChannelKind::InputNoisy => "input_noisy",
            ChannelKind::Label => "label",
            ChannelKind::Wheel => "wheel",
            ChannelKind::Body => "body",
            ChannelKind::Deflection => "deflection",
            ChannelKind::Known => "known",
            ChannelKind::Train => "train",
        }
    }
}

/// Which signals feature selection chooses from (assets/docs/learning.md §2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Candidates {
    /// The paper's 21 channels.
    Paper21,
    /// Every on-board measurable signal: the paper's 21, every body's accelerations, angular
    /// rates and track-relative displacements and angles, and every suspension deflection.
    /// Forces, contact quantities and creepages of the wheels are not candidates.
    Onboard,
}

impl Candidates {
    /// Parses `paper21` or `onboard`.
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "paper21" => Some(Candidates::Paper21),
            "onboard" => Some(Candidates::Onboard),
            _ => None,
        }
    }

    /// Name as on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Candidates::Paper21 => "paper21",
            Candidates::Onboard => "onboard",
        }
    }

    /// The candidate channels among `names` (a data set's channels), in their order.
    pub fn among(self, names: &[String], labels: &[String; 2]) -> Vec<String> {
        names
            .iter()
            .filter(|n| match ChannelKind::of(n, labels) {
                ChannelKind::Input => true,
                ChannelKind::Deflection => self == Candidates::Onboard,
                ChannelKind::Body => {
                    self == Candidates::Onboard
                        && BODY_MEASURABLE
                            .iter()
                            .any(|s| n.ends_with(&format!("_{s}")))
                }
                _ => false,
            })
            .cloned()
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kinds_and_names() {
        let labels = label_channels("2R");
        assert_eq!(labels[0], "w2r_force_y");
        assert_eq!(ChannelKind::of("w2r_force_z", &labels), ChannelKind::Label);
        assert_eq!(ChannelKind::of("w1l_force_z", &labels), ChannelKind::Wheel);
        assert_eq!(ChannelKind::of("ws1_acc_y", &labels), ChannelKind::Input);
        assert_eq!(
            ChannelKind::of("ws1_acc_y_noisy", &labels),
            ChannelKind::InputNoisy
        );
        assert_eq!(
            ChannelKind::of("nest_sideframe1l_z", &labels),
            ChannelKind::Deflection
        );
        assert_eq!(ChannelKind::of("carbody_acc_y", &labels), ChannelKind::Body);
        assert_eq!(clean_name(&noisy_name("x")), "x");
        let names: Vec<String> = [
            "time_s",
            "ws1_acc_y",
            "w1l_force_y",
            "w1l_xi_x",
            "carbody_roll",
            "nest_sideframe1l_z",
            "carbody_acc_y_noisy",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        let l = label_channels("1L");
        assert_eq!(Candidates::Paper21.among(&names, &l), ["ws1_acc_y"]);
        assert_eq!(
            Candidates::Onboard.among(&names, &l),
            ["ws1_acc_y", "carbody_roll", "nest_sideframe1l_z"]
        );
    }
}
