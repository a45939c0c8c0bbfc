//! Elliptic integrals in Carlson's symmetric form, and the one integral every rolling phase
//! needs: T = ∫ dψ / sqrt(A − B cos ψ), written so that no argument is formed by cancellation.
//!
//! Carlson's R_F is the duplication algorithm of Carlson (1995), as in the `ellip` crate (a port
//! of Boost.Math, ≤ 4.5e-16 relative on Boost's test data) but without its per-call `powf` (see
//! [`rf`]); the unit test below holds it against Carlson's (1995) published values,
//! and `src/models/suite/reference_models.rs` holds the rolling models built on it against 40-digit mpmath
//! quadrature down to δ = δ_m (1 + 1e-9), where its log singularity is exercised.

use super::SinCos;

/// Carlson's symmetric integral R_F(x, y, z) = ½ ∫₀^∞ dt / sqrt((t+x)(t+y)(t+z)).
/// Returns +∞ where at least two arguments are zero (the integral diverges) and NaN only for
/// negative or NaN arguments (callers never pass them).
///
/// Carlson's duplication algorithm (Carlson 1995; the series of DLMF 19.36.1 to 7th order, with
/// the stopping rule Q = (3ε)^{-1/8} max|A0 − x_i|, as in Boost.Math and the `ellip` crate),
/// written here rather than called from `ellip` because the crate evaluates (3ε)^{-1/8} with a
/// `powf` and rescales on every call, which the stick model, whose time is mostly R_F, pays for
/// (measured in docs/PERFORMANCE.md, "Forward models"). The arithmetic is otherwise the
/// crate's, operation for operation, so the results are the same; the unit test below holds it
/// against Carlson's published values and `src/models/suite/reference_models.rs` holds the rolling
/// models against 40-digit mpmath quadrature.
/// Arguments whose largest is outside [1e-30, 1e30] (never met by the models) are brought to
/// about 1 by the homogeneity R_F(λx, λy, λz) = λ^{-1/2} R_F(x, y, z) with λ = 4^k, exact in
/// binary (an argument below 2^-1074 after the scaling, 10^-300 times smaller than the largest,
/// becomes 0, a relative change of R_F far below ε); the unit tests hold them against the
/// `ellip` crate.
#[inline]
pub fn rf(x: f64, y: f64, z: f64) -> f64 {
    if !(x >= 0.0 && y >= 0.0 && z >= 0.0) {
        return f64::NAN;
    }
    let zeros = (x == 0.0) as u8 + (y == 0.0) as u8 + (z == 0.0) as u8;
    if zeros >= 2 {
        return f64::INFINITY;
    }
    if x == f64::INFINITY || y == f64::INFINITY || z == f64::INFINITY {
        return 0.0;
    }
    let scale = x.max(y).max(z);
    if !(1e-30..=1e30).contains(&scale) {
        return rf_rescaled(x, y, z, scale);
    }
    rf_in_range(x, y, z)
}

/// R_F of arguments whose largest is `scale`, outside [1e-30, 1e30]: by the homogeneity with
/// λ = 4^k = 2^k · 2^k (two factors: 4^k alone may overflow), R_F = 2^k R_F(λx, λy, λz). Kept
/// out of line so that [`rf`] stays small enough to inline into the models.
#[cold]
#[inline(never)]
fn rf_rescaled(x: f64, y: f64, z: f64, scale: f64) -> f64 {
    let h = rescale_root(scale);
    h * rf_in_range(x * h * h, y * h * h, z * h * h)
}

/// h = 2^k with λ = h² = 4^k bringing `scale` to about 1 (λ scale in [½, 2]): the square root of
/// the factor by which [`rf`] and [`rd`] rescale arguments outside [1e-30, 1e30].
fn rescale_root(scale: f64) -> f64 {
    2f64.powi(-(scale.log2() / 2.0).round() as i32)
}

