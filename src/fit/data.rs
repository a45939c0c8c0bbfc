//! Measurements grouped in series, as the fits across series see them.

use crate::inverse::SigmaKind;
use crate::scene::Scene;

/// One measured point.
#[derive(Debug, Clone, PartialEq)]
pub struct Point {
    /// Index of its series in [`Dataset::labels`].
    pub series: usize,
    /// The scene (ξ, δ, ρ, f; its K is a placeholder).
    pub scene: Scene,
    /// Measured dimensionless mean velocity v̄.
    pub v: f64,
    /// Its standard deviation (1 when the data carry none: see [`Dataset::sigma`]).
    pub sigma: f64,
    /// Standard uncertainty of the slope δ, radians (column `sigma_delta_deg`, in degrees, or
    /// the default of `--sigma-delta`); 0 when the slope is taken as exact.
    pub sigma_delta: f64,
}

/// Points grouped in series (in order of first appearance).
#[derive(Debug, Clone, PartialEq)]
pub struct Dataset {
    /// Series labels.
    pub labels: Vec<String>,
    /// The points.
    pub points: Vec<Point>,
    /// [`SigmaKind::Absolute`] when every point carries σ; [`SigmaKind::Relative`] when none
    /// does (unit weights, the common scale estimated from the scatter).
    pub sigma: SigmaKind,
}

/// Why measurements cannot form a [`Dataset`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DataError {
    /// No points.
    Empty,
    /// Some points carry σ and this one (index) does not.
    MixedSigma(usize),
}

impl std::fmt::Display for DataError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            DataError::Empty => f.write_str("no data rows"),
            DataError::MixedSigma(i) => write!(
                f,
                "point {}: sigma missing while other points have it: give sigma on every \
                 point or on none",
                i + 1
            ),
        }
    }
}

impl std::error::Error for DataError {}

impl Dataset {
    /// Groups `(series label, scene, v, σ)` rows; rows without a label are grouped by ξ.
    pub fn new(
        rows: impl IntoIterator<Item = (String, Scene, f64, Option<f64>)>,
    ) -> Result<Self, DataError> {
        let rows: Vec<_> = rows.into_iter().collect();
        if rows.is_empty() {
            return Err(DataError::Empty);
        }
        let with_sigma = rows.iter().filter(|r| r.3.is_some()).count();
        if with_sigma != 0 && with_sigma != rows.len() {
            let i = rows.iter().position(|r| r.3.is_none()).unwrap_or(0);
            return Err(DataError::MixedSigma(i));
        }
        let sigma = if with_sigma == 0 {
            SigmaKind::Relative
        } else {
            SigmaKind::Absolute
        };
        let mut labels: Vec<String> = Vec::new();
        let mut points = Vec::with_capacity(rows.len());
        for (label, scene, v, s) in rows {
            let label = if label.is_empty() {
                format!("xi={}", crate::numfmt::fmt_f64(scene.xi))
            } else {
                label
            };
            let series = match labels.iter().position(|l| *l == label) {
                Some(i) => i,
                None => {
                    labels.push(label);
                    labels.len() - 1
                }
            };
            points.push(Point {
                series,
                scene,
                v,
                sigma: s.unwrap_or(1.0),
                sigma_delta: 0.0,
            });
        }
        Ok(Dataset {
            labels,
            points,
            sigma,
        })
    }

    /// True when some point's slope carries an uncertainty (σ_δ > 0): the fits then treat
    /// the slopes as measured with error (orthogonal distance regression).
    pub fn has_slope_errors(&self) -> bool {
        self.points.iter().any(|p| p.sigma_delta > 0.0)
    }

    /// The points of series `s`.
    pub fn series(&self, s: usize) -> impl Iterator<Item = &Point> {
        self.points.iter().filter(move |p| p.series == s)
    }

    /// Indices (in [`Dataset::points`]) of the points of series `s`, in order.
    pub fn series_index(&self, s: usize) -> Vec<usize> {
        (0..self.points.len())
            .filter(|&i| self.points[i].series == s)
            .collect()
    }

    /// The sub-dataset of series `s` alone (its label kept, index 0).
    pub fn only(&self, s: usize) -> Dataset {
        Dataset {
            labels: vec![self.labels[s].clone()],
            points: self
                .series(s)
                .map(|p| Point {
                    series: 0,
                    ..p.clone()
                })
                .collect(),
            sigma: self.sigma,
        }
    }

    /// The points whose index passes `keep`, series without points dropped (labels kept in
    /// order). Returns the dataset and, for each kept point, its index in `self`.
    pub fn filter(&self, keep: impl Fn(usize) -> bool) -> (Dataset, Vec<usize>) {
        let mut labels: Vec<String> = Vec::new();
        let mut points = Vec::new();
        let mut index = Vec::new();
        for (i, p) in self.points.iter().enumerate() {
            if !keep(i) {
                continue;
            }
            let label = &self.labels[p.series];
            let series = match labels.iter().position(|l| l == label) {
                Some(j) => j,
                None => {
                    labels.push(label.clone());
                    labels.len() - 1
                }
            };
            points.push(Point {
                series,
                ..p.clone()
            });
            index.push(i);
        }
        (
            Dataset {
                labels,
                points,
                sigma: self.sigma,
            },
            index,
        )
    }
}

/// How one series' velocities were made dimensionless (input in m/s): the ranges over its rows
/// of the row beads' radius, of g and of the velocity unit sqrt(g R (1 + ξ)).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct SiSeries {
    /// Series label.
    pub series: String,
    /// Radius ratio ξ.
    pub xi: f64,
    /// Smallest and largest R over the series' rows, metres.
    pub r_m: (f64, f64),
    /// Smallest and largest g, m/s².
    pub g: (f64, f64),
    /// Smallest and largest velocity unit sqrt(g R (1 + ξ)), m/s.
    pub unit_m_s: (f64, f64),
}

impl SiSeries {
    /// The series' velocity unit in m/s when it is the same on every row.
    pub fn unit(&self) -> Option<f64> {
        (self.unit_m_s.0 == self.unit_m_s.1).then_some(self.unit_m_s.0)
    }
}
