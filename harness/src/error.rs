//! Errors of the harness library; the CLI wraps them with `anyhow`.

use std::path::PathBuf;

/// What can stop the harness before or while running (bad input, I/O). A method that fails on a
/// case is not an error here: it becomes a `failed` row in the report.
#[derive(Debug, thiserror::Error)]
pub enum HarnessError {
    #[error("{}: {message}", path.display())]
    Config { path: PathBuf, message: String },
    /// A scenario's input is wrong; `file` is the scenario file, when there is one.
    #[error("scenario `{scenario}`{}: {message}", file.as_ref().map(|f| format!(" ({})", f.display())).unwrap_or_default())]
    Scenario { scenario: String, file: Option<PathBuf>, message: String },
    #[error(transparent)]
    Mesh(#[from] meshes::MeshError),
    #[error(transparent)]
    Method(#[from] methods::MethodError),
    #[error("{}: {error}", path.display())]
    Io { path: PathBuf, error: std::io::Error },
    #[error("{0}")]
    Report(String),
    /// A scenario whose estimated memory exceeds what the machine has available, refused before
    /// its mesh was loaded (`--force` runs it anyway).
    #[error(transparent)]
    Memory(#[from] Box<crate::memory::MemoryRefusal>),
}

impl From<measures::MeasuresError> for HarnessError {
    /// A rules file's error as the harness's own kind of it, with the same message.
    fn from(error: measures::MeasuresError) -> Self {
        use measures::MeasuresError as E;
        match error {
            E::Read { path, error } => HarnessError::Io { path, error },
            E::Rules { path, message } => HarnessError::Config { path, message },
            E::Mesh(e) => HarnessError::Mesh(e),
            E::Handles(e) => HarnessError::Method(e),
            E::Size(message) => HarnessError::Report(message),
        }
    }
}

/// ` (did you mean `x`?)` when one of `known` is a likely misspelling of `name` (the nearest by
/// Damerau–Levenshtein distance, ignoring case, at most a third of the name's length away and at
/// least 2; else one that `name` begins), or nothing.
pub fn did_you_mean<'a>(name: &str, known: impl IntoIterator<Item = &'a str>) -> String {
    let lower = name.to_lowercase();
    let known: Vec<&str> = known.into_iter().filter(|k| *k != name).collect();
    let nearest = known
        .iter()
        .map(|k| (strsim::damerau_levenshtein(&lower, &k.to_lowercase()), *k))
        .min_by_key(|(distance, _)| *distance)
        .filter(|(distance, _)| *distance <= (name.chars().count() / 3).max(2))
        .map(|(_, k)| k);
    let begun =
        || known.iter().copied().find(|k| lower.chars().count() >= 3 && k.to_lowercase().starts_with(&lower));
    nearest.or_else(begun).map(|k| format!(" (did you mean `{k}`?)")).unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::did_you_mean;

    #[test]
    fn a_near_name_is_suggested_and_a_far_one_is_not() {
        let methods = ["laplacian", "arap", "isolines", "hirm", "scale_aware", "scale_aware_ora"];
        assert_eq!(did_you_mean("isoline", methods), " (did you mean `isolines`?)");
        assert_eq!(did_you_mean("hirn", methods), " (did you mean `hirm`?)");
        assert_eq!(did_you_mean("lapalcian", methods), " (did you mean `laplacian`?)");
        assert_eq!(did_you_mean("ARAP", methods), " (did you mean `arap`?)");
        assert_eq!(did_you_mean("scale", methods), " (did you mean `scale_aware`?)");
        assert_eq!(did_you_mean("cylinder", methods), "");
        assert_eq!(did_you_mean("x", methods), "");
    }
}
