//! File I/O of triangle meshes and of the survey edits.
//!
//! | format | read | write | module |
//! |---|---|---|---|
//! | OFF (`.off`), triangles only | [`read_off`] | [`write_off`] | [`off`] |
//! | Wavefront OBJ (`.obj`), polygons fan-triangulated | [`read_obj`] | [`write_obj`] | [`obj`] |
//! | Stanford PLY (`.ply`), ASCII and binary LE/BE, polygons fan-triangulated | [`read_ply`] | [`write_ply`] (binary LE, doubles) | [`ply`] |
//! | glTF 2.0 (`.gltf`, `.glb`) | [`read_gltf`] | [`write_glb`] (binary only, `f32` positions) | [`gltf`] |
//! | survey selection (`.sel`) | [`read_selection`] | [`write_selection`] | [`survey`] |
//! | survey handle transform (`.def`) | [`read_transform`] | [`write_transform`] | [`survey`] |
//! | libigl dense matrix (`.dmat`, text), e.g. a per-vertex selection column or an index list | [`read_dmat`], [`read_dmat_column`], [`read_dmat_integers`] | — | [`dmat`] |
//! | vertex-id list (0-based ids, `#` comments) | [`read_index_list`] | — | [`index_list`] |
//!
//! [`read_mesh`] and [`write_mesh`] choose among the mesh formats by extension. Faces of more than 3
//! corners (OBJ, PLY) are fan-triangulated from their first corner ([`polygon`]), which is correct for
//! convex polygons and those star-shaped from corner 0; errors then still name the file's face.
//! Readers keep vertices that no face uses; [`crate::clean::drop_unreferenced`] removes them and maps
//! results back.
//!
//! Conventions shared by every reader and writer:
//! - every error is wrapped in [`MeshError::InFile`], so its message starts with the file's path;
//!   text formats additionally name the 1-based line ([`MeshError::Syntax`]) or the element (vertex,
//!   face) at fault;
//! - vertex order is preserved (per-vertex data such as a `.sel` selection stays valid), and text
//!   writers print every `f64` with the shortest representation that parses back to the same value;
//! - every writer goes through [`atomic_write`]: a failed write never leaves a partial file behind and
//!   never clobbers an existing file.

pub mod dmat;
pub mod gltf;
pub mod index_list;
pub mod obj;
pub mod off;
pub mod ply;
pub mod polygon;
pub mod survey;

pub use self::gltf::{encode_glb, read_gltf, write_glb};
pub use dmat::{read_dmat, read_dmat_column, read_dmat_integers, DenseMatrix};
pub use index_list::read_index_list;
pub use obj::{parse_obj, read_obj, write_obj};
pub use off::{parse_off, read_off, write_off};
pub use ply::{parse_ply, read_ply, write_ply};
pub use survey::{read_selection, read_transform, write_selection, write_transform};

use std::ffi::OsString;
use std::fmt;
use std::fs::{self, File, OpenOptions};
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use crate::error::{MeshError, Result};
use crate::mesh::TriMesh;

/// A mesh file format, chosen from a file extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MeshFormat {
    /// Object File Format, `.off`.
    Off,
    /// Wavefront OBJ, `.obj`.
    Obj,
    /// Stanford PLY (ASCII or binary), `.ply`.
    Ply,
    /// glTF 2.0 JSON with external or embedded buffers, `.gltf`.
    Gltf,
    /// glTF 2.0 binary container, `.glb`.
    Glb,
}

impl MeshFormat {
    /// The format of `path` from its extension (case-insensitive: `off`, `obj`, `ply`, `gltf`, `glb`).
    /// Fails with [`MeshError::Invalid`] naming the file for any other or a missing extension.
    pub fn from_path(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let ext = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase());
        match ext.as_deref() {
            Some("off") => Ok(MeshFormat::Off),
            Some("obj") => Ok(MeshFormat::Obj),
            Some("ply") => Ok(MeshFormat::Ply),
            Some("gltf") => Ok(MeshFormat::Gltf),
            Some("glb") => Ok(MeshFormat::Glb),
            Some(other) => Err(MeshError::Invalid(format!(
                "unknown mesh file extension '.{other}' (supported: .off, .obj, .ply, .gltf, .glb)"
            ))
            .in_file(path)),
            None => Err(MeshError::Invalid(
                "mesh file has no extension (supported: .off, .obj, .ply, .gltf, .glb)".into(),
            )
            .in_file(path)),
        }
    }
}

/// Read a triangle mesh (`#V x 3` positions, `#F x 3` triangles) from `path`, choosing the reader
/// from the extension (see [`MeshFormat::from_path`]).
///
/// Errors name the file; see [`read_off`], [`read_obj`], [`read_ply`] and [`read_gltf`] for what each
/// format accepts.
pub fn read_mesh(path: impl AsRef<Path>) -> Result<TriMesh> {
    let path = path.as_ref();
    match MeshFormat::from_path(path)? {
        MeshFormat::Off => read_off(path),
        MeshFormat::Obj => read_obj(path),
        MeshFormat::Ply => read_ply(path),
        MeshFormat::Gltf | MeshFormat::Glb => read_gltf(path),
    }
}

