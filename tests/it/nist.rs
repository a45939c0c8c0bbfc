//! The 27 nonlinear regression problems of the NIST Statistical Reference Datasets (StRD), each
//! from both NIST starting points: 54 fits judged by the log relative error (LRE) of the
//! parameters and of their standard errors against NIST's certified values.
//!
//! The data files are unmodified copies in `tests/nist-strd/` (see its README). Each model below
//! is written by hand from its file's `Model:` section, with its analytic gradient.
//!
//! Run with `cargo test --release --test it nist:: -- --nocapture` to see the table.

// `!(x > 0.0)` is deliberate: a NaN must land in the failure branch.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use std::path::{Path, PathBuf};

use crate::cross_check::lre;
use dd::Dd;
use faer::MatMut;
use fitbead::inverse::{
    fit, CurveModel, Fit, Infeasible, LsqOptions, Residuals, SigmaKind, WeightedData,
};

/// One StRD problem: data and certified values.
#[derive(Debug, Clone)]
pub struct Problem {
    /// Dataset name (file stem).
    pub name: String,
    /// Starting values 1 and 2.
    pub starts: [Vec<f64>; 2],
    /// Certified parameter values.
    pub certified: Vec<f64>,
    /// Certified standard deviations.
    pub certified_sd: Vec<f64>,
    /// Certified residual sum of squares.
    pub certified_rss: f64,
    /// Predictors (x, or x1 and x2 for Nelson).
    pub x: Vec<[f64; 2]>,
    /// Responses (log y for Nelson, whose model is for log y).
    pub y: Vec<f64>,
    /// The model.
    pub model: Nist,
    /// (x, y) in double-double from the exact decimal text, for Lanczos1 (see [`Exact`]).
    pub exact: Option<(Vec<Dd>, Vec<Dd>)>,
}

/// Directory of the data files.
pub fn data_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests")
        .join("nist-strd")
}

fn lines_range(header: &str, key: &str) -> Option<(usize, usize)> {
    // e.g. "Data              (lines 61 to 71)"
    let line = header
        .lines()
        .find(|l| l.trim_start().starts_with(key) && l.contains("(lines"))?;
    let inner = line.split("(lines").nth(1)?.split(')').next()?;
    let mut it = inner.split("to").map(|s| s.trim().parse::<usize>());
    Some((it.next()?.ok()?, it.next()?.ok()?))
}

fn num(s: &str) -> Result<f64, String> {
    s.trim()
        .parse::<f64>()
        .map_err(|e| format!("bad number {s:?}: {e}"))
}

/// Parses one `.dat` file.
pub fn parse(path: &Path) -> Result<Problem, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let name = path
        .file_stem()
        .and_then(|s| s.to_str())
        .ok_or("file name")?
        .to_string();
    let lines: Vec<&str> = text.lines().collect();
    let file_format: String = lines
        .iter()
        .take(12)
        .cloned()
        .collect::<Vec<_>>()
        .join("\n");
    let (s0, s1) =
        lines_range(&file_format, "Starting Values").ok_or("no starting-values range")?;
    let (d0, d1) = lines_range(&file_format, "Data").ok_or("no data range")?;
    let (mut st1, mut st2, mut cert, mut sd) = (vec![], vec![], vec![], vec![]);
    for (k, l) in lines[s0 - 1..s1].iter().enumerate() {
        let rest = l
            .trim()
            .strip_prefix(&format!("b{} =", k + 1))
            .ok_or_else(|| format!("line {}: expected b{} =", s0 + k, k + 1))?;
        let f: Vec<&str> = rest.split_whitespace().collect();
        if f.len() != 4 {
            return Err(format!("line {}: expected 4 numbers", s0 + k));
        }
        st1.push(num(f[0])?);
        st2.push(num(f[1])?);
        cert.push(num(f[2])?);
        sd.push(num(f[3])?);
    }
    let rss_line = lines
        .iter()
        .find(|l| l.starts_with("Residual Sum of Squares:"))
        .ok_or("no RSS")?;
    let certified_rss = num(rss_line.split(':').nth(1).ok_or("RSS")?)?;
    let nelson = name == "Nelson";
    let (mut x, mut y) = (vec![], vec![]);
    let (mut xe, mut ye) = (vec![], vec![]);
    for (k, l) in lines[d0 - 1..d1].iter().enumerate() {
        let f: Vec<f64> = l.split_whitespace().map(num).collect::<Result<_, _>>()?;
        if name == "Lanczos1" {
            let t: Vec<&str> = l.split_whitespace().collect();
            let bad = || format!("line {}: not a decimal", d0 + k);
            ye.push(parse_dd(t[0]).ok_or_else(bad)?);
            xe.push(parse_dd(t[1]).ok_or_else(bad)?);
        }
        match (nelson, f.as_slice()) {
            (false, [yy, xx]) => {
                y.push(*yy);
                x.push([*xx, 0.0]);
            }
            (true, [yy, x1, x2]) => {
                y.push(yy.ln());
                x.push([*x1, *x2]);
            }
            _ => return Err(format!("line {}: unexpected data row", d0 + k)),
        }
    }
    let model = Nist::from_name(&name).ok_or_else(|| format!("no model for {name}"))?;
    if model.n_params() != cert.len() {
        return Err(format!(
            "{name}: model has {} parameters, file {}",
            model.n_params(),
            cert.len()
        ));
    }
    let exact = (name == "Lanczos1").then_some((xe, ye));
    Ok(Problem {
        name,
        starts: [st1, st2],
        certified: cert,
        certified_sd: sd,
        certified_rss,
        x,
        y,
        model,
        exact,
    })
}

