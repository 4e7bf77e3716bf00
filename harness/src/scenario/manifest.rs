//! Collections taken from a manifest: a CSV with one row per mesh file (column `file`, relative to
//! the manifest) and attribute columns, filtered by conditions on those columns, so tiers of a
//! dataset are data.
//!
//! ```toml
//! [manifest]
//! file = "${DEFORM_DATASET_DIR}/MANIFEST.csv"
//! where = ["vertices <= 30000", "watertight = true", "category = \"cad\""]   # all must hold
//! # files = ["goathead.obj", "block.off"]   # and, if given, only these rows (each must exist)
//! ```
//!
//! A condition is `<column> <op> <value>` with `op` one of `=`, `!=`, `<`, `<=`, `>`, `>=`; a
//! number compares as a number (every row's cell must then be one), `true`/`false` and a
//! `"quoted"` string compare as text. A column the manifest does not have, a malformed condition,
//! or a condition that leaves no file is an error of the scenario, before anything runs.

use std::path::{Path, PathBuf};

use serde::Deserialize;

use super::selection::PathContext;

/// The `[manifest]` table of a scenario.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ManifestSpec {
    /// The manifest CSV (relative to the scenario file, absolute, or `${VAR}/...`).
    pub file: String,
    /// Conditions every selected row meets.
    #[serde(default, rename = "where")]
    pub conditions: Vec<String>,
    /// Only these rows (by `file`), after the conditions.
    #[serde(default)]
    pub files: Vec<String>,
}

/// A comparison of a condition.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Op {
    Eq,
    Ne,
    Lt,
    Le,
    Gt,
    Ge,
}

/// A parsed condition.
#[derive(Clone, Debug, PartialEq)]
struct Condition {
    column: String,
    op: Op,
    value: Value,
}

#[derive(Clone, Debug, PartialEq)]
enum Value {
    Number(f64),
    Text(String),
}

impl Condition {
    /// Parse `<column> <op> <value>`.
    fn parse(text: &str) -> Result<Condition, String> {
        let bad = |why: &str| {
            format!("where = \"{text}\": {why}; write `<column> <op> <value>`, op one of = != < <= > >=")
        };
        // The two-character operators first, so `<=` is not read as `<`.
        let ops =
            [("<=", Op::Le), (">=", Op::Ge), ("!=", Op::Ne), ("=", Op::Eq), ("<", Op::Lt), (">", Op::Gt)];
        let (at, token, op) = ops
            .iter()
            .filter_map(|(token, op)| text.find(token).map(|at| (at, *token, *op)))
            .min_by_key(|(at, token, _)| (*at, std::cmp::Reverse(token.len())))
            .ok_or_else(|| bad("no operator"))?;
        let column = text[..at].trim();
        let value = text[at + token.len()..].trim();
        if column.is_empty() || column.contains(char::is_whitespace) {
            return Err(bad("the column is one word"));
        }
        let value = if let Some(quoted) = value.strip_prefix('"').and_then(|v| v.strip_suffix('"')) {
            Value::Text(quoted.to_string())
        } else if value == "true" || value == "false" {
            Value::Text(value.to_string())
        } else if let Ok(number) = value.parse::<f64>() {
            if !number.is_finite() {
                return Err(bad("the number is not finite"));
            }
            Value::Number(number)
        } else {
            return Err(bad("the value is a number, true, false or a \"quoted\" string"));
        };
        if matches!(value, Value::Text(_)) && !matches!(op, Op::Eq | Op::Ne) {
            return Err(bad("text compares only with = and !="));
        }
        Ok(Condition { column: column.to_string(), op, value })
    }

    /// Whether `cell` meets the condition; an error when a number is asked of a non-number.
    fn holds(&self, cell: &str) -> Result<bool, String> {
        let ordering = match &self.value {
            Value::Number(n) => {
                let c: f64 = cell.trim().parse().map_err(|_| format!("`{cell}` is not a number"))?;
                c.partial_cmp(n).ok_or_else(|| format!("`{cell}` is not a number"))?
            }
            Value::Text(t) => cell.trim().cmp(t.as_str()),
        };
        use std::cmp::Ordering::*;
        Ok(match self.op {
            Op::Eq => ordering == Equal,
            Op::Ne => ordering != Equal,
            Op::Lt => ordering == Less,
            Op::Le => ordering != Greater,
            Op::Gt => ordering == Greater,
            Op::Ge => ordering != Less,
        })
    }
}

/// The manifest columns a case keeps of its mesh's row, for the dataset report's filters and
/// groups (those the manifest has).
pub const MEMBER_ATTRIBUTES: [&str; 7] =
    ["vertices", "faces", "components", "boundary_loops", "watertight", "genus", "category"];

/// One selected row: the mesh file and its [`MEMBER_ATTRIBUTES`].
#[derive(Clone, Debug, PartialEq)]
pub struct ManifestEntry {
    pub path: PathBuf,
    pub columns: Vec<(String, String)>,
}

