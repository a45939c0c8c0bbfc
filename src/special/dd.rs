//! Double-double arithmetic (about 32 significant digits) for the few places where the physics
//! cancels catastrophically: the squared velocity at the top of a row bead near the lower regime
//! limit δ_m (docs/PHYSICS.md#pure-rolling), and the slip model's speed near its minimum.
//!
//! Written by hand rather than taken from the `qd` crate, which is already in the dependency
//! tree (through faer) and has a double-double type with the four operations, `sqrt`, `exp` and
//! `ln`: the models need `sin`/`cos` of a double-double angle, `asin` and `expm1` (`Dd::sin_cos`,
//! `Dd::sin_cos_dd`, `Dd::asin`, `Dd::exp_m1`), which `qd` 0.8 does not have, and they would
//! have to be written here on top of it anyway; the arithmetic itself is the error-free
//! transforms (two-sum, FMA two-product), a few lines each. The accuracy is held by tests
//! against mpmath values.

use std::ops::{Add, Div, Mul, Neg, Sub};

/// An unevaluated sum hi + lo with |lo| ≤ ulp(hi)/2.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Dd {
    /// Leading part.
    pub hi: f64,
    /// Trailing part.
    pub lo: f64,
}

#[inline]
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    let e = (a - (s - bb)) + (b - bb);
    (s, e)
}

#[inline]
fn quick_two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    (s, b - (s - a))
}

#[inline]
fn two_prod(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    (p, a.mul_add(b, -p))
}

impl From<f64> for Dd {
    fn from(x: f64) -> Self {
        Dd { hi: x, lo: 0.0 }
    }
}

impl Dd {
    /// Rounded to the nearest double.
    #[inline]
    pub fn to_f64(self) -> f64 {
        self.hi + self.lo
    }

    /// Square root (one Newton step on the double square root).
    pub fn sqrt(self) -> Dd {
        if self.hi <= 0.0 {
            return Dd::from(self.hi.max(0.0).sqrt());
        }
        let x = self.hi.sqrt();
        let (p, e) = two_prod(x, x);
        let r = ((self.hi - p) - e + self.lo) / (2.0 * x);
        let (hi, lo) = quick_two_sum(x, r);
        Dd { hi, lo }
    }

    /// Multiplication by a double.
    #[inline]
    pub fn mul_f64(self, b: f64) -> Dd {
        let (p, e) = two_prod(self.hi, b);
        let (hi, lo) = quick_two_sum(p, e + self.lo * b);
        Dd { hi, lo }
    }

    /// The exact sum a + b.
    #[inline]
    pub fn sum(a: f64, b: f64) -> Dd {
        let (hi, lo) = two_sum(a, b);
        Dd { hi, lo }
    }

    /// The exact product a b.
    #[inline]
    pub fn prod(a: f64, b: f64) -> Dd {
        let (hi, lo) = two_prod(a, b);
        Dd { hi, lo }
    }

    /// Division by a double (one correction step: about 1e-32 relative, three times cheaper
    /// than the double-double division).
    #[inline]
    pub fn div_f64(self, b: f64) -> Dd {
        let q1 = self.hi / b;
        let (p, e) = two_prod(q1, b);
        let r = ((self.hi - p) - e) + self.lo;
        let (hi, lo) = quick_two_sum(q1, r / b);
        Dd { hi, lo }
    }

    /// Multiplication by a power of two (exact).
    #[inline]
    pub fn scale(self, p: f64) -> Dd {
        Dd {
            hi: self.hi * p,
            lo: self.lo * p,
        }
    }

    /// e^x − 1 of a double-double argument (|x| ≤ 700), about 30 digits relative for every x:
    /// the Taylor series on x / 2^k with |x / 2^k| ≤ 1/64 (thirteen terms reach 1e-32), then
    /// k squarings in the form (1 + s)² − 1 = s (2 + s), which never cancels.
    pub fn exp_m1(x: Dd) -> Dd {
        let mut r = x;
        let mut k = 0;
        while r.hi.abs() > 1.0 / 64.0 && k < 20 {
            r = r.scale(0.5);
            k += 1;
        }
        let mut term = r;
        let mut s = r;
        for n in 2..=14 {
            term = (term * r).div_f64(n as f64);
            s = s + term;
        }
        for _ in 0..k {
            s = s * (s + Dd::from(2.0));
        }
        s
    }