/// A decimal numeral (as in the data files) to double-double: the digits as an exact integer
/// times an exact power of ten, divided in double-double. `None` beyond 15 significant digits.
pub fn parse_dd(s: &str) -> Option<Dd> {
    let (mant, exp) = match s.find(['E', 'e']) {
        Some(i) => (&s[..i], s[i + 1..].parse::<i32>().ok()?),
        None => (s, 0),
    };
    let (neg, mant) = match mant.strip_prefix('-') {
        Some(r) => (true, r),
        None => (false, mant.strip_prefix('+').unwrap_or(mant)),
    };
    let (int, frac) = mant.split_once('.').unwrap_or((mant, ""));
    let digits = format!("{int}{frac}");
    let digits = digits.trim_start_matches('0');
    if digits.len() > 15 || !digits.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    let m = if digits.is_empty() {
        0.0
    } else {
        digits.parse::<u64>().ok()? as f64
    };
    let k = exp - frac.len() as i32;
    if k.abs() > 22 {
        return None;
    }
    let p = Dd::from(10f64.powi(k.abs()));
    let v = if k >= 0 {
        Dd::from(m) * p
    } else {
        Dd::from(m) / p
    };
    Some(if neg { -v } else { v })
}

/// exp in double-double: x = k ln 2 + r, expm1(r/2¹⁰) by its Taylor series, ten doublings
/// (q ← 2q + q²), times 2ᵏ.
pub fn exp_dd(a: Dd) -> Dd {
    const LN2: Dd = Dd {
        hi: std::f64::consts::LN_2,
        lo: 2.319_046_813_846_299_6e-17,
    };
    let k = (a.hi / LN2.hi).round();
    let r = (a - LN2.mul_f64(k)).mul_f64(1.0 / 1024.0);
    let mut term = r;
    let mut q = r;
    for n in 2..14 {
        term = term * r / Dd::from(n as f64);
        q = q + term;
    }
    for _ in 0..10 {
        q = q * (q + Dd::from(2.0));
    }
    let e = q + Dd::from(1.0);
    let s = 2f64.powi(k as i32);
    Dd {
        hi: e.hi * s,
        lo: e.lo * s,
    }
}

/// Lanczos1 evaluated in double-double from the exact decimal data.
///
/// Lanczos1 is a zero-residual problem: its data are the model's values rounded to 13
/// significant digits, so the residuals are ~10⁻¹³ — a few hundred ulps of y — and the
/// certified standard deviations, proportional to √RSS, depend on every one of those ulps.
/// Rounding y and x to doubles alone moves RSS by ~10⁻³ relative, which caps the standard-error
/// LRE near 3 whatever the solver does. The problem (not the solver) therefore computes its
/// residuals in double-double; the solver sees ordinary f64 residuals and Jacobians.
#[derive(Debug, Clone)]
pub struct Exact {
    x: Vec<Dd>,
    y: Vec<Dd>,
}

impl Residuals for Exact {
    fn n_params(&self) -> usize {
        6
    }
    fn n_residuals(&self) -> usize {
        self.y.len()
    }
    fn residuals(&self, b: &[f64], out: &mut [f64]) -> Result<(), Infeasible> {
        for (i, o) in out.iter_mut().enumerate() {
            let x = self.x[i];
            let mut f = Dd::from(0.0);
            for t in 0..3 {
                f = f + exp_dd(x.mul_f64(-b[2 * t + 1])).mul_f64(b[2 * t]);
            }
            *o = (self.y[i] - f).to_f64();
        }
        Ok(())
    }
    fn jacobian(&self, b: &[f64], mut out: MatMut<'_, f64>) -> Option<Result<(), Infeasible>> {
        let mut g = [0.0; 6];
        for (i, x) in self.x.iter().enumerate() {
            if let Err(e) = Nist::Lanczos.eval(&[x.to_f64(), 0.0], b, &mut g) {
                return Some(Err(e));
            }
            for (j, gj) in g.iter().enumerate() {
                out[(i, j)] = -gj;
            }
        }
        Some(Ok(()))
    }
}

