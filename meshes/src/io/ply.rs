//! Stanford PLY (`.ply`): a reader through `ply-rs-bw` for the ASCII, binary little endian and binary
//! big endian encodings, and a binary little endian writer of doubles.
//!
//! Read from the `vertex` element: the scalar properties `x`, `y`, `z`, of any numeric type (`char` to
//! `double`, converted to `f64` exactly); every other vertex property (normals, colors, ...) is
//! ignored. From the `face` element: the list property `vertex_indices` (or, when a file has no such
//! property, `vertex_index`, which some writers use), with any integer count and index types. Faces
//! of more than 3 corners are fan-triangulated from their first corner (see [`super::polygon`]:
//! correct for convex polygons and those star-shaped from corner 0). Other elements (`edge`,
//! `material`, ...) are read past and ignored. A file without a `face` element is a point cloud and
//! is rejected ([`MeshError::Empty`]).
//!
//! Vertices and faces are numbered 0-based in file order, the numbers errors use.

use std::fs::File;
use std::io::{BufRead, BufReader, Read, Write};
use std::path::Path;

use ply_rs_bw::parser::{ParseError, Parser, Reader};
use ply_rs_bw::ply::{
    ElementDef, Encoding, Header, Property, PropertyAccess, PropertyAccessResult, PropertyType, ScalarType,
};

use super::atomic_write;
use super::polygon::Polygons;
use crate::error::{MeshError, Result};
use crate::mesh::TriMesh;

/// The face list properties accepted, in order of preference.
const FACE_LISTS: [&str; 2] = ["vertex_indices", "vertex_index"];

/// Read the PLY file `path` (ASCII or binary, either endianness) into a mesh of `#V x 3` positions
/// (every `vertex` element, in file order, including vertices no face uses) and `#T x 3` triangles
/// (every `face` in file order, a face of `k > 3` corners giving `k - 2` consecutive fan triangles).
///
/// Errors (all wrapped in [`MeshError::InFile`]): [`MeshError::Syntax`] with the 1-based line for a
/// malformed header line or ASCII element; [`MeshError::Truncated`] when the file ends before every
/// element its header announces; [`MeshError::Format`] for a missing `vertex` element, a missing or
/// list-typed `x`/`y`/`z`, a `face` element without an integer `vertex_indices`/`vertex_index` list,
/// a malformed binary element or a negative index (each naming the element); and, naming the face,
/// [`MeshError::IndexOutOfRange`] and [`MeshError::Untriangulable`]; [`MeshError::NonFiniteCoordinate`]
/// naming the vertex.
pub fn read_ply(path: impl AsRef<Path>) -> Result<TriMesh> {
    let path = path.as_ref();
    File::open(path).map_err(MeshError::from).and_then(parse_ply).map_err(|e| e.in_file(path))
}

/// Parse a PLY file's content from `source` (see [`read_ply`]) into a mesh. Errors are not wrapped
/// with a file name.
pub fn parse_ply(source: impl Read) -> Result<TriMesh> {
    let mut reader = Reader::new(BufReader::new(source));
    let header = Parser::<Ignored>::new().read_header(&mut reader).map_err(header_error)?;
    let layout = Layout::of(&header)?;

    let mut positions: Vec<[f64; 3]> = Vec::new();
    let mut faces = Polygons::new();
    // The payload holds the elements in header order; each must be read (or read past) in turn.
    let mut line = reader.line();
    for def in header.elements.values() {
        let mut elements =
            ElementReader { reader: &mut reader, encoding: header.encoding, line: &mut line, def };
        if def.name == "vertex" {
            // Cap the reservation: a lying header must not trigger a huge allocation.
            positions.reserve(def.count.min(1 << 20));
            let parser = Parser::<PlyVertex>::new();
            for v in 0..def.count {
                let p = elements.next(&parser, v)?;
                positions.push(p.xyz.map(|x| x.unwrap_or(f64::NAN)));
            }
        } else if def.name == "face" {
            let parser = Parser::<PlyFace>::new();
            for f in 0..def.count {
                let face = elements.next(&parser, f)?;
                let corners =
                    if layout.face_list == FACE_LISTS[0] { face.vertex_indices } else { face.vertex_index };
                let corners = corners
                    .into_iter()
                    .map(|i| {
                        u32::try_from(i).map_err(|_| {
                            MeshError::Format(format!("PLY: face {f}: vertex index {i} is negative"))
                        })
                    })
                    .collect::<Result<Vec<u32>>>()?;
                faces.push(corners);
            }
        } else {
            let parser = Parser::<Ignored>::new();
            for i in 0..def.count {
                elements.next(&parser, i)?;
            }
        }
    }
    let triangles = faces.triangulate(positions.len())?;
    TriMesh::new(positions, triangles)
}

