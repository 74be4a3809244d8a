//! What the labels depend on: the sensitivity of the force labels to every parameter an
//! estimates file marks as an estimate, over each one's stated range (assets/docs/physics.md,
//! "What the labels depend on").
//!
//! A study is a plan: every condition of a base plan is copied once per design point, each
//! copy's `[condition.vary]` fixing the parameters at that point, and every copy shares its
//! base condition's irregularities (`Condition::realisation_of`), so a parameter's effect is
//! not buried under a new track. The generator runs it (jobs, shards, resume), and the
//! analysis reads the labels back:
//! - **Morris screening** ([`morris`]) over all estimates: r·(k + 1) design runs per condition
//!   and the nominal one, ranked by μ*;
//! - **Sobol indices** ([`sobol`]) for chosen parameters (the screening's top ones): N·(k + 2)
//!   design runs per condition and the nominal one, first and total order with bootstrap
//!   intervals.
//!
//! The outputs are the labels' statistics ([`outputs`]); one nominal run per condition (the
//! files as they are) gives their reference values.

pub mod estimates;
pub mod morris;
pub mod outputs;
mod report;
pub mod sobol;

pub use estimates::{Estimate, Estimates};
pub use report::{top_of_screening, write};

use crate::error::{Error, Result};
use crate::plan::Plan;
use crate::vary::{Draw, Variation, Vary};
use std::path::Path;

/// How a study samples the ranges.
#[derive(Debug, Clone, PartialEq)]
pub enum Method {
    /// Morris screening over every estimate with this many trajectories.
    Morris {
        /// Trajectories (r).
        trajectories: usize,
    },
    /// Sobol indices of the chosen estimates (indices into the estimates file's list; the
    /// rest stay at the files' values) from this many base rows.
    Sobol {
        /// Base rows (N).
        rows: usize,
        /// The estimates sampled.
        parameters: Vec<usize>,
    },
}

impl Method {
    /// The study's folder name.
    pub fn folder(&self) -> &'static str {
        match self {
            Method::Morris { .. } => "morris",
            Method::Sobol { .. } => "sobol",
        }
    }
}

enum Sampled {
    Morris(morris::Design),
    Sobol(sobol::Design),
}

/// A study: the estimates, the base plan, the design and the plan that runs it.
pub struct Study {
    /// The estimates.
    pub estimates: Estimates,
    /// The plan whose conditions the study copies.
    pub base: Plan,
    /// The method.
    pub method: Method,
    /// The seed of the design.
    pub seed: u64,
    /// The plan of every run: per base condition, `<name>__nominal` and `<name>__p<j>`.
    pub plan: Plan,
    /// A trained model whose identification R² on each run (clean inputs) is an output too.
    pub model: Option<std::path::PathBuf>,
    design: Sampled,
}

/// The name of the copy of `condition` at design point `j` (None: the nominal copy).
pub fn point_name(condition: &str, j: Option<usize>) -> String {
    match j {
        Some(j) => format!("{condition}__p{j:05}"),
        None => format!("{condition}__nominal"),
    }
}