/// The residuals of a problem: unit-weight data and model, or [`Exact`] for Lanczos1.
#[derive(Debug, Clone)]
pub enum Data {
    /// Double precision.
    Plain(WeightedData<[f64; 2], Nist>),
    /// Double-double residuals.
    Exact(Exact),
}

impl Residuals for Data {
    fn n_params(&self) -> usize {
        match self {
            Data::Plain(d) => d.n_params(),
            Data::Exact(d) => d.n_params(),
        }
    }
    fn n_residuals(&self) -> usize {
        match self {
            Data::Plain(d) => d.n_residuals(),
            Data::Exact(d) => d.n_residuals(),
        }
    }
    fn residuals(&self, p: &[f64], out: &mut [f64]) -> Result<(), Infeasible> {
        match self {
            Data::Plain(d) => d.residuals(p, out),
            Data::Exact(d) => d.residuals(p, out),
        }
    }
    fn jacobian(&self, p: &[f64], out: MatMut<'_, f64>) -> Option<Result<(), Infeasible>> {
        match self {
            Data::Plain(d) => d.jacobian(p, out),
            Data::Exact(d) => d.jacobian(p, out),
        }
    }
}

/// All 27 problems, in NIST's order of difficulty.
pub fn problems() -> Vec<Problem> {
    const ORDER: [&str; 27] = [
        "Misra1a", "Chwirut2", "Chwirut1", "Lanczos3", "Gauss1", "Gauss2", "DanWood", "Misra1b",
        "Kirby2", "Hahn1", "Nelson", "MGH17", "Lanczos1", "Lanczos2", "Gauss3", "Misra1c",
        "Misra1d", "Roszman1", "ENSO", "MGH09", "Thurber", "BoxBOD", "Rat42", "MGH10", "Eckerle4",
        "Rat43", "Bennett5",
    ];
    ORDER
        .iter()
        .map(|n| parse(&data_dir().join(format!("{n}.dat"))).unwrap_or_else(|e| panic!("{e}")))
        .collect()
}

/// The 27 StRD model functions.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Nist {
    /// y = b1·(1 − exp(−b2·x)) (Misra1a, BoxBOD)
    Misra1a,
    /// y = exp(−b1·x)/(b2 + b3·x) (Chwirut1, Chwirut2)
    Chwirut,
    /// y = b1·exp(−b2·x) + b3·exp(−b4·x) + b5·exp(−b6·x) (Lanczos1–3)
    Lanczos,
    /// y = b1·exp(−b2·x) + b3·exp(−(x−b4)²/b5²) + b6·exp(−(x−b7)²/b8²) (Gauss1–3)
    Gauss,
    /// y = b1·x^b2
    DanWood,
    /// y = b1·(1 − (1 + b2·x/2)^(−2))
    Misra1b,
    /// y = (b1 + b2·x + b3·x²)/(1 + b4·x + b5·x²)
    Kirby2,
    /// y = (b1 + b2·x + b3·x² + b4·x³)/(1 + b5·x + b6·x² + b7·x³) (Hahn1, Thurber)
    Rational33,
    /// log y = b1 − b2·x1·exp(−b3·x2)
    Nelson,
    /// y = b1 + b2·exp(−x·b4) + b3·exp(−x·b5)
    Mgh17,
    /// y = b1·(1 − (1 + 2·b2·x)^(−1/2))
    Misra1c,
    /// y = b1·b2·x/(1 + b2·x)
    Misra1d,
    /// y = b1 − b2·x − arctan(b3/(x − b4))/π
    Roszman1,
    /// y = b1 + b2·cos(2πx/12) + b3·sin(2πx/12) + b5·cos(2πx/b4) + b6·sin(2πx/b4)
    ///       + b8·cos(2πx/b7) + b9·sin(2πx/b7)
    Enso,
    /// y = b1·(x² + x·b2)/(x² + x·b3 + b4)
    Mgh09,
    /// y = b1/(1 + exp(b2 − b3·x))
    Rat42,
    /// y = b1·exp(b2/(x + b3))
    Mgh10,
    /// y = (b1/b2)·exp(−½((x − b3)/b2)²)
    Eckerle4,
    /// y = b1/(1 + exp(b2 − b3·x))^(1/b4)
    Rat43,
    /// y = b1·(b2 + x)^(−1/b3)
    Bennett5,
}

