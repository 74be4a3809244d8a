//! Rails as beams on discrete sleepers (`[rail_support] model = "discrete"`): the coupled
//! vehicle–track model of Zhai's school, in a window of track that moves with the vehicle.
//!
//! Per rail, a vertical and a lateral Timoshenko beam (or Euler–Bernoulli, `rail_beam`) and a
//! torsional bar, simply supported at the window's ends, in modal coordinates (`φ_k(x) = √(2/(m_k·L))·sin(kπx/L)`, two
//! modes per fastener and the pinned–pinned mode, so the rail bends between the sleepers).
//! Each fastener is a rail pad (vertical and lateral spring and damper, the lateral at the
//! rail's foot and the vertical spread across it, so both restrain the roll) to a rigid sleeper
//! (vertical, lateral and roll); under each rail seat a ballast block on the subgrade, coupled
//! to its neighbours in shear. With the fasteners evenly spaced the modes' values at the
//! fasteners are a discrete sine transform (DST-I), and so are the sleepers' and the ballast's
//! fields: the track steps one wavenumber at a time ([`TrackDynamics`]), and the window shifts
//! by whole bays exactly.
//!
//! What the model leaves out (stated, not hidden):
//! - **the Timoshenko beam's second branch** (the shear wave, cut on near 5.0 kHz for CHN60
//!   vertically) and wavelengths under one bay: the shortest modes, half a bay long, stand at
//!   2.8 kHz vertically and 1.9 kHz laterally;
//! - **warping**: the rails twist as St Venant bars (`GK`), their roll restrained by the pads;
//!   the flange's warping stiffness and the section's distortion (the head bending about the
//!   web) are left out;
//! - **the pads' length**: a fastener is a point, so nothing damps the pinned–pinned mode but
//!   the step (backward Euler on the rails' bending);
//! - **the window's ends**: the rail is pinned there and the track beyond it is at rest
//!   (the window reaches 14 m past the vehicle's centre; the basin decays as `e^(−β·x)`,
//!   β ≈ 1.15 /m, so to 10⁻⁵ within it).
//!
//! Parameters: Zhai, Wang & Lin, "Modelling and experiment of railway ballast vibrations",
//! J. Sound Vib. 270 (2004) 673–683 (rail, pads, sleepers, ballast, subgrade, vertical), and the
//! lateral and shear set credited to Zhai's *Vehicle–Track Coupled Dynamics* (pad lateral,
//! sleeper lateral, ballast shear, rail Iz); CHN60's section (77.45 cm², 3217 and 524 cm⁴) as
//! tabled in Hindawi *Adv. Civ. Eng.* 2021, 8847633, Table 2, and *Shock Vib.* 2021, 5562152,
//! Table 3, which gives the vertical shear coefficient 0.4; the lateral 0.54 is the UIC60
//! figure of the rolland track model's rail table (an estimate for CHN60); the sleeper's roll
//! inertia and rail-seat distance are estimates. The torsion (GK 1.9587 × 10⁵ N·m², polar
//! moment 3.741 × 10⁻⁵ m⁴, torsion centre 94.53 mm below the rail's top, lateral pad 82 mm below
//! it, vertical pad's half width 75 mm) is the CHN60 set of Zhai's vehicle–track coupled model
//! as the VTCM code tables it; the torsion centre's lateral place, under the head's middle
//! (36.5 mm from the gauge face: half CHN60's 73 mm head), is an estimate.

mod checks;
mod dynamics;
mod file;
mod receptance;
mod system;
mod wavenumber;

pub use checks::{Check, checks};
pub use dynamics::{Lever, Load, TrackDynamics};
pub(super) use file::DiscreteFile;
pub use receptance::{cut_on_frequencies, peaks, receptance};

/// A spring and a damper in parallel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KelvinVoigt {
    /// Stiffness, N/m.
    pub stiffness: f64,
    /// Damping, N·s/m.
    pub damping: f64,
}

