//! The verdict on a case (`ok`, `suspect`, `unfinished` or `failed`) and the rules of
//! `configs/verdicts.toml` that give it. They live in the `measures` crate; this module re-exports
//! them under the harness's `crate::verdict` paths (a rules file's error converts to
//! [`crate::HarnessError`] with the same message).

pub use measures::status::*;
pub use measures::verdict::*;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::HarnessError;

    /// `?` in the harness turns the crate's error into the harness's, message unchanged.
    fn load(path: &std::path::Path) -> Result<VerdictRules, HarnessError> {
        Ok(VerdictRules::load(path)?)
    }

    #[test]
    fn a_bad_rules_file_is_a_config_error_naming_the_file_and_the_key() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("verdicts.toml");
        std::fs::write(&path, "max_fold = 0\n").unwrap();
        let e = load(&path).unwrap_err();
        assert!(matches!(e, HarnessError::Config { .. }), "{e:?}");
        assert_eq!(e.to_string(), VerdictRules::load(&path).unwrap_err().to_string());
        let missing = dir.path().join("none.toml");
        assert!(matches!(load(&missing).unwrap_err(), HarnessError::Io { .. }));
    }
}