impl Nist {
    /// The model of a dataset.
    pub fn from_name(name: &str) -> Option<Nist> {
        use Nist::*;
        Some(match name {
            "Misra1a" | "BoxBOD" => Misra1a,
            "Chwirut1" | "Chwirut2" => Chwirut,
            "Lanczos1" | "Lanczos2" | "Lanczos3" => Lanczos,
            "Gauss1" | "Gauss2" | "Gauss3" => Gauss,
            "DanWood" => DanWood,
            "Misra1b" => Misra1b,
            "Kirby2" => Kirby2,
            "Hahn1" | "Thurber" => Rational33,
            "Nelson" => Nelson,
            "MGH17" => Mgh17,
            "Misra1c" => Misra1c,
            "Misra1d" => Misra1d,
            "Roszman1" => Roszman1,
            "ENSO" => Enso,
            "MGH09" => Mgh09,
            "Rat42" => Rat42,
            "MGH10" => Mgh10,
            "Eckerle4" => Eckerle4,
            "Rat43" => Rat43,
            "Bennett5" => Bennett5,
            _ => return None,
        })
    }

    /// Value and gradient together (`g` may be empty to skip the gradient).
    fn eval(self, xx: &[f64; 2], b: &[f64], g: &mut [f64]) -> Result<f64, Infeasible> {
        use std::f64::consts::PI;
        use Nist::*;
        let x = xx[0];
        let want = !g.is_empty();
        let v = match self {
            Misra1a => {
                let e = (-b[1] * x).exp();
                if want {
                    g[0] = 1.0 - e;
                    g[1] = b[0] * x * e;
                }
                b[0] * (1.0 - e)
            }
            Chwirut => {
                let e = (-b[0] * x).exp();
                let d = b[1] + b[2] * x;
                if d == 0.0 {
                    return Err(Infeasible);
                }
                if want {
                    g[0] = -x * e / d;
                    g[1] = -e / (d * d);
                    g[2] = -x * e / (d * d);
                }
                e / d
            }
            Lanczos => {
                let e1 = (-b[1] * x).exp();
                let e2 = (-b[3] * x).exp();
                let e3 = (-b[5] * x).exp();
                if want {
                    g[0] = e1;
                    g[1] = -b[0] * x * e1;
                    g[2] = e2;
                    g[3] = -b[2] * x * e2;
                    g[4] = e3;
                    g[5] = -b[4] * x * e3;
                }
                b[0] * e1 + b[2] * e2 + b[4] * e3
            }
            Gauss => {
                let e = (-b[1] * x).exp();
                let (u1, u2) = (x - b[3], x - b[6]);
                let g1 = (-(u1 * u1) / (b[4] * b[4])).exp();
                let g2 = (-(u2 * u2) / (b[7] * b[7])).exp();
                if want {
                    g[0] = e;
                    g[1] = -b[0] * x * e;
                    g[2] = g1;
                    g[3] = b[2] * g1 * 2.0 * u1 / (b[4] * b[4]);
                    g[4] = b[2] * g1 * 2.0 * u1 * u1 / (b[4] * b[4] * b[4]);
                    g[5] = g2;
                    g[6] = b[5] * g2 * 2.0 * u2 / (b[7] * b[7]);
                    g[7] = b[5] * g2 * 2.0 * u2 * u2 / (b[7] * b[7] * b[7]);
                }
                b[0] * e + b[2] * g1 + b[5] * g2
            }
            DanWood => {
                if !(x > 0.0) {
                    return Err(Infeasible);
                }
                let p = x.powf(b[1]);
                if want {
                    g[0] = p;
                    g[1] = b[0] * p * x.ln();
                }
                b[0] * p
            }
            Misra1b => {
                let u = 1.0 + b[1] * x / 2.0;
                if u == 0.0 {
                    return Err(Infeasible);
                }
                if want {
                    g[0] = 1.0 - 1.0 / (u * u);
                    g[1] = b[0] * x / (u * u * u);
                }
                b[0] * (1.0 - 1.0 / (u * u))
            }
            Kirby2 => {
                let n = b[0] + b[1] * x + b[2] * x * x;
                let d = 1.0 + b[3] * x + b[4] * x * x;
                if d == 0.0 {
                    return Err(Infeasible);
                }
                if want {
                    g[0] = 1.0 / d;
                    g[1] = x / d;
                    g[2] = x * x / d;
                    g[3] = -n * x / (d * d);
                    g[4] = -n * x * x / (d * d);
                }
                n / d
            }
            Rational33 => {
                let (x2, x3) = (x * x, x * x * x);
                let n = b[0] + b[1] * x + b[2] * x2 + b[3] * x3;
                let d = 1.0 + b[4] * x + b[5] * x2 + b[6] * x3;
                if d == 0.0 {
                    return Err(Infeasible);
                }
                if want {
                    g[0] = 1.0 / d;
                    g[1] = x / d;
                    g[2] = x2 / d;
                    g[3] = x3 / d;
                    let q = n / (d * d);
                    g[4] = -q * x;
                    g[5] = -q * x2;
                    g[6] = -q * x3;
                }
                n / d
            }
            Nelson => {
                let (x1, x2) = (xx[0], xx[1]);
                let e = (-b[2] * x2).exp();
                if want {
                    g[0] = 1.0;
                    g[1] = -x1 * e;
                    g[2] = b[1] * x1 * x2 * e;
                }
                b[0] - b[1] * x1 * e
            }
            Mgh17 => {
                let e4 = (-x * b[3]).exp();
                let e5 = (-x * b[4]).exp();
                if want {
                    g[0] = 1.0;
                    g[1] = e4;
                    g[2] = e5;
                    g[3] = -b[1] * x * e4;
                    g[4] = -b[2] * x * e5;
                }
                b[0] + b[1] * e4 + b[2] * e5
            }
            Misra1c => {
                let u = 1.0 + 2.0 * b[1] * x;
                if !(u > 0.0) {
                    return Err(Infeasible);
                }
                let s = u.sqrt();
                if want {
                    g[0] = 1.0 - 1.0 / s;
                    g[1] = b[0] * x / (u * s);
                }
                b[0] * (1.0 - 1.0 / s)
            }
            Misra1d => {
                let d = 1.0 + b[1] * x;
                if d == 0.0 {
                    return Err(Infeasible);
                }
                if want {
                    g[0] = b[1] * x / d;
                    g[1] = b[0] * x / (d * d);
                }
                b[0] * b[1] * x / d
            }
            Roszman1 => {
                let u = x - b[3];
                if u == 0.0 {
                    return Err(Infeasible);
                }
                let w = b[2] / u;
                if want {
                    let c = 1.0 / (PI * (1.0 + w * w));
                    g[0] = 1.0;
                    g[1] = -x;
                    g[2] = -c / u;
                    g[3] = -c * b[2] / (u * u);
                }
                b[0] - b[1] * x - w.atan() / PI
            }
            Enso => {
                let t0 = 2.0 * PI * x / 12.0;
                let t1 = 2.0 * PI * x / b[3];
                let t2 = 2.0 * PI * x / b[6];
                let (s1, c1) = t1.sin_cos();
                let (s2, c2) = t2.sin_cos();
                if want {
                    g[0] = 1.0;
                    g[1] = t0.cos();
                    g[2] = t0.sin();
                    g[3] = (-b[4] * s1 + b[5] * c1) * (-t1 / b[3]);
                    g[4] = c1;
                    g[5] = s1;
                    g[6] = (-b[7] * s2 + b[8] * c2) * (-t2 / b[6]);
                    g[7] = c2;
                    g[8] = s2;
                }
                b[0] + b[1] * t0.cos()
                    + b[2] * t0.sin()
                    + b[4] * c1
                    + b[5] * s1
                    + b[7] * c2
                    + b[8] * s2
            }
            Mgh09 => {
                let n = x * x + x * b[1];
                let d = x * x + x * b[2] + b[3];
                if d == 0.0 {
                    return Err(Infeasible);
                }
                if want {
                    g[0] = n / d;
                    g[1] = b[0] * x / d;
                    g[2] = -b[0] * n * x / (d * d);
                    g[3] = -b[0] * n / (d * d);
                }
                b[0] * n / d
            }
            Rat42 => {
                let e = (b[1] - b[2] * x).exp();
                let d = 1.0 + e;
                if want {
                    g[0] = 1.0 / d;
                    g[1] = -b[0] * e / (d * d);
                    g[2] = b[0] * x * e / (d * d);
                }
                b[0] / d
            }
            Mgh10 => {
                let u = x + b[2];
                if u == 0.0 {
                    return Err(Infeasible);
                }
                let e = (b[1] / u).exp();
                if want {
                    g[0] = e;
                    g[1] = b[0] * e / u;
                    g[2] = -b[0] * e * b[1] / (u * u);
                }
                b[0] * e
            }
            Eckerle4 => {
                if b[1] == 0.0 {
                    return Err(Infeasible);
                }
                let z = (x - b[2]) / b[1];
                let e = (-0.5 * z * z).exp();
                if want {
                    g[0] = e / b[1];
                    g[1] = b[0] * e / (b[1] * b[1]) * (z * z - 1.0);
                    g[2] = b[0] / b[1] * e * z / b[1];
                }
                b[0] / b[1] * e
            }
            Rat43 => {
                if b[3] == 0.0 {
                    return Err(Infeasible);
                }
                let e = (b[1] - b[2] * x).exp();
                let d = 1.0 + e;
                let p = d.powf(-1.0 / b[3]);
                if want {
                    g[0] = p;
                    g[1] = -b[0] / b[3] * p / d * e;
                    g[2] = b[0] / b[3] * p / d * e * x;
                    g[3] = b[0] * p * d.ln() / (b[3] * b[3]);
                }
                b[0] * p
            }
            Bennett5 => {
                let u = b[1] + x;
                if !(u > 0.0) || b[2] == 0.0 {
                    return Err(Infeasible);
                }
                let p = u.powf(-1.0 / b[2]);
                if want {
                    g[0] = p;
                    g[1] = -b[0] / b[2] * p / u;
                    g[2] = b[0] * p * u.ln() / (b[2] * b[2]);
                }
                b[0] * p
            }
        };
        if v.is_finite() {
            Ok(v)
        } else {
            Err(Infeasible)
        }
    }
}