/// The discrete track's parameters (a full sleeper carries both rails).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DiscreteSupport {
    /// Sleeper spacing, m.
    pub spacing: f64,
    /// Bays in the window that moves with the vehicle.
    pub bays: usize,
    /// Rail mass per length, kg/m.
    pub rail_mass: f64,
    /// Rail bending stiffness for vertical bending (E·I_y), N·m².
    pub rail_ei_vertical: f64,
    /// Rail bending stiffness for lateral bending (E·I_z), N·m².
    pub rail_ei_lateral: f64,
    /// The rails' beam theory.
    pub rail_beam: RailBeam,
    /// Rail shear stiffness for vertical bending (κ·G·A), N (Timoshenko only).
    pub rail_shear_vertical: f64,
    /// Rail shear stiffness for lateral bending (κ·G·A), N (Timoshenko only).
    pub rail_shear_lateral: f64,
    /// Rail rotary inertia per length for vertical bending (ρ·I_y), kg·m (Timoshenko only).
    pub rail_rotary_vertical: f64,
    /// Rail rotary inertia per length for lateral bending (ρ·I_z), kg·m (Timoshenko only).
    pub rail_rotary_lateral: f64,
    /// Rail torsional stiffness (St Venant, G·K), N·m².
    pub rail_torsion_stiffness: f64,
    /// Rail roll inertia per length about its torsion centre (ρ·I₀), kg·m.
    pub rail_polar_inertia: f64,
    /// Depth of the rail's torsion centre below its top, m.
    pub torsion_centre_depth: f64,
    /// Lateral distance of the torsion centre from the gauge point, toward the field side, m.
    pub torsion_centre_offset: f64,
    /// Depth of the lateral pad's line of action below the torsion centre, m.
    pub pad_lateral_lever: f64,
    /// Half the width over which the vertical pad carries the rail (its halves' lever about
    /// the torsion centre), m.
    pub pad_vertical_half_width: f64,
    /// Rail pad, vertical (per fastener).
    pub pad_vertical: KelvinVoigt,
    /// Rail pad and fastening, lateral (per fastener).
    pub pad_lateral: KelvinVoigt,
    /// Sleeper mass (the whole sleeper), kg.
    pub sleeper_mass: f64,
    /// Sleeper's roll inertia about its centre, kg·m².
    pub sleeper_roll_inertia: f64,
    /// Half the distance between the two rail seats, m.
    pub seat_half_distance: f64,
    /// Sleeper to ballast, lateral (the whole sleeper).
    pub sleeper_lateral: KelvinVoigt,
    /// Ballast block under one rail seat, kg.
    pub ballast_mass: f64,
    /// Ballast under one rail seat, vertical (sleeper to ballast block).
    pub ballast: KelvinVoigt,
    /// Shear between neighbouring ballast blocks.
    pub ballast_shear: KelvinVoigt,
    /// Subgrade under one ballast block.
    pub subgrade: KelvinVoigt,
}

/// The rails' beam theory.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RailBeam {
    /// Bending with shear deformation and rotary inertia (the flexural branch).
    Timoshenko,
    /// Bending alone: stiffer and lighter at short waves (pinned–pinned 1.44 kHz for CHN60 on
    /// 0.6 m against Timoshenko's 1.07 kHz); the Winkler closed forms' beam.
    EulerBernoulli,
}

