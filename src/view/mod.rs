//! The viewer: one self-contained HTML page that replays a run for a class or a review — the
//! leading wheelset's two wheels on their rails (real profiles, contact patches from the one
//! contact evaluation, force arrows), a plan view of the wagon on the track and the label
//! wheel's Y, Q and Y/Q with the identified forces and the limits.
//!
//! [`Scene::build`] turns a recorded run (the columns `simulate` and `generate` write) into
//! the numbers the page draws; [`page::html`] wraps them with the inline script. Nothing is
//! fetched from the network: the page opens from disk and can be mailed.

pub mod page;

use crate::contact::{Side, WheelOnRail, height_for_load};
use crate::error::{Error, Result};
use crate::track::Track;
use crate::vehicle::Vehicle;
use serde::Serialize;

/// Lateral displacements in the plan view are drawn this many times larger than life.
pub const PLAN_LATERAL_FACTOR: f64 = 25.0;
/// Yaw angles (and so the angle of attack) in the plan view are drawn this many times larger.
pub const PLAN_YAW_FACTOR: f64 = 50.0;
/// Default frame rate of the page, Hz (the run's 200 Hz halved: smooth on a projector, half
/// the size).
pub const DEFAULT_RATE_HZ: f64 = 100.0;

/// What the page draws, serialised into it as JSON. Lengths in mm, forces in kN, angles in
/// mrad unless named otherwise.
#[derive(Debug, Clone, Serialize)]
pub struct Scene {
    /// Heading of the page.
    pub title: String,
    /// Vehicle, track, speed and seed in words.
    pub subtitle: String,
    /// The label wheel (`1L`).
    pub label: String,
    /// Exaggeration of the plan view: lateral displacement and yaw.
    pub plan_factors: [f64; 2],
    /// Profiles for the cross-section.
    pub profiles: Profiles,
    /// Bodies of the plan view.
    pub bodies: Vec<PlanBody>,
    /// Track map: centre line every few metres, `[s, x, y]` in m.
    pub map: Vec<[f64; 3]>,
    /// Track sections: `[start, end]` in m and a description.
    pub sections: Vec<(f64, f64, String)>,
    /// Time of each frame, s.
    pub time: Vec<f64>,
    /// Track position of the vehicle centre, m.
    pub s: Vec<f64>,
    /// Curvature of the track centre line at `s`, 1/km (+ to the left): the plan view bends
    /// its rails by it.
    pub curvature: Vec<f64>,
    /// The leading wheelset's wheels (left, right), frame by frame.
    pub wheels: [WheelFrames; 2],
    /// Label wheel traces, kN (true).
    pub traces: Traces,
    /// Identified forces of the label wheel, kN, where given (`null` where not).
    pub identified: Option<Traces>,
    /// Where the identified forces came from.
    pub identified_source: Option<String>,
    /// Limits drawn on the traces.
    pub limits: Limits,
    /// The couplers of a run in a train, frame by frame (absent for a wagon alone).
    pub couplers: Option<CouplerFrames>,
}

/// The wagon's two couplers, frame by frame: what the plan view draws at the carbody's ends.
#[derive(Debug, Clone, Serialize)]
pub struct CouplerFrames {
    /// Front and rear coupler force, kN (+ tension).
    pub force: [Vec<f64>; 2],
    /// Front and rear coupler angle to the carbody's axis, mrad (+ toward its left).
    pub yaw: [Vec<f64>; 2],
    /// Largest |force| the criteria allow, kN (the line turns red beyond it).
    pub limit_kn: f64,
}

/// Wheel and rail profiles as the cross-section draws them.
#[derive(Debug, Clone, Serialize)]
pub struct Profiles {
    /// Left wheel: `[distance from the wheelset centre along the axle, radius]`, mm (the
    /// right wheel is its mirror image).
    pub wheel: Vec<[f64; 2]>,
    /// Mounted rail head: `[lateral from the gauge point (+ field side), height (+ up)]`, mm.
    pub rail: Vec<[f64; 2]>,
    /// Half the gauge, mm (the gauge points lie at ±this from the track centre).
    pub half_gauge: f64,
    /// Nominal rolling radius, mm.
    pub nominal_radius: f64,
}

/// One body of the plan view.
#[derive(Debug, Clone, Serialize)]
pub struct PlanBody {
    /// Name in the vehicle file.
    pub name: String,
    /// `wheelset`, `sideframe`, `bolster`, `carbody` or `other`.
    pub kind: String,
    /// Static position ahead of the wagon centre and to the left, m.
    pub x: f64,
    /// See `x`.
    pub y0: f64,
    /// Lateral displacement from its static place over the track centre line, mm, per frame.
    pub y: Vec<f64>,
    /// Yaw relative to the track, mrad, per frame.
    pub yaw: Vec<f64>,
}

