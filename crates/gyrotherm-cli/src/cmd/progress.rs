//! Progress bars with the loss for LSTM training (one bar per network; stderr; hidden when
//! stderr is not a terminal).

use gyrotherm::fit::Target;
use indicatif::{MultiProgress, ProgressBar, ProgressStyle};

/// One bar per (label, network).
pub struct TrainingBars {
    bars: Vec<(String, Target, ProgressBar)>,
}

impl TrainingBars {
    /// Bars for each label (e.g. a method name) × {bias, scale}; none when `active` is false.
    pub fn new(active: bool, epochs: usize, labels: &[&str]) -> Self {
        let mut bars = Vec::new();
        if active {
            let multi = MultiProgress::new();
            let style =
                ProgressStyle::with_template("{prefix:>14} [{bar:30}] {pos}/{len} epochs  {msg}")
                    .unwrap_or_else(|_| ProgressStyle::default_bar())
                    .progress_chars("=> ");
            for l in labels {
                for t in [Target::Bias, Target::Scale] {
                    let b = multi.add(ProgressBar::new(epochs as u64));
                    b.set_style(style.clone());
                    b.set_prefix(format!(
                        "{l}{}{}",
                        if l.is_empty() { "" } else { " " },
                        t.as_str()
                    ));
                    bars.push((l.to_string(), t, b));
                }
            }
        }
        TrainingBars { bars }
    }

    /// Report epoch `epoch` (0-based) with its loss.
    pub fn update(&self, label: &str, target: Target, epoch: usize, loss: f64) {
        if let Some((_, _, b)) = self
            .bars
            .iter()
            .find(|(l, t, _)| l == label && *t == target)
        {
            b.set_position(epoch as u64 + 1);
            b.set_message(format!("loss {loss:.4e}"));
        }
    }

    /// Print a line on stderr above the bars (they would otherwise overwrite it).
    pub fn println(&self, line: &str) {
        match self.bars.first() {
            Some((_, _, b)) => b.suspend(|| eprintln!("{line}")),
            None => eprintln!("{line}"),
        }
    }

    /// Run `f` (which prints on stderr) with the bars out of the way.
    pub fn suspend(&self, f: impl FnOnce()) {
        match self.bars.first() {
            Some((_, _, b)) => b.suspend(f),
            None => f(),
        }
    }

    /// Finish all bars.
    pub fn finish(&self) {
        for (_, _, b) in &self.bars {
            b.finish();
        }
    }
}
