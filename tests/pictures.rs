//! Pictures of every scene: `image.png` and `falsecolor.png` of the embedded Cornell box, every
//! generated scene and every validation scene (none of the validation scenes has a camera, so they
//! are seen from the default view) are well above black; `--view` frames the image and malformed
//! views are one-line errors.

use radiosity::output::{self, OutputConfig, RenderConfig};
use radiosity::pipeline::{self, Config};
use radiosity::refine::{BfHand, BfParams};
use radiosity::scene::Scene;
use std::path::Path;
use std::process::Command;

/// A coarse threshold: these tests check pictures, not accuracy.
const EPS: f64 = 0.5;
/// Side of the test images, pixels.
const SIZE: u32 = 32;
/// Mean brightness (0–255) an image must exceed: black images (a view of the backs of a closed
/// room's surfaces) have 0.
const MIN_MEAN: f64 = 25.0;
/// Share of the false-colour picture's pixels that must show a surface (a cut-away of Ward's
/// 10 × 6 × 3 m room fills a third of a square frame).
const MIN_COVERED: f64 = 0.2;

fn scenes() -> Vec<Scene> {
    let mut out: Vec<Scene> =
        radiosity::scene::generated::NAMES.iter().map(|n| radiosity::scene::generated::by_name(n).expect("a generated name")).collect();
    out.extend(radiosity::validation::cases().into_iter().map(|c| c.scene));
    out
}

fn read_png(path: &Path) -> image::RgbImage {
    image::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display())).to_rgb8()
}

fn mean(img: &image::RgbImage) -> f64 {
    output::mean_brightness(img.as_raw())
}

#[test]
fn every_scene_renders_well_above_black() {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let oracle = BfHand { params: BfParams { eps: EPS } };
    let mut report = Vec::new();
    for scene in scenes() {
        let solved = pipeline::run(&scene, &oracle, &Config { estimate_error: false, ..Config::default() }, &|_| {});
        let out = dir.path().join(scene.name.replace([' ', '/'], "_"));
        let config = OutputConfig { render: RenderConfig { width: SIZE, height: SIZE, samples: 1 }, ..OutputConfig::default() };
        output::write_solution(&out, &scene, &solved, &config).unwrap_or_else(|e| panic!("{}: {e}", scene.name));
        let image = read_png(&out.join("image.png"));
        assert_eq!(image.dimensions(), (SIZE, SIZE), "{}", scene.name);
        let fc = read_png(&out.join("falsecolor.png"));
        assert_eq!(fc.dimensions(), (SIZE + output::LEGEND_WIDTH, output::LEGEND_MIN_HEIGHT), "{}", scene.name);
        // The picture is at the top right of falsecolor.png; every pixel not black shows a surface.
        let covered = (0..SIZE)
            .flat_map(|y| (0..SIZE).map(move |x| (x, y)))
            .filter(|&(x, y)| fc.get_pixel(output::LEGEND_WIDTH + x, y).0 != [0; 3])
            .count();
        let covered = covered as f64 / f64::from(SIZE * SIZE);
        report.push(format!("{}: mean {:.1}, false colour covers {:.0}%", scene.name, mean(&image), 100.0 * covered));
        assert!(mean(&image) > MIN_MEAN, "{}: image.png mean brightness {:.1} (all: {report:?})", scene.name, mean(&image));
        assert!(covered > MIN_COVERED, "{}: falsecolor.png shows surfaces in {:.0}% of its pixels", scene.name, 100.0 * covered);
    }
    println!("{}", report.join("\n"));
}

fn radiosity(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_radiosity")).args(args).output().expect("the binary runs")
}

#[test]
fn view_options_frame_the_image() {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let out = dir.path().join("out");
    let out_s = out.to_str().expect("a UTF-8 path");
    // A view file as `rvu` saves it: 60° × 45°.
    let view = dir.path().join("stairs.vf");
    std::fs::write(&view, "rvu -vtv -vp 0.5 2 3 -vd 1 0 0 -vu 0 1 0 -vh 60 -vv 45 -vo 0 -va 0 -vs 0 -vl 0\n").expect("writes");
    let o =
        radiosity(&["solve", "gen:stairs", "--eps", "0.5", "--size", "40", "-q", "-o", out_s, "--view", "-vh 60 -vv 45", "--scale", "log"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // tan 30° / tan 22.5° = 1.394: 40 × 29.
    assert_eq!(read_png(&out.join("image.png")).dimensions(), (40, 29));
    assert_eq!(read_png(&out.join("falsecolor.png")).dimensions(), (40 + output::LEGEND_WIDTH, output::LEGEND_MIN_HEIGHT));
    let o = radiosity(&["solve", "gen:stairs", "--eps", "0.5", "--size", "24", "-q", "-o", out_s, "--view", view.to_str().expect("UTF-8")]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(read_png(&out.join("image.png")).dimensions(), (24, 17));
    // view.vf records the view used; given back, it frames the same image.
    let saved = std::fs::read_to_string(out.join("view.vf")).expect("view.vf written");
    assert!(saved.starts_with("rvu -vtv -vp 0.5 2 3 -vd 1 0 0 -vu 0 1 0 -vh "), "{saved}");
    let image = read_png(&out.join("image.png"));
    let again = dir.path().join("again");
    let saved_path = dir.path().join("saved.vf");
    std::fs::write(&saved_path, &saved).expect("writes");
    let o = radiosity(&[
        "solve",
        "gen:stairs",
        "--eps",
        "0.5",
        "--size",
        "24",
        "-q",
        "-o",
        again.to_str().expect("UTF-8"),
        "--view",
        saved_path.to_str().expect("UTF-8"),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(read_png(&again.join("image.png")), image);
}

#[test]
fn malformed_views_are_one_line_errors() {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let missing = dir.path().join("missing.vf");
    let bad = dir.path().join("bad.vf");
    std::fs::write(&bad, "rview -vtv -vp 0 0 1\n-vth -vh 180\n").expect("writes");
    let out = dir.path().join("out");
    for (view, expected) in [
        ("-vtl -vp 0 0 1".to_owned(), "error: --view: view type -vtl is not supported (only -vtv, perspective)".to_owned()),
        ("-vp 1 2".to_owned(), "error: --view: view option -vp needs 3 numbers".to_owned()),
        ("-vd 0 0 0".to_owned(), "error: --view: view option -vd must not be the zero vector".to_owned()),
        ("-vh 0".to_owned(), "error: --view: view option -vh must be between 0 and 180 degrees (perspective), got 0".to_owned()),
        (
            missing.display().to_string(),
            format!("error: {}: cannot read view file: No such file or directory (os error 2)", missing.display()),
        ),
        (bad.display().to_string(), format!("error: {}:2: view type -vth is not supported (only -vtv, perspective)", bad.display())),
    ] {
        let o = radiosity(&["solve", "cornell", "--eps", "0.5", "--size", "8", "-q", "-o", out.to_str().expect("UTF-8"), "--view", &view]);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{view}: should fail");
        assert_eq!(stderr.trim_end(), expected, "{view}");
        assert!(!out.join("image.png").exists(), "{view}: refused before the solve");
    }
}
