//! Where the light that enters a prototype leaves it: the face transfer matrix of its bounding box.
//!
//! A closed instance is a box (see [`crate::instancing::solver`]). Light that a real prototype
//! intercepts does not leave it uniformly: a leafy twig lit from above reflects part of it back up
//! and transmits part of it down through its leaves. The face transfer matrix `T[i][j]` (per
//! channel) is the fraction of the power intercepted through face `i` of the prototype's bounding
//! box that, after any number of reflections and transmissions, leaves the box through face `j`;
//! its row sums are the escape albedos per entry face. The uniform proxy of the paper is the
//! diagonal matrix of the mean albedo (light leaves by the face it entered, in the same fraction
//! whatever the face). It is measured by the same random walks as the escape albedo (see
//! [`super::properties`]), over isotropic incident light.
//!
//! Faces are numbered as [`crate::scene::shapes::box_faces`] lists them: `2·axis` for the face at
//! the smallest coordinate on that axis, `2·axis + 1` for the largest (x−, x+, y−, y+, z−, z+).

use crate::geom::{Aabb, DVec3};

/// Faces of a box.
pub const BOX_FACES: usize = 6;

/// The face through which the line `o + t·d` (t ≥ 0, `o` outside or on `b`) enters `b`: the face
/// of the axis whose slab it enters last. `None` when `d` is zero or not finite.
#[must_use]
pub fn entry_face(b: &Aabb, o: DVec3, d: DVec3) -> Option<usize> {
    let mut best: Option<(f64, usize)> = None;
    for a in 0..3 {
        if !d[a].is_finite() || d[a] == 0.0 {
            continue;
        }
        let (plane, face) = if d[a] > 0.0 { (b.min[a], 2 * a) } else { (b.max[a], 2 * a + 1) };
        let t = (plane - o[a]) / d[a];
        if best.is_none_or(|(tb, _)| t > tb) {
            best = Some((t, face));
        }
    }
    best.map(|(_, f)| f)
}

/// The face through which the ray `x + t·d` (t ≥ 0, `x` inside or on `b`) leaves `b`: the face of
/// the axis whose slab it leaves first. `None` when `d` is zero or not finite.
#[must_use]
pub fn exit_face(b: &Aabb, x: DVec3, d: DVec3) -> Option<usize> {
    let mut best: Option<(f64, usize)> = None;
    for a in 0..3 {
        if !d[a].is_finite() || d[a] == 0.0 {
            continue;
        }
        let (plane, face) = if d[a] > 0.0 { (b.max[a], 2 * a + 1) } else { (b.min[a], 2 * a) };
        let t = (plane - x[a]) / d[a];
        if best.is_none_or(|(tb, _)| t < tb) {
            best = Some((t, face));
        }
    }
    best.map(|(_, f)| f)
}

/// Sums from which [`FaceTransfer`] is formed: per entry face the intercepted power, and per
/// (entry, exit) pair the escaped power per channel.
#[derive(Clone, Debug, Default)]
pub struct FaceTally {
    intercepted: [f64; BOX_FACES],
    escaped: [[[f64; 3]; BOX_FACES]; BOX_FACES],
}

impl FaceTally {
    /// Counts a path of power `w` that entered through face `entry`: `escape` is `None` when it
    /// was absorbed, else its exit face and escaping weight per channel.
    pub fn add(&mut self, entry: usize, w: f64, escape: Option<(usize, [f64; 3])>) {
        if entry >= BOX_FACES || !w.is_finite() || w <= 0.0 {
            return;
        }
        self.intercepted[entry] += w;
        if let Some((exit, weight)) = escape
            && exit < BOX_FACES
        {
            for (e, x) in self.escaped[entry][exit].iter_mut().zip(weight) {
                if x.is_finite() {
                    *e += w * x;
                }
            }
        }
    }

    /// The matrix; an entry face that intercepted nothing gets `fallback` (the mean albedo)
    /// leaving by itself, as the uniform proxy has it.
    #[must_use]
    pub fn finish(&self, fallback: [f64; 3]) -> FaceTransfer {
        let mut m = vec![[0.0; 3]; BOX_FACES * BOX_FACES];
        for i in 0..BOX_FACES {
            if self.intercepted[i] > 0.0 {
                for j in 0..BOX_FACES {
                    m[i * BOX_FACES + j] = self.escaped[i][j].map(|e| (e / self.intercepted[i]).clamp(0.0, 1.0));
                }
            } else {
                m[i * BOX_FACES + i] = fallback;
            }
        }
        FaceTransfer(m)
    }
}

