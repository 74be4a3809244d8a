//! The discrete track against its closed forms, as `railforce validate track` prints them.

use super::{
    DiscreteSupport, KelvinVoigt, Load, TrackDynamics, cut_on_frequencies, peaks, receptance,
};

/// One check: a measured value against its expected one.
#[derive(Debug, Clone, PartialEq)]
pub struct Check {
    /// What is compared.
    pub name: String,
    /// Measured on the model.
    pub measured: f64,
    /// The closed form's (or the reference's) value.
    pub expected: f64,
    /// The allowed difference, relative to `expected`.
    pub tolerance: f64,
    /// Unit of both values.
    pub unit: &'static str,
}

impl Check {
    /// Whether the measured value is within the tolerance.
    pub fn passes(&self) -> bool {
        (self.measured - self.expected).abs() <= self.tolerance * self.expected.abs()
    }
}

/// A wheelset's two wheels at `s`, `p` N down each.
fn pair(s: f64, p: f64) -> [Load; 2] {
    Load::wheelset(s, 0.0, -p)
}

/// Every check on the parameter set `p`: the static deflection under a load over a sleeper
/// and at mid-span and under the first of two loads 1.83 m apart against the Winkler beam
/// (shear off, 3 %); the roll under a torque over a sleeper against the bar on roll springs
/// (5 %: the sines' stop at half a bay leaves the roll's kink 4 % short); a load moving at 100 km/h against its static deflection (2 %); the
/// receptance's first two peaks against the first two cut-on frequencies (10 %); the
/// receptance's peak at mid-span near the pinned–pinned frequency against the rail's free
/// bending wave of two bays (2 %).
pub fn checks(p: &DiscreteSupport) -> Vec<Check> {
    let winkler = DiscreteSupport {
        ballast_shear: KelvinVoigt {
            stiffness: 0.0,
            damping: 0.0,
        },
        ..p.euler_bernoulli()
    };
    let (load, centre) = (100e3, 0.5 * p.window());
    let settled = |q: DiscreteSupport, loads: &[Load]| {
        let mut t = TrackDynamics::new(q, centre);
        t.settle(5e-4, 1.5, loads);
        t
    };
    let mut out = Vec::new();
    let sleeper = (centre / p.spacing).round() * p.spacing;
    for (what, s) in [
        ("over a sleeper", sleeper),
        ("at mid-span", sleeper + 0.5 * p.spacing),
    ] {
        let mut t = settled(winkler, &pair(s, load));
        out.push(Check {
            name: format!("static 100 kN {what}: deflection against the Winkler beam"),
            measured: -t.rail(0, s)[2] * 1e3,
            expected: winkler.winkler_deflection(load, 0.0) * 1e3,
            tolerance: 0.03,
            unit: "mm",
        });
    }
    let both = [pair(sleeper, load), pair(sleeper + 1.83, load)].concat();
    let mut t = settled(winkler, &both);
    out.push(Check {
        name: "two loads 1.83 m apart: under the first against Winkler's superposition".into(),
        measured: -t.rail(0, sleeper)[2] * 1e3,
        expected: (winkler.winkler_deflection(load, 0.0) + winkler.winkler_deflection(load, 1.83))
            * 1e3,
        tolerance: 0.03,
        unit: "mm",
    });
    // A torque over a sleeper, the lateral pad's lever off (the sway held out of the roll).
    let bar = DiscreteSupport {
        pad_lateral_lever: 0.0,
        ..*p
    };
    let torque = Load {
        side: 0,
        s: sleeper,
        lateral: 0.0,
        vertical: 0.0,
        torque: 5e3,
    };
    let mut t = settled(bar, &[torque]);
    out.push(Check {
        name: "static 5 kN·m torque over a sleeper: roll against the bar on roll springs".into(),
        measured: t.rail(0, sleeper)[4] * 1e3,
        expected: bar.twist_at_fastener(torque.torque, 0) * 1e3,
        tolerance: 0.05,
        unit: "mrad",
    });
    // A load moving at 100 km/h over 20 m from the window's centre.
    let (v, dt) = (100.0 / 3.6, 5e-4);
    let mut t = settled(*p, &pair(centre, load));
    let statics = -t.rail(0, centre)[2];
    let (mut s, mut worst) = (centre, statics);
    while s < centre + 20.0 {
        s += v * dt;
        t.recentre(s);
        t.step(dt, &pair(s, load));
        let w = -t.rail(0, s)[2];
        if s > centre + 5.0 && (w - statics).abs() > (worst - statics).abs() {
            worst = w;
        }
    }
    out.push(Check {
        name: format!(
            "100 kN moving at 100 km/h (critical speed {:.0} m/s): farthest deflection from the static",
            p.critical_speed()
        ),
        measured: worst * 1e3,
        expected: statics * 1e3,
        tolerance: 0.02,
        unit: "mm",
    });
    let cut = cut_on_frequencies(p);
    let r = receptance(*p, 0.0, 2e-5, 0.5, 600.0);
    let found = peaks(&r, 10.0);
    for (i, name) in ["first", "second"].iter().enumerate() {
        out.push(Check {
            name: format!("receptance over a sleeper: {name} peak against the {name} cut-on"),
            measured: found.get(i).copied().unwrap_or(f64::NAN),
            expected: cut[i],
            tolerance: 0.1,
            unit: "Hz",
        });
    }
    let pp = p.pinned_pinned(false);
    let mid = receptance(*p, 0.5 * p.spacing, 2e-5, 0.5, 2.0 * pp);
    let near = peaks(&mid, 0.5 * pp)
        .into_iter()
        .min_by(|a, b| (a - pp).abs().total_cmp(&(b - pp).abs()));
    out.push(Check {
        name: "receptance at mid-span: the pinned–pinned peak against the free rail's wave of two bays"
            .into(),
        measured: near.unwrap_or(f64::NAN),
        expected: pp,
        tolerance: 0.02,
        unit: "Hz",
    });
    out
}