/// The duplication algorithm proper, for non-negative arguments at most one of which is zero
/// and whose largest is in about [1e-30, 1e30].
#[inline(always)]
fn rf_in_range(x: f64, y: f64, z: f64) -> f64 {
    // (3 ε)^{-1/8} for ε = 2^-52.
    const STOP: f64 = 78.8959690786408;
    let (mut xn, mut yn, mut zn) = (x, y, z);
    let a0 = (x + y + z) / 3.0;
    let mut an = a0;
    let mut q = STOP * (a0 - x).abs().max((a0 - y).abs()).max((a0 - z).abs());
    let mut f = 1.0;
    for _ in 0..11 {
        let (rx, ry, rz) = (xn.sqrt(), yn.sqrt(), zn.sqrt());
        let lambda = rx * ry + rx * rz + ry * rz;
        an = (an + lambda) / 4.0;
        xn = (xn + lambda) / 4.0;
        yn = (yn + lambda) / 4.0;
        zn = (zn + lambda) / 4.0;
        q /= 4.0;
        f *= 4.0;
        if q < an.abs() {
            break;
        }
    }
    rf_series([x, y, z], a0, an, f)
}

/// The end of the duplication algorithm: the series of DLMF 19.36.1 to 7th order at the
/// last iterate `an` (after steps that multiplied `f` by 4 each), from the arguments and
/// their mean `a0`.
#[inline(always)]
fn rf_series([x, y, _]: [f64; 3], a0: f64, an: f64, f: f64) -> f64 {
    let xs = (a0 - x) / (an * f);
    let ys = (a0 - y) / (an * f);
    let zs = -xs - ys;
    let e2 = xs * ys - zs * zs;
    let e3 = xs * ys * zs;
    (1.0 + e3 * (1.0 / 14.0 + 3.0 * e3 / 104.0)
        + e2 * (-0.1 + e2 / 24.0 - (3.0 * e3) / 44.0 - 5.0 * e2 * e2 / 208.0 + e2 * e3 / 16.0))
        / an.sqrt()
}

/// Carlson's symmetric integral of the second kind
/// R_D(x, y, z) = (3/2) ∫₀^∞ dt / (sqrt((t+x)(t+y)) (t+z)^{3/2}), for x, y ≥ 0 (at most one
/// zero) and z > 0; NaN elsewhere. The duplication algorithm of Carlson (1995) with its series
/// to 7th order and the stopping rule of Boost.Math (whose `ellip` port is the oracle of the
/// tests): with the terms of orders 6 and 7 the duplication stops about as soon as R_F's does;
/// arguments whose largest is outside [1e-30, 1e30] are rescaled by
/// the homogeneity R_D(λx, λy, λz) = λ^{-3/2} R_D(x, y, z) with λ = 4^k. Held against Carlson's
/// published values and the `ellip` crate in the unit tests. R_D is −6 ∂R_F/∂z (DLMF 19.18.1):
/// the derivative [`rf_dy_lanes`] takes.
pub fn rd(x: f64, y: f64, z: f64) -> f64 {
    if !(x >= 0.0 && y >= 0.0 && z > 0.0) || (x == 0.0 && y == 0.0) {
        return f64::NAN;
    }
    if x == f64::INFINITY || y == f64::INFINITY || z == f64::INFINITY {
        return 0.0;
    }
    let scale = x.max(y).max(z);
    if !(1e-30..=1e30).contains(&scale) {
        let h = rescale_root(scale);
        // λ = h², λ^{3/2} = h³ (in three factors: h³ alone may overflow).
        return h * h * h * rd_in_range(x * h * h, y * h * h, z * h * h);
    }
    rd_in_range(x, y, z)
}

/// 1.2 (ε/4)^{-1/8} for ε = 2^-52: the duplication's stopping factor for R_D with its series to
/// 7th order (as Boost.Math's).
const RD_STOP: f64 = 129.16168938297054;

/// The duplication algorithm for R_D proper, arguments as [`rd`] admits them and the largest in
/// [1e-30, 1e30].
fn rd_in_range(x: f64, y: f64, z: f64) -> f64 {
    let a0 = (x + y + 3.0 * z) / 5.0;
    let mut q = RD_STOP * (a0 - x).abs().max((a0 - y).abs()).max((a0 - z).abs());
    let (mut n, mut an, mut f, mut sum) = ([x, y, z], a0, 1.0, 0.0);
    for _ in 0..16 {
        if q < an.abs() {
            break;
        }
        let (rx, ry, rz) = (n[0].sqrt(), n[1].sqrt(), n[2].sqrt());
        let lambda = rx * ry + rx * rz + ry * rz;
        sum += 1.0 / (f * rz * (n[2] + lambda));
        n = n.map(|v| (v + lambda) / 4.0);
        an = (an + lambda) / 4.0;
        q /= 4.0;
        f *= 4.0;
    }
    rd_series([x, y], a0, an, f, sum)
}