/// The face transfer matrix (see the module docs), row-major: entry `i * BOX_FACES + j` is the
/// fraction per channel of the power intercepted through face `i` that leaves through face `j`.
#[derive(Clone, Debug, PartialEq)]
pub struct FaceTransfer(pub Vec<[f64; 3]>);

impl FaceTransfer {
    /// The uniform proxy's matrix: `albedo` on the diagonal.
    #[must_use]
    pub fn uniform(albedo: [f64; 3]) -> FaceTransfer {
        let mut m = vec![[0.0; 3]; BOX_FACES * BOX_FACES];
        for i in 0..BOX_FACES {
            m[i * BOX_FACES + i] = albedo;
        }
        FaceTransfer(m)
    }

    /// From stored entries: `None` unless there are exactly `BOX_FACES²` finite entries in [0, 1]
    /// whose rows sum to at most 1 (plus rounding) per channel.
    #[must_use]
    pub fn from_entries(entries: &[[f64; 3]]) -> Option<FaceTransfer> {
        if entries.len() != BOX_FACES * BOX_FACES || entries.iter().flatten().any(|x| !x.is_finite() || !(0.0..=1.0).contains(x)) {
            return None;
        }
        let t = FaceTransfer(entries.to_vec());
        (0..BOX_FACES).all(|i| t.row_sum(i).iter().all(|&s| s <= 1.0 + 1e-9)).then_some(t)
    }

    /// Fraction per channel of the power entering through face `i` that leaves through face `j`
    /// (zero out of range).
    #[must_use]
    pub fn get(&self, i: usize, j: usize) -> [f64; 3] {
        if i >= BOX_FACES || j >= BOX_FACES {
            return [0.0; 3];
        }
        self.0.get(i * BOX_FACES + j).copied().unwrap_or([0.0; 3])
    }

    /// Escape albedo of the light entering through face `i`.
    #[must_use]
    pub fn row_sum(&self, i: usize) -> [f64; 3] {
        let mut s = [0.0; 3];
        for j in 0..BOX_FACES {
            let t = self.get(i, j);
            for c in 0..3 {
                s[c] += t[c];
            }
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_box() -> Aabb {
        Aabb { min: DVec3::ZERO, max: DVec3::ONE }
    }

    #[test]
    fn faces_are_found_where_rays_cross_the_box() {
        let b = unit_box();
        // From above, going down: enters through z+ (5).
        assert_eq!(entry_face(&b, DVec3::new(0.5, 0.5, 3.0), -DVec3::Z), Some(5));
        // From the x− side, slanted: the x slab is entered last.
        assert_eq!(entry_face(&b, DVec3::new(-1.0, 0.5, 0.6), DVec3::new(1.0, 0.0, 0.1)), Some(0));
        // From the centre, leaving mostly along −y.
        assert_eq!(exit_face(&b, DVec3::splat(0.5), DVec3::new(0.1, -1.0, 0.2)), Some(2));
        assert_eq!(exit_face(&b, DVec3::splat(0.5), DVec3::ZERO), None);
        assert_eq!(entry_face(&b, DVec3::splat(2.0), DVec3::new(f64::NAN, 0.0, 0.0)), None);
    }

    #[test]
    fn tally_normalises_per_entry_face_and_falls_back_on_unlit_faces() {
        let mut t = FaceTally::default();
        t.add(5, 2.0, Some((4, [0.5, 0.5, 0.5])));
        t.add(5, 2.0, Some((5, [0.25, 0.25, 0.25])));
        t.add(5, 4.0, None);
        t.add(9, 1.0, None); // out of range: ignored
        let m = t.finish([0.1, 0.2, 0.3]);
        assert_eq!(m.get(5, 4), [0.125; 3]);
        assert_eq!(m.get(5, 5), [0.0625; 3]);
        assert_eq!(m.get(0, 0), [0.1, 0.2, 0.3]);
        assert_eq!(m.get(0, 1), [0.0; 3]);
        assert!(FaceTransfer::from_entries(&m.0).is_some());
        assert!(FaceTransfer::from_entries(&m.0[..35]).is_none());
        let mut bad = m.0.clone();
        bad[0] = [0.9; 3];
        bad[1] = [0.9; 3];
        assert!(FaceTransfer::from_entries(&bad).is_none(), "a row summing past 1 is refused");
        assert_eq!(FaceTransfer::uniform([0.3; 3]).row_sum(2), [0.3; 3]);
    }
}
