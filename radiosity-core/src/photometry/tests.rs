use super::*;
use std::f64::consts::PI;

fn data(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("data/luminaires").join(name)
}

/// Every luminaire file shipped in `data/luminaires`.
const SHIPPED: [&str; 5] =
    ["lambert_1000cd.ies", "isotropic_10000lm.ies", "downlight_asymmetric.ies", "downlight_asymmetric.ldt", "linear_example.ies"];

/// Bound on linear interpolation of `1000 cos γ` on a 5° table: `h²/8 · max |f''|` with h = 5° in
/// radians and `max |f''| = 1000` cd, plus the table's rounding to 1e-6 cd.
const LAMBERT_INTERP_BOUND_CD: f64 = 0.087_266_462_6 * 0.087_266_462_6 / 8.0 * 1000.0 + 1e-6;

/// Flux of a shipped file against its declared lumens (the task's requirement).
const FLUX_REL_TOL: f64 = 5e-3;

/// Flux of a 5° Lambertian table against π·I0 (the task's requirement).
const LAMBERT_FLUX_REL_TOL: f64 = 1e-3;

/// Rounding of the shipped tables (values to 6 decimals in cd/klm, 0.1 cd in cd).
const ROUNDING_REL_TOL: f64 = 1e-6;

fn table(c: &[f64], gamma: &[f64], f: impl Fn(f64, f64) -> f64) -> Photometry {
    Photometry {
        gamma: gamma.to_vec(),
        c: c.to_vec(),
        candela: c.iter().map(|&cc| gamma.iter().map(|&g| f(cc, g)).collect()).collect(),
        declared_lumens: None,
        opening: [0.0; 3],
        source: "table".into(),
    }
}

fn steps(from: f64, to: f64, step: f64) -> Vec<f64> {
    let n = ((to - from) / step).round() as usize;
    (0..=n).map(|k| from + step * k as f64).collect()
}

#[test]
fn lambert_file_is_i0_cos_gamma_between_the_table_angles() {
    // CIE 171:2006 5.2 (shared/reference/cie171.md): I(γ) = 1000 cos γ cd.
    let p = read_ies(&data("lambert_1000cd.ies")).unwrap();
    assert_eq!(p.gamma.len(), 19);
    assert_eq!(p.c, vec![0.0]);
    assert!((p.declared_lumens.unwrap() / (1000.0 * PI) - 1.0).abs() < ROUNDING_REL_TOL);
    for &g in &[0.0, 2.5, 7.3, 12.5, 33.3, 47.7, 61.0, 75.2, 88.8, 90.0] {
        for &c in &[0.0, 37.0, 200.0, -75.0] {
            let want = 1000.0 * f64::to_radians(g).cos();
            let got = p.intensity(c, g);
            assert!((got - want).abs() <= LAMBERT_INTERP_BOUND_CD, "I({c}, {g}) = {got}, want {want} ± {LAMBERT_INTERP_BOUND_CD}");
        }
    }
    // At the table's angles it is exact; beyond its last γ it is 0.
    assert!((p.intensity(0.0, 60.0) - 500.0).abs() < 1e-6);
    assert_eq!(p.intensity(0.0, 90.5), 0.0);
    assert_eq!(p.intensity(0.0, 135.0), 0.0);
    // γ is reflected: −30° and 330° are 30°.
    assert_eq!(p.intensity(0.0, -30.0), p.intensity(0.0, 30.0));
    assert_eq!(p.intensity(0.0, 330.0), p.intensity(0.0, 30.0));
    assert_eq!(p.intensity(f64::NAN, 30.0), 0.0);
}

