//! The metric table ([`METRICS`]): every measure with its column name, unit, formula, which way is
//! better, its regression tolerance, how it is printed, and the function that computes it. The
//! CSV/JSON writers, the printed table, `index.html`, the plots and the regression gate of the
//! harness all read it; a new measure is one [`Metric`] variant, one [`MetricSpec`] row and its
//! function.

use std::fmt;

use crate::distance::{handle_residual, max_distance, rms_distance};
use crate::distortion::{area_change, area_distortion, length_distortion, volume_change};
use crate::evaluation::Evaluation;
use crate::size::{isometric_distortion, resized_shares};
use crate::turn::{turn_beyond_handles, turn_to_reference, turned_share};

/// Every measure of a result. The order is the column order of the reports.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Metric {
    EIso,
    ETheta,
    EPhi,
    EArea,
    ELength,
    AreaChange,
    VolumeChange,
    Folds,
    TurnBeyondHandles,
    TurnedShare,
    ShrunkShare,
    SwollenShare,
    HandleResidual,
    RmsToArap,
    MaxToArap,
    TurnToArap,
    ArapEnergy,
}

/// Which way a measure is better, for the gate and the plots.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Better {
    /// Smaller values are better (the measure is non-negative).
    Lower,
    /// Values nearer 0 are better (a signed change).
    NearZero,
}

/// How much worse than the baseline a gated measure may get: it regresses when its badness
/// (the value, or its magnitude for [`Better::NearZero`]) exceeds the baseline's by more than both
/// `relative x |baseline|` and `absolute`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerance {
    pub relative: f64,
    /// In the measure's unit.
    pub absolute: f64,
}

/// How a metric's value is printed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// `digits` decimals.
    Fixed(usize),
    /// Scientific with `digits` decimals of the mantissa.
    Scientific(usize),
    /// As a percentage with `digits` decimals.
    Percent(usize),
    /// With its sign, `digits` decimals.
    Signed(usize),
}

impl Format {
    /// `value` in this format; `–` for none or non-finite.
    pub fn apply(self, value: Option<f64>) -> String {
        match value.filter(|v| v.is_finite()) {
            None => "–".to_string(),
            Some(v) => match self {
                Format::Fixed(d) => format!("{v:.d$}"),
                Format::Scientific(d) => format!("{v:.d$e}"),
                Format::Percent(d) => format!("{:.d$}%", 100.0 * v),
                Format::Signed(d) => format!("{v:+.d$}"),
            },
        }
    }
}

/// One row of the metric table.
pub struct MetricSpec {
    pub metric: Metric,
    /// Column name in results.csv/json and the baseline (with its unit, e.g. `_deg`).
    pub key: &'static str,
    /// Short name for tables and plots.
    pub label: &'static str,
    /// Unit for people (empty: dimensionless).
    pub unit: &'static str,
    /// What it measures, with its formula (shown on index.html; docs/design.md has the same table).
    pub doc: &'static str,
    pub better: Better,
    /// `None`: reported, not gated.
    pub gate: Option<Tolerance>,
    /// Shown in the per-test errors plot.
    pub plotted: bool,
    /// How a value is printed in tables.
    pub format: Format,
    /// The value for a result; `None` where it does not apply (e.g. the volume of an open mesh).
    pub compute: fn(&Evaluation) -> Option<f64>,
}

