//! An error and its causes as one line of text: what a front end prints.

/// An error and its causes on one line, `: `-separated, outermost first: what a front end
/// prints. Every error of this library states only its own level's fact and returns its cause
/// from `source()`, so each cause appears once.
pub fn error_chain(err: &(dyn std::error::Error + 'static)) -> String {
    let mut text = err.to_string();
    let mut cause = err.source();
    while let Some(c) = cause {
        text.push_str(": ");
        text.push_str(&c.to_string());
        cause = c.source();
    }
    text
}
