//! What `auto` records in a model file: how the candidates were scored, each one's score and
//! the choice.

use serde::{Deserialize, Serialize};

use super::Method;

/// How the candidates were scored.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Validation {
    /// Each static training run left out in turn: the candidates are fitted on the others
    /// and scored on it (two or more static runs).
    #[serde(rename = "leave-one-run-out")]
    LeaveOneRunOut,
    /// Held-out blocks of the training runs (one static run): every few blocks are kept out
    /// of the LSTM's training.
    #[serde(rename = "held-out-blocks")]
    HeldOutBlocks,
    /// Not scored: an inertial unit's axis whose `thermal` fit reads several temperature
    /// sensors kept it, in files of the build whose `thermal-lstm` candidate read one sensor
    /// (read, no longer written: the candidate now rides on the several-sensor fit and is
    /// scored; docs/experiments/imu-auto.md).
    #[serde(rename = "several-sensors")]
    SeveralSensors,
}

impl Validation {
    /// How it reads in a sentence.
    pub fn text(&self) -> &'static str {
        match self {
            Validation::LeaveOneRunOut => "each static run left out in turn",
            Validation::HeldOutBlocks => "held-out blocks of the static run",
            Validation::SeveralSensors => {
                "no scoring: thermal reads several temperature sensors on this axis, the LSTM \
                 candidate one"
            }
        }
    }
}

/// One candidate's held-out score.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CandidateScore {
    /// The candidate method.
    pub method: Method,
    /// RMS of the held-out bias residual, °/s (each held-out run's mean removed: a constant
    /// bias is the turn-on offset, which no model of temperature predicts).
    pub bias_rms_dps: f64,
}

/// `auto`'s choice.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MethodChoice {
    /// How the candidates were scored.
    pub validation: Validation,
    /// Every candidate's score, in the order they were fitted.
    pub candidates: Vec<CandidateScore>,
    /// The candidate kept: the lowest score (the first on a tie), unless `lstm_left_out`.
    pub chosen: Method,
    /// `thermal-lstm` scored lower, but its fit on every training run kept no LSTM (its own
    /// gate on held-out blocks left the LSTM out), so `thermal` was kept: that fit would have
    /// been `thermal`'s model form without what the `thermal` candidate holds (an inertial
    /// unit's further sensors). Absent (false) in files that do not need it.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub lstm_left_out: bool,
}

impl MethodChoice {
    /// One line: the validation, each candidate's score in °/h (the chosen one starred); for a
    /// choice made without scores, what was kept and why.
    pub fn describe(&self) -> String {
        if self.candidates.is_empty() {
            return format!("{} kept, {}", self.chosen, self.validation.text());
        }
        let each: Vec<String> = self
            .candidates
            .iter()
            .map(|c| {
                let star = if c.method == self.chosen { "*" } else { "" };
                format!("{}{star} {:.4}", c.method, c.bias_rms_dps * 3600.0)
            })
            .collect();
        let left_out = match (self.folds_left_out_the_lstm(), self.lstm_left_out) {
            (true, true) => {
                "; every fold left the LSTM out (equal scores), and so did thermal-lstm's fit on \
                 every run: thermal stays"
            }
            (true, false) => {
                "; every fold left the LSTM out (equal scores): thermal-lstm's fit on every run \
                 kept it by its own gate"
            }
            (false, true) => {
                "; thermal-lstm scored lower, but its fit on every run kept no LSTM, so thermal \
                 stays"
            }
            (false, false) => "",
        };
        format!(
            "method chosen on {} (held-out bias residual RMS, °/h; * chosen): {}{left_out}",
            self.validation.text(),
            each.join(", ")
        )
    }

    /// Whether the candidates were scored on left-out runs and scored alike: every fold's
    /// LSTM was left out by its gate, so the folds say nothing of it.
    pub fn folds_left_out_the_lstm(&self) -> bool {
        self.validation == Validation::LeaveOneRunOut
            && matches!(&self.candidates[..], [a, b] if a.bias_rms_dps == b.bias_rms_dps)
    }

    /// The choice with `thermal` kept because the chosen `thermal-lstm` fit kept no LSTM.
    pub(crate) fn with_lstm_left_out(self) -> MethodChoice {
        MethodChoice {
            chosen: Method::Thermal,
            lstm_left_out: true,
            ..self
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn choice(validation: Validation, scores: [f64; 2], chosen: Method) -> MethodChoice {
        MethodChoice {
            validation,
            candidates: [Method::Thermal, Method::ThermalLstm]
                .into_iter()
                .zip(scores)
                .map(|(method, bias_rms_dps)| CandidateScore {
                    method,
                    bias_rms_dps,
                })
                .collect(),
            chosen,
            lstm_left_out: false,
        }
    }

    #[test]
    fn equal_left_out_scores_say_nothing_of_the_lstm_and_the_line_says_what_decided() {
        let tie = choice(
            Validation::LeaveOneRunOut,
            [2e-6, 2e-6],
            Method::ThermalLstm,
        );
        assert!(tie.folds_left_out_the_lstm());
        assert!(
            tie.describe().contains("kept it by its own gate"),
            "{}",
            tie.describe()
        );
        let gated = tie.with_lstm_left_out();
        assert_eq!(gated.chosen, Method::Thermal);
        assert!(
            gated.describe().contains("and so did"),
            "{}",
            gated.describe()
        );
        // Held-out blocks tie only where the LSTM's own gate left it out: nothing to defer to.
        let blocks = choice(Validation::HeldOutBlocks, [2e-6, 2e-6], Method::Thermal);
        assert!(!blocks.folds_left_out_the_lstm());
        let scored = choice(
            Validation::LeaveOneRunOut,
            [2e-6, 1e-6],
            Method::ThermalLstm,
        );
        assert!(!scored.folds_left_out_the_lstm());
        let line = scored.describe();
        assert!(
            !line.contains("equal scores") && !line.contains("no LSTM"),
            "{line}"
        );
    }
}