/// Write `mesh` (`#V x 3` positions, `#F x 3` triangles) to `path` as binary little endian PLY:
/// `double` `x y z` per vertex and a `uchar`-counted `uint` `vertex_indices` list per face, so
/// positions round-trip to the last bit. Atomic, see [`atomic_write`]; errors name the file.
///
/// Written by hand rather than through `ply-rs-bw`'s writer, which needs one property map per
/// element; the layout is fixed and the reader (through `ply-rs-bw`) checks it in the tests.
pub fn write_ply(path: impl AsRef<Path>, mesh: &TriMesh) -> Result<()> {
    atomic_write(path, |w| write_ply_to(w, mesh))
}

fn write_ply_to(w: &mut dyn Write, mesh: &TriMesh) -> Result<()> {
    write!(
        w,
        "ply\nformat binary_little_endian 1.0\ncomment deformbench meshes::io::write_ply\n\
         element vertex {}\nproperty double x\nproperty double y\nproperty double z\n\
         element face {}\nproperty list uchar uint vertex_indices\nend_header\n",
        mesh.n_vertices(),
        mesh.n_faces()
    )?;
    for p in mesh.positions() {
        for x in p {
            w.write_all(&x.to_le_bytes())?;
        }
    }
    for t in mesh.triangles() {
        w.write_all(&[3])?;
        for i in t {
            w.write_all(&i.to_le_bytes())?;
        }
    }
    Ok(())
}

/// What the header says about where the mesh is, checked before any payload is read.
struct Layout {
    face_list: &'static str,
}

impl Layout {
    fn of(header: &Header) -> Result<Self> {
        let vertex = header.elements.get("vertex").ok_or_else(|| {
            let names: Vec<&str> = header.elements.keys().map(String::as_str).collect();
            MeshError::Format(format!("PLY: the header has no 'vertex' element (elements: {names:?})"))
        })?;
        for axis in ["x", "y", "z"] {
            match vertex.properties.get(axis).map(|p| &p.data_type) {
                Some(PropertyType::Scalar(_)) => {}
                Some(PropertyType::List(..)) => {
                    return Err(MeshError::Format(format!(
                        "PLY: vertex property '{axis}' is a list, not a number"
                    )))
                }
                None => {
                    let names: Vec<&str> = vertex.properties.keys().map(String::as_str).collect();
                    return Err(MeshError::Format(format!(
                        "PLY: element 'vertex' has no property '{axis}' (properties: {names:?})"
                    )));
                }
            }
        }
        let Some(face) = header.elements.get("face") else {
            // A point cloud: TriMesh::new reports the missing faces.
            return Ok(Self { face_list: FACE_LISTS[0] });
        };
        let found = FACE_LISTS.iter().find_map(|&name| face.properties.get(name).map(|p| (name, p)));
        let Some((face_list, property)) = found else {
            let names: Vec<&str> = face.properties.keys().map(String::as_str).collect();
            return Err(MeshError::Format(format!(
                "PLY: element 'face' has no list property 'vertex_indices' or 'vertex_index' (properties: {names:?})"
            )));
        };
        match &property.data_type {
            PropertyType::List(count, index) if is_integer(count) && is_integer(index) => {
                Ok(Self { face_list })
            }
            other => Err(MeshError::Format(format!(
                "PLY: face property '{face_list}' is {other:?}; expected a list of integers"
            ))),
        }
    }
}

fn is_integer(t: &ScalarType) -> bool {
    !matches!(t, ScalarType::Float | ScalarType::Double)
}

/// Reads the elements of one header element definition one by one, so errors can name the element
/// (and, in ASCII, the line) that is at fault.
struct ElementReader<'a, R: Read> {
    reader: &'a mut Reader<BufReader<R>>,
    encoding: Encoding,
    /// 1-based line of the next ASCII payload line.
    line: &'a mut usize,
    def: &'a ElementDef,
}

impl<R: Read> ElementReader<'_, R> {
    /// Element `i` (0-based) of `self.def`.
    fn next<E: PropertyAccess>(&mut self, parser: &Parser<E>, i: usize) -> Result<E> {
        let def = self.def;
        let what = || format!("{} {i}", def.name);
        let truncated = || MeshError::Truncated {
            expected: format!("{} '{}' elements announced in the PLY header, found {i}", def.count, def.name),
        };
        let inner = self.reader.get_mut();
        match self.encoding {
            Encoding::Ascii => {
                let mut text = String::new();
                // Blank lines carry no element; skipping them costs nothing and some writers add one.
                loop {
                    text.clear();
                    let n = inner.read_line(&mut text).map_err(|e| match e.kind() {
                        std::io::ErrorKind::InvalidData => MeshError::Syntax {
                            line: *self.line,
                            message: format!("{}: not valid UTF-8 text", what()),
                        },
                        _ => MeshError::Io(e),
                    })?;
                    if n == 0 {
                        return Err(truncated());
                    }
                    let line = *self.line;
                    *self.line += 1;
                    if !text.trim().is_empty() {
                        return parser.read_ascii_element(&text, def).map_err(|e| MeshError::Syntax {
                            line,
                            message: format!("{}: {}", what(), one_line(&e)),
                        });
                    }
                }
            }
            Encoding::BinaryLittleEndian | Encoding::BinaryBigEndian => {
                let result = if self.encoding == Encoding::BinaryLittleEndian {
                    parser.read_little_endian_element(inner, def)
                } else {
                    parser.read_big_endian_element(inner, def)
                };
                result.map_err(|e| match e.kind() {
                    std::io::ErrorKind::UnexpectedEof => truncated(),
                    _ => MeshError::Format(format!("PLY: {}: {}", what(), one_line(&e))),
                })
            }
        }
    }
}