impl Default for DiscreteSupport {
    /// Zhai, Wang & Lin 2004 for CHN60 on concrete sleepers and ballast (vertical), the
    /// lateral and shear figures of Zhai's book set; roll inertia and seat distance estimates.
    fn default() -> Self {
        const E: f64 = 2.059e11;
        // CHN60: area 77.45 cm², I_y 3217 cm⁴, I_z 524 cm⁴ (the sources above); G = E/2(1 + ν)
        // with ν = 0.3.
        const AREA: f64 = 77.45e-4;
        const G: f64 = E / 2.6;
        const RHO: f64 = 60.64 / AREA;
        DiscreteSupport {
            spacing: 0.6,
            bays: 48,
            rail_mass: 60.64,
            rail_ei_vertical: E * 3.217e-5,
            rail_ei_lateral: E * 5.24e-6,
            rail_beam: RailBeam::Timoshenko,
            // Shear coefficients: 0.4 vertical (Shock Vib. 2021, 5562152, Table 3), 0.54
            // lateral (rolland's UIC60 figure; an estimate for CHN60).
            rail_shear_vertical: 0.4 * G * AREA,
            rail_shear_lateral: 0.54 * G * AREA,
            rail_rotary_vertical: RHO * 3.217e-5,
            rail_rotary_lateral: RHO * 5.24e-6,
            // CHN60's torsion in Zhai's set (VTCM's rail table): GK and I₀ = I_y + I_z.
            rail_torsion_stiffness: 1.9587e5,
            rail_polar_inertia: RHO * 3.741e-5,
            torsion_centre_depth: 0.09453,
            // Estimate: under the middle of the 73 mm head.
            torsion_centre_offset: 0.0365,
            pad_lateral_lever: 0.082,
            pad_vertical_half_width: 0.075,
            pad_vertical: KelvinVoigt {
                stiffness: 6.5e7,
                damping: 7.5e4,
            },
            pad_lateral: KelvinVoigt {
                stiffness: 3.0e7,
                damping: 5.0e4,
            },
            // Two half sleepers of 125.5 kg.
            sleeper_mass: 251.0,
            // Estimate: a uniform 2.6 m bar, m·l²/12.
            sleeper_roll_inertia: 251.0 * 2.6 * 2.6 / 12.0,
            // Estimate: the rail seats under the rails' contact lines (1.5 m apart).
            seat_half_distance: 0.75,
            sleeper_lateral: KelvinVoigt {
                stiffness: 5.0e7,
                damping: 4.0e4,
            },
            ballast_mass: 531.4,
            ballast: KelvinVoigt {
                stiffness: 137.75e6,
                damping: 5.88e4,
            },
            ballast_shear: KelvinVoigt {
                stiffness: 7.8e7,
                damping: 8.0e4,
            },
            subgrade: KelvinVoigt {
                stiffness: 77.5e6,
                damping: 3.115e4,
            },
        }
    }
}

impl DiscreteSupport {
    /// The window's length, m.
    pub fn window(&self) -> f64 {
        self.spacing * self.bays as f64
    }

    /// The rails as Euler–Bernoulli beams (the closed forms' beam), the rest the same.
    pub fn euler_bernoulli(&self) -> Self {
        DiscreteSupport {
            rail_beam: RailBeam::EulerBernoulli,
            ..*self
        }
    }

    /// A free rail's bending wave of wavenumber `kappa` (1/m), vertical or `lateral`: its
    /// mass per length as the deflection sees it and its stiffness per length, `(m, k)`,
    /// `k/m = ω²`. Timoshenko's flexural branch: the lower root of
    /// `ρI·m·ω⁴ − (m(EIκ² + S) + ρI·Sκ²)·ω² + S·EI·κ⁴ = 0` (S = κ'GA), with the section's
    /// rotation `ψ = (Sκ² − mω²)/(Sκ)·w` adding `ρI·(ψ/w)²` to the mass; Euler–Bernoulli:
    /// `(m, EI·κ⁴)`.
    pub fn bending(&self, kappa: f64, lateral: bool) -> (f64, f64) {
        let (ei, s, r) = if lateral {
            (
                self.rail_ei_lateral,
                self.rail_shear_lateral,
                self.rail_rotary_lateral,
            )
        } else {
            (
                self.rail_ei_vertical,
                self.rail_shear_vertical,
                self.rail_rotary_vertical,
            )
        };
        let (m, k2) = (self.rail_mass, kappa * kappa);
        if self.rail_beam == RailBeam::EulerBernoulli {
            return (m, ei * k2 * k2);
        }
        let b = m * (ei * k2 + s) + r * s * k2;
        let c = s * ei * k2 * k2;
        // The lower root, in the form that stays exact as ρI → 0.
        let w2 = 2.0 * c / (b + (b * b - 4.0 * m * r * c).max(0.0).sqrt());
        let psi = (s * k2 - m * w2) / (s * kappa);
        let mass = m + r * psi * psi;
        (mass, mass * w2)
    }

