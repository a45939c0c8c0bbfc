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

/// Shortest decimal that reads back as the same double (ryu); empty for inf and NaN.
pub fn fmt_f64(x: f64) -> String {
    let mut b = ryu::Buffer::new();
    f64_str(&mut b, x).to_string()
}

/// `x` as a message echoes it: the shortest decimal that reads back as the same double
/// (`1e300`, never its 301 digits), `NaN`, `inf` or `-inf`.
pub(crate) fn echo_f64(x: f64) -> String {
    if x.is_finite() {
        fmt_f64(x)
    } else {
        x.to_string()
    }
}

/// [`fmt_f64`] appended to `out`, without allocating.
pub(crate) fn push_f64(out: &mut Vec<u8>, x: f64) {
    let mut b = ryu::Buffer::new();
    out.extend_from_slice(f64_str(&mut b, x).as_bytes());
}

fn f64_str(b: &mut ryu::Buffer, x: f64) -> &str {
    if x.is_finite() {
        let s = b.format_finite(x);
        s.strip_suffix(".0").unwrap_or(s)
    } else {
        ""
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
