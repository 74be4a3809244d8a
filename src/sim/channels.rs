//! The recorder's channel list: every column a run writes, in order, with its unit and what
//! it measures. [`super::Recorder`] records exactly these; `railforce channels` prints them
//! and assets/docs/channels.md is that table (a test holds the two equal).

use crate::sensors::{ChannelKind, PAPER_CHANNELS, PAPER_UNITS, VEHICLE_MASS};
use crate::vehicle::Vehicle;

/// One recorded channel.
#[derive(Debug, Clone, PartialEq)]
pub struct Channel {
    /// Column name.
    pub name: String,
    /// Unit (`m/s2`, `rad/s`, `N`, `1` for a ratio).
    pub unit: &'static str,
    /// What it measures, with its sign.
    pub meaning: String,
}

/// The signals recorded for every body: suffix, unit, meaning.
pub(super) const BODY_SIGNALS: [(&str, &str, &str); 10] = [
    (
        "acc_x",
        "m/s2",
        "longitudinal acceleration, body axes (+ ahead)",
    ),
    ("acc_y", "m/s2", "lateral acceleration, body axes (+ left)"),
    ("acc_z", "m/s2", "vertical acceleration, body axes (+ up)"),
    ("roll_rate", "rad/s", "roll rate (+ about x ahead)"),
    (
        "pitch_rate",
        "rad/s",
        "pitch rate (+ about y left; a wheelset's spin)",
    ),
    ("yaw_rate", "rad/s", "yaw rate (+ about z up, turning left)"),
    (
        "y_rel",
        "m",
        "lateral displacement from the track centre line (+ left)",
    ),
    (
        "z_rel",
        "m",
        "vertical displacement from its static height over the track (+ up)",
    ),
    ("roll", "rad", "roll relative to the track (+ left side up)"),
    ("yaw", "rad", "yaw relative to the track (+ nose left)"),
];

/// The signals recorded for every wheel (per-wheel creepages are named `xi_*` so they never
/// clash with the paper's `w1l_creep_*` inputs): suffix, unit, meaning.
pub(super) const WHEEL_SIGNALS: [(&str, &str, &str); 9] = [
    (
        "force_y",
        "N",
        "Y: lateral force of the rail on the wheel, track axes (+ left)",
    ),
    (
        "force_z",
        "N",
        "Q: vertical force of the rail on the wheel (+ up)",
    ),
    ("normal", "N", "normal force of the contact patch(es)"),
    ("angle", "rad", "contact angle of the main patch"),
    ("xi_x", "1", "longitudinal creepage"),
    ("xi_y", "1", "lateral creepage"),
    ("xi_spin", "1/m", "spin creepage"),
    (
        "rail_y",
        "m",
        "the rail head's lateral deflection under the wheel, at its top, track axes (+ left; its roll included on sleepers; 0 on a rigid track)",
    ),
    (
        "rail_z",
        "m",
        "the rail's vertical deflection under the wheel from its unloaded place (+ up; 0 on a rigid track)",
    ),
];

/// What each of the paper's 21 inputs measures (X1 … X21, assets/docs/physics.md §5).
const PAPER_MEANINGS: [&str; 21] = [
    "X1: left side frame's lateral acceleration",
    "X2: right side frame's lateral acceleration",
    "X3: left side frame's vertical acceleration",
    "X4: right side frame's vertical acceleration",
    "X5: bolster's lateral acceleration",
    "X6: bolster's vertical acceleration",
    "X7: wheelset 1's lateral acceleration (axle box, track axes)",
    "X8: wheelset 1's vertical acceleration (axle box, track axes)",
    "X9: wheelset 1's lateral displacement from the track centre line (+ left)",
    "X10: wheelset 1's yaw relative to the track",
    "X11: wheelset 1's roll relative to the track",
    "X12: carbody roll rate",
    "X13: carbody pitch rate",
    "X14: carbody yaw rate",
    "X15: wheelset 1's roll rate (track axes)",
    "X16: wheelset 1's pitch rate (track axes: its spin)",
    "X17: wheelset 1's yaw rate (track axes)",
    "X18: the label wheel's angle of attack on its rail, alignment included",
    "X19: the label wheel's lateral creepage",
    "X20: the label wheel's longitudinal creepage",
    "X21: the label wheel's spin creepage",
];

