//! The least-squares term sets the LSTM recipes' bases are built from: the fixed sets
//! (tailored to the simulator's equations, generic linear) and the ladder that
//! [`select`](super::select) chooses among, described by data (T degree, second-order part).
//!
//! All are over [`FeatureSpec::THERMAL_STATE`](crate::features::FeatureSpec::THERMAL_STATE)
//! features `x = (T, dT, D300, D1000, D3000)`, `Dτ = T - lag_τ(T)`.

use crate::baseline::{monomial as term, Terms};
use crate::model::Target;

/// Features of the thermal-state specification.
const N: usize = 5;
/// Feature indices.
const T: usize = 0;
const D300: usize = 2;
const D1000: usize = 3;
const D3000: usize = 4;

fn terms(powers: Vec<Vec<u8>>) -> Terms {
    Terms {
        n_features: N,
        powers,
    }
}

/// Physical bias terms: `1, T, T², D300, T·D300, D300², D1000, D3000`. With the coil
/// temperature `Tc ≈ T - D300` and its rate `≈ D300/300 s`, this spans the FOG bias model
/// `c1·Tc + c2·Tc² + S·(1 + a·Tc)·dTc/dt + s·(Tc - T_stress)` (the stress state a slower lag,
/// spanned by D1000 and D3000). The 20 s rate dT is left to the LSTM: as a least-squares
/// term it only added noise (held-out seed sweeps, `docs/experiments/lstm-recipes.md`).
pub fn bias_terms() -> Terms {
    let mut powers = coil_quadratic();
    powers.extend([term(N, &[(D1000, 1)]), term(N, &[(D3000, 1)])]);
    terms(powers)
}

/// `1, T, T², D300, T·D300, D300²`: quadratic in the coil temperature `Tc ≈ T - D300`, the
/// part the tailored bias and scale-factor sets share.
fn coil_quadratic() -> Vec<Vec<u8>> {
    vec![
        term(N, &[]),
        term(N, &[(T, 1)]),
        term(N, &[(T, 2)]),
        term(N, &[(D300, 1)]),
        term(N, &[(T, 1), (D300, 1)]),
        term(N, &[(D300, 2)]),
    ]
}

/// Generic bias terms, linear in every input: `1, T, dT, D300, D1000, D3000` (the "linear fit
/// on thermal-state inputs" comparison), with `with_t2` also `T²`. Nothing here is chosen
/// from the simulator's bias equation.
pub fn generic_linear_terms(with_t2: bool) -> Terms {
    let mut powers = vec![term(N, &[])];
    powers.extend((0..N).map(|i| term(N, &[(i, 1)])));
    if with_t2 {
        powers.push(term(N, &[(T, 2)]));
    }
    terms(powers)
}

/// Physical scale-factor terms: K quadratic in the coil temperature `Tc ≈ T - D300`:
/// `1, T, T², D300, T·D300, D300²`, plus `D1000` and `T·D1000` so that a coil lag other than
/// 300 s is spanned too (with a 420 s coil, the `fast-cycle` held-out SF error fell from 18
/// to 7 ppm; unchanged for the default unit).
pub fn scale_terms() -> Terms {
    let mut powers = coil_quadratic();
    powers.extend([term(N, &[(D1000, 1)]), term(N, &[(T, 1), (D1000, 1)])]);
    terms(powers)
}

/// The second-order part of a ladder term set.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SecondOrder {
    /// None: the lag differences enter linearly only.
    None,
    /// The fastest lag's: `T·D300, D300²`.
    Fast,
    /// The two fastest lags': also `T·D1000, D300·D1000, D1000²`.
    FastMid,
}

impl SecondOrder {
    /// The suffix of the term set's name.
    pub fn suffix(&self) -> &'static str {
        match self {
            SecondOrder::None => "",
            SecondOrder::Fast => "+fast",
            SecondOrder::FastMid => "+fast+mid",
        }
    }
}

