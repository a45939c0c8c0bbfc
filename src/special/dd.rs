//! Double-double arithmetic (about 32 significant digits) for the few places where the physics
//! cancels catastrophically: the squared velocity at the top of a row bead near the lower
//! regime limit δ_m (MODEL.md §2). Written by hand because the operations needed are four lines
//! each (error-free transforms with FMA) and a crate would bring a whole numeric tower; the
//! accuracy is held by tests against mpmath values.

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

    /// sin and cos of a double argument |x| ≤ 1, by their Taylor series in double-double.
    pub fn sin_cos(x: f64) -> (Dd, Dd) {
        let xd = Dd::from(x);
        let x2 = xd * xd;
        // sin: x − x³/3! + …, cos: 1 − x²/2! + …; |x| ≤ 1 so 28 terms reach 1e-33.
        let mut term = xd;
        let mut s = xd;
        let mut n = 1.0;
        for _ in 0..14 {
            term = -(term * x2) / Dd::from((n + 1.0) * (n + 2.0));
            s = s + term;
            n += 2.0;
        }
        let mut term = Dd::from(1.0);
        let mut c = Dd::from(1.0);
        let mut n = 0.0;
        for _ in 0..14 {
            term = -(term * x2) / Dd::from((n + 1.0) * (n + 2.0));
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

    #[test]
    fn division_inverts_multiplication() {
        let a = Dd::from(1.0) / Dd::from(3.0);
        let r = a * Dd::from(3.0) - Dd::from(1.0);
        assert!(r.to_f64().abs() < 1e-31);
    }
}
