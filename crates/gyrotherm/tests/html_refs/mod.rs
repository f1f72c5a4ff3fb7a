//! Reading a report page the way a browser would find its files: every `src="…"` and
//! `href="…"` value, parsed from the HTML text (independent of how the page was built).

/// Every `src="…"` and `href="…"` value in `html`.
pub fn references(html: &str) -> Vec<String> {
    let mut out = Vec::new();
    for attr in ["src=\"", "href=\""] {
        let mut rest = html;
        while let Some(i) = rest.find(attr) {
            rest = &rest[i + attr.len()..];
            let end = rest.find('"').expect("unterminated attribute");
            out.push(rest[..end].to_owned());
            rest = &rest[end..];
        }
    }
    out
}
