//! Checks a correct simulator passes (assets/docs/physics.md §6, assets/docs/validation.md): static wheel loads, quasi-static curving
//! forces, and Klingel's kinematic oscillation of a free wheelset. Used by
//! `railforce validate dynamics` and by the test suite.

use super::{SimConfig, Simulation};
use crate::error::Result;
use crate::track::{Track, TrackSpec};
use crate::vehicle::Vehicle;
use std::path::Path;

/// Static wheel loads on level, smooth, tangent track at rest.
#[derive(Debug, Clone)]
pub struct StaticCheck {
    /// Q of each wheel after settling, N.
    pub loads: Vec<f64>,
    /// `m·g / n_wheels`, N.
    pub expected: f64,
    /// ΣQ over M·g.
    pub sum_ratio: f64,
}

/// A smooth level tangent of `length` metres on rigid rails (the closed forms' track).
pub fn smooth_tangent(length: f64) -> Track {
    let text = format!(
        "name = \"smooth tangent\"\n[[section]]\nkind = \"tangent\"\nlength_m = {length}\n"
    );
    Track::new(
        TrackSpec::parse(&text, Path::new("<smooth tangent>")).expect("valid built-in track"),
        None,
    )
}

/// Puts the vehicle at rest on smooth level track and lets it settle for `seconds`.
pub fn static_loads(vehicle: &Vehicle, seconds: f64) -> Result<StaticCheck> {
    let track = smooth_tangent(200.0);
    let cfg = SimConfig {
        speed: 0.0,
        duration: seconds,
        settle: 0.0,
        ..SimConfig::default()
    };
    let mut sim = Simulation::new(vehicle, &track, cfg)?;
    let steps = crate::bounds::count_of(seconds / sim.config().dt, "steps of the check")?;
    for _ in 0..steps {
        sim.step()?;
    }
    let loads: Vec<f64> = sim.wheels.iter().map(|w| w.q).collect();
    let weight = vehicle.mass() * crate::GRAVITY;
    Ok(StaticCheck {
        expected: weight / loads.len() as f64,
        sum_ratio: loads.iter().sum::<f64>() / weight,
        loads,
    })
}

/// A track file with its irregularity class replaced (e.g. class 6 for quasi-static checks,
/// where irregularities only keep friction elements from sticking).
pub fn with_class(path: &Path, class: i64) -> Result<Track> {
    let mut spec = TrackSpec::load(path)?;
    if let Some(irr) = spec.irregularity.as_mut() {
        irr.class = crate::track::FraClass::new(class)
            .ok_or_else(|| crate::Error::Domain(format!("unknown FRA class {class}")))?;
    }
    Ok(Track::new(spec, None))
}

/// Quasi-static curving: mean forces over the circular part of a curve.
#[derive(Debug, Clone)]
pub struct CurvingCheck {
    /// Curve radius, m.
    pub radius: f64,
    /// Cant angle, rad.
    pub cant_angle: f64,
    /// Speed, m/s.
    pub speed: f64,
    /// Mean ΣY over all wheels, track frame (+ left), N.
    pub sum_y: f64,
    /// `M·(V²/R·cos θ − g·sin θ)` toward the outside of the curve, signed in the track frame.
    pub expected_y: f64,
    /// Mean ΣQ, N.
    pub sum_q: f64,
    /// `M·(g·cos θ + V²/R·sin θ)`, N.
    pub expected_q: f64,
    /// Mean Q of the outer and inner wheel of the leading wheelset, N.
    pub outer_inner_q: (f64, f64),
    /// Samples averaged.
    pub samples: usize,
}

