//! Checking a method's parameters one key at a time, so an error names exactly the key(s) and
//! value(s) at fault and the rule they break (`tolerance = NaN: must be a finite number >= 0`),
//! not every rule of the method. Every `f64` rule asks for a finite number and says what it
//! accepts, so NaN (which fails every comparison, and so passes a rule written as what it refuses,
//! `x < 0`) and infinity are refused for every float parameter.

use std::fmt::Display;

pub use crate::error::InvalidParameter;
use crate::error::MethodError;

/// The faults found so far; [`ParamCheck::finish`] turns them into
/// [`MethodError::InvalidParameters`].
#[derive(Debug, Default)]
pub struct ParamCheck {
    faults: Vec<InvalidParameter>,
}

impl ParamCheck {
    pub fn new() -> Self {
        Self::default()
    }

    /// `key = value` breaks `rule` unless `ok`.
    pub fn rule(
        &mut self,
        key: &'static str,
        value: impl Display,
        ok: bool,
        rule: impl Into<String>,
    ) -> &mut Self {
        if !ok {
            self.faults.push(InvalidParameter { values: vec![(key, value.to_string())], rule: rule.into() });
        }
        self
    }

    /// A rule between several keys, with their values.
    pub fn joint_rule(
        &mut self,
        values: &[(&'static str, f64)],
        ok: bool,
        rule: impl Into<String>,
    ) -> &mut Self {
        if !ok {
            let values = values.iter().map(|(k, v)| (*k, v.to_string())).collect();
            self.faults.push(InvalidParameter { values, rule: rule.into() });
        }
        self
    }

    /// An integer `key >= min`.
    pub fn count_at_least(&mut self, key: &'static str, value: usize, min: usize) -> &mut Self {
        self.rule(key, value, value >= min, format!("must be >= {min}"))
    }

    /// An integer `key <= max`.
    pub fn count_at_most(&mut self, key: &'static str, value: usize, max: usize) -> &mut Self {
        self.rule(key, value, value <= max, format!("must be <= {max}"))
    }

    /// A finite `key >= min`.
    pub fn number_at_least(&mut self, key: &'static str, value: f64, min: f64) -> &mut Self {
        self.rule(key, value, value.is_finite() && value >= min, format!("must be a finite number >= {min}"))
    }

    /// A finite `key > min`.
    pub fn number_above(&mut self, key: &'static str, value: f64, min: f64) -> &mut Self {
        self.rule(key, value, value.is_finite() && value > min, format!("must be a finite number > {min}"))
    }

    /// A finite `key` in `(low, high]`.
    pub fn number_in_half_open(&mut self, key: &'static str, value: f64, low: f64, high: f64) -> &mut Self {
        let ok = value.is_finite() && value > low && value <= high;
        self.rule(key, value, ok, format!("must be a finite number in ({low}, {high}]"))
    }

    /// `Ok` when no rule was broken, else every fault of `method`.
    pub fn finish(&mut self, method: &'static str) -> Result<(), MethodError> {
        if self.faults.is_empty() {
            Ok(())
        } else {
            Err(MethodError::InvalidParameters { method, faults: std::mem::take(&mut self.faults) })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_fault_names_its_key_value_and_rule_and_nothing_else() {
        let e = ParamCheck::new()
            .number_at_least("tolerance", f64::NAN, 0.0)
            .count_at_least("max_iterations", 5, 1)
            .finish("arap")
            .unwrap_err();
        assert_eq!(e.to_string(), "arap: tolerance = NaN: must be a finite number >= 0");
        let e = ParamCheck::new()
            .number_above("omega", f64::INFINITY, 0.0)
            .count_at_most("anderson_depth", 20, 16)
            .finish("laplacian")
            .unwrap_err();
        assert_eq!(
            e.to_string(),
            "laplacian: omega = inf: must be a finite number > 0; anderson_depth = 20: must be <= 16"
        );
        let e = ParamCheck::new()
            .joint_rule(&[("stretching", 0.0), ("bending", 0.0)], false, "must not both be 0")
            .finish("spectral_mhb")
            .unwrap_err();
        assert_eq!(e.to_string(), "spectral_mhb: stretching = 0, bending = 0: must not both be 0");
        assert!(ParamCheck::new().number_in_half_open("c", 1.0, 0.0, 1.0).finish("arap").is_ok());
        assert!(ParamCheck::new().number_in_half_open("c", 0.0, 0.0, 1.0).finish("arap").is_err());
    }
}
