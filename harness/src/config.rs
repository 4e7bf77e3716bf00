//! The methods of a run, as configured: `configs/methods.toml` holds a table per method, either the
//! parameters of a built-in method (missing keys take the papers' defaults), a variant of one
//! (`method` and its `params`), or an external program (`command`, see [`ExternalEntry`]); `configs/peers.toml`, in the same format, holds the peer
//! libraries' adapters that `--peers` adds. Unknown names and keys are errors that name the file.

use std::path::{Path, PathBuf};
use std::time::Duration;

use serde::{Deserialize, Serialize};

use crate::error::HarnessError;
use methods::external::{ExternalMethod, ExternalSpec};
use methods::{DeformationMethod, MethodError};

/// Where a method's implementation comes from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Origin {
    /// One of this suite's own methods ([`methods::registry::METHODS`]).
    #[default]
    BuiltIn,
    /// A program named in `configs/methods.toml`, spoken to over the protocol.
    External,
    /// A peer library's method (`configs/peers.toml`, added by `--peers`), external too.
    Peer,
}

impl Origin {
    /// The word in tables and on the page.
    pub fn label(self) -> &'static str {
        match self {
            Origin::BuiltIn => "built-in",
            Origin::External => "external",
            Origin::Peer => "peer",
        }
    }
}

/// The keys of an external method's table; everything else is an error (its own parameters go in
/// its `params` table).
const EXTERNAL_KEYS: &[&str] = &["command", "working_dir", "timeout_s", "summary", "params"];

/// The keys of a variant of a built-in method (`method = "arap"` with other `params`).
const VARIANT_KEYS: &[&str] = &["method", "summary", "params"];

/// An external method's entry, resolved: `command = ["program", "arg", …]` with `${VAR}` expanded,
/// `working_dir` (relative to the file's directory; default that directory), `timeout_s` per
/// request, and `params`, sent to the program untouched.
#[derive(Clone, Debug)]
pub struct ExternalEntry {
    pub program: String,
    pub args: Vec<String>,
    pub working_dir: PathBuf,
    pub timeout: Duration,
    pub params: serde_json::Value,
}

/// The peers of a run (`--peers`): their file and the Python they run in.
#[derive(Clone, Debug)]
pub struct PeerSetup {
    /// `configs/peers.toml`.
    pub file: PathBuf,
    /// The cross-check Python, `${DEFORMBENCH_PYTHON}` in their commands.
    pub python: PathBuf,
}

/// What runs a configured method.
#[derive(Clone)]
pub enum Implementation {
    /// The registered method of this name (a variant's `method`).
    BuiltIn(&'static methods::registry::MethodEntry),
    /// A program over the protocol.
    External(ExternalEntry),
}

impl std::fmt::Debug for Implementation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Implementation::BuiltIn(entry) => write!(f, "BuiltIn({})", entry.name),
            Implementation::External(e) => f.debug_tuple("External").field(e).finish(),
        }
    }
}

/// One method of a run.
#[derive(Clone, Debug)]
pub struct ConfiguredMethod {
    pub name: String,
    pub origin: Origin,
    /// A built-in method's parameters (its table); an external method's `params`.
    pub params: toml::Table,
    pub implementation: Implementation,
    /// One line: what it is (`list`).
    pub summary: String,
}

impl ConfiguredMethod {
    /// A fresh instance; an external method's program is started (its stderr written to
    /// `stderr_log`, its thread variables set to `threads`).
    pub fn create(
        &self,
        stderr_log: Option<PathBuf>,
        threads: usize,
    ) -> Result<Box<dyn DeformationMethod>, MethodError> {
        match &self.implementation {
            Implementation::BuiltIn(entry) => (entry.create)(&self.params),
            Implementation::External(e) => Ok(Box::new(ExternalMethod::start(ExternalSpec {
                name: self.name.clone(),
                program: e.program.clone(),
                args: e.args.clone(),
                working_dir: Some(e.working_dir.clone()),
                env: crate::threads::external_environment(threads),
                timeout: e.timeout,
                params: e.params.clone(),
                stderr_log,
            })?)),
        }
    }

    /// Whether it runs in another process.
    pub fn is_external(&self) -> bool {
        matches!(self.implementation, Implementation::External(_))
    }
}