impl CurveModel<[f64; 2]> for Nist {
    fn n_params(&self) -> usize {
        use Nist::*;
        match self {
            Misra1a | DanWood | Misra1b | Misra1c | Misra1d => 2,
            Chwirut | Nelson | Rat42 | Mgh10 | Eckerle4 | Bennett5 => 3,
            Roszman1 | Mgh09 | Rat43 => 4,
            Kirby2 | Mgh17 => 5,
            Lanczos => 6,
            Rational33 => 7,
            Gauss => 8,
            Enso => 9,
        }
    }
    fn value(&self, x: &[f64; 2], p: &[f64]) -> Result<f64, Infeasible> {
        self.eval(x, p, &mut [])
    }
    fn gradient(
        &self,
        x: &[f64; 2],
        p: &[f64],
        grad: &mut [f64],
    ) -> Option<Result<(), Infeasible>> {
        Some(self.eval(x, p, grad).map(|_| ()))
    }
}

/// Solver settings for the StRD: tight tolerances, NIST's s² covariance scaling.
pub fn options() -> LsqOptions {
    LsqOptions {
        ftol: 1e-15,
        xtol: 1e-15,
        gtol: 1e-15,
        max_iterations: 10_000,
        max_residual_evals: 1_000_000,
        sigma: SigmaKind::Relative,
        ..LsqOptions::default()
    }
}

