//! Scenes written by tests as OBJ text: quads with a chosen front.

/// OBJ text under construction: vertices and faces, each face its own object named after its
/// material and first vertex.
pub struct Obj {
    /// The text so far.
    pub text: String,
    vertices: usize,
}

impl Obj {
    /// An OBJ file that reads its materials from `mtllib`.
    pub fn new(mtllib: &str) -> Obj {
        Obj { text: format!("mtllib {mtllib}\n"), vertices: 0 }
    }

    /// A quad with front normal `normal` (its vertices reordered to face it) of `material`,
    /// named `name` (or after its material and first vertex).
    pub fn quad_named(&mut self, v: [[f64; 3]; 4], normal: [f64; 3], material: &str, name: Option<&str>) {
        let e1: [f64; 3] = std::array::from_fn(|k| v[1][k] - v[0][k]);
        let e2: [f64; 3] = std::array::from_fn(|k| v[2][k] - v[0][k]);
        let cross = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]];
        let facing = cross.iter().zip(normal).map(|(a, b)| a * b).sum::<f64>() > 0.0;
        let order: [usize; 4] = if facing { [0, 1, 2, 3] } else { [3, 2, 1, 0] };
        for &i in &order {
            self.text.push_str(&format!("v {} {} {}\n", v[i][0], v[i][1], v[i][2]));
        }
        let b = self.vertices + 1;
        self.vertices += 4;
        let name = name.map_or_else(|| format!("{material}{b}"), str::to_owned);
        self.text.push_str(&format!("o {name}\nusemtl {material}\nf {} {} {} {}\n", b, b + 1, b + 2, b + 3));
    }

    /// [`Obj::quad_named`] named after its material and first vertex. Not every test that
    /// includes this file names its quads by material.
    #[allow(dead_code)]
    pub fn quad(&mut self, v: [[f64; 3]; 4], normal: [f64; 3], material: &str) {
        self.quad_named(v, normal, material, None);
    }
}
