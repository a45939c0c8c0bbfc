//! Numbers as text: the shortest decimal that reads back as the same double, and rounding to
//! significant digits. A leaf module every layer may use.

/// `x` rounded to `digits` significant digits, written as the shortest decimal of that
/// value (for messages and terminal tables; `inf`/`NaN` spelled out).
pub(crate) fn fmt_sig(x: f64, digits: usize) -> String {
    if x.is_finite() {
        let s = format!("{:.*e}", digits.max(1) - 1, x);
        s.parse::<f64>().map(fmt_f64).unwrap_or(s)
    } else {
        x.to_string()
    }
}

/// Shortest decimal that reads back as the same double; empty for inf and NaN.
///
/// The digits are ryu's and its layout: `0.1`, `12`, `1e-7`, `1.5e300`, `-0` (written by
/// zmij, which gives the same digits faster; the tests compare the two on random doubles).
pub fn fmt_f64(x: f64) -> String {
    let mut out = Vec::with_capacity(24);
    push_f64(&mut out, x);
    String::from_utf8(out).unwrap_or_default()
}

/// `x` as a message echoes it: the shortest decimal that reads back as the same double
/// (`1e300`, never its 301 digits), `NaN`, `inf` or `-inf`.
pub fn echo_f64(x: f64) -> String {
    if x.is_finite() {
        fmt_f64(x)
    } else {
        x.to_string()
    }
}

/// [`fmt_f64`] appended to `out`, without allocating.
pub(crate) fn push_f64(out: &mut Vec<u8>, x: f64) {
    if !x.is_finite() {
        return;
    }
    let mut b = zmij::Buffer::new();
    let s = b.format_finite(x).as_bytes();
    let n = s.len();
    // zmij writes a positive exponent with its sign (`1e+300`), ryu without (`1e300`): the
    // sign, when there is one, is 2 to 4 bytes from the end (`e+5` to `e+308`), and a text
    // with one is at least 4 bytes long. A whole number ends in `.0`, which ryu's layout
    // drops.
    let plus = if n >= 4 {
        [2, 3, 4].into_iter().find(|&k| s[n - k] == b'+')
    } else {
        None
    };
    match plus {
        Some(k) => {
            out.extend_from_slice(&s[..n - k]);
            out.extend_from_slice(&s[n - k + 1..]);
        }
        None if n >= 2 && s[n - 2..] == *b".0" => out.extend_from_slice(&s[..n - 2]),
        None => out.extend_from_slice(s),
    }
}

/// Longest echo of a user's value in a message, in characters ([`clip`]).
pub(crate) const ECHO_CHARS: usize = 80;

/// `s` cut to at most `max` characters for a message: a longer text keeps its first
/// `max` − 1 characters followed by `…` and its full length in bytes, so that a huge cell or
/// argument is never echoed whole.
pub(crate) fn clip(s: &str, max: usize) -> std::borrow::Cow<'_, str> {
    match s.char_indices().nth(max) {
        None => std::borrow::Cow::Borrowed(s),
        Some(_) => {
            let end = s
                .char_indices()
                .nth(max.saturating_sub(1))
                .map_or(s.len(), |(i, _)| i);
            std::borrow::Cow::Owned(format!("{}… ({} bytes)", &s[..end], s.len()))
        }
    }
}

/// `s` as a message echoes a user's value: cut by [`clip`], and every control character
/// (a NUL byte, a tab, an escape) written as its escape (`\0`, `\t`, `\u{1b}`), so that it
/// neither vanishes nor acts on the terminal.
pub(crate) fn echo(s: &str, max: usize) -> std::borrow::Cow<'_, str> {
    let c = clip(s, max);
    if c.chars().any(char::is_control) {
        let mut o = String::with_capacity(c.len() + 8);
        for ch in c.chars() {
            if ch.is_control() {
                o.extend(ch.escape_debug());
            } else {
                o.push(ch);
            }
        }
        std::borrow::Cow::Owned(o)
    } else {
        c
    }
}

