//! A line a job tells the user (what it read, fitted, wrote or warns of), for a front end to
//! print as it prints its own kind of line.

/// A line for the user: what a job read, did or warns of.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Told {
    /// A plain line.
    Line(String),
    /// A note (something the user may want to know).
    Note(String),
    /// A warning.
    Warning(String),
    /// An indented line under the line before.
    Item(String),
}
