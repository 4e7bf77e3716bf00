//! A bad parameter value names exactly its key, its value and its rule (issue 60): not every rule
//! of the method. Through `registry::create`, the path configs/methods.toml, `--methods` files and
//! sweep points take.

use methods::registry::{create, METHODS};
use methods::MethodError;

/// The error of `method` with the parameter table `toml`.
fn error(method: &str, toml: &str) -> MethodError {
    let table: toml::Table = toml.parse().unwrap_or_else(|e| panic!("{toml}: {e}"));
    match create(method, &table) {
        Ok(_) => panic!("{method} accepted {toml}"),
        Err(e) => e,
    }
}

#[test]
fn the_issue_examples_name_the_key_and_value_alone() {
    assert_eq!(
        error("arap", "tolerance = nan").to_string(),
        "arap: tolerance = NaN: must be a finite number >= 0"
    );
    assert_eq!(
        error("scale_aware", "normal_sweeps = 0").to_string(),
        "scale_aware: normal_sweeps = 0: must be >= 1"
    );
    assert_eq!(
        error("scale_aware", "refactor_turn = -0.5").to_string(),
        "scale_aware: refactor_turn = -0.5: must be a finite number >= 0"
    );
}

#[test]
fn one_bad_key_per_method_is_named_alone() {
    let cases = [
        ("laplacian", "omega = 0.0", "laplacian: omega = 0: must be a finite number > 0"),
        ("laplacian", "anderson_depth = 40", "laplacian: anderson_depth = 40: must be <= 16"),
        ("arap", "lbfgs_memory = 65", "arap: lbfgs_memory = 65: must be <= 64"),
        (
            "arap",
            "lbfgs_scale_floor = 1.5",
            "arap: lbfgs_scale_floor = 1.5: must be a finite number in (0, 1]",
        ),
        ("arap", "max_iterations = 0", "arap: max_iterations = 0: must be >= 1"),
        ("hirm", "threshold = 1.0", "hirm: threshold = 1: must be a finite number > 1"),
        ("hirm", "fields_per_region = inf", "hirm: fields_per_region = inf: must be a finite number >= 0"),
        ("spectral_mhb", "bases = 0", "spectral_mhb: bases = 0: must be >= 1"),
        (
            "spectral_mhb",
            "eigen_tolerance = -1e-3",
            "spectral_mhb: eigen_tolerance = -0.001: must be a finite number > 0",
        ),
        (
            "spectral_mhb",
            "stretching = 0.0\nbending = 0.0",
            "spectral_mhb: stretching = 0, bending = 0: must not both be 0",
        ),
        ("isolines", "isolines = 1", "isolines: isolines = 1: must be >= 2"),
        ("isolines_t1", "beta = -1.0", "isolines_t1: beta = -1: must be a finite number >= 0"),
        (
            "scale_aware",
            "initialization_omega = nan",
            "scale_aware: initialization_omega = NaN: must be a finite number > 0",
        ),
        (
            "scale_aware_ora",
            "constraint_weight = inf",
            "scale_aware_ora: constraint_weight = inf: must be a finite number > 0",
        ),
    ];
    for (method, toml, expected) in cases {
        assert_eq!(error(method, toml).to_string(), expected, "{method} with {toml}");
    }
    for m in METHODS {
        assert!(cases.iter().any(|(name, _, _)| *name == m.name), "no case for `{}`", m.name);
    }
}

#[test]
fn two_bad_keys_are_both_named_and_nothing_else() {
    let e = error("arap", "tolerance = -1.0\nlbfgs_memory = 100");
    assert_eq!(
        e.to_string(),
        "arap: tolerance = -1: must be a finite number >= 0; lbfgs_memory = 100: must be <= 64"
    );
    let MethodError::InvalidParameters { faults, .. } = e else { panic!("{e:?}") };
    assert_eq!(faults.iter().flat_map(|f| f.keys()).collect::<Vec<_>>(), ["tolerance", "lbfgs_memory"]);
}

#[test]
fn a_value_of_the_wrong_type_names_its_key() {
    let e = error("arap", "tolerance = \"small\"\nmax_iterations = 10").to_string();
    assert!(e.starts_with("parameters of `arap`: tolerance = \"small\": "), "{e}");
    assert!(!e.contains("max_iterations"), "{e}");
}

/// Every key of `method`, from the parse error of an unknown one (`expected one of ...`).
fn keys_of(method: &str) -> Vec<String> {
    let message = error(method, "no_such_key = 1").to_string();
    let (_, list) = message.split_once("expected one of").unwrap_or_else(|| panic!("{message}"));
    list.split(',').map(|k| k.trim().trim_matches('`').to_string()).filter(|k| !k.is_empty()).collect()
}

#[test]
fn nan_is_refused_for_every_float_parameter_of_every_method() {
    for m in METHODS {
        let keys = keys_of(m.name);
        assert!(keys.len() >= 4, "{}: {keys:?}", m.name);
        let mut floats = 0;
        for key in keys {
            // A key that is not a float refuses `nan` as a type error instead.
            match error(m.name, &format!("{key} = nan")) {
                MethodError::InvalidParameters { faults, .. } => {
                    floats += 1;
                    assert_eq!(faults.len(), 1, "{}.{key}: {faults:?}", m.name);
                    assert_eq!(
                        faults[0].values,
                        [(faults[0].keys()[0], "NaN".to_string())],
                        "{}.{key}",
                        m.name
                    );
                    assert_eq!(faults[0].keys(), [key.as_str()], "{}", m.name);
                }
                MethodError::Parameters { .. } => {}
                other => panic!("{}.{key}: {other}", m.name),
            }
        }
        assert!(floats >= 1, "{}: no float parameter found", m.name);
    }
}