/// The residuals of a problem (unit weights).
pub fn data(p: &Problem) -> Data {
    match &p.exact {
        Some((x, y)) => Data::Exact(Exact {
            x: x.clone(),
            y: y.clone(),
        }),
        None => Data::Plain(
            WeightedData::new(p.model, p.x.clone(), p.y.clone(), None)
                .unwrap_or_else(|e| panic!("{}: {e}", p.name)),
        ),
    }
}

/// Fits one problem from start 0 or 1.
pub fn run(p: &Problem, start: usize, opts: &LsqOptions) -> Fit {
    let d = data(p);
    fit(&d, &p.starts[start], opts).unwrap_or_else(|e| panic!("{}: {e}", p.name))
}

/// Minimum LREs of the parameters and of the standard errors (0 without a covariance).
pub fn min_lres(p: &Problem, f: &Fit) -> (f64, f64) {
    let lp = f
        .params
        .iter()
        .zip(&p.certified)
        .map(|(e, c)| lre(*e, *c))
        .fold(11.0, f64::min);
    let ls = match f.std_errors() {
        Some(se) => se
            .iter()
            .zip(&p.certified_sd)
            .map(|(e, c)| lre(*e, *c))
            .fold(11.0, f64::min),
        None => 0.0,
    };
    (lp, ls)
}

/// Cases that Levenberg–Marquardt cannot reach (problem name, start index 0/1) — must be
/// reported as not converged rather than wrong.
const UNREACHABLE: &[(&str, usize)] = &[];

/// Smallest log relative errors over the 54 fits against NIST's certified values: the figures
/// of docs/ACCURACY.md (parameters 7.83, standard errors 6.99), the first floored to its last
/// digit (measured 7.827).
const MIN_LRE_PARAMS: f64 = 7.82;
const MIN_LRE_STDERR: f64 = 6.99;

