//! Method parameters: one TOML file (`configs/methods.toml`) with a table per method holding the
//! papers' defaults. Unknown method names and unknown keys are errors that name the file.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use crate::error::HarnessError;

/// Parameter tables by method name, as read from `configs/methods.toml`.
#[derive(Clone, Debug, Default)]
pub struct MethodParams {
    path: PathBuf,
    tables: BTreeMap<String, toml::Table>,
}

impl MethodParams {
    /// Read and check `path`: every top-level key must be a registered method with a table of
    /// parameters that the method accepts.
    pub fn load(path: &Path) -> Result<Self, HarnessError> {
        let text = std::fs::read_to_string(path)
            .map_err(|error| HarnessError::Io { path: path.to_path_buf(), error })?;
        let table: toml::Table = text.parse().map_err(|e: toml::de::Error| HarnessError::Config {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
        let mut tables = BTreeMap::new();
        for (name, value) in table {
            let toml::Value::Table(params) = value else {
                return Err(HarnessError::Config {
                    path: path.to_path_buf(),
                    message: format!("`{name}` must be a table of parameters, e.g. [{name}]"),
                });
            };
            // Building the method validates the name and every key.
            methods::registry::create(&name, &params)
                .map_err(|e| HarnessError::Config { path: path.to_path_buf(), message: e.to_string() })?;
            tables.insert(name, params);
        }
        Ok(Self { path: path.to_path_buf(), tables })
    }

    /// Parameters of `method` (empty: the method's built-in defaults).
    pub fn get(&self, method: &str) -> toml::Table {
        self.tables.get(method).cloned().unwrap_or_default()
    }

    /// The file these parameters came from.
    pub fn path(&self) -> &Path {
        &self.path
    }
}
