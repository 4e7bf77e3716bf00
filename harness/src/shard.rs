//! Splitting a run over a cluster's job array: `harness all --shard K/N` runs a deterministic part of
//! the scenarios, balanced by an estimate of their cost, and writes a partial report;
//! `harness merge DIR...` combines the partial reports into the report one run would have written.
//!
//! The unit of work is a scenario with all its methods: every method of a scenario is compared with
//! the scenario's `arap` result (`rms_to_arap_over_diag`), so they run in one job. A study over many
//! meshes has many scenarios (one per mesh of a collection), which balances well; one huge scenario
//! is not split.

use std::fmt;
use std::str::FromStr;

use crate::scenario::LoadedScenario;

/// Part `index` (1-based) of `count`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    pub index: usize,
    pub count: usize,
}

impl FromStr for Shard {
    type Err = String;

    /// `K/N` with `1 <= K <= N`.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let err = || format!("`{s}`: a shard is K/N with 1 <= K <= N, e.g. 2/8");
        let (k, n) = s.split_once('/').ok_or_else(err)?;
        let (index, count): (usize, usize) =
            (k.trim().parse().map_err(|_| err())?, n.trim().parse().map_err(|_| err())?);
        if index == 0 || index > count {
            return Err(err());
        }
        Ok(Shard { index, count })
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// Estimated cost of running `methods` on `scenario`: seconds on the reference machine, each method
/// at its registry entry's rate ([`methods::registry::MethodEntry::seconds_per_kilovertex`]; a
/// sweep point, `isolines[isolines=10]`, at its base method's; a method the registry does not know,
/// external or a variant under another name, at the most expensive rate).
pub fn estimated_cost(scenario: &LoadedScenario, methods: &[&str]) -> f64 {
    let slowest = methods::registry::METHODS.iter().map(|m| m.seconds_per_kilovertex).fold(0.0, f64::max);
    let kilovertices = scenario.mesh.n_vertices() as f64 / 1000.0;
    let steps = scenario.steps.len() as f64;
    methods
        .iter()
        .map(|m| {
            let base = crate::sweep::base_method(m);
            methods::registry::find(base).map_or(slowest, |m| m.seconds_per_kilovertex)
        })
        .sum::<f64>()
        * kilovertices
        * steps
}

/// The shard (0-based) of each of the jobs with estimated `costs`, balanced over `count` shards:
/// longest first, each to the least loaded shard so far (ties: the lower index), so every job array
/// with the same inputs splits the same way.
pub fn assign(costs: &[f64], count: usize) -> Vec<usize> {
    let mut order: Vec<usize> = (0..costs.len()).collect();
    order.sort_by(|&a, &b| costs[b].total_cmp(&costs[a]).then(a.cmp(&b)));
    let mut load = vec![0.0f64; count.max(1)];
    let mut shard_of = vec![0; costs.len()];
    for job in order {
        let (least, _) =
            load.iter()
                .enumerate()
                .fold((0, f64::INFINITY), |best, (i, &l)| if l < best.1 { (i, l) } else { best });
        shard_of[job] = least;
        load[least] += costs[job];
    }
    shard_of
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_parse_and_print() {
        assert_eq!("2/8".parse::<Shard>().unwrap(), Shard { index: 2, count: 8 });
        assert_eq!(Shard { index: 3, count: 3 }.to_string(), "3/3");
        for bad in ["0/3", "4/3", "3", "a/b", "1/0"] {
            assert!(bad.parse::<Shard>().is_err(), "{bad}");
        }
    }

    #[test]
    fn assignment_balances_cost_not_count() {
        // One big job and six small ones over two shards: the big one alone, the small ones together.
        let costs = [1.0, 1.0, 10.0, 1.0, 1.0, 1.0, 1.0];
        let shard_of = assign(&costs, 2);
        assert_eq!(shard_of[2], 0);
        assert!(shard_of.iter().enumerate().all(|(i, &s)| i == 2 || s == 1), "{shard_of:?}");
        // Deterministic, every job assigned, more shards than jobs leaves some empty.
        assert_eq!(assign(&costs, 2), shard_of);
        let many = assign(&[3.0, 2.0], 5);
        assert_eq!(many, vec![0, 1]);
        assert!(assign(&[], 3).is_empty());
    }
}
