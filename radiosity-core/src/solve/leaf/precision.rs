//! How the leaf operator stores a chain coefficient: [`Precision`] (`f32`, or a 16-bit logarithmic
//! code for a coarse target), the code's encoding and decoding, and the stored coefficients in
//! either.

/// How the leaf operator stores its chain coefficients (the link each belongs to is implied by its
/// place in the unknown's chain of links, so only the value is stored).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Precision {
    /// `f32`: 4 bytes, rounding below 1e-7 relative.
    Single,
    /// A 16-bit logarithmic code of the values in `[2⁻⁴⁶, 4)`: 2 bytes, rounding at most
    /// [`HALF_ROUNDING`] relative; smaller values (below 1.5e-14, where a form factor is 1 at most)
    /// are dropped.
    Half,
}

/// Largest relative rounding of a [`Precision::Half`] coefficient: half a step of the code,
/// `2^(24/65534) − 1` = 2.54e-4, with the `f32` rounding of the value and of its decoded form.
pub const HALF_ROUNDING: f64 = 2.6e-4;

/// Smallest target error whose solves store [`Precision::Half`] coefficients: each coefficient is
/// then rounded by at most a quarter of the target (and the rounding, of either sign from one
/// coefficient to the next, averages out over a polygon's leaves). Finer targets, and solves
/// without one, store `f32`.
pub const HALF_MIN_TARGET: f64 = 1e-3;

/// Log₂ of the smallest [`Precision::Half`] code's value.
const CODE_LOG2_MIN: f64 = -46.0;
/// Octaves the [`Precision::Half`] codes span.
const CODE_LOG2_SPAN: f64 = 48.0;
/// Steps between the smallest and the largest code (code 0 is zero).
const CODE_STEPS: f64 = 65534.0;

impl Precision {
    /// The precision of a solve with `target` error ([`HALF_MIN_TARGET`]).
    #[must_use]
    pub fn for_target(target: Option<f64>) -> Precision {
        match target {
            Some(t) if t >= HALF_MIN_TARGET => Precision::Half,
            _ => Precision::Single,
        }
    }

    /// Bytes of one stored coefficient.
    #[must_use]
    pub fn bytes(self) -> usize {
        match self {
            Precision::Single => size_of::<f32>(),
            Precision::Half => size_of::<u16>(),
        }
    }

    /// The value a coefficient `c` (non-negative) is applied with: `c` itself, or its code's value.
    #[must_use]
    pub fn round(self, c: f32) -> f32 {
        match self {
            Precision::Single => c,
            Precision::Half => decode(encode(c)),
        }
    }
}

/// The [`Precision::Half`] code of `c ≥ 0`: 0 below the smallest code's value, otherwise the
/// nearest code on the logarithmic scale (values from 4 up get the largest code; form factors are
/// below 1).
pub(super) fn encode(c: f32) -> u16 {
    let c = f64::from(c);
    if c.is_nan() || c < CODE_LOG2_MIN.exp2() {
        return 0;
    }
    let t = ((c.log2() - CODE_LOG2_MIN) * (CODE_STEPS / CODE_LOG2_SPAN)).round();
    1 + t.min(CODE_STEPS) as u16
}

/// The value of a [`Precision::Half`] code.
pub(super) fn decode(code: u16) -> f32 {
    decode_table()[usize::from(code)]
}

/// Every [`Precision::Half`] code's value, indexed by the code: loops over many codes (the leaf
/// operator's gather) take it once instead of through [`decode`] per value.
pub(super) fn decode_table() -> &'static [f32] {
    static TABLE: std::sync::OnceLock<Vec<f32>> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| {
        (0..=u16::MAX)
            .map(|code| if code == 0 { 0.0 } else { (CODE_LOG2_MIN + f64::from(code - 1) * (CODE_LOG2_SPAN / CODE_STEPS)).exp2() as f32 })
            .collect()
    })
}

