//! Converting between a file's nodes and the scene's.

use crate::error::Error;
use crate::scene::{
    CsgOp, CustomShape, Hybrid, InsideShape, Kifs, Kind, Mandelbox, Mandelbulb, Menger, Node,
    OrbitColoring, Param, PseudoKleinian, QuaternionJulia, Sierpinski,
};

use super::MAX_NESTING;
use super::locate::SiteMap;
use super::schema::{Child, MaterialRepr, NodeRepr, PaletteRepr};
use super::sites::Located;

/// How deep `node` nests in a file: a chain of hard unions down their
/// first operands is one `Union([...])`, one level. Counted without
/// recursion.
pub(super) fn nesting(node: &Node) -> usize {
    let mut deepest = 0;
    let mut stack = vec![(node, 1)];
    while let Some((node, level)) = stack.pop() {
        deepest = deepest.max(level);
        match union_operands(node) {
            Some(operands) => stack.extend(operands.into_iter().map(|n| (n, level + 1))),
            None => stack.extend(node.kind().children().into_iter().map(|n| (n, level + 1))),
        }
    }
    deepest
}

/// The operands of a chain of hard unions down their first operands, in
/// order (`(a ∪ b) ∪ c` gives `a, b, c`), or `None` if `node` is not a
/// hard union.
pub(super) fn union_operands(node: &Node) -> Option<Vec<&Node>> {
    let is_union = |n: &Node| {
        matches!(
            n.kind(),
            Kind::Csg {
                op: CsgOp::Union,
                smoothing: None,
                ..
            }
        )
    };
    if !is_union(node) {
        return None;
    }
    let mut tail = Vec::new();
    let mut at = node;
    while let Kind::Csg { a, b, .. } = at.kind() {
        if !is_union(at) {
            break;
        }
        tail.push(b);
        at = a;
    }
    tail.push(at);
    tail.reverse();
    Some(tail)
}