#[test]
fn lambert_flux_is_pi_i0_on_a_5_degree_table() {
    let p = table(&[0.0], &steps(0.0, 90.0, 5.0), |_, g| 1000.0 * g.to_radians().cos());
    let rel = p.flux() / (PI * 1000.0) - 1.0;
    assert!(rel.abs() < LAMBERT_FLUX_REL_TOL, "flux {} vs π·1000: {rel:e}", p.flux());
    // A constant is integrated exactly: 4π·I.
    let iso = table(&[0.0], &steps(0.0, 180.0, 30.0), |_, _| 10.0);
    assert!((iso.flux() - 40.0 * PI).abs() < 1e-9 * iso.flux());
}

#[test]
fn every_shipped_file_emits_its_declared_lumens() {
    for name in SHIPPED {
        let p = read(&data(name)).unwrap_or_else(|e| panic!("{e}"));
        let declared = p.declared_lumens.unwrap();
        let rel = p.flux() / declared - 1.0;
        assert!(rel.abs() < FLUX_REL_TOL, "{name}: flux {} vs declared {declared}: {rel:e}", p.flux());
    }
    let lambert = read(&data("lambert_1000cd.ies")).unwrap();
    assert!((lambert.flux() / (PI * 1000.0) - 1.0).abs() < LAMBERT_FLUX_REL_TOL);
    let iso = read(&data("isotropic_10000lm.ies")).unwrap();
    assert!((iso.flux() / 10_000.0 - 1.0).abs() < ROUNDING_REL_TOL, "{}", iso.flux());
}

#[test]
fn ies_and_ldt_downlights_agree() {
    let ies = read(&data("downlight_asymmetric.ies")).unwrap();
    let ldt = read(&data("downlight_asymmetric.LDT".to_lowercase().as_str())).unwrap();
    assert_eq!(ies.c, ldt.c);
    assert_eq!(ies.gamma, ldt.gamma);
    assert_eq!(ies.declared_lumens, ldt.declared_lumens);
    assert_eq!(ies.opening, ldt.opening);
    assert_eq!(ies.opening, [0.08, 0.08, 0.0]);
    assert_eq!(ies.symmetry(), Some(Symmetry::Full));
    let peak = ies.max_intensity();
    for (a, b) in ies.candela.iter().flatten().zip(ldt.candela.iter().flatten()) {
        assert!((a - b).abs() <= ROUNDING_REL_TOL * peak, "{a} vs {b}");
    }
    for &(c, g) in &[(0.0, 30.0), (97.0, 41.0), (352.5, 12.0), (-7.5, 60.0), (180.0, 89.0)] {
        assert!((ies.intensity(c, g) - ldt.intensity(c, g)).abs() <= ROUNDING_REL_TOL * peak);
    }
    // The C planes are asymmetric: C0 (I = 2000 cos²γ (1 + 0.5 sin γ)) is brighter than C180.
    let g = 30f64.to_radians();
    let want = |cos_c: f64| 2000.0 * g.cos().powi(2) * (1.0 + 0.5 * g.sin() * cos_c);
    assert!((ies.intensity(0.0, 30.0) - want(1.0)).abs() < 0.05);
    assert!((ies.intensity(180.0, 30.0) - want(-1.0)).abs() < 0.05);
    // Between C345 and C360 the full table wraps to C0.
    let mid = 0.5 * (ies.intensity(345.0, 30.0) + ies.intensity(0.0, 30.0));
    assert!((ies.intensity(352.5, 30.0) - mid).abs() < 1e-9);
}

/// A distribution symmetric about both the C0–C180 and the C90–C270 planes, linear in γ.
fn quadrant_fn(c: f64, g: f64) -> f64 {
    100.0 + 50.0 * (2.0 * c.to_radians()).cos() + 0.5 * g
}

/// A distribution symmetric about the C0–C180 plane only.
fn bilateral_fn(c: f64, g: f64) -> f64 {
    100.0 + 50.0 * c.to_radians().cos() + 20.0 * (2.0 * c.to_radians()).cos() + 0.5 * g
}

const SYM_TOL: f64 = 1e-9;