/// The 54 fits against NIST's certified parameters and standard deviations (the StRD files in
/// tests/nist-strd/): each converges with LRE ≥ 6 (parameters) and ≥ 4 (standard errors), NIST's
/// usual pass mark, and the smallest LREs over all fits are at least [`MIN_LRE_PARAMS`] and
/// [`MIN_LRE_STDERR`].
#[test]
fn nist_strd_all_54() {
    let opts = options();
    let probs = problems();
    assert_eq!(probs.len(), 27);
    let mut failures = Vec::new();
    let (mut worst_p, mut worst_s) = (11.0f64, 11.0f64);
    let mut passed = 0;
    println!(
        "{:<9} {:>5} {:>8} {:>8} {:>6} {:>7} {:>6}  termination",
        "problem", "start", "LRE(b)", "LRE(sd)", "iter", "fevals", "jevals"
    );
    for p in &probs {
        for s in 0..2 {
            let f = run(p, s, &opts);
            let (lp, ls) = min_lres(p, &f);
            println!(
                "{:<9} {:>5} {:>8.2} {:>8.2} {:>6} {:>7} {:>6}  {:?}",
                p.name,
                s + 1,
                lp,
                ls,
                f.iterations,
                f.residual_evals,
                f.jacobian_evals,
                f.termination
            );
            if UNREACHABLE.contains(&(p.name.as_str(), s)) {
                if f.converged() && lp < 6.0 {
                    failures.push(format!(
                        "{} start {}: claims convergence at a wrong point",
                        p.name,
                        s + 1
                    ));
                }
                continue;
            }
            worst_p = worst_p.min(lp);
            worst_s = worst_s.min(ls);
            if f.converged() && lp >= 6.0 && ls >= 4.0 {
                passed += 1;
            } else {
                failures.push(format!(
                    "{} start {}: LRE params {lp:.2}, stderr {ls:.2}, {:?}",
                    p.name,
                    s + 1,
                    f.termination
                ));
            }
        }
    }
    println!("{passed} of 54 pass; min LRE params {worst_p:.4}, stderr {worst_s:.4}");
    assert!(failures.is_empty(), "failures:\n{}", failures.join("\n"));
    assert!(worst_p >= MIN_LRE_PARAMS, "min LRE params {worst_p}");
    assert!(worst_s >= MIN_LRE_STDERR, "min LRE stderr {worst_s}");
}

/// Checks the hand-written models: at the certified parameters the residual sum of squares
/// matches NIST's certified value (tests/nist-strd/) to 3e-10 relative (measured 1.0e-10,
/// Lanczos2) plus 6e-21 absolute, and the analytic gradients match central differences.
#[test]
fn certified_point_is_a_minimum_of_the_models() {
    let mut worst: f64 = 0.0;
    for p in problems() {
        let d = data(&p);
        let mut r = vec![0.0; p.y.len()];
        d.residuals(&p.certified, &mut r).unwrap();
        let rss: f64 = r.iter().map(|v| v * v).sum();
        let diff = (rss - p.certified_rss).abs();
        println!(
            "{:<9} RSS difference {diff:.3e}, relative {:.3e}",
            p.name,
            diff / p.certified_rss
        );
        // Lanczos1's RSS (1.4e-25) is below what its 11-digit certified parameters reproduce
        // (~4e-21, measured difference 3.9e-21), hence the absolute slack.
        if p.name != "Lanczos1" {
            worst = worst.max(diff / p.certified_rss);
        }
        assert!(
            diff <= 3e-10 * p.certified_rss + 6e-21,
            "{}: RSS {rss:e} vs certified {:e}",
            p.name,
            p.certified_rss
        );
        let n = p.certified.len();
        let mut g = vec![0.0; n];
        for x in p.x.iter().take(5) {
            p.model.gradient(x, &p.certified, &mut g).unwrap().unwrap();
            for j in 0..n {
                let h = 1e-6 * p.certified[j].abs().max(1e-12);
                let mut bp = p.certified.clone();
                let mut bm = p.certified.clone();
                bp[j] += h;
                bm[j] -= h;
                let fd = (p.model.value(x, &bp).unwrap() - p.model.value(x, &bm).unwrap())
                    / (bp[j] - bm[j]);
                assert!(
                    (fd - g[j]).abs()
                        <= 1e-5 * g[j].abs()
                            + 1e-8 * p.model.value(x, &p.certified).unwrap().abs()
                                / p.certified[j].abs(),
                    "{} ∂/∂b{}: analytic {} vs difference {fd}",
                    p.name,
                    j + 1,
                    g[j]
                );
            }
        }
    }
    println!("largest relative RSS difference but Lanczos1's: {worst:.3e}");
}

#[test]
fn double_double_helpers() {
    // e = 2.718281828459045235360287471352662497757…
    let e = exp_dd(Dd::from(1.0));
    assert_eq!(e.hi, std::f64::consts::E);
    assert!((e.lo - 1.445_646_891_729_250_2e-16).abs() < 1e-30);
    // exp(−x)·exp(x) = 1 to double-double accuracy.
    for x in [0.05, 1.15, 3.7, -2.25, 20.0] {
        let p = exp_dd(Dd::from(x)) * exp_dd(Dd::from(-x)) - Dd::from(1.0);
        assert!(p.to_f64().abs() < 1e-30, "{x}: {p:?}");
    }
    // 0.05 = 5/100 exactly: 20·x − 1 vanishes in double-double.
    let x = parse_dd("5.000000000000E-02").unwrap();
    assert!((x.mul_f64(20.0) - Dd::from(1.0)).to_f64().abs() < 1e-31);
    assert_eq!(parse_dd("-2.5E+00").unwrap().to_f64(), -2.5);
    assert_eq!(parse_dd("0.000000000000E+00").unwrap().to_f64(), 0.0);
}