/// One wheel of the leading wheelset, frame by frame, relative to its own rail (irregularity
/// and the rail's deflection removed), and the rail's deflection: what the cross-section and
/// the wheelset's schematic need.
#[derive(Debug, Clone, Default, Serialize)]
pub struct WheelFrames {
    /// Lateral shift of the wheelset centre from this rail's nominal place, mm.
    pub y: Vec<f64>,
    /// Height of the wheelset centre above this rail's top, mm (from the one contact
    /// evaluation at the recorded Q).
    pub height: Vec<f64>,
    /// Roll of the wheelset relative to the rail plane, mrad.
    pub roll: Vec<f64>,
    /// Contact patches: `[lateral, height]` of the load centre from the wheelset centre (mm),
    /// normal load (kN) and contact angle (deg); one or two.
    pub patches: Vec<Vec<[f64; 4]>>,
    /// Lateral force Y of the rail on the wheel (+ left), kN.
    pub force_y: Vec<f64>,
    /// Vertical force Q, kN.
    pub force_q: Vec<f64>,
    /// The rail's lateral deflection under the wheel (+ left), mm; empty where the run did not
    /// record it.
    pub rail_y: Vec<f64>,
    /// The rail's vertical deflection under the wheel from its unloaded place (+ up), mm;
    /// empty where the run did not record it.
    pub rail_z: Vec<f64>,
}

/// Y, Q and Y/Q of one wheel.
#[derive(Debug, Clone, Default, Serialize)]
pub struct Traces {
    /// Lateral force, kN.
    pub y: Vec<f64>,
    /// Vertical force, kN.
    pub q: Vec<f64>,
    /// |Y|/Q (`null` where Q ≤ 0).
    pub y_over_q: Vec<Option<f64>>,
    /// Identified forces only: the interval `identify` wrote around Y and Q, kN, as
    /// `[lower, upper]` (`null` where the file has none).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub band: Option<Band>,
}

/// The interval around identified Y and Q, kN (NaN where absent; drawn as a shaded band).
#[derive(Debug, Clone, Serialize)]
pub struct Band {
    /// Lower and upper bound of Y.
    pub y: [Vec<f64>; 2],
    /// Lower and upper bound of Q.
    pub q: [Vec<f64>; 2],
    /// Nominal coverage where the file says it (`identify --coverage`), else `null`.
    pub coverage: Option<f64>,
}

/// Limits drawn on the traces.
#[derive(Debug, Clone, Serialize)]
pub struct Limits {
    /// |Y|/Q limit.
    pub y_over_q: f64,
    /// Lowest Q allowed by the unloading limit, kN: `(1 − ΔQ/Q̄ limit)·Q̄`.
    pub q_min: f64,
    /// Static wheel load Q̄, kN.
    pub q_static: f64,
    /// Where the limits come from.
    pub source: String,
}

/// A named column of a table.
pub type Column = (String, Vec<f64>);

/// What [`Scene::build`] needs besides the run's columns.
pub struct Inputs<'a> {
    /// The vehicle that ran (profiles, bodies, contact table).
    pub vehicle: &'a Vehicle,
    /// The track it ran on, with the run's irregularity seed.
    pub track: &'a Track,
    /// Identified forces (columns of `identify` output files), with their source.
    pub identified: Option<(String, Vec<Column>)>,
    /// Limits of the traces.
    pub limits: Limits,
    /// Frame rate of the page, Hz.
    pub rate_hz: f64,
    /// Running speed in words for the subtitle, if known.
    pub speed_kmh: Option<f64>,
}

fn round(x: f64, decimals: i32) -> f64 {
    let p = 10f64.powi(decimals);
    let r = (x * p).round() / p;
    if r == 0.0 { 0.0 } else { r }
}

fn column<'a>(source: &str, cols: &'a [Column], name: &str) -> Result<&'a [f64]> {
    cols.iter()
        .find(|(n, _)| n == name)
        .map(|(_, v)| v.as_slice())
        .ok_or_else(|| {
            Error::Domain(format!(
                "{source}: no column '{name}' (the viewer reads the full output of `railforce simulate` or a data set's run file)"
            ))
        })
}

