//! The table of methods by name: the one place a new method is registered.

use serde::de::DeserializeOwned;

use crate::arap::Arap;
use crate::error::MethodError;
use crate::hirm::Hirm;
use crate::isolines::Isolines;
use crate::laplacian::LaplacianEditing;
use crate::method::DeformationMethod;
use crate::scale_aware::{ScaleAware, SolveMemo};
use crate::spectral_mhb::SpectralMhb;

// The registered method names live in `crate::keys::method_name` (a method module may name
// another, as `scale_aware_ora` names the `scale_aware` it reuses, without importing this table).
pub use crate::keys::method_name::*;

/// What builds a method: from its parameter table and the memo of solves it may share.
pub type Constructor = fn(&toml::Table, &SolveMemo) -> Result<Box<dyn DeformationMethod>, MethodError>;

/// One registered method.
pub struct MethodEntry {
    /// Name used in configs, on the command line and in reports.
    pub name: &'static str,
    /// One line: what it is and where it comes from.
    pub summary: &'static str,
    /// Build the method from its parameter table (missing keys take the paper's defaults), with the
    /// memo of solves it shares with the other instances given the same one (only `scale_aware*`
    /// use it; [`crate::scale_aware::solve_memo`]).
    pub create: Constructor,
    /// Whether `solve` iterates (takes `max_iterations` and `tolerance`); `false` for a direct solve.
    pub iterative: bool,
    /// Its cost, seconds per 1000 vertices per edit step: what the harness balances a cluster's
    /// shards by (only the ratios between methods matter). Measured as the median
    /// `total_s / (#V / 1000)` over the four survey tests of a `harness all` on the project's 2-core
    /// machine (at 11f8f45).
    pub seconds_per_kilovertex: f64,
    /// Its memory, bytes per vertex: what a case of it adds at its peak (`peak_memory_mib`) over the
    /// mesh's vertex count, at the largest size measured (docs/results.md, "The large real tier":
    /// igea at 2.1M vertices, 8cb439f; `spectral_mhb` from the bar at 1M after 793b558 cut its
    /// peak 2.4-fold; `scale_aware*` from igea at 134K, the largest it runs at). The harness refuses
    /// a scenario whose estimate exceeds the machine's available memory before loading its mesh
    /// (`--force` runs it anyway).
    pub bytes_per_vertex: u64,
    /// Its side of HIRM's Table 1 (Wu et al. 2015), if it is one of the two compared there.
    pub table1: Option<Table1Side>,
}

/// The two sides of HIRM's Table 1 (Wu et al. 2015): the time to take a new handle set.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Table1Side {
    /// The handle-independent model: the update is its phase `t_h`
    /// ([`crate::keys::phase::T_H_HANDLE_UPDATE`]); it also reports `t_e`, `t_b`, `n_field` and
    /// `n_t`.
    HandleIndependent,
    /// The handle-aware model, rebuilt for each handle set: the update is its whole `bind_handles`.
    Rebuilt,
}

/// Every method of the suite, in report order.
pub const METHODS: &[MethodEntry] = &[
    MethodEntry {
        name: LAPLACIAN,
        summary: "unreduced iterative Laplacian editing (Au et al. 2007 sec. 3, eq 1-3), the reference the reduced models approximate",
        create: |p, _| Ok(Box::new(LaplacianEditing::new(parse(LAPLACIAN, p)?)?)),
        iterative: true,
        seconds_per_kilovertex: 0.10,
        bytes_per_vertex: 7_600, // 15.1 GiB at 2.1M
        table1: None,
    },
    MethodEntry {
        name: ARAP,
        summary: "As-Rigid-As-Possible surface modeling (Sorkine & Alexa 2007), cotangent weights (intrinsic Delaunay by default), hard constraints",
        create: |p, _| Ok(Box::new(Arap::new(parse(ARAP, p)?)?)),
        iterative: true,
        seconds_per_kilovertex: 0.25,
        bytes_per_vertex: 3_200, // 6.33 GiB at 2.1M
        table1: None,
    },
    MethodEntry {
        name: HIRM,
        summary: "handle-independent reduced model for incremental editing: isolines of Laplacian eigenvectors, background precompute (Wu, Au, Tai & Lu 2015)",
        create: |p, _| Ok(Box::new(Hirm::new(parse(HIRM, p)?)?)),
        iterative: true,
        seconds_per_kilovertex: 0.043,
        bytes_per_vertex: 3_300, // 6.58 GiB at 2.1M
        table1: Some(Table1Side::HandleIndependent),
    },
    MethodEntry {
        name: SPECTRAL_MHB,
        summary: "spectral mesh deformation in manifold harmonics bases with deformation transfer of details (Rong, Cao & Guo 2008)",
        create: |p, _| Ok(Box::new(SpectralMhb::new(parse(SPECTRAL_MHB, p)?)?)),
        iterative: false,
        seconds_per_kilovertex: 0.039,
        bytes_per_vertex: 3_100, // 3.04 GB at 1M (14.4 GiB at 2.1M before 793b558)
        table1: None,
    },
    MethodEntry {
        name: SCALE_AWARE,
        summary: "scale-aware shape manipulation: triangle and edge angles, normals on the Gauss map, then G(Theta, N) V = 0 (Liu, Wang, Liu & Liu 2014)",
        create: |p, memo| Ok(Box::new(ScaleAware::sharing(SCALE_AWARE, parse(SCALE_AWARE, p)?, memo.clone())?)),
        iterative: true,
        seconds_per_kilovertex: 0.48,
        bytes_per_vertex: 11_100, // 1.38 GiB at 134K
        table1: None,
    },
    MethodEntry {
        name: SCALE_AWARE_ORA,
        summary: "`scale_aware` followed by the optimal rigidity approximation: triangles rescaled to their rest areas and stitched (section 5.3)",
        create: |p, memo| Ok(Box::new(ScaleAware::sharing(SCALE_AWARE_ORA, parse(SCALE_AWARE_ORA, p)?, memo.clone())?)),
        iterative: true,
        seconds_per_kilovertex: 0.44,
        bytes_per_vertex: 11_100, // scale_aware's
        table1: None,
    },
    MethodEntry {
        name: ISOLINES,
        summary: "handle-aware isolines reduced model (Au, Fu, Tai & Cohen-Or 2007), n_iso = 20, isoline-interpolated Laplacian coordinates (Table 1 t_2)",
        create: |p, _| Ok(Box::new(Isolines::new(ISOLINES, parse(ISOLINES, p)?)?)),
        iterative: true,
        seconds_per_kilovertex: 0.0042,
        bytes_per_vertex: 2_000, // 3.85 GiB at 2.1M
        table1: Some(Table1Side::Rebuilt),
    },
    MethodEntry {
        name: ISOLINES_T1,
        summary: "`isolines` with vertex interpolation only: Laplacian coordinates on the whole mesh per iteration (Au et al. 2007 eq 6, Table 1 t_1)",
        create: |p, _| Ok(Box::new(Isolines::new(ISOLINES_T1, parse(ISOLINES_T1, p)?)?)),
        iterative: true,
        seconds_per_kilovertex: 0.0081,
        bytes_per_vertex: 2_000, // isolines'; not measured at 2.1M
        table1: None,
    },
];

