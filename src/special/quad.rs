//! Adaptive Gauss–Kronrod quadrature (7-point Gauss, 15-point Kronrod; QUADPACK's QAG with
//! global bisection of the panel with the largest error).
//!
//! Written by hand rather than taken from a crate: the slip integrals are evaluated inside
//! root finders millions of times, and this version allocates nothing (a fixed panel stack),
//! accepts a closure, and reports its own error estimate and evaluation count — what the
//! work-precision runs need. Its nodes and weights are QUADPACK's (checked to 1e-27 against
//! exact polynomial moments at 40 digits; the unit test below checks exactness to degree 22).

/// Kronrod abscissae (positive half, descending; the last is the centre).
const XGK: [f64; 8] = [
    0.991_455_371_120_812_6,
    0.949_107_912_342_758_5,
    0.864_864_423_359_769_1,
    0.741_531_185_599_394_4,
    0.586_087_235_467_691_1,
    0.405_845_151_377_397_2,
    0.207_784_955_007_898_5,
    0.0,
];
/// Kronrod weights matching [`XGK`].
const WGK: [f64; 8] = [
    0.022_935_322_010_529_22,
    0.063_092_092_629_978_55,
    0.104_790_010_322_250_2,
    0.140_653_259_715_525_9,
    0.169_004_726_639_267_9,
    0.190_350_578_064_785_4,
    0.204_432_940_075_298_9,
    0.209_482_141_084_727_8,
];
/// Gauss weights for the 7-point rule on XGK[1], XGK[3], XGK[5], XGK[7].
const WG: [f64; 4] = [
    0.129_484_966_168_869_7,
    0.279_705_391_489_276_7,
    0.381_830_050_505_118_9,
    0.417_959_183_673_469_4,
];

/// Tolerances and limits of `integrate`.
#[derive(Debug, Clone, Copy)]
pub struct QuadOptions {
    /// Relative tolerance on the integral.
    pub rel_tol: f64,
    /// Absolute tolerance on the integral.
    pub abs_tol: f64,
    /// Largest number of panels.
    pub max_panels: usize,
}

impl Default for QuadOptions {
    fn default() -> Self {
        QuadOptions {
            rel_tol: 1e-14,
            abs_tol: 0.0,
            max_panels: 64,
        }
    }
}

/// The value of an integral with its error estimate.
#[derive(Debug, Clone, Copy)]
// `error` and `evals` describe the integration when a call is debugged; no caller reads them.
#[allow(dead_code)]
pub struct QuadResult {
    /// The integral.
    pub value: f64,
    /// Estimated absolute error.
    pub error: f64,
    /// Integrand evaluations.
    pub evals: usize,
    /// True when the tolerance was met.
    pub converged: bool,
}

#[inline]
fn gk15<F: FnMut(f64) -> f64>(f: &mut F, a: f64, b: f64) -> (f64, f64) {
    let c = 0.5 * (a + b);
    let h = 0.5 * (b - a);
    let fc = f(c);
    let mut rk = WGK[7] * fc;
    let mut rg = WG[3] * fc;
    for i in 0..7 {
        let dx = h * XGK[i];
        let s = f(c - dx) + f(c + dx);
        rk += WGK[i] * s;
        if i % 2 == 1 {
            rg += WG[i / 2] * s;
        }
    }
    let rk = rk * h;
    let rg = rg * h;
    // QUADPACK's error heuristic is pessimistic for smooth integrands; the plain difference
    // |K15 − G7| bounds the error of G7, hence very safely that of K15.
    (rk, (rk - rg).abs())
}

