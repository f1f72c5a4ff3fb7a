//! A [`Model`] described in a few lines of text, as a binding prints it.

use super::{Form, Model, ModelError};

impl Model {
    /// What the model is, what it was trained on and, given `training_notes` (the lines a fit
    /// told), how training went; a unit's axes, the sensors each reads and its models.
    pub fn summary(&self, training_notes: &[String]) -> Result<String, ModelError> {
        let m = match &self.form {
            Form::Single(m) => m,
            Form::Unit(m) => {
                let mut s = format!(
                    "gyrotherm unit model ({} axes; gyro columns {}; temperature columns {})\n",
                    m.axes.len(),
                    m.gyro_cols.join(", "),
                    m.temp_cols.join(", ")
                );
                for a in &m.axes {
                    s += &format!(
                        "  {}: reads {} (method {}, bias: {}, scale factor: {})\n",
                        a.gyro,
                        a.temps.join(", "),
                        a.model.method.as_str(),
                        a.model.bias.as_ref().map_or("none", |b| b.kind()),
                        a.model.scale.as_ref().map_or("none", |b| b.kind())
                    );
                }
                for n in training_notes {
                    s += &format!("  {n}\n");
                }
                return Ok(s);
            }
        };
        let t = &m.training;
        let spec = m.feature_spec()?;
        let mut s = format!(
            "gyrotherm model (format {}, method {})\n",
            m.format_version,
            m.method.as_str()
        );
        s += &format!(
            "  bias model: {}\n  scale-factor model: {}\n",
            m.bias.as_ref().map_or("none (no static log)", |b| b.kind()),
            m.scale
                .as_ref()
                .map_or("none (no rate-table log)", |b| b.kind())
        );
        s += &format!(
            "  inputs: {} features, stepped every {} s (rate lag {} s)\n",
            spec.n_features(),
            m.features.step_period_s,
            m.features.rate_lag_s
        );
        // After a fit, what training said (the lines `train` prints, the training range
        // first); from a file, what the file tells.
        if training_notes.is_empty() {
            s += &format!(
                "  training range: temperature {:.2} to {:.2} °C, rate {:.3} to {:.3} °C/min\n",
                t.temp_range_c.min,
                t.temp_range_c.max,
                t.rate_range_c_per_s.min * 60.0,
                t.rate_range_c_per_s.max * 60.0
            );
            for line in m.describe() {
                s += &format!("{line}\n");
            }
        }
        if let Some(seed) = t.seed {
            s += &format!("  seed: {seed}\n");
        }
        s += &format!(
            "  trained on: {}\n  written by: {}\n",
            t.inputs.join(", "),
            t.created_by
        );
        for n in training_notes {
            s += &format!("  {n}\n");
        }
        Ok(s)
    }
}
