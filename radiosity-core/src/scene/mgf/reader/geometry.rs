//! Geometry: faces (with holes) and tessellated primitives, transformed to world coordinates and
//! handed to the [`SceneBuilder`](crate::scene::SceneBuilder) with their material and group.

use super::Reader;
use crate::geom::DVec3;
use crate::scene::SceneError;
use crate::scene::mgf::holes;
use crate::scene::mgf::lines::Entity;
use crate::scene::mgf::primitives::{self, Faces};

impl Reader {
    pub(super) fn face(&mut self, e: &Entity) -> Result<(), SceneError> {
        if e.words.len() < 4 {
            return Err(self.parse_err(e.line, "a face needs at least 3 vertices"));
        }
        let pts = self.points(&e.words[1..], e.line)?;
        self.emit(pts, e.line)
    }

    /// `fh v.. - h.. - h..`: holes are joined to the outer contour by seams.
    pub(super) fn face_with_holes(&mut self, e: &Entity) -> Result<(), SceneError> {
        let mut contours = Vec::new();
        for names in e.words[1..].split(|w| &**w == "-") {
            if names.len() < 3 {
                return Err(self.parse_err(e.line, "each contour of `fh` needs at least 3 vertices"));
            }
            contours.push(self.points(names, e.line)?);
        }
        let holes = contours.split_off(1);
        let outer = contours.pop().unwrap_or_default();
        self.emit(holes::merge_holes(outer, holes), e.line)
    }

    pub(super) fn primitive(&mut self, e: &Entity) -> Result<(), SceneError> {
        let mut faces = std::mem::take(&mut self.scratch);
        faces.clear();
        self.primitive_faces(&mut faces, e)?;
        for f in faces.drain(..) {
            self.emit(f, e.line)?;
        }
        self.scratch = faces;
        Ok(())
    }

    /// The faces of a `sph`, `cyl`, `cone`, `ring`, `torus` or `prism`, in local coordinates.
    fn primitive_faces(&self, acc: &mut Faces, e: &Entity) -> Result<(), SceneError> {
        let (w, line) = (&e.words, e.line);
        let nq = self.options.quarter_circle_divisions.max(1);
        let result = match &*w[0] {
            "sph" => {
                self.n_args(e, 2)?;
                primitives::sphere(acc, self.vertex(&w[1], line)?.p, self.float(&w[2], line)?, nq)
            }
            "cyl" => {
                self.n_args(e, 3)?;
                let r = self.float(&w[2], line)?;
                primitives::cone(acc, self.vertex(&w[1], line)?.p, r, self.vertex(&w[3], line)?.p, r, nq)
            }
            "cone" => {
                self.n_args(e, 4)?;
                let (r1, r2) = (self.float(&w[2], line)?, self.float(&w[4], line)?);
                primitives::cone(acc, self.vertex(&w[1], line)?.p, r1, self.vertex(&w[3], line)?.p, r2, nq)
            }
            "ring" | "torus" => {
                self.n_args(e, 3)?;
                let v = self.vertex(&w[1], line)?;
                if v.n == DVec3::ZERO {
                    return Err(self.parse_err(line, format!("`{}` centre vertex `{}` has no normal (`n`)", w[0], w[1])));
                }
                let (r1, r2) = (self.float(&w[2], line)?, self.float(&w[3], line)?);
                if &*w[0] == "ring" { primitives::ring(acc, v.p, v.n, r1, r2, nq) } else { primitives::torus(acc, v.p, v.n, r1, r2, nq) }
            }
            _ => {
                // `prism v1 .. vn length`
                if w.len() < 5 {
                    return Err(self.parse_err(line, "`prism` needs at least 3 vertices and a length"));
                }
                let pts = self.points(&w[1..w.len() - 1], line)?;
                primitives::prism(acc, &pts, self.float(&w[w.len() - 1], line)?)
            }
        };
        result.map_err(|m| self.parse_err(line, format!("`{}`: {m}", w[0])))
    }

    /// Transforms a face to world coordinates and hands it to the builder.
    fn emit(&mut self, mut pts: Vec<DVec3>, line: usize) -> Result<(), SceneError> {
        if let Some(f) = self.xf.last() {
            for p in &mut pts {
                *p = f.to_world.transform_point3(*p);
            }
            if f.reversed {
                pts.reverse();
            }
        }
        if pts.iter().any(|p| !p.is_finite()) {
            return Err(SceneError::NonFinite { path: self.current_path().to_path_buf(), line, what: "transformed face vertex".into() });
        }
        let material = self.material_id()?;
        let group = self.group_id();
        let n_messages = self.builder.warnings_mut().messages.len();
        let contour = holes::without_consecutive_repeats(&pts);
        match holes::touches_itself(&contour).then(|| holes::triangulate(&contour)).flatten() {
            Some(triangles) => {
                self.builder.warnings_mut().triangulated_faces += 1;
                for [a, b, c] in triangles {
                    self.builder.face(&[contour[a], contour[b], contour[c]], material, group, line)?;
                }
            }
            None => self.builder.face(&pts, material, group, line)?,
        }
        self.relocate_messages(n_messages);
        Ok(())
    }

    /// The builder names the root file in its messages; faces from included files name theirs.
    fn relocate_messages(&mut self, from: usize) {
        let path = self.current_path();
        let here = path.display().to_string();
        if here == self.root_display {
            return;
        }
        for msg in self.builder.warnings_mut().messages.iter_mut().skip(from) {
            if let Some(rest) = msg.strip_prefix(self.root_display.as_str()).filter(|r| r.starts_with(':')) {
                *msg = format!("{here}{rest}");
            }
        }
    }
}