/// The registered method on `side` of HIRM's Table 1.
pub fn table1_method(side: Table1Side) -> Option<&'static MethodEntry> {
    METHODS.iter().find(|m| m.table1 == Some(side))
}

/// The side of HIRM's Table 1 of the registered method `name` (none for other names).
pub fn table1_side(name: &str) -> Option<Table1Side> {
    find(name).ok().and_then(|m| m.table1)
}

/// Names of all registered methods.
pub fn method_names() -> Vec<&'static str> {
    METHODS.iter().map(|m| m.name).collect()
}

/// Look up `name`; [`MethodError::UnknownMethod`] lists the known names.
pub fn find(name: &str) -> Result<&'static MethodEntry, MethodError> {
    METHODS
        .iter()
        .find(|m| m.name == name)
        .ok_or_else(|| MethodError::UnknownMethod { name: name.to_string(), known: method_names() })
}

/// Build method `name` with `params` (a TOML table of its parameters; unknown keys are errors),
/// sharing solves with no other instance.
pub fn create(name: &str, params: &toml::Table) -> Result<Box<dyn DeformationMethod>, MethodError> {
    create_sharing(name, params, &SolveMemo::default())
}

/// [`create`], the instance sharing `memo` with the others made with it: `scale_aware_ora` then
/// takes an identical solve of `scale_aware` instead of computing it again.
pub fn create_sharing(
    name: &str,
    params: &toml::Table,
    memo: &SolveMemo,
) -> Result<Box<dyn DeformationMethod>, MethodError> {
    (find(name)?.create)(params, memo)
}

fn parse<P: DeserializeOwned>(method: &'static str, table: &toml::Table) -> Result<P, MethodError> {
    toml::Value::Table(table.clone()).try_into().map_err(|e: toml::de::Error| {
        // The message of a value of the wrong type does not say whose it is: name the keys that
        // fail on their own, with their values.
        let alone = |key: &String, value: &toml::Value| {
            let one = toml::Table::from_iter([(key.clone(), value.clone())]);
            toml::Value::Table(one).try_into::<P>().is_err()
        };
        let faulty: Vec<String> =
            table.iter().filter(|(k, v)| alone(k, v)).map(|(k, v)| format!("{k} = {v}")).collect();
        let message = match faulty.is_empty() {
            true => e.message().to_string(),
            false => format!("{}: {}", faulty.join(", "), e.message()),
        };
        MethodError::Parameters { method, message }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_entry_describes_itself_for_the_harness() {
        for m in METHODS {
            assert!(m.seconds_per_kilovertex.is_finite() && m.seconds_per_kilovertex > 0.0, "{}", m.name);
            assert!(
                (100..100_000).contains(&m.bytes_per_vertex),
                "{}: {} bytes per vertex",
                m.name,
                m.bytes_per_vertex
            );
        }
        for side in [Table1Side::HandleIndependent, Table1Side::Rebuilt] {
            let sides = METHODS.iter().filter(|m| m.table1 == Some(side)).count();
            assert_eq!(sides, 1, "one method on each side of Table 1, {side:?} has {sides}");
        }
        assert_eq!(table1_method(Table1Side::HandleIndependent).map(|m| m.name), Some(HIRM));
        assert_eq!(table1_method(Table1Side::Rebuilt).map(|m| m.name), Some(ISOLINES));
    }
}
