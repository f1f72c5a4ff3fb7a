//! A table of strings, the form in which results are printed: as HTML by [`crate::report`],
//! as text by the command line.

/// A table of strings: the comparison of methods (method, bias stability °/h, scale-factor
/// error ppm, ...). Rows shorter than the headers are padded with empty cells.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Table {
    pub headers: Vec<String>,
    pub rows: Vec<Vec<String>>,
}