/// The metric table, in [`Metric`] order.
pub const METRICS: [MetricSpec; 17] = [
    MetricSpec {
        metric: Metric::EIso,
        key: "e_iso",
        label: "e_iso",
        unit: "",
        doc: "isometric distortion: RMS over faces (weighted by rest area) of the logs of the two singular \
              values of each face's deformation gradient, sqrt(Σ A⁰ (ln² σ₁ + ln² σ₂) / 2 / Σ A⁰); 0 for a \
              rigid motion, |ln s| for a uniform scaling by s: it sees size and angle together, and the \
              page ranks by it",
        better: Better::Lower,
        gate: Some(Tolerance { relative: 0.02, absolute: 0.001 }),
        plotted: true,
        format: Format::Fixed(4),
        compute: |e| Some(isometric_distortion(e)),
    },
    MetricSpec {
        metric: Metric::ETheta,
        key: "e_theta_deg",
        label: "E_θ",
        unit: "°",
        doc: "RMS over all triangle corners of the change of the corner angle, sqrt(mean (θ − θ⁰)²)",
        better: Better::Lower,
        gate: Some(Tolerance { relative: 0.02, absolute: 0.01 }),
        plotted: true,
        format: Format::Fixed(3),
        compute: |e| Some(e.angles.errors(e.rest).0),
    },
    MetricSpec {
        metric: Metric::EPhi,
        key: "e_phi_deg",
        label: "E_φ",
        unit: "°",
        doc: "RMS over interior edges of the change of the dihedral angle (between the two face normals)",
        better: Better::Lower,
        gate: Some(Tolerance { relative: 0.02, absolute: 0.01 }),
        plotted: true,
        format: Format::Fixed(3),
        compute: |e| Some(e.angles.errors(e.rest).1),
    },
    MetricSpec {
        metric: Metric::EArea,
        key: "e_area",
        label: "e_area",
        unit: "",
        doc: "area distortion: RMS over faces of ln(A_f / A_f⁰); |2 ln s| for a uniform scaling by s",
        better: Better::Lower,
        // 0.001 is a 0.1% area change: below what a figure shows, above round-off.
        gate: Some(Tolerance { relative: 0.02, absolute: 0.001 }),
        plotted: true,
        format: Format::Fixed(4),
        compute: |e| Some(area_distortion(e.rest, e.mesh, e.result)),
    },
    MetricSpec {
        metric: Metric::ELength,
        key: "e_length",
        label: "e_length",
        unit: "",
        doc: "length distortion: RMS over edges of ln(ℓ_e / ℓ_e⁰); |ln s| for a uniform scaling by s",
        better: Better::Lower,
        gate: Some(Tolerance { relative: 0.02, absolute: 0.001 }),
        plotted: true,
        format: Format::Fixed(4),
        compute: |e| Some(length_distortion(e.rest, e.topology, e.result)),
    },
    MetricSpec {
        metric: Metric::AreaChange,
        key: "area_change",
        label: "ΔA/A⁰",
        unit: "",
        doc: "(A − A⁰) / A⁰ of the total surface area; s² − 1 for a uniform scaling by s (e_area is an RMS \
              over faces and does not tell a swollen result from one stretched here and squeezed there)",
        better: Better::NearZero,
        gate: Some(Tolerance { relative: 0.02, absolute: 0.001 }),
        plotted: false,
        format: Format::Signed(3),
        compute: |e| Some(area_change(e.rest, e.mesh, e.result)),
    },
    MetricSpec {
        metric: Metric::VolumeChange,
        key: "volume_change",
        label: "ΔV/V⁰",
        unit: "",
        doc: "(V − V⁰) / V⁰ of the enclosed volume, for closed meshes (empty for open ones)",
        better: Better::NearZero,
        gate: Some(Tolerance { relative: 0.02, absolute: 0.001 }),
        plotted: false,
        format: Format::Signed(3),
        compute: |e| volume_change(e.rest, e.mesh, e.result),
    },
    MetricSpec {
        metric: Metric::Folds,
        key: "folds",
        label: "folds",
        unit: "",
        doc: "fraction of interior edges whose dihedral angle changed by more than 90°",
        better: Better::Lower,
        // One folded edge in 10^5 is a change; fewer is not measurable on the survey meshes.
        gate: Some(Tolerance { relative: 0.02, absolute: 1e-5 }),
        plotted: false,
        format: Format::Percent(3),
        compute: |e| Some(e.angles.folded_fraction(e.rest)),
    },
    MetricSpec {
        metric: Metric::TurnBeyondHandles,
        key: "turn_beyond_handles_deg",
        label: "turn",
        unit: "°",
        doc: "how far the free surface turned beyond what the handles ask: the 90th percentile over free \
              vertices of the rotation angle of their one-ring (rest to result, Procrustes), minus the \
              largest rotation of a handle region (rest to targets) and the bend 2 atan(d / g) two \
              regions moved apart by d across a rest gap g need; 0 when below",
        better: Better::Lower,
        // Not gated: a verdict rule (configs/verdicts.toml) judges it; small changes mean nothing.
        gate: None,
        plotted: false,
        format: Format::Fixed(1),
        compute: |e| Some(turn_beyond_handles(e).to_degrees()),
    },
    MetricSpec {
        metric: Metric::TurnedShare,
        key: "turned_share",
        label: "turned",
        unit: "",
        doc: "share of the free surface (rest vertex areas) whose one-ring turned more than 45° beyond what \
              the handles ask (as for turn): a patch turned on its own, however small a share",
        better: Better::Lower,
        // Not gated: a verdict rule (configs/verdicts.toml) judges it.
        gate: None,
        plotted: false,
        format: Format::Percent(1),
        compute: |e| Some(turned_share(e)),
    },
    MetricSpec {
        metric: Metric::ShrunkShare,
        key: "shrunk_share",
        label: "shrunk",
        unit: "",
        doc: "share of the rest surface area on faces whose area fell more than a factor 1.5 below what \
              the handles ask (per region from its own motion; a bend asks none) and below the same face \
              in the arap result",
        better: Better::Lower,
        gate: None,
        plotted: false,
        format: Format::Percent(1),
        compute: |e| Some(resized_shares(e).0),
    },
    MetricSpec {
        metric: Metric::SwollenShare,
        key: "swollen_share",
        label: "swollen",
        unit: "",
        doc: "share of the rest surface area on faces whose area grew more than a factor 1.5 beyond what \
              the handles ask and beyond the same face in the arap result",
        better: Better::Lower,
        gate: None,
        plotted: false,
        format: Format::Percent(1),
        compute: |e| Some(resized_shares(e).1),
    },
    MetricSpec {
        metric: Metric::HandleResidual,
        key: "handle_residual_over_diag",
        label: "residual",
        unit: "diag",
        doc: "largest distance of a constrained vertex from its target, over the rest bbox diagonal",
        better: Better::Lower,
        // Not gated: hard constraints give round-off, which has no stable relative value; a residual
        // that matters makes the case suspect, which the gate does see.
        gate: None,
        plotted: false,
        format: Format::Scientific(1),
        compute: |e| Some(handle_residual(e.handles, e.targets, e.result, e.rest.diagonal)),
    },
    MetricSpec {
        metric: Metric::RmsToArap,
        key: "rms_to_arap_over_diag",
        label: "RMS to arap",
        unit: "diag",
        doc: "RMS vertex distance to the arap result of the same scenario, over the rest bbox diagonal",
        better: Better::Lower,
        gate: None,
        plotted: false,
        format: Format::Scientific(1),
        compute: |e| e.reference.map(|r| rms_distance(e.result, r, e.rest.diagonal)),
    },
    MetricSpec {
        metric: Metric::MaxToArap,
        key: "max_to_arap_over_diag",
        label: "max to arap",
        unit: "diag",
        doc: "largest vertex distance to the arap result of the same scenario, over the rest bbox diagonal",
        better: Better::Lower,
        gate: None,
        plotted: false,
        format: Format::Scientific(1),
        compute: |e| e.reference.map(|r| max_distance(e.result, r, e.rest.diagonal)),
    },
    MetricSpec {
        metric: Metric::TurnToArap,
        key: "turn_to_arap_deg",
        label: "turn vs arap",
        unit: "°",
        doc: "how far the free surface turned against the arap result of the same scenario: the rest mesh \
              cut into cubes of 0.05 diagonals, in each the rotation best mapping arap's points onto the \
              result's (Kabsch); the median of its angle over the free vertices",
        better: Better::Lower,
        // Not gated: a verdict rule (configs/verdicts.toml) judges it.
        gate: None,
        plotted: false,
        format: Format::Fixed(1),
        compute: |e| e.reference.map(|r| turn_to_reference(e, r).to_degrees()),
    },
    MetricSpec {
        metric: Metric::ArapEnergy,
        key: "arap_energy",
        label: "E_arap",
        unit: "",
        doc:
            "the ARAP energy of the result (SA07 eq 3, tufted intrinsic Delaunay spokes, the rotations of its local \
              step), over the rest shape's Dirichlet energy sum w |p_i − p_j|²: what the reference `arap` \
              minimizes; a method below the reference found a lower local minimum (index.html says so)",
        better: Better::Lower,
        // Not gated: a nonconvex energy's local minima are findings, not regressions.
        gate: None,
        plotted: false,
        format: Format::Scientific(3),
        compute: |e| e.rest.arap_energy.as_ref().map(|a| a.relative_energy(e.result)),
    },
];