/// Runs `vehicle` through the curve of `track` at `speed` and averages over `window` metres of
/// circular curve, starting 50 m into it (transients decayed).
pub fn curving(vehicle: &Vehicle, track: &Track, speed: f64, window: f64) -> Result<CurvingCheck> {
    let curve = track
        .spec()
        .sections
        .iter()
        .find(|s| matches!(s.kind, crate::track::SectionKind::Curve { .. }))
        .copied()
        .ok_or_else(|| {
            crate::Error::Domain(format!("track '{}' has no curve", track.spec().name))
        })?;
    let (from, to) = (
        curve.start + 50.0,
        (curve.start + 50.0 + window).min(curve.end()),
    );
    let start = 10.0;
    let duration = (to - start) / speed + 1.0;
    let cfg = SimConfig {
        speed,
        duration,
        settle: 0.0,
        start: Some(start),
        ..SimConfig::default()
    };
    let mut sim = Simulation::new(vehicle, track, cfg)?;
    let first_ws = vehicle.contact.wheelsets[0];
    let (mut n, mut sy, mut sq, mut qo, mut qi) = (0usize, 0.0, 0.0, 0.0, 0.0);
    let (mut kappa, mut cant) = (0.0, 0.0);
    loop {
        sim.step()?;
        let s_rear = sim.body_s()[*vehicle.contact.wheelsets.last().unwrap()];
        let s_front = sim.body_s()[first_ws];
        if s_front > to {
            break;
        }
        if s_rear < from {
            continue;
        }
        let p = track.at(s_front);
        kappa = p.curvature;
        cant = p.cant_angle;
        n += 1;
        sy += sim.wheels.iter().map(|w| w.y).sum::<f64>();
        sq += sim.wheels.iter().map(|w| w.q).sum::<f64>();
        // The outer rail of a right-hand curve (κ < 0) is the left one.
        let (o, i) = if kappa < 0.0 { (0, 1) } else { (1, 0) };
        qo += sim.wheels[o].q;
        qi += sim.wheels[i].q;
    }
    let n_f = n.max(1) as f64;
    let m = vehicle.mass();
    let g = crate::GRAVITY;
    let r = 1.0 / kappa.abs();
    let theta = cant.abs();
    // Toward the outside of the curve: +y for a right-hand curve.
    let outward = -kappa.signum();
    Ok(CurvingCheck {
        radius: r,
        cant_angle: theta,
        speed,
        sum_y: sy / n_f,
        expected_y: outward * -m * (speed * speed / r * theta.cos() - g * theta.sin()),
        sum_q: sq / n_f,
        expected_q: m * (g * theta.cos() + speed * speed / r * theta.sin()),
        outer_inner_q: (qo / n_f, qi / n_f),
        samples: n,
    })
}

/// Klingel: wavelength of the kinematic oscillation of a free wheelset.
#[derive(Debug, Clone)]
pub struct KlingelCheck {
    /// Equivalent conicity of the profile pair at the amplitude used.
    pub conicity: f64,
    /// Half the distance between the contact points, m.
    pub b0: f64,
    /// Rolling radius, m.
    pub r0: f64,
    /// Measured wavelength (mean of the first cycles), m.
    pub measured: f64,
    /// `2π·sqrt(r0·b0/λe)`, m.
    pub expected: f64,
}