/// The end of the duplication for R_D: the series of DLMF 19.36.2, to 7th order, at the last
/// iterate `an` (after steps that multiplied `f` by 4 each) plus 3 times the steps' `sum`.
#[inline(always)]
fn rd_series([x, y]: [f64; 2], a0: f64, an: f64, f: f64, sum: f64) -> f64 {
    let xs = (a0 - x) / (f * an);
    let ys = (a0 - y) / (f * an);
    let zs = -(xs + ys) / 3.0;
    let xy = xs * ys;
    let z2 = zs * zs;
    let e2 = xy - 6.0 * z2;
    let e3 = (3.0 * xy - 8.0 * z2) * zs;
    let e4 = 3.0 * (xy - z2) * z2;
    let e5 = xy * z2 * zs;
    let series = 1.0 - 3.0 * e2 / 14.0 + e3 / 6.0 + 9.0 * e2 * e2 / 88.0
        - 3.0 * e4 / 22.0
        - 9.0 * e2 * e3 / 52.0
        + 3.0 * e5 / 26.0
        - e2 * e2 * e2 / 16.0
        + 3.0 * e3 * e3 / 40.0
        + 3.0 * e2 * e4 / 20.0
        + 45.0 * e2 * e2 * e3 / 272.0
        - 9.0 * (e3 * e4 + e2 * e5) / 68.0;
    series / (f * an * an.sqrt()) + 3.0 * sum
}

/// R_F(x, y, z) and its derivative in the middle argument ∂R_F/∂y = −R_D(x, z, y)/6
/// (DLMF 19.18.1) of `N` argument triples: where all are in the range of the duplication
/// algorithm proper, one duplication loop serves both (the iterates of R_F and R_D of the same
/// arguments are the same), running until both series apply; elsewhere [`rf`] and [`rd`]. The
/// values of R_F are [`rf`]'s to within a few ulp (the loop may take a step more than R_F
/// alone would).
#[inline(always)]
pub fn rf_dy_lanes<const N: usize>(a: [[f64; 3]; N]) -> [(f64, f64); N] {
    if !a
        .iter()
        .all(|t| in_range(*t) && t[1] > 0.0 && (t[0] > 0.0 || t[2] > 0.0))
    {
        return a.map(|[x, y, z]| (rf(x, y, z), -rd(x, z, y) / 6.0));
    }
    // (3 ε)^{-1/8} for ε = 2^-52, as in `rf_in_range`.
    const STOP: f64 = 78.8959690786408;
    let spread = |t: [f64; 3], m: f64| (m - t[0]).abs().max((m - t[1]).abs()).max((m - t[2]).abs());
    let af0 = a.map(|[x, y, z]| (x + y + z) / 3.0);
    let ad0 = a.map(|[x, y, z]| (x + z + 3.0 * y) / 5.0);
    let qf: [f64; N] = std::array::from_fn(|l| STOP * spread(a[l], af0[l]));
    let qd: [f64; N] = std::array::from_fn(|l| RD_STOP * spread(a[l], ad0[l]));
    // Both means step as A ← (A + λ)/4, so after m steps 4^m A_F = g with g ← g + 4^m λ, and
    // 4^m A_D = g − (A_F0 − A_D0): one running sum serves both stopping rules
    // (Q / 4^m < |A| as Q < |4^m A|) and both series.
    let shift: [f64; N] = std::array::from_fn(|l| af0[l] - ad0[l]);
    let (mut n, mut g) = (a, af0);
    let mut f = [1.0f64; N];
    let mut sum = [0.0f64; N];
    let mut live = [true; N];
    for _ in 0..16 {
        for l in 0..N {
            live[l] = !(qf[l] < g[l].abs() && qd[l] < (g[l] - shift[l]).abs());
            if live[l] {
                let (rx, ry, rz) = (n[l][0].sqrt(), n[l][1].sqrt(), n[l][2].sqrt());
                let lambda = rx * ry + rx * rz + ry * rz;
                sum[l] += 1.0 / (f[l] * ry * (n[l][1] + lambda));
                n[l] = n[l].map(|v| (v + lambda) / 4.0);
                g[l] += f[l] * lambda;
                f[l] *= 4.0;
            }
        }
        if !live.iter().any(|&x| x) {
            break;
        }
    }
    std::array::from_fn(|l| {
        let [x, _, z] = a[l];
        let r_f = rf_series(a[l], af0[l], g[l] / f[l], f[l]);
        let r_d = rd_series([x, z], ad0[l], (g[l] - shift[l]) / f[l], f[l], sum[l]);
        (r_f, -r_d / 6.0)
    })
}