impl Metric {
    /// Every metric, in table order.
    pub const ALL: [Metric; 17] = [
        Metric::EIso,
        Metric::ETheta,
        Metric::EPhi,
        Metric::EArea,
        Metric::ELength,
        Metric::AreaChange,
        Metric::VolumeChange,
        Metric::Folds,
        Metric::TurnBeyondHandles,
        Metric::TurnedShare,
        Metric::ShrunkShare,
        Metric::SwollenShare,
        Metric::HandleResidual,
        Metric::RmsToArap,
        Metric::MaxToArap,
        Metric::TurnToArap,
        Metric::ArapEnergy,
    ];

    /// Its row of [`METRICS`].
    pub fn spec(self) -> &'static MetricSpec {
        &METRICS[self as usize]
    }

    /// The column name.
    pub fn key(self) -> &'static str {
        self.spec().key
    }

    /// The metric with column name `key`.
    pub fn from_key(key: &str) -> Option<Metric> {
        Metric::ALL.into_iter().find(|m| m.key() == key)
    }

    /// How bad `value` is, for comparisons: the value, or its magnitude for a signed change.
    pub fn badness(self, value: f64) -> f64 {
        match self.spec().better {
            Better::Lower => value,
            Better::NearZero => value.abs(),
        }
    }
}

impl fmt::Display for Metric {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.key())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_is_in_enum_order_with_unique_keys() {
        for (i, m) in Metric::ALL.iter().enumerate() {
            assert_eq!(METRICS[i].metric, *m);
            assert_eq!(Metric::from_key(m.key()), Some(*m));
        }
        let mut keys: Vec<&str> = METRICS.iter().map(|s| s.key).collect();
        keys.sort();
        keys.dedup();
        assert_eq!(keys.len(), METRICS.len());
    }
}
