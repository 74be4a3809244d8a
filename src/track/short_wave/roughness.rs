//! Rail roughness below the geometry's shortest wavelength: one-third-octave spectra from
//! published tables, their PSD, and the contact filter a single-point Hertz contact needs.
//!
//! A band level L (dB re 1 µm) is `10·lg(r_rms²/r0²)`; the bands are base-ten, centred on
//! `k_c = 10^(n/10)` cycles/m with width `Δk = 0.2308·k_c`, so the one-sided PSD at the centre
//! is `S(k_c) = r0²·10^(L/10)/(0.2308·k_c)` in m²/(cycle/m) (EN 15610:2009's definitions).
//! Between centres the level is linear in lg λ; beyond the table it holds the end value.

/// The reference amplitude of the levels, m (1 µm).
const R0: f64 = 1e-6;
/// A one-third-octave band's width over its centre wavenumber (base-ten bands: 10^0.05 − 10^−0.05).
pub const BAND_WIDTH: f64 = 0.2308;

/// Wavelengths (mm) of the tables' one-third-octave band centres, 2 000 mm down to 0.8 mm.
const WAVELENGTHS_MM: [f64; 35] = [
    2000.0, 1600.0, 1250.0, 1000.0, 800.0, 630.0, 500.0, 400.0, 315.0, 250.0, 200.0, 160.0, 125.0,
    100.0, 80.0, 63.0, 50.0, 40.0, 31.5, 25.0, 20.0, 16.0, 12.5, 10.0, 8.0, 6.3, 5.0, 4.0, 3.15,
    2.5, 2.0, 1.6, 1.25, 1.0, 0.8,
];

/// EN ISO 3095:2013's reference-track limit, dB re 1 µm, as CNOSSOS-EU tabulates it (Directive
/// (EU) 2021/1226, Table G-1b, column "E"; EN 15610:2009 Annex B's "2007 TSI limit" agrees),
/// flat at 17.1 dB from 2 000 mm to 400 mm as CNOSSOS extends it.
const ISO_3095: [f64; 35] = [
    17.1, 17.1, 17.1, 17.1, 17.1, 17.1, 17.1, 17.1, 15.0, 13.0, 11.0, 9.0, 7.0, 4.9, 2.9, 0.9,
    -1.1, -3.2, -5.0, -5.6, -6.2, -6.8, -7.4, -8.0, -8.6, -9.2, -9.8, -10.4, -11.0, -11.6, -12.2,
    -12.8, -13.4, -14.0, -14.0,
];

/// CNOSSOS-EU's class "M", an average, normally maintained network (same table, column "M").
const CNOSSOS_M: [f64; 35] = [
    35.0, 31.0, 28.0, 25.0, 23.0, 20.0, 17.0, 13.5, 10.5, 9.0, 6.5, 5.5, 5.0, 3.5, 2.0, 0.1, -0.2,
    -0.3, -0.8, -3.0, -5.0, -7.0, -8.0, -9.0, -10.0, -12.0, -13.0, -14.0, -15.0, -16.0, -17.0,
    -18.0, -19.0, -19.0, -19.0,
];

/// The contact filter of CNOSSOS-EU (Annex G-2) for a 100 kN wheel load on a 920 mm wheel:
/// (wavelength mm, dB). The C80's 840 mm wheel at 122.5 kN has a contact patch about 4 %
/// longer (a ∝ (P·R)^⅓), which the table does not follow: an approximation.
const CONTACT_FILTER: [(f64, f64); 7] = [
    (200.0, 0.0),
    (100.0, -0.3),
    (50.0, -1.8),
    (25.0, -8.7),
    (10.0, -17.8),
    (3.15, -24.5),
    (0.8, -24.5),
];

/// A published roughness spectrum.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RoughnessSpectrum {
    /// EN ISO 3095's limit for the reference track of type tests: smooth, ground rail.
    Iso3095,
    /// CNOSSOS-EU's average network ("M").
    CnossosM,
}