/// ∫_a^b f(x) dx by adaptive Gauss–Kronrod (a ≤ b or a > b).
pub(crate) fn integrate<F: FnMut(f64) -> f64>(
    mut f: F,
    a: f64,
    b: f64,
    opts: QuadOptions,
) -> QuadResult {
    const CAP: usize = 256;
    let max_panels = opts.max_panels.clamp(1, CAP);
    let mut lo = [0.0f64; CAP];
    let mut hi = [0.0f64; CAP];
    let mut val = [0.0f64; CAP];
    let mut err = [0.0f64; CAP];
    let (v, e) = gk15(&mut f, a, b);
    lo[0] = a;
    hi[0] = b;
    val[0] = v;
    err[0] = e;
    let mut n = 1;
    let mut evals = 15;
    loop {
        let total: f64 = val[..n].iter().sum();
        let total_err: f64 = err[..n].iter().sum();
        let tol = opts.abs_tol.max(opts.rel_tol * total.abs());
        if total_err <= tol || !total.is_finite() {
            return QuadResult {
                value: total,
                error: total_err,
                evals,
                converged: total.is_finite(),
            };
        }
        if n >= max_panels {
            return QuadResult {
                value: total,
                error: total_err,
                evals,
                converged: false,
            };
        }
        // Bisect the panel with the largest error.
        let mut k = 0;
        for i in 1..n {
            if err[i] > err[k] {
                k = i;
            }
        }
        let (a0, b0) = (lo[k], hi[k]);
        let m = 0.5 * (a0 + b0);
        if m == a0 || m == b0 {
            return QuadResult {
                value: total,
                error: total_err,
                evals,
                converged: false,
            };
        }
        let (v1, e1) = gk15(&mut f, a0, m);
        let (v2, e2) = gk15(&mut f, m, b0);
        evals += 30;
        hi[k] = m;
        val[k] = v1;
        err[k] = e1;
        lo[n] = m;
        hi[n] = b0;
        val[n] = v2;
        err[n] = e2;
        n += 1;
    }
}

/// K15 on [a, b] of a vector integrand with QUADPACK's error estimate per component
/// (Piessens et al. 1983, qk15): resasc·min(1, (200 |K15 − G7| / resasc)^{3/2}),
/// resasc = ∫|f − mean|.
fn gk15_quadpack<const N: usize, F: FnMut(f64) -> [f64; N]>(
    f: &mut F,
    a: f64,
    b: f64,
) -> ([f64; N], [f64; N]) {
    let c = 0.5 * (a + b);
    let h = 0.5 * (b - a);
    let mut fv = [[0.0f64; N]; 15];
    fv[7] = f(c);
    for i in 0..7 {
        let dx = h * XGK[i];
        fv[i] = f(c - dx);
        fv[14 - i] = f(c + dx);
    }
    let mut val = [0.0; N];
    let mut err = [0.0; N];
    for n in 0..N {
        let mut rk = WGK[7] * fv[7][n];
        let mut rg = WG[3] * fv[7][n];
        for i in 0..7 {
            let s = fv[i][n] + fv[14 - i][n];
            rk += WGK[i] * s;
            if i % 2 == 1 {
                rg += WG[i / 2] * s;
            }
        }
        let mean = 0.5 * rk;
        let mut asc = WGK[7] * (fv[7][n] - mean).abs();
        for i in 0..7 {
            asc += WGK[i] * ((fv[i][n] - mean).abs() + (fv[14 - i][n] - mean).abs());
        }
        val[n] = rk * h;
        err[n] = quadpack_error((rk - rg) * h, asc * h);
    }
    (val, err)
}

/// Kronrod 21-point abscissae on [0, 1] (descending; the last is the centre), computed from
/// their definition (zeros of P_10 and of the Stieltjes polynomial E_11) at 60 digits by
/// scripts/gk21.py, rounded to double (they agree with QUADPACK's qk21).
const XK21: [f64; 11] = [
    0.9956571630258081,
    0.9739065285171717,
    0.9301574913557082,
    0.8650633666889845,
    0.7808177265864169,
    0.6794095682990244,
    0.5627571346686047,
    0.4333953941292472,
    0.2943928627014602,
    0.14887433898163122,
    0.0,
];
/// Kronrod 21-point weights matching [`XK21`] (scripts/gk21.py).
const WK21: [f64; 11] = [
    0.011694638867371874,
    0.032558162307964725,
    0.054755896574351995,
    0.07503967481091996,
    0.0931254545836976,
    0.10938715880229764,
    0.12349197626206584,
    0.13470921731147334,
    0.14277593857706009,
    0.14773910490133849,
    0.1494455540029169,
];
/// Gauss 10-point weights on XK21[1], XK21[3], …, XK21[9] (scripts/gk21.py).
const WG10: [f64; 5] = [
    0.06667134430868814,
    0.1494513491505806,
    0.21908636251598204,
    0.26926671930999635,
    0.29552422471475287,
];

