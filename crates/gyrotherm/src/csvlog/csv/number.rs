//! Number parsing of log fields: a fast exact path for plain decimals (the usual field),
//! `str::parse` for everything else; both give the same f64.

/// Parse a numeric field: ASCII spaces around it allowed, Rust float syntax (which also
/// accepts `NaN` and `inf`; the caller rejects those). Gives the same f64 as `str::parse`.
#[inline(always)]
pub(super) fn parse_f64(raw: &[u8]) -> Option<f64> {
    match parse_plain_decimal(raw) {
        Some(v) => Some(v),
        None => parse_f64_std(raw),
    }
}

/// A numeric field as every log reader parses it ([`parse_f64`]); with a separator other than
/// the comma, a decimal comma (`0,5`) is accepted too.
#[inline(always)]
pub(crate) fn parse_number(raw: &[u8], decimal_comma: bool) -> Option<f64> {
    match parse_f64(raw) {
        None if decimal_comma => parse_f64_decimal_comma(raw),
        v => v,
    }
}

/// A number written with a decimal comma (`-0,25`, `1,5e-3`): one comma and no point.
#[cold]
pub(crate) fn parse_f64_decimal_comma(raw: &[u8]) -> Option<f64> {
    let t = raw.trim_ascii();
    if t.iter().filter(|&&b| b == b',').count() != 1 || t.contains(&b'.') {
        return None;
    }
    let dotted: Vec<u8> = t
        .iter()
        .map(|&b| if b == b',' { b'.' } else { b })
        .collect();
    parse_f64(&dotted)
}

#[cold]
#[inline(never)]
fn parse_f64_std(raw: &[u8]) -> Option<f64> {
    let t = raw.trim_ascii();
    std::str::from_utf8(t).ok()?.parse().ok()
}

/// Exact powers of ten representable in f64 (10^22 is the largest, Clinger 1990).
const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// Fast path for the usual log field `[+-]digits[.digits]`: when the digits form an integer
/// `m ≤ 2^53` and there are at most 22 decimals, `m` and `10^d` are exact f64 values and one
/// IEEE division rounds `m / 10^d` correctly, so the result equals `str::parse`'s (Clinger's
/// fast path: W. D. Clinger, "How to read floating point numbers accurately", PLDI 1990).
/// Anything else (exponent, spaces, 20+ digits, NaN, inf) gives None.
#[inline(always)]
pub(super) fn parse_plain_decimal(s: &[u8]) -> Option<f64> {
    match parse_decimal_prefix(s, b'.') {
        Some((v, end)) if end == s.len() => Some(v),
        _ => None,
    }
}

/// [`parse_plain_decimal`] of the longest `[+-]digits[<point>digits]` at the start of `s`
/// (`point` is `.`, or `,` for a decimal comma): the value and the index after it (None
/// where the fast path does not apply). The caller checks that a delimiter or the end
/// follows, so a row is scanned once.
#[inline(always)]
pub(super) fn parse_decimal_prefix(s0: &[u8], point: u8) -> Option<(f64, usize)> {
    let (neg, sign, s) = match s0.first() {
        Some(b'-') => (true, 1, &s0[1..]),
        Some(b'+') => (false, 1, &s0[1..]),
        _ => (false, 0, s0),
    };
    let mut m: u64 = 0;
    let mut i = digits(s, 0, &mut m);
    let int_digits = i;
    let mut frac_digits = 0;
    if i < s.len() && s[i] == point {
        let start = i + 1;
        i = digits(s, start, &mut m);
        frac_digits = i - start;
    }
    let digits = int_digits + frac_digits;
    // 19 digits cannot overflow u64, so `m` is exact when digits <= 19.
    if digits == 0 || digits > 19 || m > (1 << 53) || frac_digits > 22 {
        return None;
    }
    let v = m as f64 / POW10[frac_digits];
    Some((if neg { -v } else { v }, sign + i))
}