impl RoughnessSpectrum {
    /// The names a track file uses.
    pub const NAMES: [&'static str; 2] = ["iso3095", "cnossos_m"];

    /// The spectrum a track file names.
    pub fn parse(name: &str) -> Option<Self> {
        match name {
            "iso3095" => Some(Self::Iso3095),
            "cnossos_m" => Some(Self::CnossosM),
            _ => None,
        }
    }

    /// The name a track file uses.
    pub fn name(self) -> &'static str {
        match self {
            Self::Iso3095 => "iso3095",
            Self::CnossosM => "cnossos_m",
        }
    }

    /// The one-third-octave level at wavelength `lambda` (m), dB re 1 µm.
    pub fn level_db(self, lambda: f64) -> f64 {
        let table = match self {
            Self::Iso3095 => &ISO_3095,
            Self::CnossosM => &CNOSSOS_M,
        };
        let points: Vec<(f64, f64)> = WAVELENGTHS_MM
            .iter()
            .copied()
            .zip(table.iter().copied())
            .collect();
        interpolate_log(&points, lambda * 1e3)
    }

    /// The one-sided PSD at wavenumber `k` (cycles/m), m²/(cycle/m).
    pub fn psd_per_cycle(self, k: f64) -> f64 {
        R0 * R0 * 10f64.powf(self.level_db(1.0 / k) / 10.0) / (BAND_WIDTH * k)
    }
}

/// The contact filter's attenuation at wavelength `lambda` (m), dB (≤ 0).
pub fn contact_filter_db(lambda: f64) -> f64 {
    interpolate_log(&CONTACT_FILTER, lambda * 1e3)
}

/// Linear in lg λ between tabulated `(λ, dB)` points (λ falling), the end values beyond.
fn interpolate_log(points: &[(f64, f64)], lambda: f64) -> f64 {
    let (first, last) = (points[0], points[points.len() - 1]);
    // A NaN wavelength takes the first value too.
    if lambda >= first.0 || lambda.is_nan() {
        return first.1;
    }
    if lambda <= last.0 {
        return last.1;
    }
    for w in points.windows(2) {
        let ((l0, d0), (l1, d1)) = (w[0], w[1]);
        if lambda <= l0 && lambda >= l1 {
            let t = (lambda / l0).ln() / (l1 / l0).ln();
            return d0 + t * (d1 - d0);
        }
    }
    last.1
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_iso_limit_gives_the_psd_its_definition_does() {
        // excitation spec: 8.8e-11 m³ at 0.4 m, 1.3e-12 at 0.1 m, 4.3e-14 at 31.5 mm.
        for (lambda, want) in [(0.4, 8.8e-11), (0.1, 1.3e-12), (0.0315, 4.3e-14)] {
            let got = RoughnessSpectrum::Iso3095.psd_per_cycle(1.0 / lambda);
            assert!(
                (got / want - 1.0).abs() < 0.03,
                "{lambda} m: {got:e} against {want:e}"
            );
        }
    }

    #[test]
    fn levels_follow_the_tables_between_and_beyond_the_centres() {
        let iso = RoughnessSpectrum::Iso3095;
        assert_eq!(iso.level_db(0.1), 4.9);
        assert_eq!(iso.level_db(5.0), 17.1);
        // Halfway in lg λ between 125 mm (7.0) and 100 mm (4.9).
        let mid = (0.125f64 * 0.1).sqrt();
        assert!((iso.level_db(mid) - 5.95).abs() < 1e-9);
        assert_eq!(RoughnessSpectrum::CnossosM.level_db(2.0), 35.0);
        assert_eq!(
            RoughnessSpectrum::parse("cnossos_m"),
            Some(RoughnessSpectrum::CnossosM)
        );
        assert_eq!(RoughnessSpectrum::parse("iso"), None);
    }

    #[test]
    fn the_contact_filter_passes_long_waves_and_stops_short_ones() {
        assert_eq!(contact_filter_db(0.5), 0.0);
        assert_eq!(contact_filter_db(0.05), -1.8);
        assert_eq!(contact_filter_db(0.01), -17.8);
        assert!(contact_filter_db(0.02) < -8.7 && contact_filter_db(0.02) > -17.8);
    }
}