    /// sin and cos of a double-double argument of any size up to |x| ≤ 2^20: the Taylor series
    /// of [`Dd::sin_cos`] on x / 2^k with |x / 2^k| ≤ 1, then k double-angle steps
    /// (sin 2y = 2 sin y cos y, cos 2y = (cos y − sin y)(cos y + sin y)). Absolute error about
    /// 1e-31 for |x| ≤ 4.
    pub fn sin_cos_dd(x: Dd) -> (Dd, Dd) {
        let mut r = x;
        let mut k = 0;
        while r.hi.abs() > 1.0 && k < 20 {
            r = r.scale(0.5);
            k += 1;
        }
        let (mut s, mut c) = Self::sin_cos_series(r);
        for _ in 0..k {
            let s2 = (s * c).scale(2.0);
            c = (c - s) * (c + s);
            s = s2;
        }
        (s, c)
    }

    /// asin s for |s| < 1: one Newton step on sin from the double asin, which squares the
    /// double's relative error of about 1e-16 (the step's own error is ~tan(x) δ²/2).
    pub fn asin(s: Dd) -> Dd {
        let x0 = Dd::from(s.hi.asin());
        let (sx, cx) = Self::sin_cos_dd(x0);
        x0 + (s - sx) / cx
    }

    /// sin and cos of a double argument |x| ≤ 1, by their Taylor series in double-double.
    pub fn sin_cos(x: f64) -> (Dd, Dd) {
        Self::sin_cos_series(Dd::from(x))
    }

    /// tan(x/2) of a double argument |x| ≤ 2, as sin / cos of [`Dd::sin_cos`].
    pub fn tan_half(x: f64) -> Dd {
        let (s, c) = Self::sin_cos(0.5 * x);
        s / c
    }

    fn sin_cos_series(xd: Dd) -> (Dd, Dd) {
        let x2 = xd * xd;
        // sin: x − x³/3! + …, cos: 1 − x²/2! + …; |x| ≤ 1 so 28 terms reach 1e-33.
        let mut term = xd;
        let mut s = xd;
        let mut n = 1.0;
        for _ in 0..14 {
            term = -(term * x2).div_f64((n + 1.0) * (n + 2.0));
            s = s + term;
            n += 2.0;
        }
        let mut term = Dd::from(1.0);
        let mut c = Dd::from(1.0);
        let mut n = 0.0;
        for _ in 0..14 {
            term = -(term * x2).div_f64((n + 1.0) * (n + 2.0));
            c = c + term;
            n += 2.0;
        }
        (s, c)
    }
}

impl Neg for Dd {
    type Output = Dd;
    #[inline]
    fn neg(self) -> Dd {
        Dd {
            hi: -self.hi,
            lo: -self.lo,
        }
    }
}

impl Add for Dd {
    type Output = Dd;
    #[inline]
    fn add(self, b: Dd) -> Dd {
        let (s, e) = two_sum(self.hi, b.hi);
        let (t, f) = two_sum(self.lo, b.lo);
        let (s, e) = quick_two_sum(s, e + t);
        let (hi, lo) = quick_two_sum(s, e + f);
        Dd { hi, lo }
    }
}

impl Sub for Dd {
    type Output = Dd;
    #[inline]
    fn sub(self, b: Dd) -> Dd {
        self + (-b)
    }
}

impl Mul for Dd {
    type Output = Dd;
    #[inline]
    fn mul(self, b: Dd) -> Dd {
        let (p, e) = two_prod(self.hi, b.hi);
        let e = e + (self.hi * b.lo + self.lo * b.hi);
        let (hi, lo) = quick_two_sum(p, e);
        Dd { hi, lo }
    }
}

