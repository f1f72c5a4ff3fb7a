//! How a number is written as text: in a CSV field (shortest round-trip form, exponent form
//! outside 1e-5..1e16) and in a message.

use std::io::Write as _;

/// Shortest round-trip decimal text of `v` (see the module doc).
#[inline]
pub(crate) fn format_f64(buf: &mut Vec<u8>, v: f64) {
    let a = v.abs();
    // Writing into a Vec cannot fail.
    let _ = if a != 0.0 && !(1e-5..1e16).contains(&a) {
        write!(buf, "{v:e}")
    } else {
        write!(buf, "{v}")
    };
}

/// `v` as [`format_f64`] writes it, as text for a message: 1e300, not 301 digits.
pub(crate) fn short_f64(v: f64) -> String {
    let mut buf = Vec::new();
    format_f64(&mut buf, v);
    String::from_utf8_lossy(&buf).into_owned()
}