/// One Gauss–Kronrod 10/21 panel of half-width `h` around a centre c, with the integrand
/// supplied in symmetric pairs — `pair(x)` = (f(c − h x), f(c + h x)) for the rule's
/// abscissae x ∈ (0, 1), `fc` = f(c) — so that a caller can share the work of the two points
/// of a pair (addition formulas). Returns the K21 value and QUADPACK's error estimate (qk21,
/// Piessens et al. 1983): resasc·min(1, (200 |K21 − G10| / resasc)^{3/2}), resasc = ∫|f − mean|.
/// With 21 points the rule is exact to degree 31: on the analytic slip integrands of a steady
/// stick/slip contact one panel reaches 1e-15 where the 15-point rule needs three.
pub(crate) fn gk21_pairs<F: FnMut(f64) -> (f64, f64)>(mut pair: F, fc: f64, h: f64) -> (f64, f64) {
    let mut fv = [(0.0f64, 0.0f64); 10];
    let mut rk = WK21[10] * fc;
    let mut rg = 0.0;
    for i in 0..10 {
        let p = pair(XK21[i]);
        fv[i] = p;
        let s = p.0 + p.1;
        rk += WK21[i] * s;
        if i % 2 == 1 {
            rg += WG10[i / 2] * s;
        }
    }
    let mean = 0.5 * rk;
    let mut asc = WK21[10] * (fc - mean).abs();
    for i in 0..10 {
        asc += WK21[i] * ((fv[i].0 - mean).abs() + (fv[i].1 - mean).abs());
    }
    (rk * h, quadpack_error((rk - rg) * h, asc * h))
}

/// QUADPACK's error estimate of a Kronrod panel (Piessens et al. 1983, qk15/qk21) from the
/// Kronrod − Gauss difference and resasc = ∫|f − mean|: resasc·min(1, (200 |K − G| / resasc)^{3/2}).
fn quadpack_error(k_minus_g: f64, resasc: f64) -> f64 {
    let (e, resasc) = (k_minus_g.abs(), resasc.abs());
    if resasc != 0.0 && e != 0.0 {
        resasc * (200.0 * e / resasc).powf(1.5).min(1.0)
    } else {
        e
    }
}

/// ∫_a^b f(x) dx for a smooth (analytic) integrand: adaptive K15 with QUADPACK's error
/// estimate, bisecting the panel with the largest error until the sum is below
/// `rel_tol`·|integral| (or 64 panels). Used where [`integrate`]'s deliberately pessimistic
/// |K15 − G7| test would subdivide a smooth integrand far past double precision: on the contact
/// model's spin integral it needs one panel where [`integrate`] needs about ten for 1e-14,
/// with the same result to round-off (tests/it/contact.rs holds it against an RK4 reference).
pub(crate) fn integrate_smooth<F: FnMut(f64) -> f64>(
    mut f: F,
    a: f64,
    b: f64,
    rel_tol: f64,
) -> f64 {
    integrate_smooth_n(|x| [f(x)], a, b, rel_tol)[0]
}