/// Linear interpolation of `(t, v)` at `x` (`None` outside `t`'s range or on a non-finite
/// value).
fn interpolate(t: &[f64], v: &[f64], x: f64) -> Option<f64> {
    let n = t.len().min(v.len());
    if n == 0 || x < t[0] - 1e-9 || x > t[n - 1] + 1e-9 {
        return None;
    }
    let i = t[..n].partition_point(|&ti| ti <= x).clamp(1, n.max(2) - 1);
    if n == 1 {
        return v[0].is_finite().then_some(v[0]);
    }
    let (t0, t1) = (t[i - 1], t[i]);
    let f = if t1 > t0 { (x - t0) / (t1 - t0) } else { 0.0 };
    let y = v[i - 1] + f.clamp(0.0, 1.0) * (v[i] - v[i - 1]);
    y.is_finite().then_some(y)
}

fn y_over_q(y: f64, q: f64) -> Option<f64> {
    (q > 0.0).then(|| round(y.abs() / q, 4))
}

impl Scene {
    /// Builds the scene of the run `cols` (named columns, read from `source`).
    pub fn build(source: &str, cols: &[Column], inp: &Inputs) -> Result<Scene> {
        let v = inp.vehicle;
        let time = column(source, cols, "time_s")?;
        let s_col = column(source, cols, "s_m")?;
        if time.len() < 2 {
            return Err(Error::Domain(format!(
                "{source}: fewer than two rows: nothing to replay"
            )));
        }
        if let Some(bad) = time.iter().position(|t| !t.is_finite()) {
            return Err(Error::Domain(format!(
                "{source}: time_s row {} is not a number",
                bad + 2
            )));
        }
        let dt = (time[time.len() - 1] - time[0]) / (time.len() - 1) as f64;
        if !(inp.rate_hz.is_finite() && inp.rate_hz > 0.0) {
            return Err(Error::Domain(format!(
                "frame rate {} Hz: give a positive rate",
                inp.rate_hz
            )));
        }
        let every = crate::bounds::count_of(((1.0 / inp.rate_hz) / dt).max(1.0), "rows per frame")?;
        let rows: Vec<usize> = (0..time.len()).step_by(every).collect();
        let pick = |c: &[f64], scale: f64, dec: i32| -> Vec<f64> {
            rows.iter().map(|&i| round(c[i] * scale, dec)).collect()
        };

        let cs = &v.contact;
        let geo = &cs.geometry;
        let lead = *cs
            .wheelsets
            .first()
            .ok_or_else(|| Error::Domain(format!("vehicle '{}' has no wheelsets", v.name)))?;
        let lead_name = v.bodies[lead].name.clone();
        let label = v.label_wheel_name();
        let label_key = label.to_ascii_lowercase();

        // The leading wheelset's wheels relative to their rails, as a run gives them to the
        // contact evaluation: irregularity and, on a compliant track, the rail's own deflection
        // removed (a file written before the deflection was recorded: taken as zero).
        let ws_y = column(source, cols, &format!("{lead_name}_y_rel"))?;
        let ws_roll = column(source, cols, &format!("{lead_name}_roll"))?;
        let ws_yaw = column(source, cols, &format!("{lead_name}_yaw"))?;
        let x_lead = v.bodies[lead].position.x;
        let table = cs.table();
        let model = cs.model();
        let mass = 0.5 * v.bodies[lead].mass;
        let mut wheels: [WheelFrames; 2] = Default::default();
        for (k, side) in [Side::Left, Side::Right].into_iter().enumerate() {
            let w = if k == 0 { "w1l" } else { "w1r" };
            let fy = column(source, cols, &format!("{w}_force_y"))?;
            let fq = column(source, cols, &format!("{w}_force_z"))?;
            let deflection = |axis: &str| column(source, cols, &format!("{w}_rail_{axis}")).ok();
            let (rail_y, rail_z) = (deflection("y"), deflection("z"));
            let out = &mut wheels[k];
            for &i in &rows {
                let rails = inp.track.at(s_col[i] + x_lead).rails;
                let irr = if k == 0 { rails.left_y } else { rails.right_y };
                let ry = rail_y.map_or(0.0, |r| r[i]);
                let mut wr = WheelOnRail::rolling(side, 0.0, geo.nominal_radius, 0.0, mass);
                wr.y = (ws_y[i] - irr - ry).clamp(-0.039, 0.039);
                if let (Some(_), Some(rz)) = (rail_y, rail_z) {
                    out.rail_y.push(round(ry * 1e3, 3));
                    out.rail_z.push(round(rz[i] * 1e3, 3));
                }
                wr.roll = ws_roll[i];
                wr.yaw = ws_yaw[i];
                let load = fq[i].max(1.0);
                wr.height = height_for_load(table, &model, &wr, load);
                let f = crate::contact::evaluate(table, &model, &wr);
                let patches = f
                    .patches
                    .iter()
                    .flatten()
                    .map(|p| {
                        [
                            round(p.point[1] * 1e3, 2),
                            round(p.point[2] * 1e3, 2),
                            round(p.normal * 1e-3, 1),
                            round(p.angle.to_degrees(), 1),
                        ]
                    })
                    .collect();
                out.y.push(round(wr.y * 1e3, 3));
                out.height.push(round(wr.height * 1e3, 3));
                out.roll.push(round(wr.roll * 1e3, 3));
                out.patches.push(patches);
                out.force_y.push(round(fy[i] * 1e-3, 2));
                out.force_q.push(round(fq[i] * 1e-3, 2));
            }
        }

        let fy = column(source, cols, &format!("w{label_key}_force_y"))?;
        let fq = column(source, cols, &format!("w{label_key}_force_z"))?;
        let traces = Traces {
            y: pick(fy, 1e-3, 2),
            q: pick(fq, 1e-3, 2),
            y_over_q: rows.iter().map(|&i| y_over_q(fy[i], fq[i])).collect(),
            band: None,
        };
        let (identified, identified_source) = match &inp.identified {
            Some((src, id)) => {
                let t_id = id
                    .iter()
                    .find(|(n, _)| n == "time_s")
                    .map(|(_, v)| v.as_slice())
                    .ok_or_else(|| {
                        Error::Domain(format!(
                            "{src}: no time_s column: identified forces are the output of `railforce identify`"
                        ))
                    })?;
                let find = |comp: char| {
                    let name = format!("w{label_key}_force_{comp}");
                    id.iter()
                        .find(|(n, _)| *n == format!("{name}_N") || *n == name)
                        .map(|(_, v)| v.as_slice())
                };
                let (iy, iq) = (find('y'), find('z'));
                if iy.is_none() && iq.is_none() {
                    return Err(Error::Domain(format!(
                        "{src}: neither w{label_key}_force_y_N nor w{label_key}_force_z_N: identify the label wheel {label} (targets FL, FQ or w{label_key})"
                    )));
                }
                let series = |c: Option<&[f64]>| -> Vec<Option<f64>> {
                    rows.iter()
                        .map(|&i| c.and_then(|c| interpolate(t_id, c, time[i])))
                        .collect()
                };
                let (sy, sq) = (series(iy), series(iq));
                let bound = |comp: char, which: &str| {
                    let name = format!("w{label_key}_force_{comp}_{which}_N");
                    id.iter()
                        .find(|(n, _)| *n == name)
                        .map(|(_, v)| v.as_slice())
                };
                let kn = |c: Option<&[f64]>| -> Vec<f64> {
                    series(c)
                        .iter()
                        .map(|x| x.map_or(f64::NAN, |x| round(x * 1e-3, 2)))
                        .collect()
                };
                let band =
                    (bound('y', "lo").is_some() || bound('z', "lo").is_some()).then(|| Band {
                        y: [kn(bound('y', "lo")), kn(bound('y', "hi"))],
                        q: [kn(bound('z', "lo")), kn(bound('z', "hi"))],
                        coverage: None,
                    });
                // Y/Q needs both; with one identified, the true other stands in (said on the
                // page).
                let tr = Traces {
                    y: sy
                        .iter()
                        .map(|x| x.map_or(f64::NAN, |x| round(x * 1e-3, 2)))
                        .collect(),
                    q: sq
                        .iter()
                        .map(|x| x.map_or(f64::NAN, |x| round(x * 1e-3, 2)))
                        .collect(),
                    y_over_q: rows
                        .iter()
                        .enumerate()
                        .map(|(j, &i)| {
                            let y = if iy.is_some() { sy[j]? } else { fy[i] };
                            let q = if iq.is_some() { sq[j]? } else { fq[i] };
                            y_over_q(y, q)
                        })
                        .collect(),
                    band,
                };
                let what = match (iy.is_some(), iq.is_some()) {
                    (true, true) => "Y and Q identified",
                    (true, false) => "Y identified (Y/Q with the true Q)",
                    _ => "Q identified (Y/Q with the true Y)",
                };
                (Some(tr), Some(format!("{src}: {what}")))
            }
            None => (None, None),
        };

        let mut bodies = Vec::new();
        for (b, body) in v.bodies.iter().enumerate() {
            let (Ok(y), Ok(yaw)) = (
                column(source, cols, &format!("{}_y_rel", body.name)),
                column(source, cols, &format!("{}_yaw", body.name)),
            ) else {
                continue;
            };
            let kind = ["wheelset", "sideframe", "bolster", "carbody"]
                .into_iter()
                .find(|k| body.name.starts_with(k))
                .unwrap_or(if cs.wheelsets.contains(&b) {
                    "wheelset"
                } else {
                    "other"
                });
            bodies.push(PlanBody {
                name: body.name.clone(),
                kind: kind.into(),
                x: round(body.position.x, 3),
                y0: round(body.position.y, 3),
                // y_rel is the lateral position in the track frame: less the static place.
                y: rows
                    .iter()
                    .map(|&i| round((y[i] - body.position.y) * 1e3, 2))
                    .collect(),
                yaw: pick(yaw, 1e3, 3),
            });
        }

        let track = inp.track;
        let length = track.length();
        let n_map = crate::bounds::to_count((length / 5.0).ceil()).clamp(2, 4000);
        let map = (0..=n_map)
            .map(|j| {
                let s = length * j as f64 / n_map as f64;
                let (x, y, _, _) = track.centre_line(s);
                [round(s, 2), round(x, 2), round(y, 2)]
            })
            .collect();
        let sections = track
            .spec()
            .sections
            .iter()
            .map(|sec| (sec.start, sec.end(), describe_section(sec)))
            .collect();

        let rail = geo.rail();
        let (r0, r1) = rail.range();
        let n = ((r1 - r0) / 2e-4) as usize;
        let rail_pts = (0..=n)
            .map(|j| {
                let ym = r0 + (r1 - r0) * j as f64 / n as f64;
                [round(ym * 1e3, 2), round(-rail.eval(ym).0 * 1e3, 3)]
            })
            .collect();
        let wheel = geo.wheel();
        let (w0, w1) = wheel.range();
        let n = ((w1 - w0) / 2e-4) as usize;
        let wheel_pts = (0..=n)
            .map(|j| {
                let eta = w0 + (w1 - w0) * j as f64 / n as f64;
                [
                    round((geo.tape_circle_half + eta) * 1e3, 2),
                    round((geo.nominal_radius + wheel.eval(eta).0) * 1e3, 3),
                ]
            })
            .collect();
        let seed = track.irregularities().map(|i| i.spec().seed);
        let subtitle = format!(
            "{} on {}{}{}",
            v.name,
            track.spec().name,
            inp.speed_kmh
                .map_or(String::new(), |s| format!(" at {s:.0} km/h")),
            seed.map_or(", smooth track".into(), |s| format!(
                ", irregularity seed {s}"
            )),
        );
        let find = |name: &str| {
            cols.iter()
                .find(|(n, _)| n == name)
                .map(|(_, c)| c.as_slice())
        };
        let couplers = match (
            find("coupler_front_force"),
            find("coupler_rear_force"),
            find("coupler_front_yaw"),
            find("coupler_rear_yaw"),
        ) {
            (Some(ff), Some(fr), Some(yf), Some(yr)) => Some(CouplerFrames {
                force: [pick(ff, 1e-3, 1), pick(fr, 1e-3, 1)],
                yaw: [pick(yf, 1e3, 2), pick(yr, 1e3, 2)],
                limit_kn: crate::assess::criteria::Criteria::builtin()
                    .coupler
                    .map_or(2250.0, |c| c.limit_kn),
            }),
            _ => None,
        };
        Ok(Scene {
            title: format!("railforce view: {source}"),
            subtitle,
            label,
            plan_factors: [PLAN_LATERAL_FACTOR, PLAN_YAW_FACTOR],
            profiles: Profiles {
                wheel: wheel_pts,
                rail: rail_pts,
                half_gauge: round(geo.half_gauge * 1e3, 3),
                nominal_radius: round(geo.nominal_radius * 1e3, 3),
            },
            bodies,
            map,
            sections,
            time: pick(time, 1.0, 3),
            s: pick(s_col, 1.0, 3),
            curvature: rows
                .iter()
                .map(|&i| round(track.centre_line(s_col[i]).3 * 1e3, 4))
                .collect(),
            wheels,
            traces,
            identified,
            identified_source,
            limits: inp.limits.clone(),
            couplers,
        })
    }
}

/// A track section in words, with the sign of its cant (which rail is higher).
fn describe_section(sec: &crate::track::Section) -> String {
    use crate::track::{SectionKind, Turn};
    match sec.kind {
        SectionKind::Tangent => "tangent".into(),
        SectionKind::Transition => "transition".into(),
        SectionKind::Curve { radius, cant, turn } => {
            let (dir, high) = match turn {
                Turn::Left => ("left", "right"),
                Turn::Right => ("right", "left"),
            };
            format!(
                "curve R {radius:.0} m to the {dir}, cant {:.0} mm ({high} rail higher)",
                cant * 1e3
            )
        }
    }
}