impl Div for Dd {
    type Output = Dd;
    fn div(self, b: Dd) -> Dd {
        let q1 = self.hi / b.hi;
        let r = self - b.mul_f64(q1);
        let q2 = r.hi / b.hi;
        let r = r - b.mul_f64(q2);
        let q3 = r.hi / b.hi;
        let (hi, lo) = quick_two_sum(q1, q2);
        Dd { hi, lo } + Dd::from(q3)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sqrt_two_squared_is_two_to_double_double_precision() {
        let r = Dd::from(2.0).sqrt();
        let back = r * r - Dd::from(2.0);
        assert!(back.to_f64().abs() < 1e-30, "{back:?}");
    }

    #[test]
    fn sin_cos_satisfy_pythagoras_and_match_libm() {
        for &x in &[1e-9, 0.1, 0.3, 0.7, 1.0, -0.5] {
            let (s, c) = Dd::sin_cos(x);
            let one = s * s + c * c - Dd::from(1.0);
            assert!(one.to_f64().abs() < 1e-30, "x={x}: {one:?}");
            assert!((s.to_f64() - x.sin()).abs() <= 2.0 * f64::EPSILON * x.sin().abs());
        }
    }

    /// |got − (hi + lo)| relative to |hi|, evaluated in double-double.
    fn rel(got: Dd, hi: f64, lo: f64) -> f64 {
        (got - Dd { hi, lo }).to_f64().abs() / hi.abs()
    }

    // Reference values: mpmath 1.3.0 at 50 digits (mpmath.expm1, sin, cos, asin of the exact
    // double inputs), split into hi = float(v), lo = float(v − hi).

    #[test]
    fn exp_m1_matches_mpmath_to_30_digits() {
        for &(x, hi, lo) in &[
            (1e-9, 1.0000000005000001e-09, -7.443897403844588e-26),
            (0.3, 0.3498588075760031, 1.6549155728191776e-17),
            (-0.7, -0.5034146962085905, 9.827550225511106e-18),
            (2.5, 11.182493960703473, 2.0334002173348147e-16),
            (11.0, 59873.14171519782, 1.7895764888916994e-12),
            (-4.0, -0.9816843611112658, -4.000829452401623e-17),
        ] {
            let e = rel(Dd::exp_m1(Dd::from(x)), hi, lo);
            assert!(e < 1e-30, "expm1({x}): {e:.2e}");
        }
    }

    #[test]
    fn sin_cos_of_large_arguments_match_mpmath() {
        for &(x, s, sl, c, cl) in &[
            (
                0.1,
                0.09983341664682815,
                3.08001512929492e-18,
                0.9950041652780258,
                -5.50210156918377e-17,
            ),
            (
                1.3,
                0.963558185417193,
                1.8247650480909386e-17,
                0.26749882862458735,
                1.6094564897898917e-17,
            ),
            (
                -1.9,
                -0.9463000876874145,
                -4.6531737366356815e-17,
                -0.32328956686350335,
                1.4359001896805716e-17,
            ),
            (
                3.0,
                0.1411200080598672,
                8.577269787017502e-18,
                -0.9899924966004454,
                -4.2060261566099734e-17,
            ),
            (
                -3.1,
                -0.04158066243329049,
                7.108355207879104e-19,
                -0.9991351502732795,
                1.3850578802683375e-17,
            ),
        ] {
            let (gs, gc) = Dd::sin_cos_dd(Dd::from(x));
            // Absolute errors: the double-angle steps keep ~1e-31 absolute.
            let es = (gs - Dd { hi: s, lo: sl }).to_f64().abs();
            let ec = (gc - Dd { hi: c, lo: cl }).to_f64().abs();
            assert!(es < 1e-30 && ec < 1e-30, "x={x}: {es:.2e} {ec:.2e}");
        }
    }

    #[test]
    #[allow(clippy::approx_constant)] // ξ = 1 gives asin(1/2) = π/6: the mpmath value is kept
    fn asin_of_one_over_one_plus_xi_matches_mpmath() {
        for &(xi, hi, lo) in &[
            (0.65, 0.6510985849711179, 4.947226873751633e-17),
            (1.0, 0.5235987755982989, -5.360408832255455e-17),
            (2.0, 0.3398369094541219, 1.001975061755438e-17),
            (10.0, 0.09103477803741508, 3.809838437924063e-18),
        ] {
            let s = Dd::from(1.0) / Dd::sum(1.0, xi);
            let e = rel(Dd::asin(s), hi, lo);
            assert!(e < 1e-30, "asin(1/(1+{xi})): {e:.2e}");
        }
    }

    #[test]
    fn division_inverts_multiplication() {
        let a = Dd::from(1.0) / Dd::from(3.0);
        let r = a * Dd::from(3.0) - Dd::from(1.0);
        assert!(r.to_f64().abs() < 1e-31);
    }
}
