//! Math with no beads in it: elliptic integrals, quadrature, root bracketing, double-double.

pub mod cheb;
pub mod dd;
pub mod elliptic;
pub mod quad;
pub mod root;

/// sin and cos of one angle, computed together.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SinCos {
    /// sin of the angle.
    pub s: f64,
    /// cos of the angle.
    pub c: f64,
}

impl SinCos {
    /// sin and cos of `x` (radians).
    #[inline]
    pub fn of(x: f64) -> Self {
        let (s, c) = x.sin_cos();
        SinCos { s, c }
    }

    /// sin and cos of the negated angle.
    #[inline]
    pub fn reflected(self) -> Self {
        SinCos {
            s: -self.s,
            c: self.c,
        }
    }
}