impl Study {
    /// Builds the study: checks every range's ends against the base plan's files first (a
    /// range outside an element's bounds is refused, naming the estimates file and key).
    pub fn new(base: Plan, estimates: Estimates, method: Method, seed: u64) -> Result<Self> {
        estimates.check(&base)?;
        let sampled_keys: Vec<usize> = match &method {
            Method::Morris { trajectories } => {
                if *trajectories < 2 {
                    return Err(Error::Domain(format!(
                        "Morris screening needs at least 2 trajectories (σ is a spread), got {trajectories}"
                    )));
                }
                (0..estimates.estimates.len()).collect()
            }
            Method::Sobol { rows, parameters } => {
                if *rows < 8 || parameters.is_empty() {
                    return Err(Error::Domain(format!(
                        "Sobol indices need at least 8 rows and one parameter, got {rows} rows and {} parameter(s)",
                        parameters.len()
                    )));
                }
                if let Some(p) = parameters.iter().find(|&&p| p >= estimates.estimates.len()) {
                    return Err(Error::Domain(format!(
                        "parameter {p} is not in {}",
                        estimates.path.display()
                    )));
                }
                parameters.clone()
            }
        };
        let k = sampled_keys.len();
        let design = match &method {
            Method::Morris { trajectories } => {
                Sampled::Morris(morris::Design::new(k, *trajectories, seed))
            }
            Method::Sobol { rows, .. } => Sampled::Sobol(sobol::Design::new(k, *rows, seed)),
        };
        let points = match &design {
            Sampled::Morris(d) => &d.points,
            Sampled::Sobol(d) => &d.points,
        };
        let mut plan = base.clone();
        plan.name = format!("{}_{}_{}", base.name, estimates.name, method.folder());
        plan.conditions.clear();
        for c in &base.conditions {
            let copy = |name: String, vary: Vary| {
                let mut d = c.clone();
                d.name = name;
                d.vary = c.vary.merged(&vary);
                d.realisation_of = Some(c.realisation_of.clone().unwrap_or(c.name.clone()));
                d
            };
            plan.conditions
                .push(copy(point_name(&c.name, None), Vary::default()));
            for (j, x) in points.iter().enumerate() {
                let variations = sampled_keys
                    .iter()
                    .zip(x)
                    .map(|(&e, &u)| {
                        let est = &estimates.estimates[e];
                        let v = est.at(u);
                        Variation {
                            draw: Draw::Uniform(v, v),
                            origin: format!("{}: estimate", estimates.path.display()),
                            ..est.variation.clone()
                        }
                    })
                    .collect();
                plan.conditions
                    .push(copy(point_name(&c.name, Some(j)), Vary { variations }));
            }
        }
        Ok(Study {
            estimates,
            base,
            method,
            seed,
            plan,
            model: None,
            design,
        })
    }

    /// How many outputs the study measures: the labels' statistics, and a model's R² when it
    /// names one.
    pub fn outputs(&self) -> usize {
        if self.model.is_some() {
            outputs::OUTPUTS.len()
        } else {
            outputs::MEASURED
        }
    }

    /// The estimates the design samples, in its column order.
    pub fn sampled(&self) -> Vec<&Estimate> {
        match &self.method {
            Method::Morris { .. } => self.estimates.estimates.iter().collect(),
            Method::Sobol { parameters, .. } => parameters
                .iter()
                .map(|&p| &self.estimates.estimates[p])
                .collect(),
        }
    }

    /// Reads the labels of every run in `data` (the study's generated data set) and computes
    /// the outputs, their spread over the design and the method's measures, per base
    /// condition. Every run of the study must be there.
    pub fn analyse(&self, data: &Path) -> Result<Vec<ConditionResult>> {
        let manifest = crate::dataset::Manifest::load(data)?;
        let [fl_name, fq_name] = manifest.labels();
        let mut model = match &self.model {
            Some(dir) => Some(crate::learn::model::Model::load(dir)?),
            None => None,
        };
        let mut outputs_of = |condition: &str| -> Result<[f64; 14]> {
            let runs: Vec<_> = manifest
                .runs
                .iter()
                .filter(|r| r.condition == condition)
                .collect();
            if runs.is_empty() {
                return Err(Error::Domain(format!(
                    "{}: no run of {condition}: generate the study first (or merge its shards)",
                    data.display()
                )));
            }
            let mut sum = [0.0; 14];
            for r in &runs {
                let file = data.join(&r.file);
                let cols = crate::dataset::read_table(&file)?;
                let col = |name: &str| {
                    cols.iter()
                        .find(|c| c.0 == name)
                        .map(|c| c.1.as_slice())
                        .ok_or_else(|| {
                            Error::Domain(format!("{}: no label column {name}", file.display()))
                        })
                };
                let mut s = [0.0; 14];
                s[..outputs::MEASURED].copy_from_slice(&outputs::label_statistics(
                    col(&fl_name)?,
                    col(&fq_name)?,
                    crate::sensors::RATE_HZ,
                ));
                if let Some(m) = model.as_mut() {
                    let table = crate::identify::SensorTable::read(&file)?;
                    let input = crate::identify::check(&table, m, false)?;
                    let id = crate::identify::identify(m, &input);
                    for (k, name) in [&fl_name, &fq_name].into_iter().enumerate() {
                        let t = id.targets.iter().position(|t| t == name).ok_or_else(|| {
                            Error::Domain(format!(
                                "the model identifies {:?}; a study scores both labels ({fl_name}, {fq_name})",
                                id.targets
                            ))
                        })?;
                        let truth = crate::identify::at_labels(m, col(name)?);
                        let est: Vec<f64> = id.values.iter().map(|v| v[t]).collect();
                        s[outputs::MEASURED + k] = outputs::r2(&truth, &est);
                    }
                }
                for (a, b) in sum.iter_mut().zip(s) {
                    *a += b / runs.len() as f64;
                }
            }
            Ok(sum)
        };
        let points = match &self.design {
            Sampled::Morris(d) => d.points.len(),
            Sampled::Sobol(d) => d.points.len(),
        };
        let mut results = Vec::new();
        for c in &self.base.conditions {
            let nominal = outputs_of(&point_name(&c.name, None))?;
            let ys: Vec<[f64; 14]> = (0..points)
                .map(|j| outputs_of(&point_name(&c.name, Some(j))))
                .collect::<Result<_>>()?;
            let column = |o: usize| ys.iter().map(|y| y[o]).collect::<Vec<f64>>();
            let spread = std::array::from_fn(|o| Spread::of(&column(o)));
            let n = self.outputs();
            let measures = match &self.design {
                Sampled::Morris(d) => {
                    Measures::Morris((0..n).map(|o| d.effects(&column(o))).collect::<Vec<_>>())
                }
                Sampled::Sobol(d) => Measures::Sobol(
                    (0..n)
                        .map(|o| d.indices(&column(o), 200, self.seed))
                        .collect(),
                ),
            };
            results.push(ConditionResult {
                condition: c.name.clone(),
                nominal,
                spread,
                measures,
            });
        }
        Ok(results)
    }
}

