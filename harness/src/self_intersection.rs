//! The self-intersection check of the results: open3d's `TriangleMesh.is_self_intersecting` on every
//! result, through `python/self_intersection.py` (the project's venv, see `scripts/python-env`).
//! Opt-in (`--self-intersections`): open3d's test is quadratic-ish in the face count, about 25 s per
//! result on the 80K-face bumpy plane.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::error::HarnessError;
use crate::record::CaseResult;
use crate::scenario::LoadedScenario;

/// Results with more faces are not checked (left empty): open3d's test took over 15 minutes on the
/// 400K-face bar of the `bar-sweep-200k` scenario without finishing.
pub const MAX_FACES: usize = 100_000;

/// The check's script, among the project files ([`crate::paths::project_files`]).
fn script() -> Result<PathBuf, HarnessError> {
    Ok(crate::paths::python_dir()?.join("self_intersection.py"))
}

/// `is_self_intersecting` of every case of `results` that has a result with at most [`MAX_FACES`]
/// faces (in order; `None` for the others), computed by `python` with open3d on two processes.
pub fn self_intersections(
    python: &Path,
    results: &[CaseResult],
    scenarios: &[LoadedScenario],
) -> Result<Vec<Option<bool>>, HarnessError> {
    let dir = std::env::temp_dir().join(format!("deformbench-self-intersection-{}", std::process::id()));
    std::fs::create_dir_all(&dir).map_err(|error| HarnessError::Io { path: dir.clone(), error })?;
    let script = script()?;
    let outcome = (|| {
        let mut files: Vec<(usize, PathBuf)> = Vec::new();
        for (i, r) in results.iter().enumerate() {
            let (Some(positions), Some(scenario)) =
                (&r.positions, scenarios.iter().find(|s| s.spec.name == r.scenario))
            else {
                continue;
            };
            if r.faces > MAX_FACES {
                continue;
            }
            let path = dir.join(format!("{i}.off"));
            meshes::io::write_off(&path, &scenario.mesh.with_positions(positions.clone())?)?;
            files.push((i, path));
        }
        // Two processes, largest meshes spread over both (the plane dominates).
        files.sort_by_key(|(i, _)| std::cmp::Reverse(results[*i].faces));
        let halves: [Vec<&PathBuf>; 2] = [
            files.iter().step_by(2).map(|(_, p)| p).collect(),
            files.iter().skip(1).step_by(2).map(|(_, p)| p).collect(),
        ];
        let children = halves
            .iter()
            .filter(|h| !h.is_empty())
            .map(|half| {
                Command::new(python)
                    .arg(&script)
                    .args(half.iter())
                    .stdout(std::process::Stdio::piped())
                    .stderr(std::process::Stdio::piped())
                    .spawn()
                    .map_err(|error| HarnessError::Io { path: python.to_path_buf(), error })
            })
            .collect::<Result<Vec<_>, _>>()?;
        let mut answers = vec![None; results.len()];
        for child in children {
            let out = child
                .wait_with_output()
                .map_err(|error| HarnessError::Io { path: python.to_path_buf(), error })?;
            if !out.status.success() {
                return Err(HarnessError::Report(format!(
                    "{} failed: {}",
                    script.display(),
                    String::from_utf8_lossy(&out.stderr).trim()
                )));
            }
            for line in String::from_utf8_lossy(&out.stdout).lines() {
                let Some((path, answer)) = line.rsplit_once(',') else { continue };
                if let Some((i, _)) = files.iter().find(|(_, p)| p.as_os_str() == path) {
                    answers[*i] = Some(answer == "true");
                }
            }
        }
        if let Some((i, _)) = files.iter().find(|(i, _)| answers[*i].is_none()) {
            return Err(HarnessError::Report(format!(
                "{}: no self-intersection answer for {} / {}",
                script.display(),
                results[*i].scenario,
                results[*i].method
            )));
        }
        Ok(answers)
    })();
    let _ = std::fs::remove_dir_all(&dir);
    outcome
}