/// Decimal places that show `stderr` to two significant digits (`None` when it is not a
/// positive finite number or would need more than 15 places).
fn pm_places(stderr: f64) -> Option<usize> {
    if !(stderr.is_finite() && stderr > 0.0) {
        return None;
    }
    let d = 1 - stderr.log10().floor() as i64;
    (d <= 15).then_some(d.max(0) as usize)
}

/// `value ± stderr` as a reader quotes it: the standard error to two significant digits and
/// the value to the same decimal place (0.493057 ± 0.00396831 → `0.4931 ± 0.0040`); the value
/// to four significant digits when there is no standard error.
pub(crate) fn fmt_value_pm(value: f64, stderr: Option<f64>) -> String {
    match stderr.and_then(|se| pm_places(se).map(|d| (se, d))) {
        Some((se, d)) if value.is_finite() => format!("{value:.d$} ± {se:.d$}"),
        _ => fmt_sig(value, 4),
    }
}

/// An interval's ends at the precision [`fmt_value_pm`] gives the value (one more place), or
/// to four significant digits when there is no standard error.
pub(crate) fn fmt_interval(lo: f64, hi: f64, stderr: Option<f64>) -> String {
    match stderr.and_then(pm_places) {
        Some(d) if lo.is_finite() && hi.is_finite() => {
            let d = d + 1;
            format!("[{lo:.d$}, {hi:.d$}]")
        }
        _ => format!("[{}, {}]", fmt_sig(lo, 4), fmt_sig(hi, 4)),
    }
}

#[cfg(test)]
mod shortest_tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// ryu's shortest decimal with the layout `fmt_f64` promises: the independent writer
    /// the fast one must match byte for byte.
    fn ryu_text(x: f64) -> String {
        if !x.is_finite() {
            return String::new();
        }
        let mut b = ryu::Buffer::new();
        let s = b.format_finite(x);
        s.strip_suffix(".0").unwrap_or(s).to_string()
    }

    #[test]
    fn shortest_decimal_is_ryus_byte_for_byte() {
        let mut fixed = vec![
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.1,
            1e-7,
            1e-5,
            1e15,
            1e16,
            1e17,
            1.5e300,
            -2.5e-300,
            f64::MIN_POSITIVE,
            5e-324,
            -5e-324,
            f64::MAX,
            f64::MIN,
            f64::EPSILON,
            123456.0,
            0.30000000000000004,
            9007199254740993.0,
            1e21,
            1e22,
            1e23,
        ];
        fixed.extend([f64::INFINITY, f64::NEG_INFINITY, f64::NAN]);
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let random = (0..400_000).map(|i| match i % 4 {
            0 => f64::from_bits(rng.random()),
            1 => rng.random::<f64>(),
            2 => rng.random::<f64>() * 10f64.powi(rng.random_range(-40..40)),
            _ => f64::from(rng.random_range(0..100_000)) * 10f64.powi(rng.random_range(-15..25)),
        });
        for x in fixed.into_iter().chain(random) {
            assert_eq!(fmt_f64(x), ryu_text(x), "{x:e} ({:#x})", x.to_bits());
        }
    }
}

#[cfg(test)]
mod pm_tests {
    use super::*;

    #[test]
    fn value_and_error_are_rounded_to_the_errors_second_digit() {
        assert_eq!(fmt_value_pm(0.493057, Some(0.00396831)), "0.4931 ± 0.0040");
        assert_eq!(fmt_value_pm(0.6559352, Some(4.475993)), "0.7 ± 4.5");
        assert_eq!(fmt_value_pm(123456.0, Some(1234.0)), "123456 ± 1234");
        assert_eq!(fmt_value_pm(0.1486807989583846, None), "0.1487");
        assert_eq!(fmt_value_pm(0.5, Some(f64::NAN)), "0.5");
        assert_eq!(
            fmt_interval(0.4852888, 0.5008624, Some(0.00396831)),
            "[0.48529, 0.50086]"
        );
        assert_eq!(fmt_interval(0.0, 12.360202, None), "[0, 12.36]");
    }
}