/// Stored chain coefficients or source weights, in either [`Precision`].
#[derive(Clone, Debug)]
pub(super) enum Stored {
    Single(Vec<f32>),
    Half(Vec<u16>),
}

impl Stored {
    /// Empty, in `precision`, with room for `capacity` values.
    pub(super) fn with_capacity(precision: Precision, capacity: usize) -> Stored {
        match precision {
            Precision::Single => Stored::Single(Vec::with_capacity(capacity)),
            Precision::Half => Stored::Half(Vec::with_capacity(capacity)),
        }
    }

    /// Appends `values` (non-negative), rounded to the precision.
    pub(super) fn extend_f64(&mut self, values: &[f64]) {
        match self {
            Stored::Single(v) => v.extend(values.iter().map(|&x| x as f32)),
            Stored::Half(v) => v.extend(values.iter().map(|&x| encode(x as f32))),
        }
    }

    /// Calls `f(j, value)` for each stored value `j` of `range`, in order.
    #[inline]
    pub(super) fn for_each_in(&self, range: std::ops::Range<usize>, mut f: impl FnMut(usize, f64)) {
        let lo = range.start;
        match self {
            Stored::Single(v) => v[range].iter().enumerate().for_each(|(i, &x)| f(lo + i, f64::from(x))),
            Stored::Half(v) => {
                let table = decode_table();
                v[range].iter().enumerate().for_each(|(i, &x)| f(lo + i, f64::from(table[usize::from(x)])));
            }
        }
    }

    /// The sum of the values of `range`, as they are applied.
    pub(super) fn sum(&self, range: std::ops::Range<usize>) -> f64 {
        let mut sum = 0.0;
        self.for_each_in(range, |_, x| sum += x);
        sum
    }

    pub(super) fn len(&self) -> usize {
        match self {
            Stored::Single(v) => v.len(),
            Stored::Half(v) => v.len(),
        }
    }

    pub(super) fn precision(&self) -> Precision {
        match self {
            Stored::Single(_) => Precision::Single,
            Stored::Half(_) => Precision::Half,
        }
    }

    /// The value coefficient `j` is applied with.
    pub(super) fn get(&self, j: usize) -> f32 {
        match self {
            Stored::Single(v) => v[j],
            Stored::Half(v) => decode(v[j]),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every value in the code's range comes back within [`HALF_ROUNDING`], in order; zero and
    /// values below the range come back as zero; `f32` values are kept as they are.
    #[test]
    fn half_coefficients_round_by_at_most_half_rounding() {
        let (lo, hi) = (CODE_LOG2_MIN.exp2(), 3.99f64);
        let n = 400_000;
        let mut worst = 0.0f64;
        let mut last = 0.0f32;
        for i in 0..=n {
            let c = (lo * (hi / lo).powf(f64::from(i) / f64::from(n))) as f32;
            let r = Precision::Half.round(c);
            worst = worst.max((f64::from(r) - f64::from(c)).abs() / f64::from(c));
            assert!(r >= last, "decoded values out of order at {c}: {r} < {last}");
            last = r;
        }
        assert!(worst <= HALF_ROUNDING, "relative rounding {worst:.3e} over {HALF_ROUNDING:.1e}");
        assert!(worst > 0.5 * HALF_ROUNDING, "the bound is tight: {worst:.3e}");
        assert_eq!(Precision::Half.round(0.0), 0.0);
        assert_eq!(Precision::Half.round((0.4 * lo) as f32), 0.0);
        assert_eq!(Precision::Single.round(0.123_456_78), 0.123_456_78);
        assert_eq!(Precision::for_target(Some(0.01)), Precision::Half);
        assert_eq!(Precision::for_target(Some(HALF_MIN_TARGET)), Precision::Half);
        assert_eq!(Precision::for_target(Some(0.0003)), Precision::Single);
        assert_eq!(Precision::for_target(None), Precision::Single);
    }
}
