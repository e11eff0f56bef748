//! The bytes between processes: finished polygons, the task that opens a subtree and the top
//! level's emitters, little-endian so that every `f64` arrives with the same bits.

use crate::geom::{DVec3, Poly, PolyKind};
use crate::instancing::InstancingError;
use crate::instancing::model::Transform;
use crate::instancing::solver::occluders::Occluders;
use crate::instancing::solver::sink::{Leaf, PolygonInfo, RadiositySink};
use crate::instancing::solver::task::Task;
use glam::DMat4;

/// Decodes the polygons of `bytes` (one or more [`WorkerEvent::Polygons`] chunks, whole) into
/// `sink`, in order; returns how many.
///
/// [`WorkerEvent::Polygons`]: super::WorkerEvent::Polygons
pub fn replay(bytes: &[u8], sink: &mut dyn RadiositySink) -> Result<u64, InstancingError> {
    let mut r = Reader { bytes, at: 0 };
    let mut n = 0;
    let mut leaves = Vec::new();
    while !r.done() {
        let info = PolygonInfo { flat_index: r.u64()?, material: r.u32()?, prototype: r.u32()? };
        let count = r.u32()? as usize;
        leaves.clear();
        for _ in 0..count {
            leaves.push(Leaf { poly: r.poly()?, b: r.rgb()?, h: r.rgb()? });
        }
        sink.polygon(&info, &leaves)?;
        n += 1;
    }
    Ok(n)
}

/// Encodes a finished polygon as [`replay`] reads it.
pub fn encode_polygon(out: &mut Vec<u8>, info: &PolygonInfo, leaves: &[Leaf]) {
    out.extend_from_slice(&info.flat_index.to_le_bytes());
    out.extend_from_slice(&info.material.to_le_bytes());
    out.extend_from_slice(&info.prototype.to_le_bytes());
    out.extend_from_slice(&(leaves.len() as u32).to_le_bytes());
    for leaf in leaves {
        put_poly(out, &leaf.poly);
        put_f64s(out, &leaf.b);
        put_f64s(out, &leaf.h);
    }
}

fn put_f64s(out: &mut Vec<u8>, xs: &[f64]) {
    for x in xs {
        out.extend_from_slice(&x.to_le_bytes());
    }
}

fn put_poly(out: &mut Vec<u8>, p: &Poly) {
    out.push(match p.kind {
        PolyKind::Triangle => 3,
        PolyKind::Quad => 4,
    });
    for v in &p.v {
        put_f64s(out, &v.to_array());
    }
}

pub(super) fn put_emitters(out: &mut Vec<u8>, emitters: &[(Poly, [f64; 3])]) {
    out.extend_from_slice(&(emitters.len() as u64).to_le_bytes());
    for (p, e) in emitters {
        put_poly(out, p);
        put_f64s(out, e);
    }
}

pub(super) fn put_task(out: &mut Vec<u8>, t: &Task) {
    out.extend_from_slice(&t.prototype.to_le_bytes());
    put_f64s(out, &t.transform.matrix.to_cols_array());
    out.extend_from_slice(&t.flat_base.to_le_bytes());
    out.extend_from_slice(&t.depth.to_le_bytes());
    match &t.incoming {
        None => out.push(0),
        Some(field) => {
            out.push(1);
            out.extend_from_slice(&(field.len() as u64).to_le_bytes());
            for f in field {
                put_f64s(out, f);
            }
        }
    }
    out.extend_from_slice(&(t.direct.len() as u64).to_le_bytes());
    for (b, e) in &t.direct {
        out.extend_from_slice(&b.to_le_bytes());
        put_f64s(out, e);
    }
    let occluders: Vec<&Poly> = t.occluders.iter().collect();
    out.extend_from_slice(&(occluders.len() as u64).to_le_bytes());
    for p in occluders {
        put_poly(out, p);
    }
}

/// Reads the little-endian encoding; every shortfall is an error, never a panic.
pub(super) struct Reader<'a> {
    pub(super) bytes: &'a [u8],
    pub(super) at: usize,
}