    /// The rail's pinned–pinned frequency, Hz: its bending wave of half a wavelength per bay
    /// (nodes at every fastener), vertical or `lateral`.
    pub fn pinned_pinned(&self, lateral: bool) -> f64 {
        let (m, k) = self.bending(std::f64::consts::PI / self.spacing, lateral);
        (k / m).sqrt() / (2.0 * std::f64::consts::PI)
    }

    /// Vertical stiffness of one rail seat's support chain (pad, ballast and subgrade in
    /// series, both rails loaded alike so the sleeper does not roll, no shear), N/m: the
    /// support a Winkler beam smears over the spacing.
    pub fn seat_stiffness(&self) -> f64 {
        1.0 / (1.0 / self.pad_vertical.stiffness
            + 1.0 / self.ballast.stiffness
            + 1.0 / self.subgrade.stiffness)
    }

    /// The Winkler beam's wavenumber `β = (k/4EI)^¼` with `k` the seat stiffness per metre,
    /// 1/m.
    pub fn beta(&self) -> f64 {
        (self.seat_stiffness() / self.spacing / (4.0 * self.rail_ei_vertical)).powf(0.25)
    }

    /// The Winkler beam's deflection at `x` from a static point load `p` (N, downward
    /// positive): `w(x) = (p·β/2k)·e^(−β|x|)(cos βx + sin β|x|)`, m.
    pub fn winkler_deflection(&self, p: f64, x: f64) -> f64 {
        let k = self.seat_stiffness() / self.spacing;
        let b = self.beta();
        let a = b * x.abs();
        p * b / (2.0 * k) * (-a).exp() * (a.cos() + a.sin())
    }

    /// The rails all but held upright, the rest the same (the lumped rail's assumption): the
    /// torsional stiffness ten thousand times the section's, so that a wheel's moment rolls
    /// the rail a hundredth as far and over a length beyond the window.
    pub fn without_roll(&self) -> Self {
        DiscreteSupport {
            rail_torsion_stiffness: 1e4 * self.rail_torsion_stiffness,
            ..*self
        }
    }

    /// The rail's roll at the `n`-th fastener from a static torque `t` (N·m) applied over one,
    /// rad: a St Venant bar (`GK`) on a roll spring `k_f = k_v·b² + k_l·a²` at each fastener
    /// (the rail's sway held), whose roll falls by `r = e^(−μ)` a bay, `cosh μ = 1 + k_f·s/2GK`,
    /// from `θ₀ = t/(2·(GK/s)·sinh μ)` (the difference equation
    /// `k_f·θ_n = (GK/s)·(θ_{n−1} − 2θ_n + θ_{n+1})`, derived here).
    pub fn twist_at_fastener(&self, t: f64, n: usize) -> f64 {
        let kf = self.pad_vertical.stiffness * self.pad_vertical_half_width.powi(2)
            + self.pad_lateral.stiffness * self.pad_lateral_lever.powi(2);
        let gk = self.rail_torsion_stiffness / self.spacing;
        let mu = (1.0 + kf / (2.0 * gk)).acosh();
        t / (2.0 * gk * mu.sinh()) * (-mu * n as f64).exp()
    }

    /// The critical speed of a load moving on the Winkler beam, `(4k·EI/m²)^¼`, m/s.
    pub fn critical_speed(&self) -> f64 {
        let k = self.seat_stiffness() / self.spacing;
        (4.0 * k * self.rail_ei_vertical / (self.rail_mass * self.rail_mass)).powf(0.25)
    }
}

#[cfg(test)]
mod tests;