/// Legendre's incomplete integral of the first kind F(φ, k) from sin φ, cos φ and the
/// complementary parameter k'² = 1 − k² (which may be negative for k > 1), as
/// F = sin φ · R_F(cos² φ, cos² φ + k'² sin² φ, 1). Passing cos φ and k'² computed without
/// cancellation keeps full relative accuracy as k → 1 and φ → π/2.
#[cfg(test)]
pub fn legendre_f(sc: SinCos, kc2: f64) -> f64 {
    let (s, c) = (sc.s, sc.c);
    if s == 0.0 {
        return 0.0;
    }
    let c2 = c * c;
    s * rf(c2, c2 + kc2 * s * s, 1.0)
}

/// Time T = ∫_{ψ0}^{ψ1} dψ / sqrt(A − B cos ψ) with B > 0, −π < ψ0 ≤ ψ1 < π, from:
/// the half-angle sines and cosines `h0`, `h1`; the squared speeds at both ends
/// `w0sq = A − B cos ψ0`, `w1sq = A − B cos ψ1`; the squared speed at the top
/// `wtsq = A − B` (used only when ψ0 < 0 < ψ1, and then it must be > 0); and
/// `den = sin²(ψ1/2) − sin²(ψ0/2) = sin((ψ1+ψ0)/2) sin((ψ1−ψ0)/2)` computed by the caller
/// in product form.
///
/// With u = sin(ψ/2), v = u², the integral is ∫ dv / sqrt(v (1−v) (A − B + 2B v)), a cubic
/// case of Carlson's reduction (DLMF 19.29.4–19.29.8): on one side of the top
/// T = 2 R_F(U₁₂², U₁₃², U₂₃²), where every U is a sum of positive products of s, c and w, so
/// no cancellation. Across the top the integral splits at ψ = 0 and each half is
/// 2 |s| R_F(c² w_t², w², w_t²): the log singularity as w_t → 0 comes out of R_F with full
/// relative accuracy in its tiny arguments. The paper's Legendre form (eqs 12–15, corrected in
/// docs/PHYSICS.md#corrections-to-the-printed-paper) is the same integral; this one needs no
/// sign cases beyond the top.
pub fn cos_integral(h0: SinCos, h1: SinCos, w0sq: f64, w1sq: f64, wtsq: f64, den: f64) -> f64 {
    if h1.s <= 0.0 {
        // Both ends at or before the top: reflect ψ → −ψ.
        if h0.s == h1.s {
            return 0.0;
        }
        return same_side(h1.reflected(), h0.reflected(), w1sq, w0sq, -den);
    }
    if h0.s >= 0.0 {
        return same_side(h0, h1, w0sq, w1sq, den);
    }
    // Across the top: the two halves' R_F run side by side (`rf_lanes`).
    let [r1, r0] = rf_lanes(across_top(h0, h1, [w0sq, w1sq, wtsq]));
    2.0 * (h1.s.abs() * r1 + h0.s.abs() * r0)
}

/// The R_F arguments of the two halves of [`cos_integral`] across the top, (Θ1 side, Θ0 side),
/// from the squared speeds `[w0sq, w1sq, wtsq]`.
#[inline(always)]
fn across_top(h0: SinCos, h1: SinCos, [w0sq, w1sq, wt2]: [f64; 3]) -> [[f64; 3]; 2] {
    [
        [h1.c * h1.c * wt2, w1sq, wt2],
        [h0.c * h0.c * wt2, w0sq, wt2],
    ]
}