/// Profile-likelihood intervals on every StRD problem (from start 2), next to the covariance
/// intervals. With s² scaling the F-based profile threshold makes the two agree for nearly
/// linear problems; the strongly nonlinear ones show how far apart they drift.
#[test]
fn nist_profile_intervals() {
    let opts = options();
    println!(
        "{:<9} {:>3} {:>14} {:>10} {:>10} {:>7}",
        "problem", "b", "estimate", "lo/Wald", "hi/Wald", "fits"
    );
    let mut found = 0;
    let mut total = 0;
    let mut agree = 0;
    for p in problems() {
        let d = data(&p);
        let f = run(&p, 1, &opts);
        assert!(f.converged());
        let ci = fitbead::inverse::ConfidenceIntervals::compute(&d, &f, 0.95, &opts).unwrap();
        let wald = ci.covariance.as_ref().unwrap();
        for (k, pi) in ci.profile.iter().enumerate() {
            total += 2;
            let b = f.params[k];
            let half = b - wald[k].lower;
            let rel = |e: fitbead::inverse::ProfileEnd| match e {
                fitbead::inverse::ProfileEnd::Found(v) => format!("{:.4}", (v - b).abs() / half),
                other => format!("{other:?}"),
            };
            println!(
                "{:<9} {:>3} {:>14.6e} {:>10} {:>10} {:>7}",
                p.name,
                k + 1,
                b,
                rel(pi.lower),
                rel(pi.upper),
                pi.fits
            );
            for e in [pi.lower, pi.upper] {
                if let Some(v) = e.value() {
                    found += 1;
                    // Re-check the end independently: Δχ² there equals the threshold.
                    let mut lower = vec![f64::NEG_INFINITY; f.params.len()];
                    let mut upper = vec![f64::INFINITY; f.params.len()];
                    lower[k] = v;
                    upper[k] = v;
                    let mut start = f.params.clone();
                    start[k] = v;
                    let o = LsqOptions {
                        lower: Some(lower),
                        upper: Some(upper),
                        ..opts.clone()
                    };
                    // The independent fit starts cold (the other parameters at the optimum),
                    // so it may stop in a worse local minimum than the profile's continuation;
                    // it must never find a lower one.
                    let g = fit(&d, &start, &o).unwrap();
                    let dchi2 = g.chi2 - f.chi2;
                    assert!(
                        dchi2 >= ci.threshold * (1.0 - 1e-5),
                        "{} b{}: Δχ² {dchi2:e} below the threshold {:e}",
                        p.name,
                        k + 1,
                        ci.threshold
                    );
                    if (dchi2 - ci.threshold).abs() <= 1e-5 * ci.threshold {
                        agree += 1;
                    }
                }
            }
        }
    }
    println!(
        "{found} of {total} profile ends found; {agree} confirmed by an independent cold-started fit"
    );
    // docs/ACCURACY.md: 240 of 240 found, 239 confirmed.
    assert_eq!(found, total);
    assert!(agree + 1 >= found, "{agree} of {found} confirmed");
}

/// Double-double arithmetic (about 32 significant digits) for the exact Lanczos1 references:
/// the error-free transforms two-sum and FMA two-product (Dekker 1971; Hida, Li & Bailey,
/// "Library for double-double and quad-double arithmetic", 2007), written here so that the
/// reference values do not depend on the library's own double-double type.
mod dd {
    use std::ops::{Add, Div, Mul, Neg, Sub};

    /// An unevaluated sum hi + lo with |lo| ≤ ulp(hi)/2.
    #[derive(Debug, Clone, Copy, PartialEq, Default)]
    pub struct Dd {
        pub hi: f64,
        pub lo: f64,
    }

    fn two_sum(a: f64, b: f64) -> (f64, f64) {
        let s = a + b;
        let bb = s - a;
        (s, (a - (s - bb)) + (b - bb))
    }

    fn quick_two_sum(a: f64, b: f64) -> (f64, f64) {
        let s = a + b;
        (s, b - (s - a))
    }

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
        pub fn to_f64(self) -> f64 {
            self.hi + self.lo
        }

        /// Multiplication by a double.
        pub fn mul_f64(self, b: f64) -> Dd {
            let (p, e) = two_prod(self.hi, b);
            let (hi, lo) = quick_two_sum(p, e + self.lo * b);
            Dd { hi, lo }
        }
    }

    impl Neg for Dd {
        type Output = Dd;
        fn neg(self) -> Dd {
            Dd {
                hi: -self.hi,
                lo: -self.lo,
            }
        }
    }

    impl Add for Dd {
        type Output = Dd;
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
        fn sub(self, b: Dd) -> Dd {
            self + (-b)
        }
    }

    impl Mul for Dd {
        type Output = Dd;
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
}