/// A candidate least-squares term set: its description and its terms.
#[derive(Debug, Clone, PartialEq)]
pub struct Candidate {
    /// Short name, e.g. `T3+fast`.
    pub name: String,
    /// Highest power of T.
    pub degree: u8,
    /// Second-order part.
    pub second_order: SecondOrder,
    pub terms: Terms,
}

impl Candidate {
    /// The ladder's term set for `degree` in T and a second-order part: `1, T..T^degree,
    /// D300, D1000, D3000` plus the second-order terms (ordered as the tailored set
    /// [`bias_terms`] where they overlap).
    pub fn new(degree: u8, second_order: SecondOrder) -> Candidate {
        let mut powers = vec![term(N, &[])];
        powers.extend((1..=degree).map(|q| term(N, &[(T, q)])));
        match second_order {
            SecondOrder::None => {
                powers.extend([D300, D1000, D3000].map(|i| term(N, &[(i, 1)])));
            }
            SecondOrder::Fast | SecondOrder::FastMid => {
                powers.push(term(N, &[(D300, 1)]));
                powers.push(term(N, &[(T, 1), (D300, 1)]));
                powers.push(term(N, &[(D300, 2)]));
                powers.push(term(N, &[(D1000, 1)]));
                powers.push(term(N, &[(D3000, 1)]));
                if second_order == SecondOrder::FastMid {
                    powers.push(term(N, &[(T, 1), (D1000, 1)]));
                    powers.push(term(N, &[(D300, 1), (D1000, 1)]));
                    powers.push(term(N, &[(D1000, 2)]));
                }
            }
        }
        Candidate {
            name: format!("T{degree}{}", second_order.suffix()),
            degree,
            second_order,
            terms: terms(powers),
        }
    }
}

/// The ladder's rungs, in the order tried: (T degree, second-order part).
pub(crate) const LADDER: [(u8, SecondOrder); 9] = [
    (1, SecondOrder::None),
    (2, SecondOrder::None),
    (3, SecondOrder::None),
    (1, SecondOrder::Fast),
    (2, SecondOrder::Fast),
    (3, SecondOrder::Fast),
    (1, SecondOrder::FastMid),
    (2, SecondOrder::FastMid),
    (3, SecondOrder::FastMid),
];

/// The ladder of term sets (`LADDER`): a polynomial in T of degree 1 to 3, the lag
/// differences linear, and none, the fastest lag's or the two fastest lags' second-order
/// terms; named `T<d>`, `T<d>+fast`, `T<d>+fast+mid`. 9 sets of 5 to 12 terms, all within the
/// flight crate's 16. The 20 s rate dT is not a term: the lag differences carry the rate at
/// the time scales that matter, and dT adds sensor noise (with dT and `T·dT` in, the scale
/// factor left 64 ppm held out). `T2+fast` equals the tailored [`bias_terms`].
pub fn ladder() -> Vec<Candidate> {
    LADDER
        .iter()
        .map(|&(degree, second)| Candidate::new(degree, second))
        .collect()
}

/// The candidates [`BaseTerms::Selected`] chooses among: for the bias the [`ladder`] without
/// its [`SecondOrder::FastMid`] sets (cross-validation on one run chose them and they
/// extrapolated badly: `docs/experiments/term-selection.md`), for the scale factor the whole
/// ladder.
pub fn candidates(target: Target) -> Vec<Candidate> {
    let all = ladder();
    match target {
        Target::Bias => all
            .into_iter()
            .filter(|c| c.second_order != SecondOrder::FastMid)
            .collect(),
        Target::Scale => all,
    }
}