impl NodeRepr {
    /// The file form of `node` (nested at most [`MAX_NESTING`] deep).
    pub(super) fn from_node(node: &Node) -> NodeRepr {
        let child = |c: &Node| Box::new(Located::new(NodeRepr::from_node(c)));
        if let Some(operands) = union_operands(node) {
            return NodeRepr::Union(
                operands
                    .into_iter()
                    .map(|n| Located::new(NodeRepr::from_node(n)))
                    .collect(),
            );
        }
        match node.kind().clone() {
            Kind::Sphere { radius } => NodeRepr::Sphere { radius },
            Kind::Cuboid { half_extents } => NodeRepr::Cuboid { half_extents },
            Kind::RoundBox {
                half_extents,
                radius,
            } => NodeRepr::RoundBox {
                half_extents,
                radius,
            },
            Kind::Torus {
                major_radius,
                minor_radius,
            } => NodeRepr::Torus {
                major_radius,
                minor_radius,
            },
            Kind::Cylinder {
                radius,
                half_height,
            } => NodeRepr::Cylinder {
                radius,
                half_height,
            },
            Kind::Capsule { a, b, radius } => NodeRepr::Capsule { a, b, radius },
            Kind::Plane { normal, offset } => NodeRepr::Plane { normal, offset },
            Kind::Octahedron { size } => NodeRepr::Octahedron { size },
            Kind::OctahedronBound { size } => NodeRepr::OctahedronBound { size },
            Kind::CappedCone {
                half_height,
                bottom_radius,
                top_radius,
            } => NodeRepr::CappedCone {
                half_height,
                bottom_radius,
                top_radius,
            },
            Kind::HexPrism {
                radius,
                half_height,
            } => NodeRepr::HexPrism {
                radius,
                half_height,
            },
            Kind::RoundCone {
                half_height,
                bottom_radius,
                top_radius,
            } => NodeRepr::RoundCone {
                half_height,
                bottom_radius,
                top_radius,
            },
            Kind::Link {
                half_length,
                major_radius,
                minor_radius,
            } => NodeRepr::Link {
                half_length,
                major_radius,
                minor_radius,
            },
            Kind::CutSphere { radius, height } => NodeRepr::CutSphere { radius, height },
            Kind::SolidAngle { angle, radius } => NodeRepr::SolidAngle { angle, radius },
            Kind::CappedTorus {
                angle,
                major_radius,
                minor_radius,
            } => NodeRepr::CappedTorus {
                angle,
                major_radius,
                minor_radius,
            },
            Kind::Triangle { a, b, c, thickness } => NodeRepr::Triangle { a, b, c, thickness },
            Kind::Quad {
                a,
                b,
                c,
                d,
                thickness,
            } => NodeRepr::Quad {
                a,
                b,
                c,
                d,
                thickness,
            },
            Kind::Pyramid { half_base, height } => NodeRepr::Pyramid { half_base, height },
            Kind::Rhombus {
                half_x,
                half_z,
                half_height,
                radius,
            } => NodeRepr::Rhombus {
                half_x,
                half_z,
                half_height,
                radius,
            },
            Kind::TriPrism {
                radius,
                half_height,
            } => NodeRepr::TriPrism {
                radius,
                half_height,
            },
            Kind::RoundedCylinder {
                radius,
                half_height,
                rounding,
            } => NodeRepr::RoundedCylinder {
                radius,
                half_height,
                rounding,
            },
            Kind::Cone { radius, height } => NodeRepr::Cone { radius, height },
            Kind::InfiniteCylinder { radius } => NodeRepr::InfiniteCylinder { radius },
            Kind::InfiniteCone { angle } => NodeRepr::InfiniteCone { angle },
            Kind::CutHollowSphere {
                radius,
                height,
                thickness,
            } => NodeRepr::CutHollowSphere {
                radius,
                height,
                thickness,
            },
            Kind::DeathStar {
                radius,
                carve_radius,
                carve_distance,
            } => NodeRepr::DeathStar {
                radius,
                carve_radius,
                carve_distance,
            },
            Kind::BoxFrame {
                half_extents,
                thickness,
            } => NodeRepr::BoxFrame {
                half_extents,
                thickness,
            },
            Kind::CylinderBetween { a, b, radius } => NodeRepr::CylinderBetween { a, b, radius },
            Kind::ConeBetween {
                a,
                b,
                radius_a,
                radius_b,
            } => NodeRepr::ConeBetween {
                a,
                b,
                radius_a,
                radius_b,
            },
            Kind::RoundConeBetween {
                a,
                b,
                radius_a,
                radius_b,
            } => NodeRepr::RoundConeBetween {
                a,
                b,
                radius_a,
                radius_b,
            },
            Kind::Extrude {
                profile,
                half_height,
            } => NodeRepr::Extrude {
                profile,
                half_height,
            },
            Kind::Revolve { profile, offset } => NodeRepr::Revolve { profile, offset },
            Kind::Ellipsoid { radii } => NodeRepr::Ellipsoid { radii },
            Kind::Mandelbulb(Mandelbulb {
                power,
                iterations,
                bailout,
            }) => NodeRepr::Mandelbulb {
                power,
                iterations,
                bailout,
            },
            Kind::Menger(Menger { iterations, scale }) => NodeRepr::Menger { iterations, scale },
            Kind::Julia(QuaternionJulia {
                c,
                iterations,
                bailout,
                slice_w,
            }) => NodeRepr::Julia {
                c,
                iterations,
                bailout,
                slice_w,
            },
            Kind::Sierpinski(Sierpinski { iterations, scale }) => {
                NodeRepr::Sierpinski { iterations, scale }
            }
            Kind::Mandelbox(Mandelbox {
                scale,
                min_radius,
                fixed_radius,
                fold_limit,
                iterations,
                julia,
            }) => NodeRepr::Mandelbox {
                scale,
                min_radius,
                fixed_radius,
                fold_limit,
                iterations,
                julia,
            },
            Kind::PseudoKleinian(PseudoKleinian {
                fold_size,
                inversion,
                offset,
                thickness,
                iterations,
            }) => NodeRepr::PseudoKleinian {
                fold_size: Some(fold_size),
                inversion: Some(inversion),
                offset: Some(offset),
                thickness: Some(thickness),
                iterations: Some(iterations),
            },
            Kind::Kifs(Kifs {
                fold,
                scale,
                offset,
                rotate_before,
                rotate_after,
                iterations,
            }) => NodeRepr::Kifs {
                fold,
                scale: Some(scale),
                offset: Some(offset),
                rotate_before,
                rotate_after,
                iterations: Some(iterations),
            },
            Kind::Hybrid(Hybrid {
                stages,
                iterations,
                bailout,
                safety,
            }) => NodeRepr::Hybrid {
                stages,
                iterations,
                bailout,
                safety,
            },
            Kind::Translate { offset, child: c } => NodeRepr::Translate {
                offset,
                child: child(&c),
            },
            Kind::Rotate {
                axis,
                angle,
                child: c,
            } => NodeRepr::Rotate {
                axis,
                angle,
                child: child(&c),
            },
            Kind::Scale { factor, child: c } => NodeRepr::Scale {
                factor,
                child: child(&c),
            },
            Kind::Mirror { axis, child: c } => NodeRepr::Mirror {
                axis,
                child: child(&c),
            },
            Kind::Round { radius, child: c } => NodeRepr::Round {
                radius,
                child: child(&c),
            },
            Kind::Onion {
                thickness,
                child: c,
            } => NodeRepr::Onion {
                thickness,
                child: child(&c),
            },
            Kind::Elongate { extents, child: c } => NodeRepr::Elongate {
                extents,
                child: child(&c),
            },
            Kind::Repeat { period, child: c } => NodeRepr::Repeat {
                period,
                child: child(&c),
            },
            Kind::RepeatLimited {
                period,
                limit,
                child: c,
            } => NodeRepr::RepeatLimited {
                period,
                limit,
                child: child(&c),
            },
            Kind::Twist { rate, child: c } => NodeRepr::Twist {
                rate,
                child: child(&c),
            },
            Kind::Bend { rate, child: c } => NodeRepr::Bend {
                rate,
                child: child(&c),
            },
            Kind::Color { color, child: c } => NodeRepr::Color {
                color,
                child: child(&c),
            },
            Kind::Glow {
                color,
                strength,
                child: c,
            } => NodeRepr::Glow {
                color,
                strength,
                child: child(&c),
            },
            Kind::Material { material, child: c } => NodeRepr::Material {
                material: MaterialRepr::from_material(&material),
                child: child(&c),
            },
            Kind::OrbitTrap { coloring, child: c } => NodeRepr::OrbitTrap {
                trap: coloring.trap,
                palette: PaletteRepr::from_palette(&coloring.palette),
                near: coloring.near,
                far: coloring.far,
                child: child(&c),
            },
            Kind::Csg {
                op,
                smoothing,
                a,
                b,
            } => {
                // A cut by a plane is written as `Node::cut_plane` makes it.
                if let (CsgOp::Cut, None, Kind::Plane { normal, offset }) =
                    (op, &smoothing, b.kind())
                {
                    return NodeRepr::CutPlane {
                        normal: normal.clone(),
                        offset: offset.clone(),
                        child: child(&a),
                    };
                }
                let (a, b) = (child(&a), child(&b));
                match (op, smoothing) {
                    (CsgOp::Union, None) => NodeRepr::Union(vec![*a, *b]),
                    (CsgOp::Subtract, None) => NodeRepr::Subtract { a, b },
                    (CsgOp::Intersect, None) => NodeRepr::Intersect { a, b },
                    (CsgOp::Union, Some(k)) => NodeRepr::SmoothUnion { k, a, b },
                    (CsgOp::Subtract, Some(k)) => NodeRepr::SmoothSubtract { k, a, b },
                    (CsgOp::Intersect, Some(k)) => NodeRepr::SmoothIntersect { k, a, b },
                    (CsgOp::Cut, None) => NodeRepr::Cut { a, b },
                    (CsgOp::Cut, Some(k)) => NodeRepr::SmoothCut { k, a, b },
                }
            }
            Kind::Custom { shape, args } => NodeRepr::Custom {
                name: shape.name().to_string(),
                args,
            },
        }
    }
}

