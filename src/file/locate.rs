//! Locating errors in a scene file's text.

use std::collections::HashMap;

use crate::error::Error;
use crate::scene::{Kind, Node, NodeKind, Scene};

use super::options;
use super::schema::FileRepr;
use super::sites::{STOP, Sites};

/// The line and column where the parser meets `site`.
pub(super) fn locate(text: &str, site: usize) -> Option<(usize, usize)> {
    let result: ron::error::SpannedResult<FileRepr> =
        Sites::run(Some(site), || options().from_str(text));
    match result {
        Err(e) if e.code == ron::Error::Message(STOP.into()) => {
            Some(skip_blank(text, e.span.end.line, e.span.end.col))
        }
        _ => None,
    }
}

/// Every name a file may write before `(`: the nodes, the parameter forms,
/// and the enum variants and structs of the settings.
pub(super) const NAMES: &[&str] = &[
    "Sphere",
    "Cuboid",
    "RoundBox",
    "Torus",
    "Cylinder",
    "Capsule",
    "Plane",
    "Octahedron",
    "OctahedronBound",
    "CappedCone",
    "HexPrism",
    "RoundCone",
    "Link",
    "CutSphere",
    "SolidAngle",
    "CappedTorus",
    "Triangle",
    "Quad",
    "Pyramid",
    "Rhombus",
    "TriPrism",
    "RoundedCylinder",
    "Cone",
    "InfiniteCylinder",
    "InfiniteCone",
    "CutHollowSphere",
    "DeathStar",
    "BoxFrame",
    "CylinderBetween",
    "ConeBetween",
    "RoundConeBetween",
    "Extrude",
    "Revolve",
    "Circle",
    "Rect",
    "RoundRect",
    "Segment",
    "Vesica",
    "Ellipse",
    "Polygon",
    "Ellipsoid",
    "Mandelbulb",
    "Menger",
    "Julia",
    "Sierpinski",
    "Mandelbox",
    "PseudoKleinian",
    "Kifs",
    "Hybrid",
    "Stage",
    "BoxFold",
    "SurfFold",
    "SphereFold",
    "AbsFold",
    "PlaneFold",
    "Fold",
    "Power",
    "BulbSquare",
    "QuaternionSquare",
    "AddPoint",
    "AddConstant",
    "Translate",
    "Rotate",
    "Scale",
    "Mirror",
    "Round",
    "Onion",
    "Elongate",
    "Repeat",
    "RepeatLimited",
    "Twist",
    "Bend",
    "Color",
    "Glow",
    "Material",
    "OrbitTrap",
    "Line",
    "Gradient",
    "Union",
    "Subtract",
    "Intersect",
    "SmoothUnion",
    "SmoothSubtract",
    "SmoothIntersect",
    "Cut",
    "CutPlane",
    "SmoothCut",
    "Custom",
    "param",
    "param3",
    "Some",
    "Perspective",
    "Orthographic",
    "Directional",
    "Point",
    "Oscillate",
    "Orbit",
    "Keys",
    "Key",
    "Camera",
    "Light",
    "Glow",
    "Effects",
    "Keyframe",
];

/// The first name written before `(` that is not one of [`NAMES`] (outside
/// strings and comments), with its byte offset.
pub(super) fn unknown_name(text: &str) -> Option<(usize, &str)> {
    let bytes = text.as_bytes();
    let mut i = 0;
    while i < bytes.len() {
        match bytes[i] {
            b'"' => {
                i += 1;
                while i < bytes.len() && bytes[i] != b'"' {
                    i += if bytes[i] == b'\\' { 2 } else { 1 };
                }
                i += 1;
            }
            b'r' if text[i..].starts_with("r#") || text[i..].starts_with("r\"") => {
                let hashes = text[i + 1..].bytes().take_while(|&b| b == b'#').count();
                let close = format!("\"{}", "#".repeat(hashes));
                let body = i + 2 + hashes;
                i = text
                    .get(body..)
                    .and_then(|rest| rest.find(&close))
                    .map_or(bytes.len(), |at| body + at + close.len());
            }
            b'/' if text[i..].starts_with("//") => {
                i = text[i..].find('\n').map_or(bytes.len(), |at| i + at);
            }
            b'/' if text[i..].starts_with("/*") => {
                i = text[i + 2..]
                    .find("*/")
                    .map_or(bytes.len(), |at| i + 2 + at + 2);
            }
            b if b.is_ascii_alphabetic() || b == b'_' => {
                let start = i;
                while i < bytes.len() && (bytes[i].is_ascii_alphanumeric() || bytes[i] == b'_') {
                    i += 1;
                }
                let name = &text[start..i];
                let next = text[i..].trim_start();
                if next.starts_with('(') && !NAMES.contains(&name) {
                    return Some((start, name));
                }
            }
            _ => i += 1,
        }
    }
    None
}

