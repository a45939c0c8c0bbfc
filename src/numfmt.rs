//! Numbers as text: the shortest decimal that reads back as the same double, and rounding to
//! significant digits. A leaf module every layer may use.

/// `x` rounded to `digits` significant digits, written as the shortest decimal of that
/// value (for messages and terminal tables; `inf`/`NaN` spelled out).
pub fn fmt_sig(x: f64, digits: usize) -> String {
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

/// [`fmt_f64`] appended to `out`, without allocating.
pub fn push_f64(out: &mut Vec<u8>, x: f64) {
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
pub const ECHO_CHARS: usize = 80;

/// `s` cut to at most `max` characters for a message: a longer text keeps its first
/// `max` − 1 characters followed by `…` and its full length in bytes, so that a huge cell or
/// argument is never echoed whole.
pub fn clip(s: &str, max: usize) -> std::borrow::Cow<'_, str> {
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
