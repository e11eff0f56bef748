//! `xf` transform arguments: `-t x y z`, `-rx/-ry/-rz degrees`, `-s factor`, `-mx/-my/-mz`,
//! `-i n` (repeat the following arguments n times) and `-a n` (an array of n instances: the following
//! arguments are repeated 0, 1, ..., n−1 times, one instance per value).
//!
//! Arguments apply left to right (the first one listed acts first on a point), as in mgflib; a
//! nested `xf` acts before the enclosing one.

use super::lines::{parse_f64, parse_int};
use glam::{DAffine3, DVec3};

/// Most instances of an array, with the enclosing arrays' (`xf -a 4294967296` would otherwise
/// exhaust memory: found by the reader fuzz, issue 17).
pub(super) const MAX_INSTANCES: usize = 1_000_000;
/// Most repeats of `-i` (each is a matrix product: ten million take a fraction of a second).
const MAX_REPEATS: usize = 10_000_000;

/// A parsed argument list; its matrix depends on the current array indices.
#[derive(Clone, Debug)]
pub(super) struct XfSpec {
    ops: Vec<Op>,
    /// Instance count of each `-a`, in order.
    pub array_sizes: Vec<usize>,
}

#[derive(Clone, Copy, Debug)]
enum Op {
    /// An elementary transform.
    Affine(DAffine3),
    /// `-i n` or `-a` (the k-th array): repeat the following transforms.
    Repeat(Count),
}

#[derive(Clone, Copy, Debug)]
enum Count {
    Fixed(usize),
    Array(usize),
}

impl XfSpec {
    /// Parses the arguments of `xf` (without the entity name). The error says what is wrong.
    pub fn parse(args: &[Box<str>]) -> Result<XfSpec, String> {
        let mut ops = Vec::new();
        let mut array_sizes = Vec::new();
        let mut i = 0;
        let float = |i: usize, opt: &str| -> Result<f64, String> {
            let w = args.get(i).ok_or_else(|| format!("transform option `{opt}` is missing its argument"))?;
            parse_f64(w).ok_or_else(|| format!("transform option `{opt}`: `{w}` is not a number"))
        };
        let count = |i: usize, opt: &str| -> Result<i64, String> {
            let w = args.get(i).ok_or_else(|| format!("transform option `{opt}` is missing its count"))?;
            parse_int(w).ok_or_else(|| format!("transform option `{opt}`: `{w}` is not an integer"))
        };
        while i < args.len() {
            let opt = &*args[i];
            let op = match opt {
                "-t" => {
                    let t = DVec3::new(float(i + 1, opt)?, float(i + 2, opt)?, float(i + 3, opt)?);
                    i += 3;
                    Op::Affine(DAffine3::from_translation(t))
                }
                "-rx" | "-ry" | "-rz" => {
                    let a = float(i + 1, opt)?.to_radians();
                    i += 1;
                    Op::Affine(match opt {
                        "-rx" => DAffine3::from_rotation_x(a),
                        "-ry" => DAffine3::from_rotation_y(a),
                        _ => DAffine3::from_rotation_z(a),
                    })
                }
                "-s" => {
                    let s = float(i + 1, opt)?;
                    if s == 0.0 {
                        return Err("transform scale factor `-s 0` is not allowed".into());
                    }
                    i += 1;
                    Op::Affine(DAffine3::from_scale(DVec3::splat(s)))
                }
                "-mx" => Op::Affine(DAffine3::from_scale(DVec3::new(-1.0, 1.0, 1.0))),
                "-my" => Op::Affine(DAffine3::from_scale(DVec3::new(1.0, -1.0, 1.0))),
                "-mz" => Op::Affine(DAffine3::from_scale(DVec3::new(1.0, 1.0, -1.0))),
                "-i" => {
                    let n = count(i + 1, opt)?;
                    i += 1;
                    let n = usize::try_from(n).map_err(|_| format!("transform repeat count `-i {n}` is negative"))?;
                    if n > MAX_REPEATS {
                        return Err(format!("transform repeat count `-i {n}` is over {MAX_REPEATS}"));
                    }
                    Op::Repeat(Count::Fixed(n))
                }
                "-a" => {
                    let n = count(i + 1, opt)?;
                    i += 1;
                    let n = usize::try_from(n).ok().filter(|&n| n >= 1).ok_or_else(|| format!("array size `-a {n}` must be at least 1"))?;
                    array_sizes.push(n);
                    Op::Repeat(Count::Array(array_sizes.len() - 1))
                }
                _ => return Err(format!("unknown transform option `{opt}`")),
            };
            ops.push(op);
            i += 1;
        }
        Ok(XfSpec { ops, array_sizes })
    }