impl ManifestSpec {
    /// The rows of the manifest that meet every condition (and are in `files`, when given), in the
    /// manifest's order of `file` names sorted; paths relative to the manifest's directory.
    pub fn entries(&self, paths: &PathContext) -> Result<Vec<ManifestEntry>, String> {
        let manifest = paths.resolve_existing("manifest.file", &self.file)?;
        let at = |message: String| format!("manifest {}: {message}", manifest.display());
        let conditions: Vec<Condition> =
            self.conditions.iter().map(|c| Condition::parse(c)).collect::<Result<_, _>>()?;
        let mut reader = csv::Reader::from_path(&manifest).map_err(|e| at(e.to_string()))?;
        let header: Vec<String> =
            reader.headers().map_err(|e| at(e.to_string()))?.iter().map(str::to_string).collect();
        let column = |name: &str| {
            header
                .iter()
                .position(|h| h == name)
                .ok_or_else(|| at(format!("no column `{name}`; its columns are {}", header.join(", "))))
        };
        let file_column = column("file")?;
        let condition_columns: Vec<usize> =
            conditions.iter().map(|c| column(&c.column)).collect::<Result<_, _>>()?;
        let base = manifest.parent().map(Path::to_path_buf).unwrap_or_default();
        let mut entries = Vec::new();
        let mut names = Vec::new();
        for (row, record) in reader.records().enumerate() {
            let record = record.map_err(|e| at(format!("row {}: {e}", row + 2)))?;
            let cell = |c: usize| record.get(c).unwrap_or("");
            let name = cell(file_column).to_string();
            if name.is_empty() {
                return Err(at(format!("row {}: empty `file`", row + 2)));
            }
            names.push(name.clone());
            let mut keep = true;
            for (condition, &c) in conditions.iter().zip(&condition_columns) {
                keep &= condition.holds(cell(c)).map_err(|e| {
                    at(format!("row {} ({name}), column `{}`: {e}", row + 2, condition.column))
                })?;
            }
            if keep && (self.files.is_empty() || self.files.contains(&name)) {
                let columns = header
                    .iter()
                    .zip(record.iter())
                    .filter(|(h, _)| MEMBER_ATTRIBUTES.contains(&h.as_str()))
                    .map(|(h, v)| (h.clone(), v.to_string()))
                    .collect();
                entries.push(ManifestEntry { path: base.join(&name), columns });
            }
        }
        if let Some(missing) = self.files.iter().find(|f| !names.contains(f)) {
            return Err(at(format!("files: `{missing}` is not a row of the manifest")));
        }
        if entries.is_empty() {
            return Err(at(format!(
                "no row meets where = {:?} and files = {:?}",
                self.conditions, self.files
            )));
        }
        entries.sort_by(|a, b| a.path.cmp(&b.path));
        Ok(entries)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn context(dir: &Path) -> PathContext {
        PathContext { base: dir.to_path_buf(), stem: None, read: Default::default() }
    }

    fn write_manifest(dir: &Path) {
        std::fs::write(
            dir.join("MANIFEST.csv"),
            "file,vertices,watertight,category\n\
             b.obj,30000,true,cad\n\
             a.obj,1200,false,\"organic-scan\"\n\
             c.off,30001,true,cad\n",
        )
        .unwrap();
    }

    fn names(spec: &ManifestSpec, dir: &Path) -> Result<Vec<String>, String> {
        Ok(spec
            .entries(&context(dir))?
            .iter()
            .map(|e| e.path.file_name().unwrap().to_string_lossy().into_owned())
            .collect())
    }

    #[test]
    fn conditions_select_rows_sorted_by_file() {
        let dir = tempfile::tempdir().unwrap();
        write_manifest(dir.path());
        let spec = |conditions: &[&str], files: &[&str]| ManifestSpec {
            file: "MANIFEST.csv".into(),
            conditions: conditions.iter().map(|s| s.to_string()).collect(),
            files: files.iter().map(|s| s.to_string()).collect(),
        };
        assert_eq!(names(&spec(&[], &[]), dir.path()).unwrap(), ["a.obj", "b.obj", "c.off"]);
        assert_eq!(names(&spec(&["vertices <= 30000"], &[]), dir.path()).unwrap(), ["a.obj", "b.obj"]);
        assert_eq!(names(&spec(&["vertices<30000"], &[]), dir.path()).unwrap(), ["a.obj"]);
        assert_eq!(
            names(&spec(&["vertices >= 30000", "watertight = true"], &[]), dir.path()).unwrap(),
            ["b.obj", "c.off"]
        );
        assert_eq!(
            names(&spec(&["category = \"cad\"", "vertices > 30000"], &[]), dir.path()).unwrap(),
            ["c.off"]
        );
        assert_eq!(names(&spec(&["category != \"cad\""], &[]), dir.path()).unwrap(), ["a.obj"]);
        assert_eq!(names(&spec(&["watertight = true"], &["c.off"]), dir.path()).unwrap(), ["c.off"]);
        let entries = spec(&[], &["a.obj"]).entries(&context(dir.path())).unwrap();
        assert!(entries[0].columns.contains(&("category".to_string(), "organic-scan".to_string())));
    }

    #[test]
    fn bad_conditions_name_what_is_wrong() {
        let dir = tempfile::tempdir().unwrap();
        write_manifest(dir.path());
        let err = |conditions: &[&str], files: &[&str]| {
            ManifestSpec {
                file: "MANIFEST.csv".into(),
                conditions: conditions.iter().map(|s| s.to_string()).collect(),
                files: files.iter().map(|s| s.to_string()).collect(),
            }
            .entries(&context(dir.path()))
            .unwrap_err()
        };
        assert!(err(&["genus >= 1"], &[]).contains("no column `genus`"));
        assert!(err(&["vertices ~ 3"], &[]).contains("no operator"));
        assert!(err(&["category < \"cad\""], &[]).contains("text compares only"));
        assert!(err(&["category = cad"], &[]).contains("quoted"));
        assert!(err(&["category >= 3"], &[]).contains("row 2 (b.obj), column `category`"));
        assert!(err(&["vertices > 1e9"], &[]).contains("no row meets"));
        assert!(err(&[], &["z.obj"]).contains("`z.obj` is not a row"));
        let missing = ManifestSpec { file: "NOPE.csv".into(), ..Default::default() };
        assert!(missing.entries(&context(dir.path())).unwrap_err().contains("NOPE.csv"));
    }
}
