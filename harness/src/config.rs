//! The methods of a run, as configured: `configs/methods.toml` holds a table per method, either the
//! parameters of a built-in method (missing keys take the papers' defaults), a variant of one
//! (`method` and its `params`, laid over the base method's table), or an external program
//! (`command`, see [`ExternalEntry`]); `configs/peers.toml`, in the same format, holds the peer
//! libraries' adapters that `--peers` adds, and `configs/sweeps.toml` the parameter sweeps that
//! `--sweeps` adds. A variant whose `params` hold lists is a sweep ([`crate::sweep`]): one variant
//! per value. Unknown names and keys are errors that name the file.

use std::path::{Path, PathBuf};
use std::time::Duration;

use serde::{Deserialize, Serialize};

use crate::error::HarnessError;
use crate::sweep::{self, SweepPosition};
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
const EXTERNAL_KEYS: &[&str] = &["command", "working_dir", "timeout_s", "kind", "summary", "params"];

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
    /// `kind = "iterative"` (default `"direct"`): a solve without `converged` is then reported as
    /// "convergence unknown", not finished.
    pub iterative: bool,
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
    /// A method in this process, given by the program that runs the harness.
    Provided(ProvidedMethod),
}

impl std::fmt::Debug for Implementation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Implementation::BuiltIn(entry) => write!(f, "BuiltIn({})", entry.name),
            Implementation::External(e) => f.debug_tuple("External").field(e).finish(),
            Implementation::Provided(p) => f.debug_tuple("Provided").field(p).finish(),
        }
    }
}

/// A method a program hands the harness in its own process (the Python module's
/// `deformbench.run(methods=[my_method])`): a fresh instance per case from `create`. Reported as
/// an external method (not this suite's), without a process or a protocol.
#[derive(Clone)]
pub struct ProvidedMethod {
    pub name: String,
    /// One line: what it is (`list`, the page).
    pub summary: String,
    pub create: std::sync::Arc<dyn Fn() -> Result<Box<dyn DeformationMethod>, MethodError> + Send + Sync>,
}

impl std::fmt::Debug for ProvidedMethod {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ProvidedMethod").field("name", &self.name).finish_non_exhaustive()
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
    /// The sweeps it is a point of (a base method is one where a sweep sets its own values).
    pub sweeps: Vec<SweepPosition>,
    /// The scenarios it runs on unless a scenario names it (`None`: every scenario that does not
    /// restrict its methods); a sweep file's `scenarios`.
    pub runs_on: Option<Vec<String>>,
    /// The file its entry is in (empty for a built-in method without a table).
    pub file: PathBuf,
    /// Why it cannot run on this machine, when it cannot: an external entry whose environment
    /// variable is unset, whose working directory or program is missing. It disables itself: a run
    /// that asks for it by name fails with the reason, any other run goes on without it.
    pub unavailable: Option<String>,
}

