//! [`Quality`]: the value of every measure of one result, and how it is written into results.json.

use std::fmt;

use serde::de::{IgnoredAny, MapAccess, Visitor};
use serde::ser::SerializeMap;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::evaluation::Evaluation;
use crate::metric::{Metric, METRICS};

/// The value of every metric of one result (`None`: not applicable or not computed). Written into
/// results.json as one field per metric key (`null` for none).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Quality {
    values: [Option<f64>; Metric::ALL.len()],
}

impl Quality {
    /// Every metric of the result in `evaluation`.
    pub fn evaluate(evaluation: &Evaluation) -> Quality {
        let mut quality = Quality::default();
        for spec in &METRICS {
            quality.set(spec.metric, (spec.compute)(evaluation));
        }
        quality
    }

    pub fn get(&self, metric: Metric) -> Option<f64> {
        self.values[metric as usize]
    }

    /// The value, NaN where there is none.
    pub fn value(&self, metric: Metric) -> f64 {
        self.get(metric).unwrap_or(f64::NAN)
    }

    pub fn set(&mut self, metric: Metric, value: Option<f64>) {
        self.values[metric as usize] = value;
    }

    /// The metrics whose value is present and not finite.
    pub fn non_finite(&self) -> impl Iterator<Item = Metric> + '_ {
        Metric::ALL.into_iter().filter(|m| self.get(*m).is_some_and(|v| !v.is_finite()))
    }
}

impl Serialize for Quality {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let mut map = serializer.serialize_map(Some(Metric::ALL.len()))?;
        for m in Metric::ALL {
            // NaN is not JSON; a missing value is null either way.
            map.serialize_entry(m.key(), &self.get(m).filter(|v| v.is_finite()))?;
        }
        map.end()
    }
}

impl<'de> Deserialize<'de> for Quality {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct QualityVisitor;
        impl<'de> Visitor<'de> for QualityVisitor {
            type Value = Quality;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("metric values by key")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Quality, A::Error> {
                let mut quality = Quality::default();
                while let Some(key) = map.next_key::<String>()? {
                    match Metric::from_key(&key) {
                        Some(m) => quality.set(m, map.next_value::<Option<f64>>()?),
                        None => {
                            map.next_value::<IgnoredAny>()?;
                        }
                    }
                }
                Ok(quality)
            }
        }
        deserializer.deserialize_map(QualityVisitor)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quality_round_trips_through_json_with_null_for_missing_and_non_finite() {
        let mut q = Quality::default();
        q.set(Metric::ETheta, Some(1.5));
        q.set(Metric::EArea, Some(f64::INFINITY));
        let json = serde_json::to_value(&q).unwrap();
        assert_eq!(json["e_theta_deg"], 1.5);
        assert!(json["e_area"].is_null() && json["volume_change"].is_null());
        let back: Quality = serde_json::from_value(json).unwrap();
        assert_eq!(back.get(Metric::ETheta), Some(1.5));
        assert_eq!(back.get(Metric::EArea), None);
        assert_eq!(q.non_finite().collect::<Vec<_>>(), vec![Metric::EArea]);
    }
}
