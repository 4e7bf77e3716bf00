//! Parameter sweeps: a variant's `params` whose values are lists (`isolines = [5, 10, 20, 40]`)
//! stand for one variant per value, or per combination of values when several keys are lists (the
//! Cartesian product, in key order). Each point is named by its base method and the values it sets,
//! `isolines[isolines=10]`, and is then an ordinary variant: run, reported, drawn and gated like any
//! method. The points of one sweep, in the order of its values, are one line of the quality–time
//! plots ([`crate::pareto`]).

use serde::{Deserialize, Serialize};

/// Where a method sits in a sweep: the sweep's name (its table in the configuration), the position
/// of its values in the sweep's order, and those values as text (`isolines=10`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SweepPosition {
    pub sweep: String,
    pub position: usize,
    pub values: String,
}

/// One point of a sweep: the values it sets, in key order.
#[derive(Clone, Debug, PartialEq)]
pub struct Point {
    pub values: Vec<(String, toml::Value)>,
}

impl Point {
    /// `base[key=value,…]`, the point's method name.
    pub fn name(&self, base: &str) -> String {
        format!("{base}[{}]", self.values_text())
    }

    /// `key=value,…` (values as [`value_text`] writes them).
    pub fn values_text(&self) -> String {
        self.values.iter().map(|(k, v)| format!("{k}={}", value_text(v))).collect::<Vec<_>>().join(",")
    }

    /// `params` with this point's values set.
    pub fn apply(&self, params: &toml::Table) -> toml::Table {
        laid_over(params, self.values.iter().map(|(k, v)| (k, v)))
    }
}

/// `base` with `values` set: a variant's or a point's parameters over its base method's table.
pub fn laid_over<'a>(
    base: &toml::Table,
    values: impl IntoIterator<Item = (&'a String, &'a toml::Value)>,
) -> toml::Table {
    let mut out = base.clone();
    for (k, v) in values {
        out.insert(k.clone(), v.clone());
    }
    out
}

/// The base method of a point's name (`isolines` of `isolines[isolines=10]`); any other name itself.
pub fn base_method(name: &str) -> &str {
    name.split('[').next().unwrap_or(name)
}

/// Whether `params` holds a sweep (some value is a list).
pub fn is_sweep(params: &toml::Table) -> bool {
    params.values().any(|v| matches!(v, toml::Value::Array(_)))
}

/// The points of `params`' list-valued keys (key order; the last key varies fastest), and the
/// table of its other keys, which every point shares. A list must hold at least one value, and no
/// lists or tables (a parameter is a number, a string or a boolean).
pub fn expand(params: &toml::Table) -> Result<(Vec<Point>, toml::Table), String> {
    let mut fixed = toml::Table::new();
    let mut swept: Vec<(&String, &Vec<toml::Value>)> = Vec::new();
    // Key order is sorted order: toml's map keeps the file's (the workspace enables its
    // `preserve_order`), and the points' names and order were always in sorted key order.
    let mut sorted: Vec<(&String, &toml::Value)> = params.iter().collect();
    sorted.sort_by(|(a, _), (b, _)| a.cmp(b));
    for (k, v) in sorted {
        match v {
            toml::Value::Array(values) => {
                if values.is_empty() {
                    return Err(format!("`{k}` sweeps no values (an empty list)"));
                }
                if let Some(bad) =
                    values.iter().find(|v| matches!(v, toml::Value::Array(_) | toml::Value::Table(_)))
                {
                    return Err(format!(
                        "`{k}`: a swept value must be a number, string or boolean, not {bad}"
                    ));
                }
                swept.push((k, values));
            }
            other => {
                fixed.insert(k.clone(), other.clone());
            }
        }
    }
    let mut points = vec![Point { values: Vec::new() }];
    for (k, values) in swept {
        points = points
            .into_iter()
            .flat_map(|p| {
                values.iter().map(move |v| {
                    let mut values = p.values.clone();
                    values.push((k.clone(), v.clone()));
                    Point { values }
                })
            })
            .collect();
    }
    Ok((points, fixed))
}

/// A parameter value as it appears in a point's name: integers and integral floats without a
/// fraction (`100`), floats below 0.01 or from 10^6 in exponent form (`1e-5`), strings without quotes.
pub fn value_text(v: &toml::Value) -> String {
    match v {
        toml::Value::Integer(i) => i.to_string(),
        toml::Value::Float(f) if f.fract() == 0.0 && f.abs() < 1e6 => format!("{}", *f as i64),
        toml::Value::Float(f) if *f != 0.0 && (f.abs() < 1e-2 || f.abs() >= 1e6) => format!("{f:e}"),
        toml::Value::Float(f) => format!("{f}"),
        toml::Value::String(s) => s.clone(),
        toml::Value::Boolean(b) => b.to_string(),
        other => other.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(text: &str) -> toml::Table {
        text.parse().unwrap()
    }

    #[test]
    fn a_list_valued_parameter_expands_to_one_named_variant_per_value() {
        let (points, fixed) = expand(&table("isolines = [5, 10, 40]\nbeta = 0.01")).unwrap();
        let names: Vec<String> = points.iter().map(|p| p.name("isolines")).collect();
        assert_eq!(names, ["isolines[isolines=5]", "isolines[isolines=10]", "isolines[isolines=40]"]);
        assert_eq!(fixed, table("beta = 0.01"));
        let params = points[1].apply(&table("isolines = 20\nomega = 1000.0"));
        assert_eq!(params, table("isolines = 10\nomega = 1000.0"));
    }

    #[test]
    fn two_lists_expand_to_their_product_in_key_order() {
        let (points, _) =
            expand(&table("tolerance = [1e-3, 1e-6]\nacceleration = [\"anderson\", \"none\"]")).unwrap();
        let names: Vec<String> = points.iter().map(|p| p.name("arap")).collect();
        assert_eq!(
            names,
            [
                "arap[acceleration=anderson,tolerance=1e-3]",
                "arap[acceleration=anderson,tolerance=1e-6]",
                "arap[acceleration=none,tolerance=1e-3]",
                "arap[acceleration=none,tolerance=1e-6]",
            ]
        );
    }

    #[test]
    fn values_read_as_written() {
        let text = |s: &str| value_text(&s.parse::<toml::Table>().unwrap()["v"]);
        assert_eq!(text("v = 100.0"), "100");
        assert_eq!(text("v = 0.01"), "0.01");
        assert_eq!(text("v = 1e-5"), "1e-5");
        assert_eq!(text("v = 2.5e7"), "2.5e7");
        assert_eq!(text("v = 0.0"), "0");
        assert_eq!(text("v = true"), "true");
        assert_eq!(text("v = \"vertices\""), "vertices");
    }

    #[test]
    fn bad_sweeps_are_named() {
        assert!(expand(&table("k = []")).unwrap_err().contains("`k`"));
        assert!(expand(&table("k = [[1]]")).unwrap_err().contains("`k`"));
        assert!(!is_sweep(&table("k = 1")));
        assert!(is_sweep(&table("k = [1]")));
    }
}