/// [`cos_integral`] of two motions between the same angles (`h0`, `h1`, `den`) with the squared
/// speeds `a` and `b` (each `[w0sq, w1sq, wtsq]`), each to the last bit; across the top their
/// four R_F run side by side (`rf_lanes`), past it their two. Always inlined, as is
/// [`rf_lanes`]: out of line, with its arrays passed through memory, the crawl rows of
/// `fitbead k --model stick` took 4 % longer and `fitbead forward --model stick` 5 %
/// (docs/PERFORMANCE.md).
#[inline(always)]
pub fn cos_integral_pair(h0: SinCos, h1: SinCos, a: [f64; 3], b: [f64; 3], den: f64) -> [f64; 2] {
    if h1.s > 0.0 && h0.s < 0.0 {
        let [a1, a0] = across_top(h0, h1, a);
        let [b1, b0] = across_top(h0, h1, b);
        let [ra1, ra0, rb1, rb0] = rf_lanes([a1, a0, b1, b0]);
        return [
            2.0 * (h1.s.abs() * ra1 + h0.s.abs() * ra0),
            2.0 * (h1.s.abs() * rb1 + h0.s.abs() * rb0),
        ];
    }
    if h1.s > 0.0 && h0.s >= 0.0 {
        if let (Some(ra), Some(rb)) = (
            same_side_args(h0, h1, a[0], a[1], den),
            same_side_args(h0, h1, b[0], b[1], den),
        ) {
            return rf_lanes([ra, rb]).map(|r| 2.0 * r);
        }
    }
    [a, b].map(|[w0sq, w1sq, wtsq]| cos_integral(h0, h1, w0sq, w1sq, wtsq, den))
}

/// [`rf`] of `N` argument triples, each to the last bit: where all are in the range of the
/// duplication algorithm proper, their iterations run in one loop, each stopping after its own
/// number of steps with the operations of [`rf`], so that the processor overlaps the chains of
/// dependent square roots (one R_F is bound by their latency: four of the stick model's R_F
/// take 92.5 ns side by side against 145.5 ns one after the other; docs/PERFORMANCE.md,
/// "Python"); elsewhere `N` calls of [`rf`].
#[inline(always)]
pub fn rf_lanes<const N: usize>(a: [[f64; 3]; N]) -> [f64; N] {
    if !a.iter().all(|t| in_range(*t)) {
        return a.map(|[x, y, z]| rf(x, y, z));
    }
    // (3 ε)^{-1/8} for ε = 2^-52, as in `rf_in_range`.
    const STOP: f64 = 78.8959690786408;
    let mut a0 = [0.0; N];
    let mut q = [0.0; N];
    for l in 0..N {
        let [x, y, z] = a[l];
        a0[l] = (x + y + z) / 3.0;
        q[l] = STOP
            * (a0[l] - x)
                .abs()
                .max((a0[l] - y).abs())
                .max((a0[l] - z).abs());
    }
    let mut n = a;
    let mut an = a0;
    let mut f = [1.0f64; N];
    let mut live = [true; N];
    for _ in 0..11 {
        for l in 0..N {
            if live[l] {
                let (rx, ry, rz) = (n[l][0].sqrt(), n[l][1].sqrt(), n[l][2].sqrt());
                let lambda = rx * ry + rx * rz + ry * rz;
                an[l] = (an[l] + lambda) / 4.0;
                n[l] = [
                    (n[l][0] + lambda) / 4.0,
                    (n[l][1] + lambda) / 4.0,
                    (n[l][2] + lambda) / 4.0,
                ];
                q[l] /= 4.0;
                f[l] *= 4.0;
                live[l] = !(q[l] < an[l].abs());
            }
        }
        if !live.iter().any(|&x| x) {
            break;
        }
    }
    let mut out = [0.0; N];
    for l in 0..N {
        out[l] = rf_series(a[l], a0[l], an[l], f[l]);
    }
    out
}

/// Arguments that [`rf`] hands to the duplication algorithm proper unchanged: non-negative,
/// at most one zero, none infinite, the largest in [1e-30, 1e30].
#[inline(always)]
fn in_range([x, y, z]: [f64; 3]) -> bool {
    let zeros = (x == 0.0) as u8 + (y == 0.0) as u8 + (z == 0.0) as u8;
    x >= 0.0 && y >= 0.0 && z >= 0.0 && zeros < 2 && (1e-30..=1e30).contains(&x.max(y).max(z))
}

#[inline]
fn same_side(h0: SinCos, h1: SinCos, w0sq: f64, w1sq: f64, den: f64) -> f64 {
    match same_side_args(h0, h1, w0sq, w1sq, den) {
        Some([x, y, z]) => 2.0 * rf(x, y, z),
        None => 0.0,
    }
}