/// The line and column (from 1, in characters) of byte `offset` of `text`.
pub(super) fn line_and_column(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().unwrap_or("").chars().count() + 1;
    (line, column)
}

/// The first line and column at or after (`line`, `column`) that is not
/// white space or a comment: where the value there starts.
fn skip_blank(text: &str, line: usize, column: usize) -> (usize, usize) {
    let (mut line, mut column) = (line, column);
    let mut rest = text
        .split_inclusive('\n')
        .nth(line.saturating_sub(1))
        .map(|l| l.chars().skip(column.saturating_sub(1)).collect::<String>())
        .unwrap_or_default();
    let mut lines = text.split_inclusive('\n').skip(line);
    loop {
        let trimmed = rest.trim_start();
        column += rest.chars().count() - trimmed.chars().count();
        if !trimmed.is_empty() && !trimmed.starts_with("//") {
            return (line, column);
        }
        match lines.next() {
            Some(next) => {
                rest = next.to_string();
                line += 1;
                column = 1;
            }
            None => return (line, column),
        }
    }
}

/// Which site each node of the converted tree came from.
#[derive(Default)]
pub(super) struct SiteMap {
    nodes: HashMap<*const NodeKind, usize>,
}

impl SiteMap {
    pub(super) fn insert(&mut self, node: &Node, site: usize) {
        self.nodes.insert(std::ptr::from_ref(node.kind()), site);
    }

    pub(super) fn insert_new(&mut self, node: &Node, site: usize) {
        self.nodes
            .entry(std::ptr::from_ref(node.kind()))
            .or_insert(site);
    }

    /// The site of what a validation error names: a node's path, the
    /// camera, or a light.
    pub(super) fn site_of(&self, scene: &Scene, repr: &FileRepr, e: &Error) -> Option<usize> {
        let node = match e {
            Error::Camera { .. } => return Some(repr.camera.site),
            Error::CustomShape { name, .. } => return self.custom_site(scene, name),
            Error::NonFinite { node, .. }
            | Error::OutOfRange { node, .. }
            | Error::Precision { node, .. }
            | Error::Iterations { node, .. }
            | Error::ZeroVector { node, .. } => node,
            _ => return None,
        };
        if node == "camera" {
            return Some(repr.camera.site);
        }
        if let Some(i) = node
            .strip_prefix("light[")
            .and_then(|rest| rest.strip_suffix(']'))
            .and_then(|i| i.parse::<usize>().ok())
        {
            return repr.lights.get(i).map(|l| l.site);
        }
        let mut at = scene.geometry.as_ref()?;
        for step in node.split('/').skip(1) {
            let children = at.kind().children();
            at = match step.split_once(':') {
                Some(("b", _)) => children.get(1)?,
                _ => children.first()?,
            };
        }
        self.nodes.get(&std::ptr::from_ref(at.kind())).copied()
    }

    /// The site of the first node of the custom shape `name`.
    pub(super) fn custom_site(&self, scene: &Scene, name: &str) -> Option<usize> {
        let mut stack = vec![scene.geometry.as_ref()?];
        while let Some(node) = stack.pop() {
            if let Kind::Custom { shape, .. } = node.kind()
                && shape.name() == name
            {
                return self.nodes.get(&std::ptr::from_ref(node.kind())).copied();
            }
            stack.extend(node.kind().children().into_iter().rev());
        }
        None
    }
}