#[test]
fn quadrant_bilateral_and_full_tables_of_one_distribution_agree() {
    let gamma = steps(0.0, 180.0, 10.0);
    let quadrant = table(&steps(0.0, 90.0, 15.0), &gamma, quadrant_fn);
    let bilateral = table(&steps(0.0, 180.0, 15.0), &gamma, quadrant_fn);
    let full = table(&steps(0.0, 345.0, 15.0), &gamma, quadrant_fn);
    assert_eq!(quadrant.symmetry(), Some(Symmetry::Quadrant));
    assert_eq!(bilateral.symmetry(), Some(Symmetry::Bilateral));
    assert_eq!(full.symmetry(), Some(Symmetry::Full));
    for k in 0..73 {
        let c = -360.0 + 10.0 * k as f64 + 2.5;
        for &g in &[0.0, 7.5, 45.0, 93.0, 180.0] {
            let q = quadrant.intensity(c, g);
            assert!((q - full.intensity(c, g)).abs() < SYM_TOL, "C {c} γ {g}");
            assert!((q - bilateral.intensity(c, g)).abs() < SYM_TOL, "C {c} γ {g}");
            // The reflections a quadrant-symmetric table implies.
            for mirrored in [-c, 180.0 - c, 180.0 + c, c + 360.0] {
                assert!((q - quadrant.intensity(mirrored, g)).abs() < SYM_TOL);
            }
        }
    }
    // On a table plane, γ between rows is linear (the function is linear in γ): exact.
    assert!((quadrant.intensity(30.0, 47.0) - quadrant_fn(30.0, 47.0)).abs() < SYM_TOL);
    // Mirrored onto the plane C30: C150, C210, C330.
    for c in [150.0, 210.0, 330.0, -30.0] {
        assert!((quadrant.intensity(c, 47.0) - quadrant_fn(30.0, 47.0)).abs() < SYM_TOL);
    }
    // Halfway between C15 and C30 the planes are averaged.
    let want = 0.5 * (quadrant_fn(15.0, 40.0) + quadrant_fn(30.0, 40.0));
    assert!((quadrant.intensity(22.5, 40.0) - want).abs() < SYM_TOL);
    let (fq, fb, ff) = (quadrant.flux(), bilateral.flux(), full.flux());
    assert!((fq - ff).abs() < SYM_TOL * ff && (fb - ff).abs() < SYM_TOL * ff, "{fq} {fb} {ff}");
}

#[test]
fn bilateral_table_reflects_about_the_c0_c180_plane_only() {
    let gamma = steps(0.0, 90.0, 5.0);
    let bilateral = table(&steps(0.0, 180.0, 10.0), &gamma, bilateral_fn);
    let full = table(&steps(0.0, 350.0, 10.0), &gamma, bilateral_fn);
    for k in 0..36 {
        let c = 10.0 * k as f64 + 3.0;
        assert!((bilateral.intensity(c, 33.0) - full.intensity(c, 33.0)).abs() < SYM_TOL, "C {c}");
        assert!((bilateral.intensity(c, 33.0) - bilateral.intensity(-c, 33.0)).abs() < SYM_TOL);
    }
    // C0 and C180 differ (not quadrant symmetric).
    assert!((bilateral.intensity(0.0, 0.0) - 170.0).abs() < SYM_TOL);
    assert!((bilateral.intensity(180.0, 0.0) - 70.0).abs() < SYM_TOL);
    assert!((bilateral.flux() - full.flux()).abs() < SYM_TOL * full.flux());
}

#[test]
fn axial_table_is_the_same_in_every_plane() {
    let p = table(&[0.0], &steps(0.0, 180.0, 45.0), |_, g| 200.0 - g);
    assert_eq!(p.symmetry(), Some(Symmetry::Axial));
    for c in [0.0, 45.0, 123.0, -300.0, 720.5] {
        assert!((p.intensity(c, 22.5) - 177.5).abs() < SYM_TOL);
    }
    // ∫∫ (200 − γ°) sin γ dγ dC = 2π (400 − 180·π/180·... ) exactly: 2π(200·2 − (180/π)·π) = 2π·220.
    assert!((p.flux() - 2.0 * PI * 220.0).abs() < 1e-9, "{}", p.flux());
}

