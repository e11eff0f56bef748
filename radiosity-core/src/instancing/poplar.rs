//! The synthetic poplar of the shared scene folder (`twig.obj` placed by `tree_twig_instances.csv`
//! on `tree_skeleton.obj`; trees placed by `forest_tree_instances.csv` on `ground.obj`) written in
//! the scene format with instances.

use super::InstancingError;
use std::fmt::Write as _;
use std::path::Path;

/// Light sources added above the poplar: (centre x, centre y, half-size), at [`POPLAR_LIGHT_HEIGHT`].
pub const POPLAR_LIGHTS: [(f64, f64, f64); 3] = [(-6.0, 0.0, 2.0), (3.0, 5.2, 2.0), (3.0, -5.2, 2.0)];
/// Height of the poplar's light sources, metres (the tree is 20.78 m tall).
pub const POPLAR_LIGHT_HEIGHT: f64 = 30.0;

/// Reads the 3×4 row-major matrices of an instance CSV (comment lines start with `#`, one header
/// line of names); errors name the file and line.
pub fn read_matrices(path: &Path) -> Result<Vec<[f64; 12]>, InstancingError> {
    let text = std::fs::read_to_string(path).map_err(|e| InstancingError::io(path, "cannot read file", e))?;
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') || line.starts_with('m') {
            continue;
        }
        let vals: Result<Vec<f64>, _> = line.split(',').map(|w| w.trim().parse::<f64>()).collect();
        match vals {
            Ok(v) if v.len() == 12 => out.push(v.try_into().expect("length checked")),
            Ok(v) => return Err(InstancingError::at(path, i + 1, format!("expected 12 numbers, found {}", v.len()))),
            Err(e) => return Err(InstancingError::at(path, i + 1, format!("not a number: {e}"))),
        }
    }
    Ok(out)
}

/// TOML text of the poplar from the files in `source_dir`; OBJ paths are written as `obj_dir`
/// joined with the file names (give the folder as seen from where the TOML will be written, or an
/// absolute path). With `forest`, the root is the 8 × 8 forest on the ground; otherwise one tree on
/// the ground. Three emitters face down from above. Leaves are two-sided and transmitting.
pub fn poplar_toml(source_dir: &Path, obj_dir: &str, forest: bool) -> Result<String, InstancingError> {
    let twigs = read_matrices(&source_dir.join("tree_twig_instances.csv"))?;
    let trees = if forest { read_matrices(&source_dir.join("forest_tree_instances.csv"))? } else { Vec::new() };
    let obj = |f: &str| if obj_dir.is_empty() { f.to_owned() } else { format!("{}/{f}", obj_dir.trim_end_matches('/')) };
    let mut s = String::with_capacity(200 * (twigs.len() + trees.len()) + 2000);
    let _ = writeln!(
        s,
        "# Synthetic poplar (instanced_poplar): twig x {} on the skeleton{}",
        twigs.len(),
        if forest { ", 8 x 8 forest" } else { "" }
    );
    let _ = writeln!(s, "name = \"{}\"", if forest { "poplar-forest" } else { "poplar" });
    let _ = writeln!(s, "obj = \"{}\"\n", obj("ground.obj"));
    let _ = writeln!(s, "[[material]]\nname = \"bark\"\nreflectance = [0.32, 0.27, 0.22]\n");
    let _ = writeln!(
        s,
        "[[material]]\nname = \"leaf\"\nreflectance = [0.18, 0.38, 0.12]\ntransmittance = [0.12, 0.30, 0.08]\ntwo_sided = true\n"
    );
    let _ = writeln!(s, "[[material]]\nname = \"ground\"\nreflectance = [0.25, 0.22, 0.18]\n");
    let _ = writeln!(s, "[[material]]\nname = \"light\"\nreflectance = 0.0\nemission = 10.0\n");
    for (x, y, h) in POPLAR_LIGHTS {
        let z = POPLAR_LIGHT_HEIGHT;
        let _ = writeln!(
            s,
            "[[polygon]]\nmaterial = \"light\"\nvertices = [[{}, {}, {z}], [{}, {}, {z}], [{}, {}, {z}], [{}, {}, {z}]]\n",
            x - h,
            y - h,
            x - h,
            y + h,
            x + h,
            y + h,
            x + h,
            y - h
        );
    }
    if forest {
        for m in &trees {
            let _ = writeln!(s, "[[instance]]\nof = \"tree\"\nmatrix = {m:?}\n");
        }
    } else {
        let _ = writeln!(s, "[[instance]]\nof = \"tree\"\n");
    }
    let _ = writeln!(s, "[[prototype]]\nname = \"twig\"\nobj = \"{}\"\n", obj("twig.obj"));
    let _ = writeln!(s, "[[prototype]]\nname = \"tree\"\nobj = \"{}\"", obj("tree_skeleton.obj"));
    for m in &twigs {
        let _ = writeln!(s, "\n[[prototype.instance]]\nof = \"twig\"\nmatrix = {m:?}");
    }
    Ok(s)
}
