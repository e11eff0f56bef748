//! Tests of the sun, the sky's cells, the escape cells and the open backs.

use super::*;

const TOL: f64 = 1e-12;

/// A closed box's faces have no open back (nothing reaches their insides); a lone face has;
/// a face with its back written after it has none (the back reflects).
#[test]
fn open_backs_are_one_sided_faces_of_open_meshes() {
    use crate::scene::{Material, SceneBuilder};
    let mut b = SceneBuilder::new(std::path::Path::new("test"), "test");
    let m = b.material(Material::diffuse("grey", [0.5; 3])).unwrap();
    let mut two = Material::diffuse("leaf", [0.4; 3]);
    two.two_sided = true;
    let leaf = b.material(two).unwrap();
    let g = b.group("g");
    let c = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
    // A unit cube, faces outward.
    let cube = [
        [c(0., 0., 0.), c(0., 1., 0.), c(1., 1., 0.), c(1., 0., 0.)],
        [c(0., 0., 1.), c(1., 0., 1.), c(1., 1., 1.), c(0., 1., 1.)],
        [c(0., 0., 0.), c(1., 0., 0.), c(1., 0., 1.), c(0., 0., 1.)],
        [c(0., 1., 0.), c(0., 1., 1.), c(1., 1., 1.), c(1., 1., 0.)],
        [c(0., 0., 0.), c(0., 0., 1.), c(0., 1., 1.), c(0., 1., 0.)],
        [c(1., 0., 0.), c(1., 1., 0.), c(1., 1., 1.), c(1., 0., 1.)],
    ];
    for f in &cube {
        b.face(f, m, g, 0).unwrap();
    }
    let lone = [c(3., 0., 1.), c(4., 0., 1.), c(4., 1., 1.), c(3., 1., 1.)];
    b.face(&lone, m, g, 0).unwrap();
    b.face(&lone.map(|v| v + DVec3::Z), leaf, g, 0).unwrap();
    let mut scene = b.finish();
    scene.pair_two_sided();
    let h = crate::hierarchy::build(&scene, &crate::hierarchy::BuildConfig::default());
    let open = open_backs(&h);
    assert_eq!(open, [vec![false; 6], vec![true], vec![false, false]].concat());
}

#[test]
fn cells_have_equal_solid_angle_and_cover_the_hemisphere() {
    for n in [1, 7, 46, 145, 500] {
        let cells = sky_cells(n).unwrap();
        assert_eq!(cells.len(), n as usize);
        let total: f64 = cells.iter().map(|c| c.phi_width * (c.mu_high - c.mu_low)).sum();
        assert!((total - std::f64::consts::TAU).abs() < 1e-9, "{n}: {total}");
        for c in &cells {
            let omega = c.phi_width * (c.mu_high - c.mu_low);
            assert!((omega - std::f64::consts::TAU / f64::from(n)).abs() < 1e-9, "{n}: {omega}");
        }
    }
    assert!(sky_cells(0).is_err());
}

#[test]
fn sky_delivers_the_diffuse_horizontal_irradiance_to_a_horizontal_plane() {
    let site = Site::default();
    for model in [SkyModel::Uniform, SkyModel::CieOvercast] {
        for n in [46, 145] {
            let s = sky(model, [100.0, 50.0, 0.0], n, &site).unwrap();
            let h: f64 = s.iter().map(|b| b.on(DVec3::Z)[0]).sum();
            assert!((h - 100.0).abs() < 1e-9, "{model:?} {n}: {h}");
            // Nothing reaches a plane facing down.
            assert!(s.iter().all(|b| b.on(-DVec3::Z) == [0.0; 3]));
        }
    }
}