#[test]
fn uplight_table_is_zero_below_its_first_gamma() {
    let p = table(&[0.0], &steps(90.0, 180.0, 10.0), |_, _| 50.0);
    assert_eq!(p.intensity(0.0, 45.0), 0.0);
    assert_eq!(p.intensity(0.0, 135.0), 50.0);
    assert!((p.flux() - 2.0 * PI * 50.0).abs() < 1e-9);
}

#[test]
fn scaled_multiplies_intensities_and_lumens() {
    let p = read(&data("isotropic_10000lm.ies")).unwrap().scaled(0.5);
    assert!((p.flux() - 5000.0).abs() < 1e-3);
    assert_eq!(p.declared_lumens, Some(5000.0));
}

const GOOD_IES: &str = "IESNA:LM-63-2002\n[TEST] t\nTILT=NONE\n1 1000 1 3 1 1 2 0 0 0\n1 1 0\n0 45 90\n0\n100 70 0\n";

fn ies_err(text: &str) -> String {
    let e = parse_ies(text, "t.ies").unwrap_err().to_string();
    assert!(!e.contains('\n'), "not one line: {e}");
    e
}

fn ldt_err(text: &str) -> String {
    let e = parse_ldt(text, "t.ldt").unwrap_err().to_string();
    assert!(!e.contains('\n'), "not one line: {e}");
    e
}

#[test]
fn ies_reads_a_minimal_file_and_its_multipliers() {
    let p = parse_ies(GOOD_IES, "t.ies").unwrap();
    assert_eq!(p.gamma, vec![0.0, 45.0, 90.0]);
    assert_eq!(p.candela, vec![vec![100.0, 70.0, 0.0]]);
    assert_eq!(p.declared_lumens, Some(1000.0));
    // Candela multiplier 2 and ballast factor 0.5 cancel; 2 lamps; -1: absolute photometry; feet.
    let p = parse_ies(&GOOD_IES.replace("1 1000 1 3 1 1 2 0 0 0\n1 1 0", "2 -1 2 3 1 1 1 1 2 0\n0.25 1 0"), "t.ies").unwrap();
    assert_eq!(p.candela, vec![vec![50.0, 35.0, 0.0]]);
    assert_eq!(p.declared_lumens, None);
    assert_eq!(p.opening, [0.3048, 0.6096, 0.0]);
    // A 1986 file: no version line, free text, commas between values.
    let p = parse_ies("free text\nTILT=NONE\n1,1000,1,3,1,1,2,0,0,0\n1,1,0\n0,45,90\n0\n100,70,0\n", "t.ies").unwrap();
    assert_eq!(p.candela, vec![vec![100.0, 70.0, 0.0]]);
    // TILT=INCLUDE is read and its factors are not applied.
    let tilt = GOOD_IES.replace("TILT=NONE\n", "TILT=INCLUDE\n1\n3\n0 45 90\n1 0.9 0.8\n");
    assert_eq!(parse_ies(&tilt, "t.ies").unwrap().candela, vec![vec![100.0, 70.0, 0.0]]);
}

