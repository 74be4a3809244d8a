use super::*;

fn spec(filter: bool) -> ShortWaveSpec {
    ShortWaveSpec {
        roughness: Some(RoughnessSpec {
            spectrum: RoughnessSpectrum::Iso3095,
            min_wavelength: 0.02,
            max_wavelength: 1.0,
            contact_filter: filter,
            seed: 7,
        }),
        welds: None,
        joints: None,
        smooth_start: 0.0,
        fade_in: 0.0,
    }
}

#[test]
fn the_drawn_rails_hold_the_spectrums_band_levels() {
    for filter in [false, true] {
        let w = ShortWaves::synthesize(spec(filter), 400.0);
        let bands = crate::track::check::roughness_bands(&w, 400.0);
        // 0.8 m down to 32 mm on both rails (a third of an octave inside the drawn band).
        assert_eq!(bands.len(), 2 * 15, "{bands:?}");
        for b in bands {
            assert!(
                (b.drawn_db - b.expected_db).abs() < 1.0,
                "filter {filter}: {b:?}"
            );
        }
    }
}

#[test]
fn the_two_rails_are_drawn_apart_and_the_same_seed_draws_the_same() {
    let a = ShortWaves::synthesize(spec(true), 200.0);
    let b = ShortWaves::synthesize(spec(true), 200.0);
    assert_eq!(a.roughness_samples(0), b.roughness_samples(0));
    let (l, r) = (a.roughness_samples(0), a.roughness_samples(1));
    let dot: f64 = l.iter().zip(r).map(|(x, y)| x * y).sum();
    let norm = (l.iter().map(|x| x * x).sum::<f64>() * r.iter().map(|x| x * x).sum::<f64>()).sqrt();
    assert!((dot / norm).abs() < 0.1, "correlation {}", dot / norm);
}

#[test]
fn welds_and_roughness_add_fade_in_and_the_gradient_is_the_derivative() {
    let mut s = spec(true);
    s.welds = Some(Welds {
        spacing: 30.0,
        first: 30.0,
        depth: 0.3e-3,
        length: 1.0,
    });
    s.smooth_start = 10.0;
    s.fade_in = 10.0;
    let w = ShortWaves::synthesize(s, 200.0);
    assert_eq!(w.at(5.0), [0.0; 4]);
    let h = 1e-5;
    for x in [15.0, 29.8, 30.0, 61.3] {
        let [zl, dl, zr, dr] = w.at(x);
        let (p, m) = (w.at(x + h), w.at(x - h));
        assert!((dl - (p[0] - m[0]) / (2.0 * h)).abs() < 1e-6, "at {x}");
        assert!((dr - (p[2] - m[2]) / (2.0 * h)).abs() < 1e-6, "at {x}");
        assert!(zl.is_finite() && zr.is_finite());
    }
    // At a weld's centre the dip is 0.3 mm under the roughness alone.
    let mut rough = s;
    rough.welds = None;
    let r = ShortWaves::synthesize(rough, 200.0);
    assert!((w.at(60.0)[0] - r.at(60.0)[0] + 0.3e-3).abs() < 1e-12);
}

fn parse(extra: &str) -> Result<Option<ShortWaveSpec>> {
    let text = format!("{extra}\n");
    #[derive(Deserialize)]
    struct T {
        roughness: Option<RoughnessFile>,
        welds: Option<WeldsFile>,
        joints: Option<JointsFile>,
    }
    let t: T = toml::from_str(&text).unwrap();
    from_file(
        Path::new("t.toml"),
        Tables {
            roughness: t.roughness.as_ref(),
            welds: t.welds.as_ref(),
            joints: t.joints.as_ref(),
        },
        2000.0,
        Some((1.0, 3, 20.0, 50.0)),
    )
}

#[test]
fn a_track_files_tables_are_read_with_their_defaults_and_bad_keys_refused() {
    assert_eq!(parse("").unwrap(), None);
    let s = parse("[roughness]\nspectrum = \"cnossos_m\"\n[welds]\n")
        .unwrap()
        .unwrap();
    let r = s.roughness.unwrap();
    assert_eq!(
        (r.min_wavelength, r.max_wavelength, r.contact_filter, r.seed),
        (0.1, 1.0, true, 3)
    );
    assert_eq!(s.welds.unwrap().spacing, 100.0);
    assert_eq!(s.shortest_wavelength(), 0.1);
    let j = parse("[joints]\nangle_mrad = 20.0").unwrap().unwrap();
    assert_eq!(
        j.joints,
        Some(Joints {
            spacing: 25.0,
            first: 25.0,
            angle: 0.02,
            length: 2.0
        })
    );
    assert_eq!((j.roughness, j.welds), (None, None));
    assert_eq!(j.shortest_wavelength(), 0.05);
    for (bad, field) in [
        ("[roughness]\nspectrum = \"iso\"", "roughness.spectrum"),
        (
            "[roughness]\nspectrum = \"iso3095\"\nmin_wavelength_m = 0.001",
            "roughness.min_wavelength_m",
        ),
        (
            "[roughness]\nspectrum = \"iso3095\"\nmax_wavelength_m = 2.0",
            "roughness.max_wavelength_m",
        ),
        ("[welds]\ndepth_mm = -0.1", "welds.depth_mm"),
        (
            "[welds]\nspacing_m = 10.0\nlength_m = 6.0",
            "welds.length_m",
        ),
        ("[joints]\n", "joints.angle_mrad"),
        ("[joints]\nangle_mrad = 80.0", "joints.angle_mrad"),
        (
            "[joints]\nangle_mrad = 10.0\nlength_m = 20.0",
            "joints.length_m",
        ),
        (
            "[joints]\nangle_mrad = 10.0\nfirst_m = -1.0",
            "joints.first_m",
        ),
        (
            "[joints]\nangle_mrad = 10.0\nfirst_m = 2500.0",
            "joints.first_m",
        ),
        ("[welds]\nfirst_m = 2500.0", "welds.first_m"),
    ] {
        let e = parse(bad).unwrap_err().to_string();
        assert!(e.contains(field) && e.contains("t.toml"), "{bad}: {e}");
    }
}