/// Every channel a run of `v` records, in column order: time and track position, the
/// paper's 21 (vehicles with a sensor layout), every wheel's forces and contact and its rail's deflection, every
/// body's motion, every suspension element's deflection, and the vehicle's mass.
pub fn channels(v: &Vehicle) -> Vec<Channel> {
    let ch = |name: String, unit: &'static str, meaning: String| Channel {
        name,
        unit,
        meaning,
    };
    let mut out = vec![
        ch("time_s".into(), "s", "time".into()),
        ch(
            "s_m".into(),
            "m",
            "distance along the track's centre line from its start".into(),
        ),
    ];
    if v.sensors.is_some() {
        for ((n, u), m) in PAPER_CHANNELS.iter().zip(PAPER_UNITS).zip(PAPER_MEANINGS) {
            out.push(ch(n.to_string(), u, m.into()));
        }
    }
    for k in 0..2 * v.contact.wheelsets.len() {
        let wheel = super::wheel_name(k);
        let w = wheel.to_ascii_lowercase();
        for (s, u, m) in WHEEL_SIGNALS {
            out.push(ch(format!("w{w}_{s}"), u, format!("wheel {wheel}: {m}")));
        }
    }
    for b in &v.bodies {
        for (s, u, m) in BODY_SIGNALS {
            out.push(ch(format!("{}_{s}", b.name), u, format!("{}: {m}", b.name)));
        }
    }
    for e in &v.elements {
        for (name, axis) in e.gauges(&v.bodies) {
            let dir = ["longitudinal", "lateral", "vertical (+ in compression)"][axis];
            out.push(ch(
                name,
                "m",
                format!("{dir} deflection from the element's unloaded state"),
            ));
        }
    }
    out.push(ch(
        VEHICLE_MASS.into(),
        "t",
        "the wagon's total mass (a weighed constant, no sensor)".into(),
    ));
    out
}

/// The channels a run in a train adds after [`channels`]: each coupler's force and angle.
/// Not among the paper's inputs: no wagon measures them.
pub const TRAIN_SIGNALS: [(&str, &str, &str); 4] = [
    (
        "coupler_front_force",
        "N",
        "front coupler's force on the carbody (+ tension)",
    ),
    (
        "coupler_rear_force",
        "N",
        "rear coupler's force on the carbody (+ tension)",
    ),
    (
        "coupler_front_yaw",
        "rad",
        "front coupler's angle to the carbody's axis (+ toward its left)",
    ),
    (
        "coupler_rear_yaw",
        "rad",
        "rear coupler's angle to the carbody's axis (+ toward its left)",
    ),
];

/// The channels of a run: [`channels`], and [`TRAIN_SIGNALS`] when the wagon runs in a
/// train.
pub fn channels_of(v: &Vehicle, in_train: bool) -> Vec<Channel> {
    let mut out = channels(v);
    if in_train {
        out.extend(TRAIN_SIGNALS.iter().map(|&(n, u, m)| Channel {
            name: n.into(),
            unit: u,
            meaning: m.into(),
        }));
    }
    out
}

/// The channel list as a Markdown table: name, unit, kind (as manifests name it), meaning.
pub fn markdown(channels: &[Channel], labels: &[String; 2]) -> String {
    let mut s = String::from("| # | channel | unit | kind | meaning |\n|---|---|---|---|---|\n");
    for (i, c) in channels.iter().enumerate() {
        s += &format!(
            "| {} | `{}` | {} | {} | {} |\n",
            i + 1,
            c.name,
            c.unit,
            ChannelKind::of(&c.name, labels).name(),
            c.meaning
        );
    }
    s
}