/// A header error: with the line where `ply-rs-bw` knows it, as a [`MeshError::Truncated`] when the
/// file ends inside the header.
fn header_error(e: ParseError) -> MeshError {
    if e.kind() == std::io::ErrorKind::UnexpectedEof {
        return MeshError::Truncated { expected: format!("a complete PLY header ({})", one_line(&e)) };
    }
    match e.line() {
        Some(line) => MeshError::Syntax { line, message: format!("PLY header: {}", one_line(&e)) },
        None => MeshError::Format(format!("PLY header: {}", one_line(&e))),
    }
}

/// `ply-rs-bw`'s message on one line, without its own `Line N: ` prefix (ours names the line).
fn one_line(e: &ParseError) -> String {
    let text = e.to_string();
    let text = match e.line() {
        Some(line) => text.strip_prefix(&format!("Line {line}: ")).unwrap_or(&text).to_string(),
        None => text,
    };
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// Any scalar as `f64`: exact for every PLY type (integers are at most 32 bits).
fn scalar(p: &Property) -> Option<f64> {
    Some(match *p {
        Property::Char(v) => f64::from(v),
        Property::UChar(v) => f64::from(v),
        Property::Short(v) => f64::from(v),
        Property::UShort(v) => f64::from(v),
        Property::Int(v) => f64::from(v),
        Property::UInt(v) => f64::from(v),
        Property::Float(v) => f64::from(v),
        Property::Double(v) => v,
        _ => return None,
    })
}

/// Any integer list as `i64`s (exact); `None` for float lists and scalars.
fn int_list(p: Property) -> Option<Vec<i64>> {
    Some(match p {
        Property::ListChar(v) => v.into_iter().map(i64::from).collect(),
        Property::ListUChar(v) => v.into_iter().map(i64::from).collect(),
        Property::ListShort(v) => v.into_iter().map(i64::from).collect(),
        Property::ListUShort(v) => v.into_iter().map(i64::from).collect(),
        Property::ListInt(v) => v.into_iter().map(i64::from).collect(),
        Property::ListUInt(v) => v.into_iter().map(i64::from).collect(),
        _ => return None,
    })
}

/// A `vertex` element: its position, other properties dropped. Every typed setter of
/// [`PropertyAccess`] defaults to `set_property`, so this one method sees every type.
struct PlyVertex {
    xyz: [Option<f64>; 3],
}

impl PropertyAccess for PlyVertex {
    fn new() -> Self {
        Self { xyz: [None; 3] }
    }

    fn set_property(&mut self, name: &str, property: Property) -> PropertyAccessResult {
        let axis = match name {
            "x" => 0,
            "y" => 1,
            "z" => 2,
            _ => return PropertyAccessResult::Ignored,
        };
        // The header check made x, y, z scalars, so `scalar` always succeeds here.
        self.xyz[axis] = scalar(&property);
        PropertyAccessResult::Set
    }
}

/// A `face` element: both accepted index lists (the header decides which one is used).
struct PlyFace {
    vertex_indices: Vec<i64>,
    vertex_index: Vec<i64>,
}

impl PropertyAccess for PlyFace {
    fn new() -> Self {
        Self { vertex_indices: Vec::new(), vertex_index: Vec::new() }
    }

    fn set_property(&mut self, name: &str, property: Property) -> PropertyAccessResult {
        let slot = match name {
            "vertex_indices" => &mut self.vertex_indices,
            "vertex_index" => &mut self.vertex_index,
            _ => return PropertyAccessResult::Ignored,
        };
        match int_list(property) {
            Some(list) => {
                *slot = list;
                PropertyAccessResult::Set
            }
            // Only reachable for the list the header check did not choose.
            None => PropertyAccessResult::Ignored,
        }
    }
}

/// Any element that is not needed: everything ignored (the default of every setter).
struct Ignored;

impl PropertyAccess for Ignored {
    fn new() -> Self {
        Ignored
    }
}