/// The vertex and face counts an OFF or PLY file's header announces, read from its first 64 KiB
/// without reading the rest: what a caller can know of a mesh's size before loading it (the harness
/// estimates a run's memory from it). `None` for other formats, an unreadable file or header, and
/// counts the file is too small to hold (at least 3 bytes a vertex and 4 a face: a lying header is
/// for the reader to report). A PLY face of more than 3 corners becomes several triangles, so the
/// face count is a lower bound there.
pub fn header_counts(path: impl AsRef<Path>) -> Option<(usize, usize)> {
    use std::io::Read;
    let path = path.as_ref();
    let format = MeshFormat::from_path(path).ok()?;
    if !matches!(format, MeshFormat::Off | MeshFormat::Ply) {
        return None;
    }
    let file = File::open(path).ok()?;
    let size = file.metadata().ok()?.len();
    let mut head = Vec::new();
    file.take(64 << 10).read_to_end(&mut head).ok()?;
    let text = String::from_utf8_lossy(&head);
    let counts = match format {
        MeshFormat::Off => {
            let mut lines = data_lines(&text).map(|(_, l)| l);
            let mut tokens: Vec<&str> = lines.next()?.split_ascii_whitespace().collect();
            if !off::is_off_keyword(tokens.first()?) {
                return None;
            }
            tokens.remove(0);
            if tokens.is_empty() {
                tokens = lines.next()?.split_ascii_whitespace().collect();
            }
            (tokens.first()?.parse().ok()?, tokens.get(1)?.parse().ok()?)
        }
        _ => {
            let header = text.split("end_header").next()?;
            let count = |element: &str| {
                header.lines().find_map(|l| {
                    let mut t = l.split_ascii_whitespace();
                    (t.next() == Some("element") && t.next() == Some(element))
                        .then(|| t.next()?.parse().ok())?
                })
            };
            (count("vertex")?, count("face")?)
        }
    };
    let needed = (counts.0 as u64).saturating_mul(3).saturating_add((counts.1 as u64).saturating_mul(4));
    (needed <= size).then_some(counts)
}

/// Write `mesh` (`#V x 3` positions, `#F x 3` triangles) to `path`, choosing the writer from the
/// extension: `.off`, `.obj`, `.ply` (binary, doubles) or `.glb` (without colors). Writing `.gltf` is not supported (a `.glb`
/// holds the same content in one file). Atomic, see [`atomic_write`].
pub fn write_mesh(path: impl AsRef<Path>, mesh: &TriMesh) -> Result<()> {
    let path = path.as_ref();
    match MeshFormat::from_path(path)? {
        MeshFormat::Off => write_off(path, mesh),
        MeshFormat::Obj => write_obj(path, mesh),
        MeshFormat::Ply => write_ply(path, mesh),
        MeshFormat::Glb => write_glb(path, mesh, None),
        MeshFormat::Gltf => Err(MeshError::Invalid(
            "writing .gltf is not supported; write a .glb (binary glTF) instead".into(),
        )
        .in_file(path)),
    }
}

/// Create or replace the file `path` with what `write` produces, atomically.
///
/// `write` receives a buffered writer on a fresh temporary file `.{name}.tmp-{pid}-{n}` in the same
/// directory as `path` (so the final rename never crosses file systems). Only when `write` returns
/// `Ok` and the data is flushed and synced is the temporary file renamed onto `path`; on any error (or
/// a panic inside `write`) the temporary file is removed and an existing `path` is left untouched.
/// Errors are wrapped with the file name. The new file gets default permissions, not those of a
/// file it replaces.
pub fn atomic_write<F>(path: impl AsRef<Path>, write: F) -> Result<()>
where
    F: FnOnce(&mut dyn Write) -> Result<()>,
{
    let path = path.as_ref();
    atomic_write_inner(path, write).map_err(|e| e.in_file(path))
}

/// Distinguishes concurrent writes to the same path from one process (threads share the pid).
static TEMP_COUNTER: AtomicU64 = AtomicU64::new(0);

fn atomic_write_inner<F>(path: &Path, write: F) -> Result<()>
where
    F: FnOnce(&mut dyn Write) -> Result<()>,
{
    let name = path.file_name().ok_or_else(|| MeshError::Invalid("the path does not name a file".into()))?;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let mut temp_name = OsString::from(".");
    temp_name.push(name);
    temp_name.push(format!(".tmp-{}-{}", std::process::id(), TEMP_COUNTER.fetch_add(1, Ordering::Relaxed)));
    let temp = TempFile { path: dir.join(temp_name) };
    // create_new: never follow or truncate something that happens to have the temporary name.
    let file = OpenOptions::new().write(true).create_new(true).open(&temp.path)?;
    let mut writer = BufWriter::new(file);
    write(&mut writer)?;
    let file = writer.into_inner().map_err(|e| MeshError::Io(e.into_error()))?;
    // Sync before the rename, or a crash could leave `path` naming an empty file.
    file.sync_all()?;
    drop(file);
    fs::rename(&temp.path, path)?;
    temp.keep();
    sync_dir(dir);
    Ok(())
}