impl Reader<'_> {
    fn take<const N: usize>(&mut self) -> Result<[u8; N], InstancingError> {
        let end = self.at.checked_add(N).filter(|&e| e <= self.bytes.len());
        let Some(end) = end else {
            return Err(InstancingError::Distributed(format!("message cut short at byte {} of {}", self.at, self.bytes.len())));
        };
        let mut a = [0u8; N];
        a.copy_from_slice(&self.bytes[self.at..end]);
        self.at = end;
        Ok(a)
    }
    fn u8(&mut self) -> Result<u8, InstancingError> {
        Ok(self.take::<1>()?[0])
    }
    fn u32(&mut self) -> Result<u32, InstancingError> {
        Ok(u32::from_le_bytes(self.take()?))
    }
    pub(super) fn u64(&mut self) -> Result<u64, InstancingError> {
        Ok(u64::from_le_bytes(self.take()?))
    }
    fn f64(&mut self) -> Result<f64, InstancingError> {
        Ok(f64::from_le_bytes(self.take()?))
    }
    fn rgb(&mut self) -> Result<[f64; 3], InstancingError> {
        Ok([self.f64()?, self.f64()?, self.f64()?])
    }
    /// A count of items of at least `min_bytes` each, checked against the bytes left.
    fn count(&mut self, min_bytes: usize) -> Result<usize, InstancingError> {
        let n = self.u64()?;
        let left = (self.bytes.len() - self.at) as u64;
        if n.saturating_mul(min_bytes as u64) > left {
            return Err(InstancingError::Distributed(format!("message claims {n} items in {left} bytes")));
        }
        Ok(n as usize)
    }
    fn poly(&mut self) -> Result<Poly, InstancingError> {
        let kind = match self.u8()? {
            3 => PolyKind::Triangle,
            4 => PolyKind::Quad,
            k => return Err(InstancingError::Distributed(format!("bad polygon kind {k}"))),
        };
        let mut v = [DVec3::ZERO; 4];
        for x in &mut v {
            *x = DVec3::new(self.f64()?, self.f64()?, self.f64()?);
        }
        Ok(Poly { v, kind })
    }
    fn done(&self) -> bool {
        self.at >= self.bytes.len()
    }
    pub(super) fn end(&self) -> Result<(), InstancingError> {
        if self.done() {
            Ok(())
        } else {
            Err(InstancingError::Distributed(format!("{} bytes left over in a message", self.bytes.len() - self.at)))
        }
    }
}

pub(super) fn get_emitters(r: &mut Reader<'_>) -> Result<Vec<(Poly, [f64; 3])>, InstancingError> {
    let n = r.count(97 + 24)?;
    (0..n).map(|_| Ok((r.poly()?, r.rgb()?))).collect()
}

pub(super) fn get_task(r: &mut Reader<'_>) -> Result<Task, InstancingError> {
    let prototype = r.u32()?;
    let mut m = [0.0; 16];
    for x in &mut m {
        *x = r.f64()?;
    }
    let transform = Transform { matrix: DMat4::from_cols_array(&m) };
    let flat_base = r.u64()?;
    let depth = r.u32()?;
    let incoming = match r.u8()? {
        0 => None,
        1 => {
            let n = r.count(24)?;
            Some((0..n).map(|_| r.rgb()).collect::<Result<Vec<_>, _>>()?)
        }
        k => return Err(InstancingError::Distributed(format!("bad field flag {k}"))),
    };
    let n = r.count(28)?;
    let direct = (0..n).map(|_| Ok((r.u32()?, r.rgb()?))).collect::<Result<Vec<_>, InstancingError>>()?;
    let n = r.count(97)?;
    let occluders = Occluders::from_polys((0..n).map(|_| r.poly()).collect::<Result<Vec<_>, _>>()?);
    Ok(Task { prototype, transform, flat_base, depth, incoming, direct, occluders })
}