/// Accumulate the decimal digits of `s` from `i` into `m` (wrapping; the caller bounds the
/// count), eight bytes at a time where eight are left; returns the index after the last
/// digit.
#[inline(always)]
fn digits(s: &[u8], mut i: usize, m: &mut u64) -> usize {
    while let Some(chunk) = s.get(i..i + 8) {
        let mut word = [0u8; 8];
        word.copy_from_slice(chunk);
        let v = u64::from_le_bytes(word);
        // High bit of each byte not in b'0'..=b'9' (SWAR test as in simdjson / fast_float).
        // Digits below a byte carry or borrow nothing into it, so the lowest flagged byte
        // is exactly the first non-digit.
        let non_digit = (v.wrapping_add(0x4646_4646_4646_4646)
            | v.wrapping_sub(0x3030_3030_3030_3030))
            & 0x8080_8080_8080_8080;
        if non_digit == 0 {
            *m = m.wrapping_mul(100_000_000).wrapping_add(eight_digits(v));
            i += 8;
            continue;
        }
        let n = (non_digit.trailing_zeros() / 8) as usize;
        if n > 0 {
            // The n digits moved to the top bytes, b'0' below them: the same value.
            let shift = 8 * (8 - n as u32);
            let v = (v << shift) | (0x3030_3030_3030_3030 >> (64 - shift));
            *m = m.wrapping_mul(POW10_U64[n]).wrapping_add(eight_digits(v));
            i += n;
        }
        return i;
    }
    while i < s.len() && s[i].is_ascii_digit() {
        *m = m.wrapping_mul(10).wrapping_add(u64::from(s[i] - b'0'));
        i += 1;
    }
    i
}

/// 10^n for n < 8.
const POW10_U64: [u64; 8] = [1, 10, 100, 1_000, 10_000, 100_000, 1_000_000, 10_000_000];

/// Value of eight ASCII digits packed little-endian in `v` (first digit in the low byte).
#[inline(always)]
fn eight_digits(v: u64) -> u64 {
    const MASK: u64 = 0x0000_00FF_0000_00FF;
    const MUL1: u64 = 0x000F_4240_0000_0064; // 100 + (1_000_000 << 32)
    const MUL2: u64 = 0x0000_2710_0000_0001; // 1 + (10_000 << 32)
    let v = v.wrapping_sub(0x3030_3030_3030_3030);
    let v = v.wrapping_mul(10).wrapping_add(v >> 8);
    (((v & MASK).wrapping_mul(MUL1)).wrapping_add(((v >> 16) & MASK).wrapping_mul(MUL2))) >> 32
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The fast path must agree bit for bit with `str::parse` (the independent reference).
    fn same_as_std(s: &str) {
        let want: Option<f64> = s.trim_ascii().parse().ok();
        let got = parse_f64(s.as_bytes());
        assert_eq!(
            got.map(f64::to_bits),
            want.map(f64::to_bits),
            "{s:?}: want {want:?} got {got:?}"
        );
    }

    #[test]
    fn decimal_parse_edge_cases() {
        for s in [
            "0",
            "-0",
            "+0",
            "1.",
            ".5",
            ".",
            "-",
            "",
            " 1.5 ",
            "12345.000",
            "0.0012345678901",
            "23.4375",
            "9007199254740993",
            "9007199254740992",
            "0.1",
            "1e5",
            "nan",
            "inf",
            "-infinity",
            "1,5",
            "00000000000000000001.5",
            "1.00000000000000000000001",
            "123456789012345678901234",
            "4.9e-324",
            "1.7976931348623157e308",
            "0x10",
            "1_0",
        ] {
            same_as_std(s);
        }
    }

    proptest! {
        #[test]
        fn decimal_parse_matches_std(s in "[+-]?[0-9]{0,20}(\\.[0-9]{0,25})?") {
            same_as_std(&s);
        }

        /// A number followed by a delimiter and more of the row: the prefix parser gives the
        /// number's value (as `str::parse` of the number alone) and where it ends.
        #[test]
        fn decimal_prefix_matches_std(
            s in "[+-]?[0-9]{0,20}(\\.[0-9]{0,25})?",
            rest in "[,;\t.a-z0-9]{0,12}",
        ) {
            let want: Option<f64> = s.parse().ok();
            let text = format!("{s}{rest}");
            match parse_decimal_prefix(text.as_bytes(), b'.') {
                Some((v, n)) if n == s.len() => prop_assert_eq!(Some(v.to_bits()), want.map(f64::to_bits)),
                // The prefix ran on into `rest` (digits or a point there): judge that prefix.
                Some((v, n)) => {
                    let longer: Option<f64> = text[..n].parse().ok();
                    prop_assert!(n > s.len());
                    prop_assert_eq!(Some(v.to_bits()), longer.map(f64::to_bits));
                }
                // The fast path declines: too many digits, or no digits at all.
                None => {}
            }
            // With a decimal comma: the same.
            let dotted = format!("{s};1");
            let comma = format!("{};1", s.replace('.', ","));
            prop_assert_eq!(
                parse_decimal_prefix(comma.as_bytes(), b','),
                parse_decimal_prefix(dotted.as_bytes(), b'.')
            );
        }

        #[test]
        fn decimal_parse_of_printed_f64_round_trips(v in any::<f64>().prop_filter("finite", |v| v.is_finite()), d in 0usize..17) {
            same_as_std(&format!("{v}"));
            same_as_std(&format!("{v:.d$}"));
        }
    }
}