/// The temporary file of [`atomic_write`]; removed on drop unless it was renamed into place.
struct TempFile {
    path: PathBuf,
}

impl TempFile {
    fn keep(self) {
        std::mem::forget(self);
    }
}

impl Drop for TempFile {
    fn drop(&mut self) {
        // The write already failed; a failure to clean up must not hide that error.
        let _ = fs::remove_file(&self.path);
    }
}

/// Make the rename itself durable. Best effort: not every platform or file system can sync a
/// directory, and the data is already safe in the renamed file.
fn sync_dir(dir: &Path) {
    #[cfg(unix)]
    if let Ok(d) = File::open(dir) {
        let _ = d.sync_all();
    }
    #[cfg(not(unix))]
    let _ = dir;
}

/// The whole file as UTF-8 text; invalid UTF-8 is a [`MeshError::Syntax`] naming the line.
pub(crate) fn read_text(path: &Path) -> Result<String> {
    let bytes = fs::read(path)?;
    String::from_utf8(bytes).map_err(|e| {
        let valid = e.utf8_error().valid_up_to();
        let line = e.as_bytes().get(..valid).map_or(0, |b| b.iter().filter(|&&c| c == b'\n').count()) + 1;
        MeshError::Syntax { line, message: "not valid UTF-8 text".into() }
    })
}

/// The lines of `text` that carry data: `(1-based line number, content)` with `#` comments (full-line
/// or trailing) removed and blank lines skipped. The content is not trimmed: callers split it on
/// ASCII whitespace anyway.
pub(crate) fn data_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    text.lines().enumerate().filter_map(|(i, line)| {
        let content = match line.find('#') {
            Some(k) => &line[..k],
            None => line,
        };
        if content.bytes().all(|b| b.is_ascii_whitespace()) {
            None
        } else {
            Some((i + 1, content))
        }
    })
}

/// Shorthand for a [`MeshError::Syntax`] at `line`.
pub(crate) fn syntax(line: usize, message: impl Into<String>) -> MeshError {
    MeshError::Syntax { line, message: message.into() }
}

/// Formats an `f64` so that it parses back to the identical value, compactly: plain decimals for
/// ordinary magnitudes, scientific notation where plain decimals would be long (Rust's `Display`
/// never switches to an exponent, so `1e300` would print 301 digits).
pub(crate) struct RoundTrip(pub f64);

impl fmt::Display for RoundTrip {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let a = self.0.abs();
        if a == 0.0 || (1e-5..1e16).contains(&a) {
            write!(f, "{}", self.0)
        } else {
            write!(f, "{:e}", self.0)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_formatting_is_exact() {
        for x in [0.0, -0.0, 1.0, -2.5, 0.1, 1.0 / 3.0, 1e-300, 5e-324, 1e300, f64::MAX, 123456.789e-7] {
            let s = RoundTrip(x).to_string();
            assert_eq!(s.parse::<f64>().unwrap().to_bits(), x.to_bits(), "{x} printed as {s}");
            assert!(s.len() < 30, "{x} printed as {s}");
        }
    }

    #[test]
    fn header_counts_are_read_from_off_and_ply_headers_alone() {
        let dir = tempfile::tempdir().unwrap();
        let off = dir.path().join("a.off");
        fs::write(&off, "# a comment\nOFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1 2\n3 1 3 2\n").unwrap();
        assert_eq!(header_counts(&off), Some((4, 2)));
        let ply = dir.path().join("a.ply");
        let mesh = TriMesh::new(
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]],
            vec![[0, 1, 2], [1, 3, 2]],
        )
        .unwrap();
        write_ply(&ply, &mesh).unwrap();
        assert_eq!(header_counts(&ply), Some((4, 2)));
        let lying = dir.path().join("b.off");
        fs::write(&lying, "OFF\n1000000000 1 0\n0 0 0\n").unwrap();
        assert_eq!(header_counts(&lying), None, "counts the file cannot hold");
        let obj = dir.path().join("a.obj");
        write_obj(&obj, &mesh).unwrap();
        assert_eq!(header_counts(&obj), None);
    }

    #[test]
    fn data_lines_strip_comments_and_blanks() {
        let text = "# c\nOFF # trailing\n\n   \n 1 2 3\r\n#\n";
        let lines: Vec<_> = data_lines(text).collect();
        assert_eq!(lines, vec![(2, "OFF "), (5, " 1 2 3")]);
    }
}