/// The R_F arguments of [`same_side`] (whose value is 2 R_F of them); `None` where `den` ≤ 0
/// (no motion between the angles: the time is 0).
#[inline(always)]
fn same_side_args(h0: SinCos, h1: SinCos, w0sq: f64, w1sq: f64, den: f64) -> Option<[f64; 3]> {
    if den <= 0.0 {
        return None;
    }
    let w0 = w0sq.max(0.0).sqrt();
    let w1 = w1sq.max(0.0).sqrt();
    let u12 = (h1.s * h1.c * w0 + h0.s * h0.c * w1) / den;
    let u13 = (h1.s * h0.c * w1 + h0.s * h1.c * w0) / den;
    let u23 = (h0.s * h1.c * w1 + h1.s * h0.c * w0) / den;
    Some([u12 * u12, u13 * u13, u23 * u23])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::special::quad::{integrate, QuadOptions};

    fn by_quadrature(a: f64, b: f64, p0: f64, p1: f64) -> f64 {
        let f = |x: f64| 1.0 / (a - b * x.cos()).sqrt();
        let opts = QuadOptions {
            rel_tol: 1e-15,
            ..Default::default()
        };
        if p0 < 0.0 && p1 > 0.0 {
            integrate(f, p0, 0.0, opts).value + integrate(f, 0.0, p1, opts).value
        } else {
            integrate(f, p0, p1, opts).value
        }
    }

    /// Uniform draws in [0, 1) from Marsaglia's xorshift64 started at `seed`.
    fn xorshift(mut seed: u64) -> impl FnMut() -> f64 {
        move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    #[test]
    fn rf_matches_carlsons_published_values() {
        // B. C. Carlson, "Numerical computation of real or complex elliptic integrals",
        // Numer. Algorithms 10 (1995) 13–26, §3 test values (14 digits).
        for &(x, y, z, v) in &[
            (1.0, 2.0, 0.0, 1.3110287771461),
            (0.5, 1.0, 0.0, 1.8540746773014),
            (2.0, 3.0, 4.0, 0.58408284167715),
        ] {
            assert!((rf(x, y, z) - v).abs() < 1e-13 * v, "R_F({x},{y},{z})");
        }
        assert_eq!(rf(0.0, 0.0, 1.0), f64::INFINITY);
        assert_eq!(rf(f64::INFINITY, 1.0, 1.0), 0.0);
        assert!(rf(-1.0, 1.0, 1.0).is_nan() && rf(f64::NAN, 1.0, 1.0).is_nan());
    }

    #[test]
    fn rd_matches_carlsons_published_values_and_ellip() {
        // B. C. Carlson, Numer. Algorithms 10 (1995) 13–26, §3 test values (14 digits).
        for &(x, y, z, v) in &[
            (0.0, 2.0, 1.0, 1.7972103521034),
            (2.0, 3.0, 4.0, 0.16510527294261),
        ] {
            assert!(
                (rd(x, y, z) - v).abs() < 1e-13 * v,
                "R_D({x},{y},{z}) = {}",
                rd(x, y, z)
            );
        }
        // The `ellip` crate (a port of Boost.Math) over 24 decades, and rescaled arguments.
        let mut uniform = xorshift(0x2545_f491_4f6c_dd1du64);
        let mut worst = 0.0f64;
        for i in 0..2000 {
            let e = |u: f64| 10f64.powf(-12.0 + 24.0 * u);
            let s = if i % 10 == 0 {
                1e-40
            } else if i % 10 == 1 {
                1e40
            } else {
                1.0
            };
            let (x, y, z) = (s * e(uniform()), s * e(uniform()), s * e(uniform()));
            let ours = rd(x, y, z);
            let theirs = ellip::carlson::elliprd_unchecked(x, y, z);
            worst = worst.max(((ours - theirs) / theirs).abs());
        }
        assert!(
            worst < 2e-15,
            "largest relative difference from ellip: {worst:e}"
        );
        assert!(rd(0.0, 0.0, 1.0).is_nan() && rd(1.0, 1.0, 0.0).is_nan());
    }

    /// `rf_dy_lanes` gives R_F to a few ulp of `rf` and ∂R_F/∂y to a few ulp of −R_D(x, z, y)/6,
    /// on across-the-top triples as the rolling contact forms them (c² w_t², w², w_t² with w_t²
    /// from 1e-14 to 1) and on random ones; and ∂R_F/∂y agrees with a central difference of
    /// R_F (step 1e-6 y, error ~1e-11).
    #[test]
    fn rf_dy_lanes_is_rf_and_its_derivative() {
        let mut uniform = xorshift(0x9e37_79b9_7f4a_7c15u64);
        let (mut worst_f, mut worst_d, mut worst_fd) = (0.0f64, 0.0f64, 0.0f64);
        for i in 0..1000 {
            let e = |u: f64| 10f64.powf(-12.0 + 24.0 * u);
            let t = if i % 2 == 0 {
                let wt2 = 10f64.powf(-14.0 * uniform());
                let c2 = uniform();
                [c2 * wt2, wt2 + 0.1 + uniform(), wt2]
            } else {
                [e(uniform()), e(uniform()), e(uniform())]
            };
            let [(r_f, d), _] = rf_dy_lanes([t, [1.0, 2.0, 3.0]]);
            let [x, y, z] = t;
            let want_d = -rd(x, z, y) / 6.0;
            worst_f = worst_f.max(((r_f - rf(x, y, z)) / r_f).abs());
            worst_d = worst_d.max(((d - want_d) / want_d).abs());
            if i % 2 == 0 {
                let h = 1e-6 * y;
                let fd = (rf(x, y + h, z) - rf(x, y - h, z)) / (2.0 * h);
                worst_fd = worst_fd.max(((d - fd) / d).abs());
            }
        }
        assert!(worst_f < 4.0 * f64::EPSILON, "R_F: {worst_f:e}");
        assert!(
            worst_d < 4.0 * f64::EPSILON,
            "dR_F/dy against R_D: {worst_d:e}"
        );
        assert!(
            worst_fd < 1e-8,
            "dR_F/dy against a difference: {worst_fd:e}"
        );
    }

    /// `rf_lanes` is `rf` lane by lane, to the last bit, wherever the lanes stop: argument
    /// triples over 24 decades (so that the two lanes take different numbers of steps),
    /// across-the-top triples as `cos_integral` forms them, and the special and out-of-range
    /// triples that fall back to `rf`.
    #[test]
    fn rf_lanes_are_rf_calls_to_the_bit() {
        let mut triples = vec![
            [0.0, 1.0, 2.0],
            [0.0, 0.0, 1.0],
            [f64::INFINITY, 1.0, 1.0],
            [-1.0, 1.0, 1.0],
            [f64::NAN, 1.0, 1.0],
            [1e-40, 2e-40, 3e-40],
            [1e31, 1.0, 2.0],
            [1.0, 1.0, 1.0],
        ];
        let mut uniform = xorshift(0x9e37_79b9_7f4a_7c15u64);
        for _ in 0..400 {
            let e = |u: f64| 10f64.powf(-12.0 + 24.0 * u);
            triples.push([e(uniform()), e(uniform()), e(uniform())]);
            // Across the top: c² w_t², w², w_t² with w_t² from 1e-14 to 1.
            let wt2 = 10f64.powf(-14.0 * uniform());
            let c = 0.8 + 0.2 * uniform();
            triples.push([c * c * wt2, wt2 + uniform(), wt2]);
        }
        let one = |[x, y, z]: [f64; 3]| rf(x, y, z).to_bits();
        for (i, a) in triples.iter().enumerate() {
            for b in triples.iter().step_by(7) {
                let [p, q] = rf_lanes([*a, *b]);
                assert_eq!(
                    [p.to_bits(), q.to_bits()],
                    [one(*a), one(*b)],
                    "{a:?} {b:?}"
                );
                let c = triples[(i * 13 + 5) % triples.len()];
                let d = triples[(i * 29 + 11) % triples.len()];
                let four = rf_lanes([*a, *b, c, d]).map(f64::to_bits);
                assert_eq!(
                    four,
                    [one(*a), one(*b), one(c), one(d)],
                    "{a:?} {b:?} {c:?} {d:?}"
                );
            }
        }
    }

    /// Arguments beyond [1e-30, 1e30], which `rf` scales by its homogeneity, against the
    /// `ellip` crate (Boost.Math's algorithm with its own rescaling, ≤ 4.5e-16 relative on
    /// Boost's data): within 4ε relative (measured: at most 3.0e-16).
    #[test]
    fn rf_out_of_range_matches_the_ellip_crate() {
        let mut worst: f64 = 0.0;
        for &s in &[
            1e-320, 1e-300, 1e-200, 1e-100, 1e-31, 1e31, 1e100, 1e200, 1e300, 5e307,
        ] {
            for &(x, y, z) in &[
                (1.0, 2.0, 3.0),
                (0.0, 1.0, 2.0),
                (1e-5, 1.0, 1.0),
                (0.25, 0.5, 0.75),
                (1.0, 1.0, 1.0),
            ] {
                let (x, y, z) = (x * s, y * s, z * s);
                let ours = rf(x, y, z);
                let theirs = ellip::carlson::elliprf_unchecked(x, y, z);
                let rel = ((ours - theirs) / theirs).abs();
                assert!(
                    rel <= 4.0 * f64::EPSILON,
                    "R_F({x:e},{y:e},{z:e}): {ours:e} vs {theirs:e}"
                );
                worst = worst.max(rel);
            }
        }
        println!("worst relative difference from ellip beyond [1e-30, 1e30]: {worst:.2e}");
    }

    #[test]
    fn cos_integral_matches_quadrature_on_both_sides_and_across_the_top() {
        // Independent check: adaptive Gauss–Kronrod on the defining integral.
        for &(a, b, p0, p1) in &[
            (1.5, 1.0, -0.3, 0.8),
            (1.5, 1.0, 0.2, 0.8),
            (1.5, 1.0, -0.9, -0.1),
            (0.9, 1.0, 0.5, 1.2), // A < B: only reachable on one side
            (3.0, 1.4, -1.0, 0.0),
            (3.0, 1.4, 0.0, 1.0),
        ] {
            let h0 = SinCos::of(0.5 * p0);
            let h1 = SinCos::of(0.5 * p1);
            let w = |p: f64| a - b * p.cos();
            let den = (0.5 * (p1 + p0)).sin() * (0.5 * (p1 - p0)).sin();
            let t = cos_integral(h0, h1, w(p0), w(p1), a - b, den);
            let q = by_quadrature(a, b, p0, p1);
            assert!((t - q).abs() <= 1e-14 * q, "{a} {b} {p0} {p1}: {t} vs {q}");
        }
    }

    /// `cos_integral_pair` is two calls of `cos_integral`, to the last bit: across the top
    /// (four R_F side by side) with top speeds from 1e-14 to 1, past it (two R_F side by
    /// side), from rest past it, and before it (two calls).
    #[test]
    fn cos_integral_pair_is_two_calls_to_the_bit() {
        // From rest past the top (w0 = 0) beside launches from 1e-14 to 1.
        let (p0, p1) = (0.03, 0.26);
        let (h0, h1) = (SinCos::of(0.5 * p0), SinCos::of(0.5 * p1));
        let den = (0.5 * (p1 + p0)).sin() * (0.5 * (p1 - p0)).sin();
        let drop = f64::cos(p0) - f64::cos(p1);
        for i in 0..=14 {
            let w0 = 10f64.powi(-i);
            let (a, b) = ([0.0, drop, -1.0], [w0, w0 + drop, -1.0]);
            let one = |[w0, w1, wt]: [f64; 3]| cos_integral(h0, h1, w0, w1, wt, den);
            let pair = cos_integral_pair(h0, h1, a, b, den);
            assert_eq!(pair.map(f64::to_bits), [one(a).to_bits(), one(b).to_bits()]);
        }
        for &(p0, p1) in &[(-0.3, 0.8), (-1.2, 0.05), (0.2, 0.8), (-0.9, -0.1)] {
            let (h0, h1) = (SinCos::of(0.5 * p0), SinCos::of(0.5 * p1));
            let den = (0.5 * (p1 + p0)).sin() * (0.5 * (p1 - p0)).sin();
            let speeds = |wt: f64| {
                let (a, b) = (1.0 + wt, 1.0);
                [a - b * f64::cos(p0), a - b * f64::cos(p1), wt]
            };
            for i in 0..=14 {
                for j in [0, 3, 7, 14] {
                    let (a, b) = (speeds(10f64.powi(-i)), speeds(10f64.powi(-j)));
                    let one = |[w0, w1, wt]: [f64; 3]| cos_integral(h0, h1, w0, w1, wt, den);
                    let pair = cos_integral_pair(h0, h1, a, b, den);
                    assert_eq!(pair.map(f64::to_bits), [one(a).to_bits(), one(b).to_bits()]);
                }
            }
        }
    }
}