/// Lets a free wheelset (`vehicle` with one wheelset and no suspension) run from a lateral
/// offset `amplitude` at `speed` and measures the distance between upward zero crossings of its
/// lateral displacement over the first `cycles` cycles.
pub fn klingel(
    vehicle: &Vehicle,
    speed: f64,
    amplitude: f64,
    cycles: usize,
) -> Result<KlingelCheck> {
    let table = vehicle.contact.table();
    let centred = table.lookup(0.0);
    let b0 = 0.5 * (centred.wheels[0].point[1] - centred.wheels[1].point[1]);
    let r0 = 0.5 * (centred.wheels[0].rolling_radius + centred.wheels[1].rolling_radius);
    let conicity = table.equivalent_conicity(amplitude).ok_or_else(|| {
        crate::Error::Domain("no kinematic oscillation in the contact table".into())
    })?;
    let expected = 2.0 * std::f64::consts::PI * (r0 * b0 / conicity).sqrt();
    let length = 60.0 + expected * (cycles as f64 + 2.0);
    let track = smooth_tangent(length + 20.0);
    let cfg = SimConfig {
        speed,
        duration: length / speed,
        settle: 0.0,
        start: Some(10.0),
        initial_offset: amplitude,
        ..SimConfig::default()
    };
    let mut sim = Simulation::new(vehicle, &track, cfg)?;
    let mut last = f64::NAN;
    let mut crossings: Vec<f64> = Vec::new();
    while crossings.len() <= cycles {
        sim.step()?;
        let y = sim.wheels[0].y_centre;
        if last < 0.0 && y >= 0.0 {
            // Interpolate the crossing position.
            let s = sim.body_s()[vehicle.contact.wheelsets[0]];
            let ds = speed * sim.config().dt;
            crossings.push(s - ds * y / (y - last));
        }
        last = y;
        if sim.time() > length / speed {
            break;
        }
    }
    let measured = if crossings.len() >= 2 {
        (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f64
    } else {
        f64::NAN
    };
    Ok(KlingelCheck {
        conicity,
        b0,
        r0,
        measured,
        expected,
    })
}

/// Wickens: critical speed of a single wheelset restrained by lateral and yaw springs.
#[derive(Debug, Clone)]
pub struct WickensCheck {
    /// Critical speed found by simulation (bisection on growth or decay of a perturbation), m/s.
    pub measured: f64,
    /// Wickens' closed form with the wheelset's gyroscopic yaw moment,
    /// `sqrt((r0·b0/λe)·(k_ψ + b0²·k_y)/(m·b0² + I_z − I_y))`, m/s (see [`wickens`]).
    pub expected: f64,
    /// The textbook form without it, `sqrt((r0·b0/λe)·(k_ψ + b0²·k_y)/(m·b0² + I_z))`, m/s.
    pub textbook: f64,
    /// Equivalent conicity used, at the perturbation's amplitude.
    pub conicity: f64,
}

/// Whether a lateral perturbation of `amplitude` grows over `seconds` at `speed`.
fn grows(vehicle: &Vehicle, speed: f64, amplitude: f64, seconds: f64) -> Result<bool> {
    let track = smooth_tangent(speed * seconds + 60.0);
    let cfg = SimConfig {
        speed,
        duration: seconds,
        settle: 0.0,
        start: Some(10.0),
        initial_offset: amplitude,
        ..SimConfig::default()
    };
    let mut sim = Simulation::new(vehicle, &track, cfg)?;
    let steps = (seconds / sim.config().dt) as usize;
    let (mut first, mut last) = (0.0f64, 0.0f64);
    for i in 0..steps {
        if sim.step().is_err() {
            // Ran off the cones or diverged: the perturbation grew.
            return Ok(true);
        }
        let y = sim.wheels[0].y_centre.abs();
        if i < steps / 3 {
            first = first.max(y);
        } else if i >= 2 * steps / 3 {
            last = last.max(y);
        }
    }
    Ok(last > first)
}

/// Finds the critical speed of a restrained single wheelset (`vehicle` with one wheelset and a
/// `track_spring`) by bisection between half and twice Wickens' value, and compares.
///
/// The closed form: Wickens' two equations of the wheelset (lateral `y`, yaw `ψ`, equal creep
/// coefficients `f`, large against the springs) with the gyroscopic yaw moment of the spinning
/// wheelset, `I_y·(V/r0)·φ̇` with its kinematic roll `φ = λ·y/b0` (assets/docs/stability.md).
/// At the stability boundary `s = iω` the real part gives `ω² = V²·λ/(r0·b0)` and the imaginary
/// part `ω² = (k_ψ + b0²·k_y)/(m·b0² + I_z − I_y)`: the spin's moment of inertia takes `I_y`
/// off the yaw inertia. Without it (the textbook form) the critical speed is 4–5 % lower for
/// a wheelset with `I_y/I_z` ≈ 0.17; the model without spin inertia meets that form
/// (tests/stability.rs).
pub fn wickens(vehicle: &Vehicle) -> Result<WickensCheck> {
    let (ky, kpsi) = vehicle
        .elements
        .iter()
        .find_map(|e| match e {
            crate::vehicle::Element::TrackSpring(t) => Some((t.lateral_stiffness, t.yaw_stiffness)),
            _ => None,
        })
        .ok_or_else(|| crate::Error::Domain("the Wickens check needs a track_spring".into()))?;
    let ws = &vehicle.bodies[vehicle.contact.wheelsets[0]];
    let table = vehicle.contact.table();
    let centred = table.lookup(0.0);
    let b0 = 0.5 * (centred.wheels[0].point[1] - centred.wheels[1].point[1]);
    let r0 = 0.5 * (centred.wheels[0].rolling_radius + centred.wheels[1].rolling_radius);
    let amplitude = 1e-3;
    let conicity = table.equivalent_conicity(amplitude).ok_or_else(|| {
        crate::Error::Domain("no kinematic oscillation in the contact table".into())
    })?;
    let closed = |yaw_inertia: f64| {
        ((r0 * b0 / conicity) * (kpsi + b0 * b0 * ky) / (ws.mass * b0 * b0 + yaw_inertia)).sqrt()
    };
    let (expected, textbook) = (closed(ws.inertia.z - ws.inertia.y), closed(ws.inertia.z));
    let (mut lo, mut hi) = (0.5 * expected, 2.0 * expected);
    for _ in 0..10 {
        let mid = 0.5 * (lo + hi);
        if grows(vehicle, mid, amplitude, 8.0)? {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Ok(WickensCheck {
        measured: 0.5 * (lo + hi),
        expected,
        textbook,
        conicity,
    })
}