impl Located<NodeRepr> {
    /// The node this file node describes, recording where each node came
    /// from. `level` is its nesting (the parser bounds it); an error names
    /// the site it belongs to.
    pub(super) fn to_node(
        &self,
        shapes: &[CustomShape],
        sites: &mut SiteMap,
        level: usize,
    ) -> std::result::Result<Node, (usize, Error)> {
        let site = self.site;
        let fail = |reason: String| {
            (
                site,
                Error::Invalid {
                    what: "scene file",
                    reason,
                },
            )
        };
        if level > MAX_NESTING {
            return Err(fail(format!(
                "nodes are nested more than {MAX_NESTING} deep"
            )));
        }
        let mut child = |c: &Child| c.to_node(shapes, sites, level + 1);
        let csg = |op, smoothing: Option<&Param>, a: Node, b: Node| -> Node {
            Kind::Csg {
                op,
                smoothing: smoothing.cloned(),
                a,
                b,
            }
            .into()
        };
        let node: Node = match &self.value {
            NodeRepr::Sphere { radius } => Kind::Sphere {
                radius: radius.clone(),
            }
            .into(),
            NodeRepr::Cuboid { half_extents } => Kind::Cuboid {
                half_extents: half_extents.clone(),
            }
            .into(),
            NodeRepr::RoundBox {
                half_extents,
                radius,
            } => Kind::RoundBox {
                half_extents: half_extents.clone(),
                radius: radius.clone(),
            }
            .into(),
            NodeRepr::Torus {
                major_radius,
                minor_radius,
            } => Kind::Torus {
                major_radius: major_radius.clone(),
                minor_radius: minor_radius.clone(),
            }
            .into(),
            NodeRepr::Cylinder {
                radius,
                half_height,
            } => Kind::Cylinder {
                radius: radius.clone(),
                half_height: half_height.clone(),
            }
            .into(),
            NodeRepr::Capsule { a, b, radius } => Kind::Capsule {
                a: a.clone(),
                b: b.clone(),
                radius: radius.clone(),
            }
            .into(),
            NodeRepr::Plane { normal, offset } => Kind::Plane {
                normal: normal.clone(),
                offset: offset.clone(),
            }
            .into(),
            NodeRepr::Octahedron { size } => Kind::Octahedron { size: size.clone() }.into(),
            NodeRepr::OctahedronBound { size } => {
                Kind::OctahedronBound { size: size.clone() }.into()
            }
            NodeRepr::CappedCone {
                half_height,
                bottom_radius,
                top_radius,
            } => Kind::CappedCone {
                half_height: half_height.clone(),
                bottom_radius: bottom_radius.clone(),
                top_radius: top_radius.clone(),
            }
            .into(),
            NodeRepr::HexPrism {
                radius,
                half_height,
            } => Kind::HexPrism {
                radius: radius.clone(),
                half_height: half_height.clone(),
            }
            .into(),
            NodeRepr::RoundCone {
                half_height,
                bottom_radius,
                top_radius,
            } => Kind::RoundCone {
                half_height: half_height.clone(),
                bottom_radius: bottom_radius.clone(),
                top_radius: top_radius.clone(),
            }
            .into(),
            NodeRepr::Link {
                half_length,
                major_radius,
                minor_radius,
            } => Kind::Link {
                half_length: half_length.clone(),
                major_radius: major_radius.clone(),
                minor_radius: minor_radius.clone(),
            }
            .into(),
            NodeRepr::CutSphere { radius, height } => Kind::CutSphere {
                radius: radius.clone(),
                height: height.clone(),
            }
            .into(),
            NodeRepr::CappedTorus {
                angle,
                major_radius,
                minor_radius,
            } => Kind::CappedTorus {
                angle: angle.clone(),
                major_radius: major_radius.clone(),
                minor_radius: minor_radius.clone(),
            }
            .into(),
            NodeRepr::SolidAngle { angle, radius } => Kind::SolidAngle {
                angle: angle.clone(),
                radius: radius.clone(),
            }
            .into(),
            NodeRepr::Triangle { a, b, c, thickness } => Kind::Triangle {
                a: a.clone(),
                b: b.clone(),
                c: c.clone(),
                thickness: thickness.clone(),
            }
            .into(),
            NodeRepr::Quad {
                a,
                b,
                c,
                d,
                thickness,
            } => Kind::Quad {
                a: a.clone(),
                b: b.clone(),
                c: c.clone(),
                d: d.clone(),
                thickness: thickness.clone(),
            }
            .into(),
            NodeRepr::Pyramid { half_base, height } => Kind::Pyramid {
                half_base: half_base.clone(),
                height: height.clone(),
            }
            .into(),
            NodeRepr::Rhombus {
                half_x,
                half_z,
                half_height,
                radius,
            } => Kind::Rhombus {
                half_x: half_x.clone(),
                half_z: half_z.clone(),
                half_height: half_height.clone(),
                radius: radius.clone(),
            }
            .into(),
            NodeRepr::TriPrism {
                radius,
                half_height,
            } => Kind::TriPrism {
                radius: radius.clone(),
                half_height: half_height.clone(),
            }
            .into(),
            NodeRepr::RoundedCylinder {
                radius,
                half_height,
                rounding,
            } => Kind::RoundedCylinder {
                radius: radius.clone(),
                half_height: half_height.clone(),
                rounding: rounding.clone(),
            }
            .into(),
            NodeRepr::Cone { radius, height } => Kind::Cone {
                radius: radius.clone(),
                height: height.clone(),
            }
            .into(),
            NodeRepr::InfiniteCylinder { radius } => Kind::InfiniteCylinder {
                radius: radius.clone(),
            }
            .into(),
            NodeRepr::InfiniteCone { angle } => Kind::InfiniteCone {
                angle: angle.clone(),
            }
            .into(),
            NodeRepr::CutHollowSphere {
                radius,
                height,
                thickness,
            } => Kind::CutHollowSphere {
                radius: radius.clone(),
                height: height.clone(),
                thickness: thickness.clone(),
            }
            .into(),
            NodeRepr::DeathStar {
                radius,
                carve_radius,
                carve_distance,
            } => Kind::DeathStar {
                radius: radius.clone(),
                carve_radius: carve_radius.clone(),
                carve_distance: carve_distance.clone(),
            }
            .into(),
            NodeRepr::BoxFrame {
                half_extents,
                thickness,
            } => Kind::BoxFrame {
                half_extents: half_extents.clone(),
                thickness: thickness.clone(),
            }
            .into(),
            NodeRepr::CylinderBetween { a, b, radius } => Kind::CylinderBetween {
                a: a.clone(),
                b: b.clone(),
                radius: radius.clone(),
            }
            .into(),
            NodeRepr::ConeBetween {
                a,
                b,
                radius_a,
                radius_b,
            } => Kind::ConeBetween {
                a: a.clone(),
                b: b.clone(),
                radius_a: radius_a.clone(),
                radius_b: radius_b.clone(),
            }
            .into(),
            NodeRepr::RoundConeBetween {
                a,
                b,
                radius_a,
                radius_b,
            } => Kind::RoundConeBetween {
                a: a.clone(),
                b: b.clone(),
                radius_a: radius_a.clone(),
                radius_b: radius_b.clone(),
            }
            .into(),
            NodeRepr::Extrude {
                profile,
                half_height,
            } => Kind::Extrude {
                profile: profile.clone(),
                half_height: half_height.clone(),
            }
            .into(),
            NodeRepr::Revolve { profile, offset } => Kind::Revolve {
                profile: profile.clone(),
                offset: offset.clone(),
            }
            .into(),
            NodeRepr::Ellipsoid { radii } => Kind::Ellipsoid {
                radii: radii.clone(),
            }
            .into(),
            NodeRepr::Mandelbulb {
                power,
                iterations,
                bailout,
            } => Mandelbulb {
                power: power.clone(),
                iterations: *iterations,
                bailout: bailout.clone(),
            }
            .into(),
            NodeRepr::Menger { iterations, scale } => Menger {
                iterations: *iterations,
                scale: scale.clone(),
            }
            .into(),
            NodeRepr::Julia {
                c,
                iterations,
                bailout,
                slice_w,
            } => QuaternionJulia {
                c: c.clone(),
                iterations: *iterations,
                bailout: bailout.clone(),
                slice_w: slice_w.clone(),
            }
            .into(),
            NodeRepr::Sierpinski { iterations, scale } => Sierpinski {
                iterations: *iterations,
                scale: scale.clone(),
            }
            .into(),
            NodeRepr::Mandelbox {
                scale,
                min_radius,
                fixed_radius,
                fold_limit,
                iterations,
                julia,
            } => {
                let mut b = Mandelbox::new(scale.clone())
                    .min_radius(min_radius.clone())
                    .fixed_radius(fixed_radius.clone())
                    .fold_limit(fold_limit.clone())
                    .iterations(*iterations);
                b.julia.clone_from(julia);
                b.into()
            }
            NodeRepr::PseudoKleinian {
                fold_size,
                inversion,
                offset,
                thickness,
                iterations,
            } => {
                let mut k = PseudoKleinian::new();
                if let Some(size) = fold_size {
                    k.fold_size.clone_from(size);
                }
                if let Some(inversion) = inversion {
                    k.inversion = inversion.clone();
                }
                if let Some(offset) = offset {
                    k.offset.clone_from(offset);
                }
                if let Some(thickness) = thickness {
                    k.thickness = thickness.clone();
                }
                if let Some(n) = iterations {
                    k.iterations = *n;
                }
                k.into()
            }
            NodeRepr::Kifs {
                fold,
                scale,
                offset,
                rotate_before,
                rotate_after,
                iterations,
            } => {
                let mut k = Kifs::new(*fold);
                if let Some(scale) = scale {
                    k.scale = scale.clone();
                }
                if let Some(offset) = offset {
                    k.offset.clone_from(offset);
                }
                if let Some(n) = iterations {
                    k.iterations = *n;
                }
                k.rotate_before.clone_from(rotate_before);
                k.rotate_after.clone_from(rotate_after);
                k.into()
            }
            NodeRepr::Hybrid {
                stages,
                iterations,
                bailout,
                safety,
            } => Kind::Hybrid(Hybrid {
                stages: stages.clone(),
                iterations: *iterations,
                bailout: bailout.clone(),
                safety: safety.clone(),
            })
            .into(),
            NodeRepr::Translate { offset, child: c } => Kind::Translate {
                offset: offset.clone(),
                child: child(c)?,
            }
            .into(),
            NodeRepr::Rotate {
                axis,
                angle,
                child: c,
            } => Kind::Rotate {
                axis: *axis,
                angle: angle.clone(),
                child: child(c)?,
            }
            .into(),
            NodeRepr::Scale { factor, child: c } => Kind::Scale {
                factor: factor.clone(),
                child: child(c)?,
            }
            .into(),
            NodeRepr::Mirror { axis, child: c } => Kind::Mirror {
                axis: *axis,
                child: child(c)?,
            }
            .into(),
            NodeRepr::Round { radius, child: c } => Kind::Round {
                radius: radius.clone(),
                child: child(c)?,
            }
            .into(),
            NodeRepr::Onion {
                thickness,
                child: c,
            } => Kind::Onion {
                thickness: thickness.clone(),
                child: child(c)?,
            }
            .into(),
            NodeRepr::Elongate { extents, child: c } => Kind::Elongate {
                extents: extents.clone(),
                child: child(c)?,
            }
            .into(),
            NodeRepr::Repeat { period, child: c } => Kind::Repeat {
                period: period.clone(),
                child: child(c)?,
            }
            .into(),
            NodeRepr::RepeatLimited {
                period,
                limit,
                child: c,
            } => Kind::RepeatLimited {
                period: period.clone(),
                limit: *limit,
                child: child(c)?,
            }
            .into(),
            NodeRepr::Twist { rate, child: c } => Kind::Twist {
                rate: rate.clone(),
                child: child(c)?,
            }
            .into(),
            NodeRepr::Bend { rate, child: c } => Kind::Bend {
                rate: rate.clone(),
                child: child(c)?,
            }
            .into(),
            NodeRepr::Color { color, child: c } => Kind::Color {
                color: color.clone(),
                child: child(c)?,
            }
            .into(),
            NodeRepr::Glow {
                color,
                strength,
                child: c,
            } => Kind::Glow {
                color: color.clone(),
                strength: strength.clone(),
                child: child(c)?,
            }
            .into(),
            NodeRepr::Material { material, child: c } => Kind::Material {
                material: material.to_material(),
                child: child(c)?,
            }
            .into(),
            NodeRepr::OrbitTrap {
                trap,
                palette,
                near,
                far,
                child: c,
            } => child(c)?.orbit_coloring(
                OrbitColoring::new(trap.clone(), palette.to_palette())
                    .range(near.clone(), far.clone()),
            ),
            NodeRepr::Union(operands) => {
                let mut operands = operands.iter();
                let first = operands
                    .next()
                    .ok_or_else(|| fail("a union needs at least one operand".into()))?;
                let mut node = first.to_node(shapes, sites, level + 1)?;
                for operand in operands {
                    let b = operand.to_node(shapes, sites, level + 1)?;
                    node = csg(CsgOp::Union, None, node, b);
                    // Each union of the chain stands at the list.
                    sites.insert(&node, site);
                }
                node
            }
            NodeRepr::Subtract { a, b } => csg(CsgOp::Subtract, None, child(a)?, child(b)?),
            NodeRepr::Intersect { a, b } => csg(CsgOp::Intersect, None, child(a)?, child(b)?),
            NodeRepr::SmoothUnion { k, a, b } => csg(CsgOp::Union, Some(k), child(a)?, child(b)?),
            NodeRepr::SmoothSubtract { k, a, b } => {
                csg(CsgOp::Subtract, Some(k), child(a)?, child(b)?)
            }
            NodeRepr::SmoothIntersect { k, a, b } => {
                csg(CsgOp::Intersect, Some(k), child(a)?, child(b)?)
            }
            NodeRepr::Cut { a, b } => csg(CsgOp::Cut, None, child(a)?, child(b)?),
            NodeRepr::CutPlane {
                normal,
                offset,
                child: c,
            } => {
                let node = child(c)?.cut_plane(normal.clone(), offset.clone());
                // The plane stands where the cut is written.
                if let Some(plane) = node.kind().children().get(1) {
                    sites.insert(plane, site);
                }
                node
            }
            NodeRepr::SmoothCut { k, a, b } => csg(CsgOp::Cut, Some(k), child(a)?, child(b)?),
            NodeRepr::Custom { name, args } => {
                // Shapes given first, then the built-in inside shapes.
                let builtin = InsideShape::builtin(name).map(CustomShape::from);
                let shape = shapes
                    .iter()
                    .find(|s| s.name() == name)
                    .or(builtin.as_ref());
                let shape = shape.ok_or_else(|| {
                    let known: Vec<&str> = shapes.iter().map(CustomShape::name).collect();
                    fail(if known.is_empty() {
                        format!(
                            "no custom shape named `{name}` was given to read this file with \
                             (`SceneFile::parse_with` or `load_with` take them), and no built-in \
                             inside shape has that name"
                        )
                    } else {
                        format!(
                            "no custom shape named `{name}`; the shapes given are {}",
                            known.join(", ")
                        )
                    })
                })?;
                Kind::Custom {
                    shape: shape.clone(),
                    args: args.clone(),
                }
                .into()
            }
        };
        // A one-operand union is its operand, which keeps its own site.
        sites.insert_new(&node, site);
        Ok(node)
    }
}