#[test]
fn ies_errors_are_one_line_with_file_line_and_reason() {
    let cases: [(String, &str); 14] = [
        (GOOD_IES.replace("TILT=NONE\n", ""), "t.ies: missing `TILT=` line (not an IES LM-63 file?)"),
        (
            GOOD_IES.replace("TILT=NONE", "TILT=lamp.tlt"),
            "t.ies:3: `TILT=lamp.tlt`: tilt data in another file is not supported (use TILT=NONE or TILT=INCLUDE)",
        ),
        (GOOD_IES.replace("100 70 0", "100 70"), "t.ies:8: file ends before candela value (horizontal angle 0) at vertical angle 3 of 3"),
        (GOOD_IES.replace("100 70 0", "100 70 0 5"), "t.ies:8: unexpected `5` after the candela values (1 values too many)"),
        (
            GOOD_IES.replace("100 70 0", "100 NaN 0"),
            "t.ies:8: candela value (horizontal angle 0) at vertical angle 2 of 3: `NaN` is not a finite number",
        ),
        (
            GOOD_IES.replace("100 70 0", "100 -70 0"),
            "t.ies:8: candela value (horizontal angle 0) at vertical angle 2 of 3: negative intensity -70",
        ),
        (GOOD_IES.replace("0 45 90", "0 90 45"), "t.ies:6: vertical angles must be strictly ascending, found 90 then 45"),
        (GOOD_IES.replace("0 45 90", "0 45 190"), "t.ies:6: vertical angle 190 lies outside [0, 180]"),
        (
            GOOD_IES.replace("1 1000 1 3 1 1 2", "1 1000 1 3 1 2 2"),
            "t.ies:4: type B photometry is not supported (only type C, photometric type 1)",
        ),
        (
            GOOD_IES.replace("1 1000 1 3 1 1 2", "1 1000 1 3.5 1 1 2"),
            "t.ies:4: the number of vertical angles must be a whole number from 1 to 10000, found 3.5",
        ),
        (GOOD_IES.replace("1 1000 1 3 1 1 2", "0 1000 1 3 1 1 2"), "t.ies:4: number of lamps must be positive, found 0"),
        (GOOD_IES.replace("1 1000 1 3 1 1 2", "1 1000 1 3 1 1 7"), "t.ies:4: units type must be 1 (feet) or 2 (metres), found 7"),
        (GOOD_IES.replace("\n0\n", "\n90\n"), "t.ies:7: horizontal angles must start at 0, found 90 (tables of 90–270° are not supported)"),
        ("TILT=NONE\n".into(), "t.ies:1: file ends before the number of lamps"),
    ];
    for (text, want) in cases {
        assert_eq!(ies_err(&text), want);
    }
}

#[test]
fn truncated_files_give_errors_not_panics() {
    for name in SHIPPED {
        let text = std::fs::read_to_string(data(name)).unwrap();
        let parse = |t: &str| if name.ends_with(".ldt") { parse_ldt(t, name) } else { parse_ies(t, name) };
        assert!(parse(&text).is_ok());
        for end in (0..text.len()).filter(|&i| text.is_char_boundary(i)) {
            let cut = &text[..end];
            // A cut inside the last number may still parse; a shorter file never does.
            if let Err(e) = parse(cut) {
                assert!(!e.to_string().contains('\n'));
            } else {
                assert!(end + 12 >= text.len(), "{name} parsed when cut at {end} of {}", text.len());
            }
        }
    }
}

/// A EULUMDAT file of 4 C planes (Isym `isym`) and 3 γ angles, 1000 lm.
fn ldt_text(isym: u32, values: &str) -> String {
    let mut lines: Vec<String> = vec!["co".into(), "1".into(), isym.to_string(), "4".into(), "90".into(), "3".into(), "45".into()];
    lines.extend(["r", "name", "n", "f.ldt", "d"].map(String::from));
    lines.extend(["100", "100", "50", "200", "0", "0", "0", "0", "0", "100", "80", "1", "0", "1"].map(String::from));
    lines.extend(["1", "LED", "1000", "3000", "1B", "10"].map(String::from));
    lines.extend(std::iter::repeat_n("0".to_string(), 10));
    lines.extend(["0", "90", "180", "270", "0", "45", "90"].map(String::from));
    lines.extend(values.split(' ').map(String::from));
    lines.join("\r\n") + "\r\n"
}

