//! Bracketed one-dimensional root finding (Brent 1973, the `zeroin` algorithm).
//!
//! Written by hand rather than through argmin's `BrentRoot`: it is called inside every
//! stick/slip evaluation and K inversion, where the executor's state and observer machinery cost
//! more than the function it solves. Measured by `cargo bench --features bench-internals --bench k -- root` on Kepler's
//! equation to 1e-15 (a function of a few flops, like the inner loops'): 400–402 ns here against
//! 1.10–1.22 µs for `BrentRoot` under argmin's `Executor` (criterion medians of two runs, 2-core
//! AMD EPYC, 2026-11-23). This version also allocates nothing and reports its evaluation
//! count. The one root found outside a hot loop, a profile interval's end (each evaluation a
//! constrained fit), keeps this finder too: `BrentRoot` takes other steps, so the intervals would
//! move in their last digits.

/// A root with the bracket it came from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Root {
    /// The root.
    pub x: f64,
    /// f at the root.
    pub fx: f64,
    /// Function evaluations used.
    pub evals: usize,
}

/// Finds x in [a, b] with f(x) = 0, given f(a) and f(b) of opposite signs (or zero), to an
/// absolute tolerance `xtol` plus 2 ulp. Returns `None` when the bracket is not a bracket or a
/// value is NaN.
pub fn brent<F: FnMut(f64) -> f64>(
    f: F,
    a: f64,
    b: f64,
    fa: f64,
    fb: f64,
    xtol: f64,
    max_evals: usize,
) -> Option<Root> {
    brent_until(f, a, b, fa, fb, xtol, max_evals, |_, _| false)
}

/// [`brent`] that also ends as soon as `resolved(b, c)` holds for its best point b and the
/// other end c of its bracket, and |f(b)| < |f(c)| strictly. For a function that is constant
/// on cells of x (the cells a computation resolves, such as the doubles of K = K_min + eˢ
/// when x = s), once b and c lie in adjacent cells every later iterate lies in one of the two,
/// and after each step b is the end with the smaller |f|: with the two values of |f| unequal,
/// [`brent`] ends in b's cell. This returns b then, without the steps that only shrink the
/// bracket inside the two cells (about 40 near the crawl end of the K inversion, where one
/// double of K spans 1e-2 in s). Where |f| is equal in both cells (f = ±one rounding step, say)
/// it goes on as [`brent`] does, whose end then depends on its path.
#[allow(clippy::too_many_arguments)]
pub(crate) fn brent_until<F: FnMut(f64) -> f64>(
    mut f: F,
    a: f64,
    b: f64,
    fa: f64,
    fb: f64,
    xtol: f64,
    max_evals: usize,
    mut resolved: impl FnMut(f64, f64) -> bool,
) -> Option<Root> {
    let (mut a, mut b, mut fa, mut fb) = (a, b, fa, fb);
    if fa.is_nan() || fb.is_nan() || fa * fb > 0.0 {
        return None;
    }
    if fa == 0.0 {
        return Some(Root {
            x: a,
            fx: fa,
            evals: 0,
        });
    }
    if fb == 0.0 {
        return Some(Root {
            x: b,
            fx: fb,
            evals: 0,
        });
    }
    let mut c = a;
    let mut fc = fa;
    let mut d = b - a;
    let mut e = d;
    let mut evals = 0;
    loop {
        if fb.signum() == fc.signum() {
            c = a;
            fc = fa;
            d = b - a;
            e = d;
        }
        if fc.abs() < fb.abs() {
            a = b;
            b = c;
            c = a;
            fa = fb;
            fb = fc;
            fc = fa;
        }
        let tol = 2.0 * f64::EPSILON * b.abs() + 0.5 * xtol;
        let m = 0.5 * (c - b);
        if m.abs() <= tol
            || fb == 0.0
            || evals >= max_evals
            || (fb.abs() < fc.abs() && resolved(b, c))
        {
            return Some(Root {
                x: b,
                fx: fb,
                evals,
            });
        }
        if e.abs() >= tol && fa.abs() > fb.abs() {
            let s = fb / fa;
            let (mut p, mut q);
            if a == c {
                p = 2.0 * m * s;
                q = 1.0 - s;
            } else {
                let qq = fa / fc;
                let r = fb / fc;
                p = s * (2.0 * m * qq * (qq - r) - (b - a) * (r - 1.0));
                q = (qq - 1.0) * (r - 1.0) * (s - 1.0);
            }
            if p > 0.0 {
                q = -q;
            } else {
                p = -p;
            }
            if 2.0 * p < (3.0 * m * q - (tol * q).abs()).min((e * q).abs()) {
                e = d;
                d = p / q;
            } else {
                d = m;
                e = m;
            }
        } else {
            d = m;
            e = m;
        }
        a = b;
        fa = fb;
        b += if d.abs() > tol { d } else { tol.copysign(m) };
        fb = f(b);
        evals += 1;
        if fb.is_nan() {
            return None;
        }
    }
}

/// The maximum of a unimodal f on [a, b] by golden-section search, to a bracket of width
/// ≤ `xtol` (at most `max_iter` steps); returns the lower end of the final bracket. Used on
/// K(launch speed) of the stick/slip model, whose maximum is the saddle-node of its map.
pub(crate) fn golden_max<F: FnMut(f64) -> f64>(
    mut f: F,
    mut a: f64,
    mut b: f64,
    xtol: f64,
    max_iter: usize,
) -> f64 {
    let r = 0.5 * (5f64.sqrt() - 1.0);
    let (mut c, mut d) = (b - r * (b - a), a + r * (b - a));
    let (mut fc, mut fd) = (f(c), f(d));
    for _ in 0..max_iter {
        if b - a <= xtol {
            break;
        }
        if fc >= fd {
            b = d;
            d = c;
            fd = fc;
            c = b - r * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + r * (b - a);
            fd = f(d);
        }
    }
    a
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_cube_root_of_two_to_full_precision() {
        let f = |x: f64| x * x * x - 2.0;
        let r = brent(f, 0.0, 2.0, f(0.0), f(2.0), 0.0, 200).unwrap();
        assert!((r.x - 2f64.cbrt()).abs() <= 4.0 * f64::EPSILON, "{r:?}");
        assert!(r.evals < 20);
    }

    #[test]
    fn golden_section_finds_a_parabola_peak() {
        let x = golden_max(|x| -(x - 0.3) * (x - 0.3), 0.0, 1.0, 1e-12, 200);
        assert!((x - 0.3).abs() < 1e-6, "{x}");
    }

    #[test]
    fn refuses_a_non_bracket() {
        let f = |x: f64| x * x + 1.0;
        assert!(brent(f, -1.0, 1.0, f(-1.0), f(1.0), 0.0, 100).is_none());
    }
}