impl ConfiguredMethod {
    /// A fresh instance; an external method's program is started (its stderr written to
    /// `stderr_log`, its thread variables set to `threads`). A built-in instance shares `solves`
    /// ([`methods::scale_aware::solve_memo`]) with the others made with it: a run gives every case
    /// its one memo, so that the `scale_aware_ora` case of an edit step takes the identical solve
    /// of its `scale_aware` case instead of computing it again.
    pub fn create(
        &self,
        stderr_log: Option<PathBuf>,
        threads: usize,
        solves: &methods::scale_aware::SolveMemo,
    ) -> Result<Box<dyn DeformationMethod>, MethodError> {
        if let Some(why) = &self.unavailable {
            return Err(MethodError::External {
                method: self.name.clone(),
                message: format!("unavailable: {why}"),
            });
        }
        match &self.implementation {
            Implementation::BuiltIn(entry) => (entry.create)(&self.params, solves),
            Implementation::Provided(p) => (p.create)(),
            Implementation::External(e) => Ok(Box::new(ExternalMethod::start(ExternalSpec {
                name: self.name.clone(),
                program: e.program.clone(),
                args: e.args.clone(),
                working_dir: Some(e.working_dir.clone()),
                env: crate::threads::external_environment(threads),
                timeout: e.timeout,
                params: e.params.clone(),
                stderr_log,
                iterative: e.iterative,
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
        Self::load_with(path, &[])
    }

    /// [`MethodCatalog::load`] with `given` variables expanded before the environment's
    /// (`--python` as `${DEFORMBENCH_PYTHON}`).
    pub fn load_with(path: &Path, given: &[(&str, &str)]) -> Result<Self, HarnessError> {
        let mut methods: Vec<ConfiguredMethod> = methods::registry::METHODS
            .iter()
            .map(|m| ConfiguredMethod {
                name: m.name.to_string(),
                origin: Origin::BuiltIn,
                params: toml::Table::new(),
                implementation: Implementation::BuiltIn(m),
                summary: m.summary.to_string(),
                sweeps: Vec::new(),
                runs_on: None,
                file: PathBuf::new(),
                unavailable: None,
            })
            .collect();
        let tables = read_tables(path)?;
        let is_entry = |t: &toml::Table| t.contains_key("command") || t.contains_key("method");
        // The built-in methods' own tables first: variants lay their params over them.
        for (name, table) in tables.iter().filter(|(_, t)| !is_entry(t)) {
            let config = |message: String| HarnessError::Config { path: path.to_path_buf(), message };
            // Building the method validates the name and every key.
            methods::registry::create(name, table).map_err(|e| config(e.to_string()))?;
            let entry = methods.iter_mut().find(|m| &m.name == name).expect("a registered method");
            entry.params = table.clone();
            entry.file = path.to_path_buf();
        }
        let mut catalog = Self { path: path.to_path_buf(), methods };
        for (name, table) in tables.iter().filter(|(_, t)| is_entry(t)) {
            if catalog.methods.iter().any(|m| &m.name == name) {
                return Err(HarnessError::Config {
                    path: path.to_path_buf(),
                    message: format!("`{name}` is a built-in method; a new entry needs another name"),
                });
            }
            catalog.add_entry(path, name, table, Origin::External, given, None)?;
        }
        Ok(catalog)
    }

    /// Add the entries of a method file of the user's (`--methods FILE`): external methods and
    /// variants in the `methods.toml` format, paths relative to `path`, `given` variables expanded
    /// before the environment's. A name another file already gives is an error naming both.
    pub fn add_method_file(&mut self, path: &Path, given: &[(&str, &str)]) -> Result<(), HarnessError> {
        for (name, table) in read_tables(path)? {
            let config = |message: String| HarnessError::Config { path: path.to_path_buf(), message };
            if let Some(other) = self.get(&name) {
                let where_ = if other.file.as_os_str().is_empty() {
                    "a built-in method".to_string()
                } else {
                    format!("already an entry of {}", other.file.display())
                };
                return Err(config(format!("[{name}]: `{name}` is {where_}; give this one another name")));
            }
            if !table.contains_key("command") && !table.contains_key("method") {
                return Err(config(format!(
                    "[{name}]: an entry of a method file is an external program (`command`) or a variant \
                     (`method = \"arap\"` and its `params`)"
                )));
            }
            self.add_entry(path, &name, &table, Origin::External, given, None)?;
        }
        Ok(())
    }

    /// Add a method given in-process (`deformbench.run`); its name must be new.
    pub fn add_provided(&mut self, provided: &ProvidedMethod) -> Result<(), HarnessError> {
        if let Some(other) = self.get(&provided.name) {
            let whose = if other.file.as_os_str().is_empty() {
                "a built-in method".to_string()
            } else {
                format!("an entry of {}", other.file.display())
            };
            return Err(HarnessError::Method(MethodError::External {
                method: provided.name.clone(),
                message: format!("the name is taken by {whose}; give the method another name"),
            }));
        }
        self.methods.push(ConfiguredMethod {
            name: provided.name.clone(),
            origin: Origin::External,
            params: toml::Table::new(),
            implementation: Implementation::Provided(provided.clone()),
            summary: provided.summary.clone(),
            sweeps: Vec::new(),
            runs_on: None,
            file: PathBuf::new(),
            unavailable: None,
        });
        Ok(())
    }

    /// Add the sweeps of `path` (`configs/sweeps.toml`, `--sweeps`): variants with list-valued
    /// `params`, run on the scenarios its top-level `scenarios` list names (default: every one that
    /// does not restrict its methods).
    pub fn add_sweeps(&mut self, path: &Path) -> Result<(), HarnessError> {
        let config = |message: String| HarnessError::Config { path: path.to_path_buf(), message };
        let text = std::fs::read_to_string(path)
            .map_err(|error| HarnessError::Io { path: path.to_path_buf(), error })?;
        let mut top: toml::Table = text.parse().map_err(|e: toml::de::Error| config(e.to_string()))?;
        let scenarios = match top.remove("scenarios") {
            None => None,
            Some(toml::Value::Array(list)) => Some(
                list.iter()
                    .map(|v| v.as_str().map(str::to_string))
                    .collect::<Option<Vec<String>>>()
                    .ok_or_else(|| config("`scenarios` must be a list of scenario names".into()))?,
            ),
            Some(_) => return Err(config("`scenarios` must be a list of scenario names".into())),
        };
        let peers = peer_names(&path.with_file_name("peers.toml"));
        for (name, table) in tables_in_file_order(top).map_err(config)? {
            let Some(base) = table.get("method").and_then(toml::Value::as_str) else {
                return Err(config(format!("[{name}]: a sweep names its base method: method = \"…\"")));
            };
            if self.get(base).is_none() && peers.iter().any(|p| p == base) {
                // A peer's knob: swept when the run has the peers.
                eprintln!("note: sweep [{name}] of the peer `{base}` not run (add --peers)");
                continue;
            }
            self.add_entry(path, &name, &table, Origin::BuiltIn, &[], scenarios.as_deref())?;
        }
        Ok(())
    }

    /// Add the external methods of `peers.file` (`configs/peers.toml`) as peers, with
    /// `${DEFORMBENCH_PYTHON}` the peers' Python.
    pub fn add_peers(&mut self, peers: &PeerSetup) -> Result<(), HarnessError> {
        let path = &peers.file;
        let python = peers.python.to_string_lossy();
        let given = [(crate::paths::PYTHON_ENV, python.as_ref())];
        for (name, table) in read_tables(path)? {
            if self.methods.iter().any(|m| m.name == name) {
                return Err(HarnessError::Config {
                    path: path.to_path_buf(),
                    message: format!("peer `{name}` has the name of a method of {}", self.path.display()),
                });
            }
            self.add_entry(path, &name, &table, Origin::Peer, &given, None)?;
        }
        Ok(())
    }

    /// Add the entry `name` of `path`: a variant (one method, or a sweep's points) or an external
    /// method of `origin`.
    fn add_entry(
        &mut self,
        path: &Path,
        name: &str,
        table: &toml::Table,
        origin: Origin,
        given: &[(&str, &str)],
        runs_on: Option<&[String]>,
    ) -> Result<(), HarnessError> {
        let base_name = table.get("method").and_then(toml::Value::as_str);
        let params = match table.get("params") {
            Some(toml::Value::Table(t)) => t.clone(),
            _ => toml::Table::new(),
        };
        let Some(base_name) = base_name.filter(|_| sweep::is_sweep(&params)) else {
            let mut method = entry(path, name, table, origin, given, self)?;
            method.runs_on = runs_on.map(<[String]>::to_vec);
            self.methods.push(method);
            return Ok(());
        };
        let summary = table.get("summary").and_then(toml::Value::as_str);
        let sweep = SweepEntry { path, name, summary, runs_on };
        self.add_sweep(&sweep, base_name, &params).map_err(|message| HarnessError::Config {
            path: path.to_path_buf(),
            message: format!("[{name}]: {message}"),
        })
    }

    /// Add the points of `sweep`, a sweep of the method `base_name` with the lists of values of
    /// `params`: one variant per point, named by its values (the swept ones, then the ones every
    /// point shares), laid over the base method's table. `Err`: what is wrong, without the entry's
    /// name.
    fn add_sweep(&mut self, sweep: &SweepEntry, base_name: &str, params: &toml::Table) -> Result<(), String> {
        let base = self.sweep_base(base_name)?;
        let (points, shared) = sweep::expand(params)?;
        self.forget_sweep(sweep.name);
        for (position, point) in points.iter().enumerate() {
            self.add_point(sweep, &base, position, point, &shared)?;
        }
        Ok(())
    }

    /// The method `base_name` a sweep varies: a method of its own, a built-in one, or an external
    /// program or peer (whose points send it other `params`); not a variant. `Err` lists the
    /// methods a sweep can vary.
    fn sweep_base(&self, base_name: &str) -> Result<ConfiguredMethod, String> {
        let base = self.get(base_name).filter(|m| match &m.implementation {
            Implementation::BuiltIn(e) => e.name == m.name,
            Implementation::External(_) => !m.name.contains('['),
            Implementation::Provided(_) => false,
        });
        base.cloned().ok_or_else(|| {
            format!(
                "`method = \"{base_name}\"`: a sweep varies a built-in, external or peer method (known: {})",
                self.names().filter(|n| !n.contains('[')).collect::<Vec<_>>().join(", ")
            )
        })
    }

    /// Take every method out of the sweep `name`: a sweep of the same name declared again
    /// (sweeps.toml extending methods.toml's) replaces the earlier one's line.
    fn forget_sweep(&mut self, name: &str) {
        for m in &mut self.methods {
            m.sweeps.retain(|p| p.sweep != name);
        }
    }

    /// Add `point`, at `position` of `sweep` (its shared values `shared`), over the method `base`:
    /// a position of `base` itself when the point's parameters are its own, of the existing method
    /// of the point's name, else a new method. `Err`: what is wrong, without the entry's name.
    fn add_point(
        &mut self,
        sweep: &SweepEntry,
        base: &ConfiguredMethod,
        position: usize,
        point: &sweep::Point,
        shared: &toml::Table,
    ) -> Result<(), String> {
        // Sorted again: keys the base lacks would come last ([`in_key_order`]).
        let params = in_key_order(sweep::laid_over(&point.apply(&base.params), shared));
        let here = SweepPosition { sweep: sweep.name.to_string(), position, values: point.values_text() };
        if params == base.params {
            self.methods.iter_mut().find(|m| m.name == base.name).expect("the base").sweeps.push(here);
            return Ok(());
        }
        let mut named = point.clone();
        named.values.extend(shared.clone());
        let point_name = named.name(&base.name);
        if let Some(existing) = self.methods.iter_mut().find(|m| m.name == point_name) {
            if existing.params != params {
                return Err(format!("`{point_name}` is configured twice with different parameters"));
            }
            existing.sweeps.push(here);
            return Ok(());
        }
        let implementation = point_implementation(base, &params).map_err(|e| format!("{point_name}: {e}"))?;
        self.methods.push(ConfiguredMethod {
            name: point_name,
            origin: base.origin,
            params,
            implementation,
            summary: match sweep.summary {
                Some(s) => format!("{s}: {}", named.values_text()),
                None => format!("`{}` with {}", base.name, named.values_text()),
            },
            sweeps: vec![here],
            runs_on: sweep.runs_on.map(<[String]>::to_vec),
            file: sweep.path.to_path_buf(),
            unavailable: base.unavailable.clone(),
        });
        Ok(())
    }

    /// The method called `name`.
    pub fn get(&self, name: &str) -> Option<&ConfiguredMethod> {
        self.methods.iter().find(|m| m.name == name)
    }

    /// The method called `name`, or an error listing the known names.
    pub fn find(&self, name: &str) -> Result<&ConfiguredMethod, String> {
        self.get(name).ok_or_else(|| {
            format!(
                "unknown method `{name}`{}; known methods: {}",
                crate::error::did_you_mean(name, self.names()),
                self.names().collect::<Vec<_>>().join(", ")
            )
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
    let config = |message: String| HarnessError::Config { path: path.to_path_buf(), message };
    let table: toml::Table = text.parse().map_err(|e: toml::de::Error| config(e.to_string()))?;
    tables_in_file_order(table).map_err(config)
}

/// The method names of the peers' file `path` (its top-level tables, in file order); none when it is missing or
/// not TOML (the peers' own loading reports that when they are asked for).
pub fn peer_names(path: &Path) -> Vec<String> {
    std::fs::read_to_string(path)
        .ok()
        .and_then(|text| text.parse::<toml::Table>().ok())
        .map(|table| table.into_iter().filter(|(_, v)| v.is_table()).map(|(k, _)| k).collect())
        .unwrap_or_default()
}

/// The top-level tables of the parsed file `top`, in file order (toml's `preserve_order` keeps
/// it), each with its own keys sorted ([`in_key_order`]); `Err` names a top-level key that is not
/// a table.
fn tables_in_file_order(top: toml::Table) -> Result<Vec<(String, toml::Table)>, String> {
    // Of several keys that are not tables, the first in sorted order is named, as when toml's map
    // was sorted.
    if let Some(name) = top.iter().filter(|(_, value)| !value.is_table()).map(|(name, _)| name).min() {
        return Err(format!("`{name}` must be a table of parameters, e.g. [{name}]"));
    }
    let tables = top.into_iter().filter_map(|(name, value)| match value {
        toml::Value::Table(table) => Some((name, in_key_order(table))),
        _ => None,
    });
    Ok(tables.collect())
}

/// `table` with its keys, and those of every table within it, in sorted order. toml's
/// `preserve_order` (enabled for the file order of the entries) keeps an entry's keys in file
/// order; everything after reading relies on the sorted order toml's map had before: the unknown
/// key an error names (the first), `params` as a variant's summary writes them, a sweep's keys in
/// its points' names and in the order of its points ([`sweep::expand`]), and the order
/// [`methods::registry::create`] checks and names the keys of a parameter error in.
pub(crate) fn in_key_order(table: toml::Table) -> toml::Table {
    let mut entries: Vec<(String, toml::Value)> = table.into_iter().collect();
    entries.sort_by(|(a, _), (b, _)| a.cmp(b));
    entries.into_iter().map(|(key, value)| (key, value_in_key_order(value))).collect()
}

/// `value` with the keys of every table within it sorted ([`in_key_order`]).
fn value_in_key_order(value: toml::Value) -> toml::Value {
    match value {
        toml::Value::Table(table) => toml::Value::Table(in_key_order(table)),
        toml::Value::Array(items) => toml::Value::Array(items.into_iter().map(value_in_key_order).collect()),
        other => other,
    }
}

/// A sweep's entry, as its points need it: its file, its name, its `summary` (the points' begin
/// with it) and the scenarios its points run on (`None`: every one that does not restrict its
/// methods).
struct SweepEntry<'a> {
    path: &'a Path,
    name: &'a str,
    summary: Option<&'a str>,
    runs_on: Option<&'a [String]>,
}

/// What runs a sweep point with `params` over the method `base`: `base`'s built-in method (the
/// parameters checked here), or its external program sent `params` (which checks them when it
/// starts). `Err`: why the parameters are refused.
fn point_implementation(base: &ConfiguredMethod, params: &toml::Table) -> Result<Implementation, String> {
    Ok(match &base.implementation {
        Implementation::BuiltIn(builtin) => {
            methods::registry::create(builtin.name, params).map_err(|e| e.to_string())?;
            Implementation::BuiltIn(builtin)
        }
        Implementation::External(e) => Implementation::External(ExternalEntry {
            params: serde_json::to_value(params).map_err(|e| e.to_string())?,
            ..e.clone()
        }),
        Implementation::Provided(_) => {
            return Err("a method given in-process takes no parameters".to_string())
        }
    })
}

/// The entry `name` of `path` (its table `table`): a variant of a built-in method (`method`), or an
/// external method (`command`, `given` variables expanded before the environment's) of `origin`.
fn entry(
    path: &Path,
    name: &str,
    table: &toml::Table,
    origin: Origin,
    given: &[(&str, &str)],
    catalog: &MethodCatalog,
) -> Result<ConfiguredMethod, HarnessError> {
    let config = |message: String| HarnessError::Config {
        path: path.to_path_buf(),
        message: format!("[{name}]: {message}"),
    };
    let entry = Entry::read(path, name, table).map_err(config)?;
    let method = match table.get("method") {
        Some(base) => entry.variant(base, catalog),
        None => entry.external(origin, given),
    };
    method.map_err(config)
}

/// An entry of a method file with the keys every entry may have read: its file, name and table,
/// its `params` (default empty) and `summary`.
struct Entry<'a> {
    path: &'a Path,
    name: &'a str,
    table: &'a toml::Table,
    params: toml::Table,
    summary: Option<String>,
}

impl<'a> Entry<'a> {
    /// The entry `name` of `path` with the table `table`, its name checked (it names report files)
    /// and its `params` and `summary` read. `Err`: what is wrong, without the entry's name.
    fn read(path: &'a Path, name: &'a str, table: &'a toml::Table) -> Result<Self, String> {
        if !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-') {
            return Err("a method name is letters, digits, `_` and `-` (it names report files)".into());
        }
        let params = match table.get("params") {
            None => toml::Table::new(),
            Some(toml::Value::Table(t)) => t.clone(),
            Some(_) => return Err("`params` must be a table".into()),
        };
        let summary = match table.get("summary") {
            None => None,
            Some(toml::Value::String(s)) => Some(s.clone()),
            Some(_) => return Err("`summary` must be a string".into()),
        };
        Ok(Self { path, name, table, params, summary })
    }

    /// The variant of the built-in method `base` (the value of `method`) that this entry is: its
    /// `params` laid over the base method's table as `catalog` configures it, and checked. `Err`:
    /// what is wrong, without the entry's name.
    fn variant(self, base: &toml::Value, catalog: &MethodCatalog) -> Result<ConfiguredMethod, String> {
        if self.table.contains_key("command") {
            return Err("give `method` (a variant of a built-in method) or `command`, not both".into());
        }
        if let Some(key) = self.table.keys().find(|k| !VARIANT_KEYS.contains(&k.as_str())) {
            return Err(format!("unknown key `{key}` (a variant takes {})", VARIANT_KEYS.join(", ")));
        }
        let base = base.as_str().ok_or_else(|| "`method` must be a method name".to_string())?;
        let builtin = methods::registry::find(base).map_err(|e| e.to_string())?;
        let params = self.params;
        let summary = self.summary.unwrap_or_else(|| format!("`{base}` with {params}").replace('\n', ", "));
        // The base method as configured, with the variant's own values.
        let params = match catalog.get(base) {
            // Keys the base lacks would come last: sorted again, as every entry's keys are.
            Some(configured) => in_key_order(sweep::laid_over(&configured.params, &params)),
            None => params,
        };
        methods::registry::create(base, &params).map_err(|e| e.to_string())?;
        Ok(ConfiguredMethod {
            name: self.name.to_string(),
            // Our own implementation, whichever file named it.
            origin: Origin::BuiltIn,
            summary,
            params,
            implementation: Implementation::BuiltIn(builtin),
            sweeps: Vec::new(),
            runs_on: None,
            file: self.path.to_path_buf(),
            unavailable: None,
        })
    }

    /// The external method of `origin` that this entry is (`command`, `given` variables expanded
    /// before the environment's): unavailable, with the reason, when this machine lacks what it
    /// needs. `Err`: what is wrong in the entry, without its name.
    fn external(self, origin: Origin, given: &[(&str, &str)]) -> Result<ConfiguredMethod, String> {
        if let Some(key) = self.table.keys().find(|k| !EXTERNAL_KEYS.contains(&k.as_str())) {
            return Err(format!(
                "unknown key `{key}` (an external method takes {}; its own parameters go in [{}.params])",
                EXTERNAL_KEYS.join(", "),
                self.name
            ));
        }
        let command = command_list(self.table)?;
        // What the machine lacks (a variable, a directory, a program) disables the entry, not the run.
        let mut unavailable: Option<String> = None;
        let command = expanded_command(&command, given, &mut unavailable);
        let working_dir = working_dir(self.table, self.path, &mut unavailable)?;
        if unavailable.is_none() {
            unavailable = program_found(&command[0], &working_dir).err();
        }
        let timeout = request_timeout(self.table)?;
        let iterative = is_iterative(self.table)?;
        let summary = self.summary.unwrap_or_else(|| format!("external program `{}`", command.join(" ")));
        let json = serde_json::to_value(&self.params).map_err(|e| format!("params: {e}"))?;
        let mut command = command.into_iter();
        Ok(ConfiguredMethod {
            name: self.name.to_string(),
            origin,
            params: self.params,
            summary,
            sweeps: Vec::new(),
            runs_on: None,
            file: self.path.to_path_buf(),
            unavailable,
            implementation: Implementation::External(ExternalEntry {
                program: command.next().expect("non-empty"),
                args: command.collect(),
                working_dir,
                timeout,
                params: json,
                iterative,
            }),
        })
    }
}

/// The `command` of an external method's table, as written: a non-empty list of strings. `Err`:
/// what it must be.
fn command_list(table: &toml::Table) -> Result<Vec<String>, String> {
    match table.get("command") {
        Some(toml::Value::Array(items)) if !items.is_empty() => items
            .iter()
            .map(|v| v.as_str().map(str::to_string))
            .collect::<Option<_>>()
            .ok_or_else(|| "`command` must be a list of strings".into()),
        _ => Err("`command` must be a non-empty list of strings: [\"program\", \"arg\", …]".into()),
    }
}

/// `command` with its `${VAR}`s expanded (`given` before the environment's). A part that cannot be
/// expanded is kept as written and makes the method `unavailable` (the first reason kept).
fn expanded_command(
    command: &[String],
    given: &[(&str, &str)],
    unavailable: &mut Option<String>,
) -> Vec<String> {
    command
        .iter()
        .map(|part| {
            crate::variables::expand_with(part, "the command of an external method", given).unwrap_or_else(
                |why| {
                    unavailable.get_or_insert(why);
                    part.clone()
                },
            )
        })
        .collect()
}

/// The directory an external method of the file `path` runs in: its `working_dir` (`${VAR}`s
/// expanded, relative to the file's directory), default the file's directory; canonical when it
/// exists. One that cannot be expanded or is not a directory makes the method `unavailable` (the
/// first reason kept). `Err`: `working_dir` is not a string.
fn working_dir(
    table: &toml::Table,
    path: &Path,
    unavailable: &mut Option<String>,
) -> Result<PathBuf, String> {
    let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let working_dir = match table.get("working_dir") {
        None => base.clone(),
        Some(toml::Value::String(dir)) => match crate::variables::expand(dir, "working_dir") {
            Ok(expanded) if Path::new(&expanded).is_absolute() => PathBuf::from(expanded),
            Ok(expanded) => base.join(expanded),
            Err(why) => {
                unavailable.get_or_insert(why);
                base.clone()
            }
        },
        Some(_) => return Err("`working_dir` must be a string".into()),
    };
    if unavailable.is_none() && !working_dir.is_dir() {
        *unavailable = Some(format!("its working_dir {} is not a directory", working_dir.display()));
    }
    Ok(working_dir.canonicalize().unwrap_or(working_dir))
}

/// How long an external method may take over one request: its `timeout_s` (seconds), default
/// [`methods::external::DEFAULT_TIMEOUT`]. `Err`: not a positive number.
fn request_timeout(table: &toml::Table) -> Result<Duration, String> {
    match table.get("timeout_s") {
        None => Ok(methods::external::DEFAULT_TIMEOUT),
        Some(v) => match v.as_float().or_else(|| v.as_integer().map(|i| i as f64)) {
            Some(s) if s.is_finite() && s > 0.0 => Ok(Duration::from_secs_f64(s)),
            _ => Err("`timeout_s` must be a positive number of seconds".into()),
        },
    }
}

/// Whether an external method is iterative: its `kind`, `"direct"` (the default) or
/// `"iterative"`. `Err`: another value.
fn is_iterative(table: &toml::Table) -> Result<bool, String> {
    match table.get("kind").map(toml::Value::as_str) {
        None | Some(Some("direct")) => Ok(false),
        Some(Some("iterative")) => Ok(true),
        Some(_) => Err("`kind` is \"direct\" or \"iterative\"".into()),
    }
}

/// Whether `program` can be started from `working_dir`: a path (with a `/`) names a file there or
/// anywhere; a bare name is looked up on `PATH`. `Err` says what is missing.
fn program_found(program: &str, working_dir: &Path) -> Result<(), String> {
    if program.contains('/') {
        let file = working_dir.join(program);
        return if file.is_file() {
            Ok(())
        } else {
            Err(format!("its program {} does not exist", file.display()))
        };
    }
    let on_path = std::env::var_os("PATH")
        .is_some_and(|paths| std::env::split_paths(&paths).any(|dir| dir.join(program).is_file()));
    if on_path {
        Ok(())
    } else {
        Err(format!("its program `{program}` is not on PATH"))
    }
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
    fn a_bad_parameter_names_its_file_key_and_value_alone() {
        // configs/methods.toml
        let dir = tempfile::tempdir().unwrap();
        let methods = dir.path().join("methods.toml");
        std::fs::write(&methods, "[arap]\ntolerance = nan\n").unwrap();
        let e = MethodCatalog::load(&methods).unwrap_err().to_string();
        assert_eq!(e, format!("{}: arap: tolerance = NaN: must be a finite number >= 0", methods.display()));
        // A --methods file's variant.
        std::fs::write(&methods, "[arap]\nmax_iterations = 100\n").unwrap();
        let mut catalog = MethodCatalog::load(&methods).unwrap();
        let mine = dir.path().join("mine.toml");
        std::fs::write(&mine, "[sa]\nmethod = \"scale_aware\"\nparams = { normal_sweeps = 0 }\n").unwrap();
        let e = catalog.add_method_file(&mine, &[]).unwrap_err().to_string();
        assert_eq!(e, format!("{}: [sa]: scale_aware: normal_sweeps = 0: must be >= 1", mine.display()));
        // A sweep point.
        let sweeps = dir.path().join("sweeps.toml");
        std::fs::write(
            &sweeps,
            "[turns]\nmethod = \"scale_aware\"\nparams = { refactor_turn = [0.1, -0.5] }\n",
        )
        .unwrap();
        let e = catalog.add_sweeps(&sweeps).unwrap_err().to_string();
        assert!(e.starts_with(&format!("{}: [turns]: ", sweeps.display())), "{e}");
        assert!(e.ends_with("scale_aware: refactor_turn = -0.5: must be a finite number >= 0"), "{e}");
    }

    #[test]
    fn bad_external_entries_are_named() {
        let err = load("[m]\ncommand = []\n").unwrap_err();
        assert!(err.contains("[m]") && err.contains("non-empty list"), "{err}");
        let err = load("[m]\ncommand = [\"p\"]\nk = 2\n").unwrap_err();
        assert!(err.contains("unknown key `k`") && err.contains("[m.params]"), "{err}");
        // What the machine lacks disables the entry (issue 38), the others load.
        let catalog = load("[m]\ncommand = [\"${DEFORMBENCH_SURELY_UNSET}\"]\n").unwrap();
        let why = catalog.get("m").unwrap().unavailable.clone().unwrap();
        assert!(why.contains("DEFORMBENCH_SURELY_UNSET"), "{why}");
        assert!(catalog.get("arap").unwrap().unavailable.is_none());
        let why = load("[m]\ncommand = [\"./p\"]\n").unwrap().get("m").unwrap().unavailable.clone().unwrap();
        assert!(why.contains("p does not exist"), "{why}");
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

    #[test]
    fn a_sweep_is_one_named_variant_per_value_laid_over_the_base_table() {
        let catalog = load(
            "[isolines]\nisolines = 20\nbeta = 0.02\n\
             [per_field]\nmethod = \"isolines\"\nparams = { isolines = [5, 20, 40] }\n\
             [fields]\nmethod = \"hirm\"\nparams = { min_fields = [6, 12], threshold = 1.001 }\n",
        )
        .unwrap();
        let builtin = methods::registry::METHODS.len();
        let names: Vec<&str> = catalog.names().skip(builtin).collect();
        // isolines = 20 is [isolines] itself: not a method of its own.
        assert_eq!(
            names,
            [
                "isolines[isolines=5]",
                "isolines[isolines=40]",
                "hirm[min_fields=6,threshold=1.001]",
                "hirm[min_fields=12,threshold=1.001]"
            ]
        );
        let five = catalog.get("isolines[isolines=5]").unwrap();
        assert_eq!(five.params, "isolines = 5\nbeta = 0.02".parse::<toml::Table>().unwrap());
        assert!(matches!(five.implementation, Implementation::BuiltIn(e) if e.name == "isolines"));
        let at = |m: &ConfiguredMethod| -> Vec<(String, usize, String)> {
            m.sweeps.iter().map(|p| (p.sweep.clone(), p.position, p.values.clone())).collect()
        };
        assert_eq!(at(five), [("per_field".to_string(), 0, "isolines=5".to_string())]);
        assert_eq!(
            at(catalog.get("isolines").unwrap()),
            [("per_field".to_string(), 1, "isolines=20".to_string())]
        );
        assert_eq!(
            at(catalog.get("hirm[min_fields=12,threshold=1.001]").unwrap()),
            [("fields".to_string(), 1, "min_fields=12".to_string())]
        );
        let err = load("[s]\nmethod = \"isolines\"\nparams = { isolines = [] }\n").unwrap_err();
        assert!(err.contains("[s]") && err.contains("`isolines`"), "{err}");
        let err = load("[s]\nmethod = \"isolines\"\nparams = { isolines = [1] }\n").unwrap_err();
        assert!(err.contains("isolines[isolines=1]"), "{err}");
    }

    #[test]
    fn entries_keep_file_order_and_their_keys_the_sorted_order() {
        // A comment naming a later table does not move it ahead (the order was once found by
        // searching the text for `[name]`).
        let catalog = load(
            "# alpha comes before [beta]\n[alpha]\ncommand = [\"p\"]\n[beta]\ncommand = [\"p\"]\n\
             [fields]\nmethod = \"hirm\"\nparams = { threshold = 1.001, min_fields = [6, 12], isolines = [5, 10] }\n",
        )
        .unwrap();
        let builtin = methods::registry::METHODS.len();
        let names: Vec<&str> = catalog.names().skip(builtin).collect();
        // A sweep's keys in sorted order, whatever the file's: its points' names and order.
        assert_eq!(
            names,
            [
                "alpha",
                "beta",
                "hirm[isolines=5,min_fields=6,threshold=1.001]",
                "hirm[isolines=5,min_fields=12,threshold=1.001]",
                "hirm[isolines=10,min_fields=6,threshold=1.001]",
                "hirm[isolines=10,min_fields=12,threshold=1.001]"
            ]
        );
        let catalog =
            load("[v]\nmethod = \"arap\"\nparams = { weights = \"cotan\", max_iterations = 5 }\n").unwrap();
        assert_eq!(
            catalog.get("v").unwrap().summary,
            "`arap` with max_iterations = 5, weights = \"cotan\", "
        );
        let keys: Vec<&String> = catalog.get("v").unwrap().params.keys().collect();
        assert_eq!(keys, ["max_iterations", "weights"]);
        let err = load("[m]\ncommand = [\"p\"]\nzz = 1\nkk = 2\n").unwrap_err();
        assert!(err.contains("unknown key `kk`"), "{err}");
        let err = load("b = 1\na = 2\n").unwrap_err();
        assert!(err.contains("`a` must be a table"), "{err}");
    }

    #[test]
    fn a_sweep_file_adds_points_where_it_says_and_shares_the_existing_ones() {
        let dir = tempfile::tempdir().unwrap();
        let methods = dir.path().join("methods.toml");
        std::fs::write(&methods, "[few]\nmethod = \"isolines\"\nparams = { isolines = [10] }\n").unwrap();
        let sweeps = dir.path().join("sweeps.toml");
        std::fs::write(
            &sweeps,
            "scenarios = [\"bar\"]\n[per_field]\nmethod = \"isolines\"\nparams = { isolines = [10, 30] }\n",
        )
        .unwrap();
        let mut catalog = MethodCatalog::load(&methods).unwrap();
        catalog.add_sweeps(&sweeps).unwrap();
        let ten = catalog.get("isolines[isolines=10]").unwrap();
        assert_eq!(ten.runs_on, None, "methods.toml's point runs everywhere");
        assert_eq!(ten.sweeps.iter().map(|p| p.sweep.as_str()).collect::<Vec<_>>(), ["few", "per_field"]);
        // A sweep of the same name again is one line, the later one's.
        std::fs::write(&sweeps, "[few]\nmethod = \"isolines\"\nparams = { isolines = [30, 10] }\n").unwrap();
        catalog.add_sweeps(&sweeps).unwrap();
        let ten = catalog.get("isolines[isolines=10]").unwrap();
        let few: Vec<usize> = ten.sweeps.iter().filter(|p| p.sweep == "few").map(|p| p.position).collect();
        assert_eq!(few, [1]);
        let thirty = catalog.get("isolines[isolines=30]").unwrap();
        assert_eq!(thirty.runs_on, Some(vec!["bar".to_string()]));
        std::fs::write(&sweeps, "[x]\ncommand = [\"p\"]\n").unwrap();
        let err = catalog.add_sweeps(&sweeps).unwrap_err().to_string();
        assert!(err.contains("[x]") && err.contains("method"), "{err}");
    }
}