    /// The transform for array indices `idx` (one per `-a`).
    #[must_use]
    pub fn matrix(&self, idx: &[usize]) -> DAffine3 {
        let mut total = DAffine3::IDENTITY;
        let mut block = DAffine3::IDENTITY;
        let mut repeats = 1;
        for op in &self.ops {
            match *op {
                Op::Affine(m) => block = m * block,
                Op::Repeat(count) => {
                    total = power(block, repeats) * total;
                    repeats = match count {
                        Count::Fixed(n) => n,
                        Count::Array(k) => idx[k],
                    };
                    block = DAffine3::IDENTITY;
                }
            }
        }
        power(block, repeats) * total
    }
}

/// `m` applied `n` times (by repeated squaring, so that huge `-i` counts stay cheap).
fn power(m: DAffine3, n: usize) -> DAffine3 {
    let (mut result, mut base, mut n) = (DAffine3::IDENTITY, m, n);
    while n > 0 {
        if n & 1 == 1 {
            result = base * result;
        }
        base = base * base;
        n >>= 1;
    }
    result
}

/// Advances array indices like an odometer (last index fastest); false when all instances are done
/// (the indices are then back to zero).
pub(super) fn next_instance(idx: &mut [usize], sizes: &[usize]) -> bool {
    for k in (0..idx.len()).rev() {
        idx[k] += 1;
        if idx[k] < sizes[k] {
            return true;
        }
        idx[k] = 0;
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec(s: &str) -> Result<XfSpec, String> {
        let args: Vec<Box<str>> = s.split_whitespace().map(Box::from).collect();
        XfSpec::parse(&args)
    }

    fn near(a: DVec3, b: DVec3) -> bool {
        (a - b).length() < 1e-12
    }

    #[test]
    fn arguments_apply_left_to_right() {
        let m = spec("-t 1 0 0 -rz 90").unwrap().matrix(&[]);
        assert!(near(m.transform_point3(DVec3::ZERO), DVec3::Y));
        let m = spec("-rz 90 -t 1 0 0 -s 2").unwrap().matrix(&[]);
        assert!(near(m.transform_point3(DVec3::X), DVec3::new(2.0, 2.0, 0.0)));
        let m = spec("-mx").unwrap().matrix(&[]);
        assert!(m.matrix3.determinant() < 0.0);
    }

    #[test]
    fn repeats_and_arrays() {
        let m = spec("-t 1 0 0 -i 3 -t 0 2 0").unwrap().matrix(&[]);
        assert!(near(m.transform_point3(DVec3::ZERO), DVec3::new(1.0, 6.0, 0.0)));
        let m = spec("-i 1000003 -t 1 0 0 -rz 90").unwrap().matrix(&[]);
        // cos 90° is 6e-17, not 0: the error grows with the count.
        assert!(
            (m.transform_point3(DVec3::ZERO) - DVec3::new(-1.0, 0.0, 0.0)).length() < 1e-6,
            "the map has period 4 and 1000003 = 3 mod 4: {m:?}"
        );
        let s = spec("-t -21 0 0 -a 15 -t 3 0 0").unwrap();
        assert_eq!(s.array_sizes, vec![15]);
        assert!(near(s.matrix(&[0]).transform_point3(DVec3::ZERO), DVec3::new(-21.0, 0.0, 0.0)));
        assert!(near(s.matrix(&[14]).transform_point3(DVec3::ZERO), DVec3::new(21.0, 0.0, 0.0)));
        let mut idx = vec![0, 0];
        let mut n = 1;
        while next_instance(&mut idx, &[2, 3]) {
            n += 1;
        }
        assert_eq!((n, idx), (6, vec![0, 0]));
    }

    #[test]
    fn bad_arguments_are_reported() {
        assert!(spec("-t 1 2").unwrap_err().contains("-t"));
        assert!(spec("-s 0").is_err());
        assert!(spec("-q").unwrap_err().contains("-q"));
        assert!(spec("-a 0").is_err());
        assert!(spec("-rx y").unwrap_err().contains("`y`"));
    }
}