#[test]
fn vertical_plane_gets_half_the_uniform_sky_and_less_of_the_overcast() {
    // Uniform sky: a vertical plane sees half the sky's hemisphere: E_v = E_h / 2 exactly in
    // the continuum; the 145-cell sky within 0.5%. CIE overcast: E_v / E_h = 0.396 (the
    // integral of (1 + 2 cos θ)/3 against the vertical plane's cosine, over the
    // horizontal's, by a fine midpoint rule below).
    let site = Site::default();
    let uni = sky(SkyModel::Uniform, [1.0; 3], 145, &site).unwrap();
    let v: f64 = uni.iter().map(|b| b.on(DVec3::X)[0]).sum();
    assert!((v - 0.5).abs() < 0.0025, "uniform vertical {v}");
    let ov = sky(SkyModel::CieOvercast, [1.0; 3], 145, &site).unwrap();
    let v: f64 = ov.iter().map(|b| b.on(DVec3::X)[0]).sum();
    let exact = vertical_over_horizontal_overcast();
    assert!((v - exact).abs() < 0.01 * exact, "overcast vertical {v} vs {exact}");
}

/// E_v / E_h of the CIE overcast sky by a fine midpoint rule.
fn vertical_over_horizontal_overcast() -> f64 {
    let (nt, np) = (2000, 2000);
    let (mut ev, mut eh) = (0.0, 0.0);
    for i in 0..nt {
        let th = (i as f64 + 0.5) / nt as f64 * std::f64::consts::FRAC_PI_2;
        let l = (1.0 + 2.0 * th.cos()) / 3.0;
        let dth = std::f64::consts::FRAC_PI_2 / nt as f64;
        eh += l * th.cos() * th.sin() * dth * std::f64::consts::TAU;
        for j in 0..np {
            let ph = (j as f64 + 0.5) / np as f64 * std::f64::consts::TAU;
            let c = th.sin() * ph.cos();
            if c > 0.0 {
                ev += l * c * th.sin() * dth * std::f64::consts::TAU / np as f64;
            }
        }
    }
    ev / eh
}

#[test]
fn sun_position_at_a_known_place_and_time() {
    // Equinox noon at the equator on the Greenwich meridian: the sun is near the zenith
    // (declination ~0, equation of time ~ -7 min on 2026-03-20: within 3 degrees).
    let (z, _) = sun_position(0.0, 0.0, "2026-03-20T12:00:00Z").unwrap();
    assert!(z < 3.0, "zenith {z}");
    // Summer solstice solar noon at 45 N: zenith = 45 - 23.44 = 21.56 degrees, due south.
    let (z, a) = sun_position(45.0, 0.0, "2026-06-21T12:02:00Z").unwrap();
    assert!((z - 21.56).abs() < 0.3, "zenith {z}");
    assert!((a - 180.0).abs() < 2.0, "azimuth {a}");
    assert!(sun_position(0.0, 0.0, "noon").is_err());
    assert!(sun_position(95.0, 0.0, "2026-03-20T12:00:00Z").is_err());
}

#[test]
fn site_directions() {
    let s = Site::default();
    assert!((s.direction(0.0, 0.0) - DVec3::Z).length() < TOL);
    assert!((s.direction(std::f64::consts::FRAC_PI_2, 0.0) - DVec3::Y).length() < TOL);
    assert!((s.direction(std::f64::consts::FRAC_PI_2, std::f64::consts::FRAC_PI_2) - DVec3::X).length() < TOL);
    let y_up = Site::new(DVec3::Y, DVec3::NEG_Z).unwrap();
    assert!((y_up.direction(0.0, 1.0) - DVec3::Y).length() < TOL);
    assert!(Site::new(DVec3::Z, DVec3::Z).is_err());
    // A sun below the horizon gives no source.
    assert!(sun(DVec3::Z, [1.0; 3], &s).unwrap().is_none());
    assert!(sun(-DVec3::Z, [f64::NAN; 3], &s).is_err());
}

#[test]
fn escape_cells_are_cosine_weights() {
    let cells = escape_cells();
    let total: f64 = cells.iter().map(|c| c.1).sum();
    assert!((total - 1.0).abs() < 1e-9);
    assert!(cells.iter().all(|(d, _)| d.z > 0.0 && (d.length() - 1.0).abs() < 1e-9));
}
