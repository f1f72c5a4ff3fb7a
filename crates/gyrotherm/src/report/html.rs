//! `DIR/index.html`: one self-contained page (inline CSS, no script, no external link) that
//! opens from disk. Images are referenced by their file name relative to `DIR`; every text
//! is HTML-escaped.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::plot::FigureFiles;
use super::ReportError;
use crate::atomic_file::write_bytes_atomically;
pub use crate::string_table::Table;

/// A figure of the report: file names relative to the report folder.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ReportFigure {
    /// PNG file name, shown inline.
    pub png: String,
    /// SVG file name, linked.
    pub svg: Option<String>,
    pub caption: String,
    /// Its number on the page (None: its place among the figures). A report whose notes
    /// name figures that were not drawn numbers every figure, so that "Figure 5" means one
    /// plot whether it was drawn or not.
    pub number: Option<usize>,
}

impl ReportFigure {
    /// The figure written as `files`, referenced by file name (the files must lie in the
    /// report folder).
    pub fn from_files(files: &FigureFiles, caption: impl Into<String>) -> Self {
        let name = |p: &Path| {
            p.file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default()
        };
        ReportFigure {
            png: name(&files.png),
            svg: Some(name(&files.svg)),
            caption: caption.into(),
            number: None,
        }
    }
}

/// Everything the report page shows, in order.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct ReportContent {
    pub title: String,
    /// What to read first (e.g. every model worse than raw), shown under the title.
    pub headline: Vec<String>,
    /// The comparison table of `gyrotherm compare`.
    pub table: Option<Table>,
    /// Notes under the comparison table (why a column has no figures).
    pub table_notes: Vec<String>,
    /// Settings shared by all models, key then value (shown above [`ReportContent::models`]).
    pub metadata: Vec<(String, String)>,
    /// The models side by side: one column per model, one row per field.
    pub models: Option<Table>,
    /// Warnings (extrapolation, gaps filled, ...).
    pub warnings: Vec<String>,
    pub figures: Vec<ReportFigure>,
    /// Notes on figures that were not drawn (e.g. "no rate-table log"), shown after them.
    pub notes: Vec<String>,
}

pub(crate) const CSS: &str =
    "body{font-family:'DejaVu Sans',Helvetica,Arial,sans-serif;margin:2em auto;\
max-width:1050px;color:#222;line-height:1.4}h1{font-size:1.6em}h2{font-size:1.25em;\
border-bottom:1px solid #ccc;padding-bottom:.2em;margin-top:1.6em}table{border-collapse:collapse;\
margin:.5em 0}th,td{border:1px solid #bbb;padding:.3em .7em;text-align:right}\
th{background:#eee}td:first-child,th:first-child{text-align:left}dl{display:grid;\
grid-template-columns:max-content auto;gap:.2em 1.2em}dt{font-weight:bold}dd{margin:0;\
font-family:monospace}ul.warnings li{color:#8a4b00}figure{margin:1.2em 0}\
figure img{max-width:100%;border:1px solid #ddd}figcaption{font-size:.95em;color:#444}\
table.models td{text-align:left;overflow-wrap:anywhere}table.models th{text-align:left}\
div.table-wrap{max-width:100%;overflow-x:auto}p.headline{font-weight:bold;color:#a00;\
border-left:4px solid #a00;background:#fff4f4;padding:.4em .8em}";

/// Write `dir/index.html` for `content` (creating `dir` if missing) and return its path.
/// Every referenced image must already exist in `dir`: a missing one is an error naming it,
/// so the page never shows a broken image. Written atomically.
pub fn write_report(dir: &Path, content: &ReportContent) -> Result<PathBuf, ReportError> {
    std::fs::create_dir_all(dir).map_err(|source| ReportError::Io {
        path: dir.to_path_buf(),
        source,
    })?;
    for f in &content.figures {
        for name in std::iter::once(&f.png).chain(f.svg.iter()) {
            let is_plain_name = !name.is_empty()
                && Path::new(name).file_name().map(|n| n.to_string_lossy()) == Some(name.into());
            if !is_plain_name {
                return Err(ReportError::Data {
                    what: format!(
                        "report figure file \"{name}\" must be a plain file name inside {}",
                        dir.display()
                    ),
                });
            }
            if !dir.join(name).is_file() {
                return Err(ReportError::Data {
                    what: format!(
                        "report figure {} does not exist; write the figures before the report",
                        dir.join(name).display()
                    ),
                });
            }
        }
    }
    let path = dir.join("index.html");
    write_bytes_atomically(&path, render_html(content).as_bytes()).map_err(|source| {
        ReportError::Io {
            path: path.clone(),
            source,
        }
    })?;
    Ok(path)
}

