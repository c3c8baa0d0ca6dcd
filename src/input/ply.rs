//! PLY (Stanford polygon format): ASCII, binary little-endian and binary big-endian bodies.
//!
//! Read: the `vertex` element's `x y z` (and `nx ny nz` when present) of any numeric type, and the
//! `face` element's `vertex_indices` (or `vertex_index`) list. Every other property and element is
//! read past and dropped, so files with colours, texture coordinates, edges or custom elements load.

use super::{push_fan, shorten, PointCloud};
use crate::error::Error;
use crate::mesh::Mesh;
use glam::Vec3;

#[derive(Debug, Clone, Copy, PartialEq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(name: &str) -> Option<Scalar> {
        Some(match name {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    /// Decodes `bytes` (exactly `size()` of them) in the given byte order.
    fn decode(self, bytes: &[u8], big_endian: bool) -> f64 {
        let mut b = [0u8; 8];
        b[..bytes.len()].copy_from_slice(bytes);
        if big_endian {
            b[..bytes.len()].reverse();
        }
        match self {
            Scalar::I8 => b[0] as i8 as f64,
            Scalar::U8 => b[0] as f64,
            Scalar::I16 => i16::from_le_bytes([b[0], b[1]]) as f64,
            Scalar::U16 => u16::from_le_bytes([b[0], b[1]]) as f64,
            Scalar::I32 => i32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            Scalar::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            Scalar::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            Scalar::F64 => f64::from_le_bytes(b),
        }
    }
}

#[derive(Debug, Clone)]
enum Kind {
    Scalar(Scalar),
    /// A list: the type of its length, then of its items.
    List(Scalar, Scalar),
}

#[derive(Debug, Clone)]
struct Property {
    name: String,
    kind: Kind,
}

#[derive(Debug, Clone)]
struct Element {
    name: String,
    count: u64,
    properties: Vec<Property>,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Encoding {
    Ascii,
    BinaryLittleEndian,
    BinaryBigEndian,
}

/// What a PLY file holds that the library uses.
#[derive(Debug, Default)]
pub(super) struct PlyData {
    positions: Vec<Vec3>,
    /// Present when the vertices have `nx ny nz`.
    normals: Option<Vec<Vec3>>,
    triangles: Vec<[u32; 3]>,
}

impl PlyData {
    pub(super) fn into_mesh(self) -> Result<Mesh, Error> {
        Ok(Mesh { positions: self.positions, normals: Vec::new(), triangles: self.triangles })
    }

    pub(super) fn into_points(self) -> Result<PointCloud, Error> {
        let Some(normals) = self.normals else {
            return Err(Error::Io(
                "PLY vertices have no normals (properties nx ny nz); a point cloud needs oriented points"
                    .into(),
            ));
        };
        PointCloud { positions: self.positions, normals }
            .normalized()
            .map_err(|e| Error::Io(format!("PLY {}", e.to_string().trim_start_matches("invalid option: "))))
    }
}

pub(super) fn read(bytes: &[u8]) -> Result<PlyData, Error> {
    let (encoding, elements, body_start, header_lines) = header(bytes)?;
    let body = &bytes[body_start..];
    let text;
    let mut source = match encoding {
        Encoding::Ascii => {
            text = String::from_utf8_lossy(body);
            Source::Ascii { lines: text.lines(), tokens: "".split_whitespace(), line: header_lines }
        }
        _ => Source::Binary {
            bytes: body,
            pos: 0,
            offset: body_start,
            big: encoding == Encoding::BinaryBigEndian,
        },
    };
    let mut data = PlyData::default();
    let mut vertex_count = None;
    let mut largest_index: Option<(u64, u64)> = None;
    for element in &elements {
        if element.properties.is_empty() {
            continue;
        }
        let role = match element.name.as_str() {
            "vertex" if vertex_count.is_none() => Role::Vertex(vertex_slots(element)?),
            "face" => Role::Face(face_list(element)),
            _ => Role::Skip,
        };
        if let Role::Vertex(slots) = &role {
            let capacity = element.count.min(bytes.len() as u64 / 3) as usize;
            data.positions.reserve(capacity);
            if slots[3..].iter().all(Option::is_some) {
                data.normals = Some(Vec::with_capacity(capacity));
            }
        }
        let mut values = [0.0f64; 6];
        let mut polygon: Vec<u32> = Vec::new();
        for i in 0..element.count {
            let at = |what: &str, source: &Source| {
                format!("element '{}' {i}{}: {what}", element.name, source.location())
            };
            for (p, property) in element.properties.iter().enumerate() {
                match property.kind {
                    Kind::Scalar(ty) => {
                        let v = source.value(ty).map_err(|e| Error::Io(at(&e, &source)))?;
                        if let Role::Vertex(slots) = &role {
                            if let Some(k) = slots.iter().position(|&s| s == Some(p)) {
                                values[k] = v;
                            }
                        }
                    }
                    Kind::List(count_ty, item_ty) => {
                        let n = source.value(count_ty).map_err(|e| Error::Io(at(&e, &source)))?;
                        if n < 0.0 || n.fract() != 0.0 {
                            return Err(Error::Io(at(&format!("list length {n} is not a count"), &source)));
                        }
                        let is_faces = matches!(role, Role::Face(Some(f)) if f == p);
                        polygon.clear();
                        for _ in 0..n as u64 {
                            let v = source.value(item_ty).map_err(|e| Error::Io(at(&e, &source)))?;
                            if is_faces {
                                if v < 0.0 || v.fract() != 0.0 || v > u32::MAX as f64 {
                                    return Err(Error::Io(at(
                                        &format!("vertex index {v} is invalid"),
                                        &source,
                                    )));
                                }
                                let index = v as u32;
                                if largest_index.is_none_or(|(m, _)| m < index as u64) {
                                    largest_index = Some((index as u64, i));
                                }
                                polygon.push(index);
                            }
                        }
                        if is_faces {
                            if polygon.len() < 3 {
                                let msg =
                                    format!("face has {} vertices; faces need at least 3", polygon.len());
                                return Err(Error::Io(at(&msg, &source)));
                            }
                            push_fan(&polygon, &mut data.triangles);
                        }
                    }
                }
            }
            if let Role::Vertex(_) = role {
                let p = Vec3::new(values[0] as f32, values[1] as f32, values[2] as f32);
                if !p.is_finite() {
                    return Err(Error::Io(at(&format!("position {p} is not finite"), &source)));
                }
                data.positions.push(p);
                if let Some(normals) = data.normals.as_mut() {
                    let n = Vec3::new(values[3] as f32, values[4] as f32, values[5] as f32);
                    if !n.is_finite() {
                        return Err(Error::Io(at(&format!("normal {n} is not finite"), &source)));
                    }
                    normals.push(n);
                }
            }
        }
        if let Role::Vertex(_) = role {
            vertex_count = Some(element.count);
        }
    }
    if let Some(location) = source.leftover() {
        return Err(Error::Io(format!(
            "PLY has data after its declared elements{location}; the header's counts are too small"
        )));
    }
    if let Some((index, face)) = largest_index {
        let vertices = vertex_count.unwrap_or(0);
        if index >= vertices {
            return Err(Error::Io(format!(
                "PLY face {face} uses vertex {index}, but the file has {vertices} vertices"
            )));
        }
    }
    Ok(data)
}

/// What an element's values are used for.
enum Role {
    /// Which property holds x, y, z, nx, ny, nz.
    Vertex([Option<usize>; 6]),
    /// Which property is the list of vertex indices (faces without one are read and dropped).
    Face(Option<usize>),
    Skip,
}

fn vertex_slots(element: &Element) -> Result<[Option<usize>; 6], Error> {
    let slots = ["x", "y", "z", "nx", "ny", "nz"].map(|name| {
        element.properties.iter().position(|p| p.name == name && matches!(p.kind, Kind::Scalar(_)))
    });
    if slots[..3].iter().any(Option::is_none) {
        return Err(Error::Io("PLY 'vertex' element lacks a scalar x, y or z property".into()));
    }
    Ok(slots)
}

fn face_list(element: &Element) -> Option<usize> {
    element.properties.iter().position(|p| {
        matches!(p.kind, Kind::List(..)) && (p.name == "vertex_indices" || p.name == "vertex_index")
    })
}

/// Where the values come from: whitespace-separated text, or packed bytes.
enum Source<'a> {
    Ascii { lines: std::str::Lines<'a>, tokens: std::str::SplitWhitespace<'a>, line: usize },
    Binary { bytes: &'a [u8], pos: usize, offset: usize, big: bool },
}

impl Source<'_> {
    fn value(&mut self, ty: Scalar) -> Result<f64, String> {
        match self {
            Source::Ascii { lines, tokens, line } => {
                let token = loop {
                    if let Some(t) = tokens.next() {
                        break t;
                    }
                    *tokens = lines.next().ok_or("the file ends")?.split_whitespace();
                    *line += 1;
                };
                match token.parse::<f64>() {
                    Ok(v) if v.is_finite() => Ok(v),
                    _ => Err(format!("expected a number, found '{}'", shorten(token))),
                }
            }
            Source::Binary { bytes, pos, big, .. } => {
                let end = *pos + ty.size();
                let raw = bytes.get(*pos..end).ok_or("the file ends")?;
                *pos = end;
                Ok(ty.decode(raw, *big))
            }
        }
    }

    /// Where data follows the last declared element, if any does (blank text does not count).
    fn leftover(&mut self) -> Option<String> {
        match self {
            Source::Ascii { lines, tokens, line } => {
                if tokens.next().is_some() {
                    return Some(format!(" (line {line})"));
                }
                for l in lines.by_ref() {
                    *line += 1;
                    if !l.trim().is_empty() {
                        return Some(format!(" (line {line})"));
                    }
                }
                None
            }
            Source::Binary { bytes, pos, offset, .. } => (*pos < bytes.len())
                .then(|| format!(" (byte {}, {} bytes left)", *pos + *offset, bytes.len() - *pos)),
        }
    }

    fn location(&self) -> String {
        match self {
            Source::Ascii { line, .. } => format!(" (line {line})"),
            Source::Binary { pos, offset, .. } => format!(" (byte {})", pos + offset),
        }
    }
}

/// Parses the header: the encoding, the elements, where the body starts and how many lines the
/// header has.
fn header(bytes: &[u8]) -> Result<(Encoding, Vec<Element>, usize, usize), Error> {
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    let mut start = 0;
    let mut line_no = 0;
    while start < bytes.len() {
        let end = bytes[start..].iter().position(|&b| b == b'\n').map_or(bytes.len(), |e| start + e);
        let line = String::from_utf8_lossy(&bytes[start..end]);
        let line = line.trim_end_matches('\r');
        start = (end + 1).min(bytes.len());
        line_no += 1;
        let fail = |msg: String| Error::Io(format!("PLY header line {line_no}: {msg}"));
        let tokens: Vec<&str> = line.split_whitespace().collect();
        if line_no == 1 {
            if line.trim() != "ply" {
                return Err(fail("a PLY file starts with the line 'ply'".into()));
            }
            continue;
        }
        match tokens.as_slice() {
            ["format", name, _version] => {
                encoding = Some(match *name {
                    "ascii" => Encoding::Ascii,
                    "binary_little_endian" => Encoding::BinaryLittleEndian,
                    "binary_big_endian" => Encoding::BinaryBigEndian,
                    other => return Err(fail(format!("unknown format '{}'", shorten(other)))),
                })
            }
            ["comment", ..] | ["obj_info", ..] | [] => {}
            ["element", name, count] => {
                let count = count
                    .parse()
                    .map_err(|_| fail(format!("element count '{}' is not a count", shorten(count))))?;
                elements.push(Element { name: name.to_string(), count, properties: Vec::new() });
            }
            ["property", rest @ ..] => {
                let element =
                    elements.last_mut().ok_or_else(|| fail("property before any element".into()))?;
                let scalar = |name: &str| {
                    Scalar::parse(name).ok_or_else(|| fail(format!("unknown type '{}'", shorten(name))))
                };
                let (kind, name) = match rest {
                    ["list", count, item, name] => (Kind::List(scalar(count)?, scalar(item)?), name),
                    [ty, name] => (Kind::Scalar(scalar(ty)?), name),
                    _ => {
                        return Err(fail(
                            "expected 'property TYPE NAME' or 'property list TYPE TYPE NAME'".into(),
                        ))
                    }
                };
                element.properties.push(Property { name: name.to_string(), kind });
            }
            ["end_header"] => {
                let encoding = encoding.ok_or_else(|| fail("no 'format' line before 'end_header'".into()))?;
                return Ok((encoding, elements, start, line_no));
            }
            _ => return Err(fail(format!("unexpected '{}'", shorten(line)))),
        }
    }
    Err(Error::Io("PLY header has no 'end_header' line".into()))
}

#[cfg(test)]
mod tests {
    use super::*;

    const SQUARE: &str = "ply\nformat ascii 1.0\ncomment a unit square\nelement vertex 4\n\
        property float x\nproperty float y\nproperty float z\nproperty uchar red\n\
        element face 1\nproperty list uchar int vertex_indices\nend_header\n\
        0 0 0 255\n1 0 0 255\n1 1 0 255\n0 1 0 255\n4 0 1 2 3\n";

    #[test]
    fn ascii_polygons_are_fanned_and_extra_properties_skipped() {
        let data = read(SQUARE.as_bytes()).unwrap();
        assert_eq!(data.positions.len(), 4);
        assert_eq!(data.positions[2], Vec3::new(1.0, 1.0, 0.0));
        assert_eq!(data.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        assert!(data.normals.is_none());
        assert!(read(SQUARE.as_bytes()).unwrap().into_points().is_err());
    }

    #[test]
    fn binary_big_endian_with_doubles_and_an_extra_element() {
        let mut bytes = b"ply\r\nformat binary_big_endian 1.0\r\nelement vertex 3\r\nproperty double x\r\n\
            property double y\r\nproperty double z\r\nelement edge 1\r\nproperty int a\r\nproperty int b\r\n\
            element face 1\r\nproperty list uchar uint vertex_indices\r\nend_header\r\n"
            .to_vec();
        for p in [[0.0f64, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
            for x in p {
                bytes.extend_from_slice(&x.to_be_bytes());
            }
        }
        bytes.extend_from_slice(&[0, 0, 0, 1, 0, 0, 0, 2]);
        bytes.push(3);
        for i in [0u32, 1, 2] {
            bytes.extend_from_slice(&i.to_be_bytes());
        }
        let data = read(&bytes).unwrap();
        assert_eq!(data.positions, vec![Vec3::ZERO, Vec3::X, Vec3::Y]);
        assert_eq!(data.triangles, vec![[0, 1, 2]]);
        let err = read(&bytes[..bytes.len() - 2]).unwrap_err().to_string();
        assert!(err.contains("element 'face' 0") && err.contains("file ends"), "{err}");
    }

    #[test]
    fn errors_name_the_line() {
        let err = read(SQUARE.replace("1 1 0 255", "1 one 0 255").as_bytes()).unwrap_err().to_string();
        assert!(err.contains("line 14") && err.contains("'one'"), "{err}");
        let err = read(SQUARE.replace("4 0 1 2 3", "4 0 1 2 9").as_bytes()).unwrap_err().to_string();
        assert!(err.contains("vertex 9"), "{err}");
        let err = read(SQUARE.replace("property float z\n", "property float w\n").as_bytes()).unwrap_err();
        assert!(err.to_string().contains("lacks"), "{err}");
        let err = read(SQUARE.replace("format ascii", "format utf8").as_bytes()).unwrap_err().to_string();
        assert!(err.contains("header line 2"), "{err}");
        let err = read(
            b"ply\nformat ascii 1.0\nelement vertex 1000000000000\n\
            property float x\nproperty float y\nproperty float z\nend_header\n1 2 3\n",
        )
        .unwrap_err();
        assert!(err.to_string().contains("file ends"), "{err}");
    }

    #[test]
    fn points_with_normals() {
        let text = "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n\
            property float z\nproperty float nx\nproperty float ny\nproperty float nz\nend_header\n\
            0 0 0 0 0 2\n1 0 0 1 0 0\n";
        let cloud = read(text.as_bytes()).unwrap().into_points().unwrap();
        assert_eq!(cloud.normals, vec![Vec3::Z, Vec3::X]);
    }
}