/// An output's values over the design: the labels' own uncertainty from the estimates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spread {
    /// Lowest.
    pub min: f64,
    /// Highest.
    pub max: f64,
    /// Standard deviation over the points.
    pub std: f64,
}

impl Spread {
    fn of(v: &[f64]) -> Self {
        let n = v.len().max(1) as f64;
        let mean = v.iter().sum::<f64>() / n;
        Spread {
            min: v.iter().copied().fold(f64::INFINITY, f64::min),
            max: v.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            std: (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n).sqrt(),
        }
    }
}

/// The method's measures, `[output][parameter]`.
#[derive(Debug, Clone, PartialEq)]
pub enum Measures {
    /// Elementary effects.
    Morris(Vec<Vec<morris::Effect>>),
    /// Sobol indices.
    Sobol(Vec<Vec<sobol::Indices>>),
}

/// One base condition's result.
#[derive(Debug, Clone, PartialEq)]
pub struct ConditionResult {
    /// The base condition.
    pub condition: String,
    /// The outputs of the nominal run (the files' values), kN (R² as a fraction); the last two
    /// are zero unless the study names a model.
    pub nominal: [f64; 14],
    /// Each output's spread over the design's points.
    pub spread: [Spread; 14],
    /// The method's measures.
    pub measures: Measures,
}

impl ConditionResult {
    /// The parameters ranked by their largest Morris μ* on the labels' mean and std, each over
    /// the nominal std of its label: most influential first (the 99.85 % percentiles are
    /// reported, not ranked on: a single flange contact moves them). The score (in % of the
    /// label's std) is returned beside each index. Sobol ranks by the larger total index of
    /// FL std and FQ std.
    pub fn ranking(&self) -> Vec<(usize, f64)> {
        let mut score: Vec<(usize, f64)> = match &self.measures {
            Measures::Morris(m) => (0..m[0].len())
                .map(|p| {
                    let s = [0usize, 1, 6, 7]
                        .iter()
                        .map(|&o| {
                            let label_std = self.nominal[if outputs::is_fl(o) { 1 } else { 7 }];
                            100.0 * m[o][p].mu_star / label_std.max(1e-9)
                        })
                        .fold(0.0, f64::max);
                    (p, s)
                })
                .collect(),
            Measures::Sobol(m) => (0..m[0].len())
                .map(|p| (p, 100.0 * m[7][p].total.max(m[1][p].total)))
                .collect(),
        };
        score.sort_by(|a, b| b.1.total_cmp(&a.1));
        score
    }
}