/// Every method a run can use: the built-in ones in registry order, then the external ones of
/// `methods.toml` in file order, then the peers when asked for.
#[derive(Clone, Debug, Default)]
pub struct MethodCatalog {
    path: PathBuf,
    methods: Vec<ConfiguredMethod>,
}

impl MethodCatalog {
    /// Read and check `path` (`configs/methods.toml`): every top-level key is a built-in method with
    /// parameters it accepts, a variant of one (`method`, `params`), or an external method with a
    /// `command`.
    pub fn load(path: &Path) -> Result<Self, HarnessError> {
        let mut methods: Vec<ConfiguredMethod> = methods::registry::METHODS
            .iter()
            .map(|m| ConfiguredMethod {
                name: m.name.to_string(),
                origin: Origin::BuiltIn,
                params: toml::Table::new(),
                implementation: Implementation::BuiltIn(m),
                summary: m.summary.to_string(),
            })
            .collect();
        for (name, table) in read_tables(path)? {
            let config = |message: String| HarnessError::Config { path: path.to_path_buf(), message };
            if table.contains_key("command") || table.contains_key("method") {
                if methods.iter().any(|m| m.name == name) {
                    return Err(config(format!(
                        "`{name}` is a built-in method; a new entry needs another name"
                    )));
                }
                methods.push(entry(path, &name, &table, Origin::External, &[])?);
            } else {
                // Building the method validates the name and every key.
                methods::registry::create(&name, &table).map_err(|e| config(e.to_string()))?;
                let entry = methods.iter_mut().find(|m| m.name == name).expect("a registered method");
                entry.params = table;
            }
        }
        Ok(Self { path: path.to_path_buf(), methods })
    }

    /// Add the external methods of `peers.file` (`configs/peers.toml`) as peers, with
    /// `${DEFORMBENCH_PYTHON}` the peers' Python.
    pub fn add_peers(&mut self, peers: &PeerSetup) -> Result<(), HarnessError> {
        let path = &peers.file;
        let python = peers.python.to_string_lossy();
        let given = [(crate::peers::PYTHON_ENV, python.as_ref())];
        for (name, table) in read_tables(path)? {
            if self.methods.iter().any(|m| m.name == name) {
                return Err(HarnessError::Config {
                    path: path.to_path_buf(),
                    message: format!("peer `{name}` has the name of a method of {}", self.path.display()),
                });
            }
            self.methods.push(entry(path, &name, &table, Origin::Peer, &given)?);
        }
        Ok(())
    }

    /// The method called `name`.
    pub fn get(&self, name: &str) -> Option<&ConfiguredMethod> {
        self.methods.iter().find(|m| m.name == name)
    }

    /// The method called `name`, or an error listing the known names.
    pub fn find(&self, name: &str) -> Result<&ConfiguredMethod, String> {
        self.get(name).ok_or_else(|| {
            format!("unknown method `{name}`; known methods: {}", self.names().collect::<Vec<_>>().join(", "))
        })
    }

    /// Every method, in report order.
    pub fn methods(&self) -> &[ConfiguredMethod] {
        &self.methods
    }

    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.methods.iter().map(|m| m.name.as_str())
    }

    /// The file the methods came from.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

