//! True against identified: each assessed statistic of the identified forces beside the same
//! statistic of the true ones, their ratio and whether the verdicts agree.

use super::Assessment;
use serde::Serialize;

/// One assessed statistic of the identified forces against the same statistic of the true
/// ones: what identification is for, judged by the numbers that decide acceptance.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StatCheck {
    /// Section of track.
    pub section: String,
    /// Quantity.
    pub quantity: String,
    /// Wheel or wheelset.
    pub place: String,
    /// Unit.
    pub unit: String,
    /// Limit.
    pub limit: f64,
    /// The statistic of the true forces.
    pub true_value: f64,
    /// The statistic of the identified forces.
    pub identified_value: f64,
    /// Identified ÷ true (`None` where the true value is zero).
    pub ratio: Option<f64>,
    /// Both within the limit, or both beyond it.
    pub verdicts_agree: bool,
}

/// Pairs the rows of two assessments of the same run (true and identified forces).
pub fn compare(truth: &Assessment, identified: &Assessment) -> Vec<StatCheck> {
    truth
        .rows
        .iter()
        .filter_map(|t| {
            let i = identified.rows.iter().find(|i| {
                i.section == t.section && i.quantity == t.quantity && i.place == t.place
            })?;
            Some(StatCheck {
                section: t.section.clone(),
                quantity: t.quantity.clone(),
                place: t.place.clone(),
                unit: t.unit.clone(),
                limit: t.limit,
                true_value: t.value,
                identified_value: i.value,
                ratio: (t.value.abs() > 1e-9).then(|| i.value / t.value),
                verdicts_agree: t.pass == i.pass,
            })
        })
        .collect()
}