/// [`integrate_smooth`] of N integrands sharing their abscissae (one evaluation of `f` gives
/// all N values): each component to `rel_tol` of its own magnitude.
pub(crate) fn integrate_smooth_n<const N: usize, F: FnMut(f64) -> [f64; N]>(
    mut f: F,
    a: f64,
    b: f64,
    rel_tol: f64,
) -> [f64; N] {
    const CAP: usize = 64;
    let mut lo = [0.0f64; CAP];
    let mut hi = [0.0f64; CAP];
    let mut val = [[0.0f64; N]; CAP];
    let mut err = [[0.0f64; N]; CAP];
    // Panel error relative to the tolerance of its component, worst component.
    let (v, e) = gk15_quadpack(&mut f, a, b);
    lo[0] = a;
    hi[0] = b;
    val[0] = v;
    err[0] = e;
    let mut n = 1;
    loop {
        let mut total = [0.0; N];
        let mut total_err = [0.0; N];
        for i in 0..n {
            for c in 0..N {
                total[c] += val[i][c];
                total_err[c] += err[i][c];
            }
        }
        let done = (0..N).all(|c| total_err[c] <= rel_tol * total[c].abs());
        if done || total.iter().any(|t| !t.is_finite()) || n == CAP {
            return total;
        }
        let scale = |i: usize| {
            (0..N)
                .map(|c| err[i][c] / (rel_tol * total[c].abs()).max(f64::MIN_POSITIVE))
                .fold(0.0, f64::max)
        };
        let mut k = 0;
        for i in 1..n {
            if scale(i) > scale(k) {
                k = i;
            }
        }
        let (a0, b0) = (lo[k], hi[k]);
        let m = 0.5 * (a0 + b0);
        if m == a0 || m == b0 {
            return total;
        }
        let (v1, e1) = gk15_quadpack(&mut f, a0, m);
        let (v2, e2) = gk15_quadpack(&mut f, m, b0);
        hi[k] = m;
        val[k] = v1;
        err[k] = e1;
        lo[n] = m;
        hi[n] = b0;
        val[n] = v2;
        err[n] = e2;
        n += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kronrod_rule_is_exact_for_polynomials_to_degree_22() {
        for deg in 0..=22 {
            let (v, _) = gk15(&mut |x: f64| x.powi(deg), -1.0, 1.0);
            let exact = if deg % 2 == 1 {
                0.0
            } else {
                2.0 / (deg as f64 + 1.0)
            };
            assert!((v - exact).abs() < 4e-16, "degree {deg}: {v} vs {exact}");
        }
    }

    #[test]
    fn kronrod_21_rule_is_exact_for_polynomials_to_degree_31() {
        // ∫_{-1}^{1} x^k dx = 2/(k+1) for even k, 0 for odd k (exact moments).
        for k in 0..=31 {
            let f = |x: f64| x.powi(k);
            let (v, _) = gk21_pairs(|x| (f(-x), f(x)), f(0.0), 1.0);
            let exact = if k % 2 == 0 {
                2.0 / (k as f64 + 1.0)
            } else {
                0.0
            };
            assert!((v - exact).abs() <= 4e-16, "degree {k}: {v} vs {exact}");
        }
        // Degree 32 is not integrated exactly: the rule is not trivially exact.
        let (v, _) = gk21_pairs(|x| (x.powi(32), x.powi(32)), 0.0, 1.0);
        assert!((v - 2.0 / 33.0).abs() > 1e-12);
    }

    #[test]
    fn smooth_rule_matches_closed_forms() {
        // ∫_0^1 e^x dx = e − 1; ∫_{-0.4}^{0.6} dx/sqrt(1.2 − cos x) against the adaptive rule
        // at its strict setting.
        let v = integrate_smooth(|x: f64| x.exp(), 0.0, 1.0, 1e-14);
        assert!((v - (1f64.exp() - 1.0)).abs() < 4e-16, "{v}");
        let g = |x: f64| 1.0 / (1.2 - x.cos()).sqrt();
        let v = integrate_smooth(g, -0.4, 0.6, 1e-14);
        let strict = integrate(
            g,
            -0.4,
            0.6,
            QuadOptions {
                rel_tol: 1e-15,
                abs_tol: 0.0,
                max_panels: 256,
            },
        );
        assert!(strict.converged);
        assert!((v - strict.value).abs() < 4e-15 * v, "{v} {}", strict.value);
    }

    #[test]
    fn adaptive_rule_handles_an_inverse_square_root_endpoint() {
        // ∫_0^1 x^{-1/2} dx = 2 (closed form).
        let r = integrate(
            |x: f64| 1.0 / x.sqrt(),
            0.0,
            1.0,
            QuadOptions {
                rel_tol: 1e-10,
                max_panels: 200,
                ..Default::default()
            },
        );
        assert!((r.value - 2.0).abs() < 1e-9, "{r:?}");
    }
}