/// The least-squares base of the residual recipes ([`RecipeSettings::base`] for the bias,
/// [`RecipeSettings::scale_base`] for the scale factor).
///
/// [`RecipeSettings::base`]: super::RecipeSettings::base
/// [`RecipeSettings::scale_base`]: super::RecipeSettings::scale_base
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BaseTerms {
    /// Chosen from the training data among [`candidates`] by blocked cross-validation in time
    /// ([`select_terms`](super::select::select_terms)).
    Selected,
    /// [`bias_terms`] (bias) or [`scale_terms`] (scale factor): terms chosen to span the
    /// simulator's FOG bias and scale-factor equations.
    Tailored,
    /// [`generic_linear_terms`]: `1, T, dT, D300, D1000, D3000` (linear in the inputs).
    Linear,
    /// [`generic_linear_terms`] plus `T²`.
    LinearT2,
    /// A constant (per-run offset) only: the LSTM models the whole bias (a direct LSTM).
    Constant,
    /// Term set `i` of [`ladder`], fixed (to measure what selection chooses among; name
    /// `family:<candidate name>`).
    Family(u8),
}

impl BaseTerms {
    /// Parse an experiment name (`heldout --base`).
    pub fn parse(name: &str) -> Result<BaseTerms, UnknownBase> {
        match name {
            "selected" => Ok(BaseTerms::Selected),
            "tailored" => Ok(BaseTerms::Tailored),
            "linear" => Ok(BaseTerms::Linear),
            "linear-t2" => Ok(BaseTerms::LinearT2),
            "constant" => Ok(BaseTerms::Constant),
            _ => name
                .strip_prefix("family:")
                .and_then(|c| ladder().iter().position(|k| k.name == c))
                .map(|i| BaseTerms::Family(i as u8))
                .ok_or_else(|| UnknownBase {
                    name: name.to_owned(),
                }),
        }
    }

    /// The experiment name ([`BaseTerms::parse`] reads it back).
    pub fn name(&self) -> String {
        match self {
            BaseTerms::Selected => "selected".into(),
            BaseTerms::Tailored => "tailored".into(),
            BaseTerms::Linear => "linear".into(),
            BaseTerms::LinearT2 => "linear-t2".into(),
            BaseTerms::Constant => "constant".into(),
            BaseTerms::Family(i) => format!(
                "family:{}",
                ladder().get(*i as usize).map_or("?", |c| c.name.as_str())
            ),
        }
    }

    /// The fixed terms for a target (`None` for [`BaseTerms::Selected`], chosen from the
    /// data, and for a family index beyond the ladder).
    pub fn fixed_terms(&self, target: Target) -> Option<Terms> {
        Some(match (self, target) {
            (BaseTerms::Selected, _) => return None,
            (BaseTerms::Tailored, Target::Bias) => bias_terms(),
            (BaseTerms::Tailored, Target::Scale) => scale_terms(),
            (BaseTerms::Linear, _) => generic_linear_terms(false),
            (BaseTerms::LinearT2, _) => generic_linear_terms(true),
            (BaseTerms::Constant, _) => terms(vec![term(N, &[])]),
            (BaseTerms::Family(i), _) => ladder().get(*i as usize)?.terms.clone(),
        })
    }
}

/// A base name [`BaseTerms::parse`] does not know.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UnknownBase {
    pub name: String,
}

impl std::fmt::Display for UnknownBase {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "unknown base {:?}: use selected, tailored, linear, linear-t2, constant or \
             family:<name> (names: {})",
            self.name,
            ladder()
                .iter()
                .map(|c| c.name.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        )
    }
}

impl std::error::Error for UnknownBase {}

#[cfg(test)]
mod tests {
    use super::*;

    /// The ladder's names follow its data, and `T2+fast` is the tailored bias set (the
    /// documented overlap).
    #[test]
    fn ladder_names_and_the_tailored_overlap() {
        let names: Vec<String> = ladder().into_iter().map(|c| c.name).collect();
        assert_eq!(
            names,
            [
                "T1",
                "T2",
                "T3",
                "T1+fast",
                "T2+fast",
                "T3+fast",
                "T1+fast+mid",
                "T2+fast+mid",
                "T3+fast+mid"
            ]
        );
        let t2f = ladder().into_iter().find(|c| c.name == "T2+fast").unwrap();
        assert_eq!(t2f.terms, bias_terms());
        assert_eq!(candidates(Target::Bias).len(), 6);
    }
}