#[test]
fn ldt_symmetries_become_tables() {
    // Isym 1: one plane; per-1000-lm values times 1000 lm / 1000.
    let p = parse_ldt(&ldt_text(1, "300 200 0"), "t.ldt").unwrap();
    assert_eq!((p.c.clone(), p.candela.clone()), (vec![0.0], vec![vec![300.0, 200.0, 0.0]]));
    assert_eq!(p.opening, [0.2, 0.2, 0.0]);
    assert_eq!(p.declared_lumens, Some(1000.0));
    // Isym 4: C0–C90.
    let p = parse_ldt(&ldt_text(4, "300 200 0 100 50 0"), "t.ldt").unwrap();
    assert_eq!(p.c, vec![0.0, 90.0]);
    assert_eq!(p.symmetry(), Some(Symmetry::Quadrant));
    // Isym 2: C0–C180.
    let p = parse_ldt(&ldt_text(2, "300 200 0 100 50 0 30 20 0"), "t.ldt").unwrap();
    assert_eq!(p.c, vec![0.0, 90.0, 180.0]);
    // Isym 3: C90–C270, mirrored: C0 is C180, C270 itself.
    let p = parse_ldt(&ldt_text(3, "100 50 0 30 20 0 7 6 0"), "t.ldt").unwrap();
    assert_eq!(p.c, vec![0.0, 90.0, 180.0, 270.0]);
    assert_eq!(p.candela, vec![vec![30.0, 20.0, 0.0], vec![100.0, 50.0, 0.0], vec![30.0, 20.0, 0.0], vec![7.0, 6.0, 0.0]]);
    // Isym 0: all four.
    let p = parse_ldt(&ldt_text(0, "1 1 0 2 2 0 3 3 0 4 4 0"), "t.ldt").unwrap();
    assert_eq!(p.candela[3], vec![4.0, 4.0, 0.0]);
    // A comma is a decimal point.
    let p = parse_ldt(&ldt_text(1, "300,5 200 0"), "t.ldt").unwrap();
    assert_eq!(p.candela[0][0], 300.5);
}

#[test]
fn ldt_errors_are_one_line_with_file_line_and_reason() {
    let good = ldt_text(1, "300 200 0");
    let cases: [(String, &str); 7] = [
        (
            good.replacen("co\r\n1\r\n1\r\n", "co\r\n1\r\n7\r\n", 1),
            "t.ldt:3: symmetry indicator Isym must be a whole number from 0 to 4, found 7",
        ),
        (ldt_text(1, "300 200"), "t.ldt:51: file ends before intensity (C plane 0) at γ angle 3 of 3"),
        (ldt_text(1, "300 200 0 9"), "t.ldt:53: unexpected `9` after the intensities (1 values too many)"),
        (ldt_text(1, "300 nan 0"), "t.ldt:51: intensity (C plane 0) at γ angle 2 of 3: `nan` is not a finite number"),
        (ldt_text(1, "300 -2 0"), "t.ldt:51: intensity (C plane 0) at γ angle 2 of 3: negative intensity -2"),
        (good.replace("\r\n0\r\n45\r\n90\r\n", "\r\n0\r\n90\r\n45\r\n"), "t.ldt:49: γ angles must be strictly ascending, found 90 then 45"),
        ("co\r\n1\r\n1\r\n".into(), "t.ldt:3: file ends before line 4 (number of C planes Mc)"),
    ];
    for (text, want) in cases {
        assert_eq!(ldt_err(&text), want);
    }
}

#[test]
fn read_chooses_by_extension() {
    assert!(read(&data("LAMBERT_1000CD.IES".to_lowercase().as_str())).is_ok());
    let e = read(Path::new("lamp.txt")).unwrap_err().to_string();
    assert_eq!(e, "lamp.txt: unknown photometric file type (expected .ies or .ldt)");
    let e = read(Path::new("/nonexistent/lamp.ies")).unwrap_err().to_string();
    assert!(e.starts_with("/nonexistent/lamp.ies: cannot read file: "), "{e}");
}