/// The top-level tables of `path`, in file order.
fn read_tables(path: &Path) -> Result<Vec<(String, toml::Table)>, HarnessError> {
    let text = std::fs::read_to_string(path)
        .map_err(|error| HarnessError::Io { path: path.to_path_buf(), error })?;
    let table: toml::Table = text.parse().map_err(|e: toml::de::Error| HarnessError::Config {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    let mut tables = Vec::new();
    for (name, value) in table {
        let toml::Value::Table(params) = value else {
            return Err(HarnessError::Config {
                path: path.to_path_buf(),
                message: format!("`{name}` must be a table of parameters, e.g. [{name}]"),
            });
        };
        tables.push((name, params));
    }
    // toml's map is sorted by key; report order follows the file.
    tables.sort_by_key(|(name, _)| text.find(&format!("[{name}]")).unwrap_or(usize::MAX));
    Ok(tables)
}

/// The entry `name` of `path` (its table `table`): a variant of a built-in method (`method`), or an
/// external method (`command`, `given` variables expanded before the environment's) of `origin`.
fn entry(
    path: &Path,
    name: &str,
    table: &toml::Table,
    origin: Origin,
    given: &[(&str, &str)],
) -> Result<ConfiguredMethod, HarnessError> {
    let config = |message: String| HarnessError::Config {
        path: path.to_path_buf(),
        message: format!("[{name}]: {message}"),
    };
    if !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-') {
        return Err(config("a method name is letters, digits, `_` and `-` (it names report files)".into()));
    }
    let params = match table.get("params") {
        None => toml::Table::new(),
        Some(toml::Value::Table(t)) => t.clone(),
        Some(_) => return Err(config("`params` must be a table".into())),
    };
    let summary = match table.get("summary") {
        None => None,
        Some(toml::Value::String(s)) => Some(s.clone()),
        Some(_) => return Err(config("`summary` must be a string".into())),
    };
    if let Some(base) = table.get("method") {
        if table.contains_key("command") {
            return Err(config(
                "give `method` (a variant of a built-in method) or `command`, not both".into(),
            ));
        }
        if let Some(key) = table.keys().find(|k| !VARIANT_KEYS.contains(&k.as_str())) {
            return Err(config(format!("unknown key `{key}` (a variant takes {})", VARIANT_KEYS.join(", "))));
        }
        let base = base.as_str().ok_or_else(|| config("`method` must be a method name".into()))?;
        let builtin = methods::registry::find(base).map_err(|e| config(e.to_string()))?;
        methods::registry::create(base, &params).map_err(|e| config(e.to_string()))?;
        return Ok(ConfiguredMethod {
            name: name.to_string(),
            // Our own implementation, whichever file named it.
            origin: Origin::BuiltIn,
            summary: summary.unwrap_or_else(|| format!("`{base}` with {params}").replace('\n', ", ")),
            params,
            implementation: Implementation::BuiltIn(builtin),
        });
    }
    if let Some(key) = table.keys().find(|k| !EXTERNAL_KEYS.contains(&k.as_str())) {
        return Err(config(format!(
            "unknown key `{key}` (an external method takes {}; its own parameters go in [{name}.params])",
            EXTERNAL_KEYS.join(", ")
        )));
    }
    let command: Vec<String> = match table.get("command") {
        Some(toml::Value::Array(items)) if !items.is_empty() => items
            .iter()
            .map(|v| v.as_str().map(str::to_string))
            .collect::<Option<_>>()
            .ok_or_else(|| config("`command` must be a list of strings".into()))?,
        _ => {
            return Err(config(
                "`command` must be a non-empty list of strings: [\"program\", \"arg\", …]".into(),
            ))
        }
    };
    let command = command
        .iter()
        .map(|part| crate::variables::expand_with(part, "the command of an external method", given))
        .collect::<Result<Vec<String>, String>>()
        .map_err(config)?;
    let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let working_dir = match table.get("working_dir") {
        None => base.clone(),
        Some(toml::Value::String(dir)) => {
            let dir = PathBuf::from(crate::variables::expand(dir, "working_dir").map_err(config)?);
            if dir.is_absolute() {
                dir
            } else {
                base.join(dir)
            }
        }
        Some(_) => return Err(config("`working_dir` must be a string".into())),
    };
    if !working_dir.is_dir() {
        return Err(config(format!("working_dir {} is not a directory", working_dir.display())));
    }
    let working_dir = working_dir.canonicalize().unwrap_or(working_dir);
    let timeout = match table.get("timeout_s") {
        None => methods::external::DEFAULT_TIMEOUT,
        Some(v) => match v.as_float().or_else(|| v.as_integer().map(|i| i as f64)) {
            Some(s) if s.is_finite() && s > 0.0 => Duration::from_secs_f64(s),
            _ => return Err(config("`timeout_s` must be a positive number of seconds".into())),
        },
    };
    let summary = summary.unwrap_or_else(|| format!("external program `{}`", command.join(" ")));
    let json = serde_json::to_value(&params).map_err(|e| config(format!("params: {e}")))?;
    let mut command = command.into_iter();
    Ok(ConfiguredMethod {
        name: name.to_string(),
        origin,
        params,
        summary,
        implementation: Implementation::External(ExternalEntry {
            program: command.next().expect("non-empty"),
            args: command.collect(),
            working_dir,
            timeout,
            params: json,
        }),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn load(text: &str) -> Result<MethodCatalog, String> {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("methods.toml");
        std::fs::write(&path, text).unwrap();
        MethodCatalog::load(&path).map_err(|e| e.to_string())
    }

    #[test]
    fn an_external_entry_is_read_in_file_order_after_the_built_in_ones() {
        std::env::set_var("DEFORMBENCH_CONFIG_TEST_PROGRAM", "/usr/bin/env");
        let catalog = load(
            "[zeta]\ncommand = [\"${DEFORMBENCH_CONFIG_TEST_PROGRAM}\", \"x.py\"]\ntimeout_s = 5\n\
             [zeta.params]\nk = 2\nname = \"a\"\n\n[alpha]\ncommand = [\"prog\"]\n\n[arap]\nmax_iterations = 5\n",
        )
        .unwrap();
        let names: Vec<&str> = catalog.names().collect();
        let builtin = methods::registry::METHODS.len();
        assert_eq!(&names[builtin..], &["zeta", "alpha"]);
        let zeta = catalog.get("zeta").unwrap();
        let Implementation::External(e) = &zeta.implementation else { panic!("not external") };
        assert_eq!((e.program.as_str(), e.args.as_slice()), ("/usr/bin/env", &["x.py".to_string()][..]));
        assert_eq!(e.timeout, Duration::from_secs(5));
        assert_eq!(e.params, serde_json::json!({"k": 2, "name": "a"}));
        assert_eq!(zeta.origin, Origin::External);
        assert_eq!(catalog.get("arap").unwrap().params.get("max_iterations").unwrap().as_integer(), Some(5));
    }

    #[test]
    fn bad_external_entries_are_named() {
        let err = load("[m]\ncommand = []\n").unwrap_err();
        assert!(err.contains("[m]") && err.contains("non-empty list"), "{err}");
        let err = load("[m]\ncommand = [\"p\"]\nk = 2\n").unwrap_err();
        assert!(err.contains("unknown key `k`") && err.contains("[m.params]"), "{err}");
        let err = load("[m]\ncommand = [\"${DEFORMBENCH_SURELY_UNSET}\"]\n").unwrap_err();
        assert!(err.contains("DEFORMBENCH_SURELY_UNSET"), "{err}");
        let err = load("[arap]\ncommand = [\"p\"]\n").unwrap_err();
        assert!(err.contains("built-in"), "{err}");
        let err = load("[m]\ncommand = [\"p\"]\ntimeout_s = 0\n").unwrap_err();
        assert!(err.contains("timeout_s"), "{err}");
        let err = load("[\"a b\"]\ncommand = [\"p\"]\n").unwrap_err();
        assert!(err.contains("letters, digits"), "{err}");
        let err = load("[nosuch]\nk = 1\n").unwrap_err();
        assert!(err.contains("unknown method `nosuch`"), "{err}");
        let err = load("[v]\nmethod = \"arap\"\n[v.params]\nwieghts = \"cotan\"\n").unwrap_err();
        assert!(err.contains("[v]") && err.contains("wieghts"), "{err}");
        let err = load("[v]\nmethod = \"nosuch\"\n").unwrap_err();
        assert!(err.contains("unknown method `nosuch`"), "{err}");
    }

    #[test]
    fn a_variant_runs_a_built_in_method_with_its_own_parameters() {
        let catalog =
            load("[arap_cotan]\nmethod = \"arap\"\n[arap_cotan.params]\nweights = \"cotan\"\n").unwrap();
        let variant = catalog.get("arap_cotan").unwrap();
        assert!(matches!(variant.implementation, Implementation::BuiltIn(e) if e.name == "arap"));
        assert_eq!(variant.origin, Origin::BuiltIn);
        assert_eq!(variant.params.get("weights").and_then(|v| v.as_str()), Some("cotan"));
        assert!(catalog.get("arap").unwrap().params.is_empty(), "the base keeps its own parameters");
    }
}