/// The page as a string (see [`write_report`]).
pub(crate) fn render_html(c: &ReportContent) -> String {
    let mut h = String::with_capacity(4096);
    let title = escape(&c.title);
    // `write!` into a String cannot fail.
    let _ = write!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <title>{title}</title>\n<style>{CSS}</style>\n</head>\n<body>\n<h1>{title}</h1>\n"
    );
    for line in &c.headline {
        let _ = writeln!(h, "<p class=\"headline\">{}</p>", escape(line));
    }
    if let Some(t) = &c.table {
        h.push_str("<h2>Comparison</h2>\n");
        push_table(&mut h, t, "comparison");
    }
    if !c.table_notes.is_empty() {
        h.push_str("<ul class=\"table-notes\">\n");
        for n in &c.table_notes {
            let _ = writeln!(h, "<li>{}</li>", escape(n));
        }
        h.push_str("</ul>\n");
    }
    if !c.metadata.is_empty() || c.models.is_some() {
        h.push_str("<h2>Model</h2>\n");
    }
    if !c.metadata.is_empty() {
        h.push_str("<dl>\n");
        for (k, v) in &c.metadata {
            let _ = writeln!(h, "<dt>{}</dt><dd>{}</dd>", escape(k), escape(v));
        }
        h.push_str("</dl>\n");
    }
    if let Some(t) = &c.models {
        push_table(&mut h, t, "models");
    }
    h.push_str("<h2>Warnings</h2>\n");
    if c.warnings.is_empty() {
        h.push_str("<p>None.</p>\n");
    } else {
        h.push_str("<ul class=\"warnings\">\n");
        for w in &c.warnings {
            let _ = writeln!(h, "<li>{}</li>", escape(w));
        }
        h.push_str("</ul>\n");
    }
    if !c.figures.is_empty() {
        h.push_str("<h2>Figures</h2>\n");
    }
    for (i, f) in c.figures.iter().enumerate() {
        let caption = escape(&f.caption);
        let _ = write!(
            h,
            "<figure>\n<img src=\"{}\" alt=\"{caption}\">\n<figcaption>Figure {}. {caption}",
            escape(&f.png),
            f.number.unwrap_or(i + 1)
        );
        if let Some(svg) = &f.svg {
            let _ = write!(h, " (<a href=\"{}\">SVG</a>)", escape(svg));
        }
        h.push_str("</figcaption>\n</figure>\n");
    }
    if !c.notes.is_empty() {
        h.push_str("<h2>Figures not drawn</h2>\n<ul class=\"notes\">\n");
        for n in &c.notes {
            let _ = writeln!(h, "<li>{}</li>", escape(n));
        }
        h.push_str("</ul>\n");
    }
    h.push_str("</body>\n</html>\n");
    h
}

/// `t` as an HTML table of class `class`; rows shorter than the headers are padded.
pub(crate) fn push_table(h: &mut String, t: &Table, class: &str) {
    // A table wider than the page scrolls inside its own box rather than overflowing the
    // page (many model columns, long figure names).
    let _ = write!(
        h,
        "<div class=\"table-wrap\">\n<table class=\"{class}\">\n<thead><tr>"
    );
    for head in &t.headers {
        let _ = write!(h, "<th>{}</th>", escape(head));
    }
    h.push_str("</tr></thead>\n<tbody>\n");
    for row in &t.rows {
        h.push_str("<tr>");
        let width = t.headers.len().max(row.len());
        for i in 0..width {
            let cell = row.get(i).map(String::as_str).unwrap_or("");
            let _ = write!(h, "<td>{}</td>", escape(cell));
        }
        h.push_str("</tr>\n");
    }
    h.push_str("</tbody>\n</table>\n</div>\n");
}

/// Escape `& < > " '` for text and attribute values.
pub fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for ch in s.chars() {
        match ch {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            _ => out.push(ch),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escapes_markup() {
        assert_eq!(
            escape(r#"<b>"a" & 'b'</b>"#),
            "&lt;b&gt;&quot;a&quot; &amp; &#39;b&#39;&lt;/b&gt;"
        );
    }
}
