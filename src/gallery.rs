//! Ready-made example scenes, each framed by its camera and lit.
//!
//! The examples, the viewer, the benchmarks and the tests all draw from
//! here, so a scene that looks right in the gallery is the scene the tests
//! check.
//!
//! ```
//! for (name, scene) in fractal_sdf::gallery::all() {
//!     scene.validate().unwrap_or_else(|e| panic!("{name}: {e}"));
//! }
//! ```

use std::f64::consts::FRAC_PI_2;

use glam::{DVec3, dvec3};

use crate::animation::{CameraPath, Motion};
use crate::error::Result;
use crate::file::SceneFile;
use crate::quality::{Effects, GlobalIllumination, Glow, Quality};
use crate::scene::{
    Axis, Camera, Environment, EnvironmentMap, Hybrid, HybridOp, InsideShape, Kifs, KifsFold,
    Light, Mandelbulb, Material, Node, OrbitColoring, Palette, Profile, PseudoKleinian,
    QuaternionJulia, Scene, Trap, box_frame, capped_cone, capped_torus, capsule, cone,
    cone_between, cuboid, cut_hollow_sphere, cut_sphere, cylinder, cylinder_between, death_star,
    ellipsoid, extrude, hex_prism, julia, link, menger, octahedron, param, param3, plane, pyramid,
    quad, revolve, rhombus, round_box, round_cone, round_cone_between, rounded_cylinder,
    sierpinski, solid_angle, sphere, torus, tri_prism, triangle,
};

/// Every gallery scene by name.
#[must_use]
pub fn all() -> Vec<(&'static str, Scene)> {
    vec![
        ("mandelbulb", mandelbulb()),
        ("menger", menger_sponge()),
        ("julia", quaternion_julia()),
        ("sierpinski", sierpinski_tetrahedron()),
        ("csg", csg()),
        ("primitives", primitives()),
        ("domain_ops", domain_ops()),
        ("fractal_mix", fractal_mix()),
        ("benchmark", benchmark()),
        ("depth_of_field", depth_of_field()),
        ("cross_section", cross_section()),
        ("materials", materials()),
        ("mandelbulb_escape", mandelbulb_escape()),
        ("mandelbox", mandelbox()),
        ("kifs", kifs()),
        ("hybrid", hybrid()),
        ("bulb_variants", bulb_variants()),
        ("kleinian", kleinian()),
        ("orbit_traps", orbit_traps()),
        ("profiles", profiles()),
        ("keyframes", keyframes()),
        ("gi", global_illumination()),
    ]
}

/// The direction of the sun in [`sky`]: low on the right, a little in
/// front of the subject, so that its shadows fall to the left across the
/// floor and onto the wall behind.
pub const SKY_SUN: DVec3 = DVec3::new(0.85, 0.4, 0.35);

/// The size of [`sky`]'s image, in texels.
pub const SKY_SIZE: (u32, u32) = (256, 128);

/// The daylight sky the gallery's `gi` scene is lit by: the crate's
/// `scenes/sky.hdr`, which [`EnvironmentMap::sky`] makes with the sun
/// along [`SKY_SUN`] at [`SKY_SIZE`] (and the scene files name as
/// `sky.hdr`, beside them).
///
/// # Panics
/// Never: the image is part of the crate.
#[must_use]
pub fn sky() -> Environment {
    let bytes = include_bytes!("../scenes/sky.hdr");
    let map = EnvironmentMap::from_hdr_bytes(bytes).expect("the crate's sky is a valid image");
    Environment::new(map).source("sky.hdr")
}

/// A Mandelbulb on a pale floor beside a white wall, a red ball and a
/// glass ball, lit by nothing but [`sky`], with global illumination in
/// its scene file: the wall takes the sky's light and the ball's red onto
/// the floor and the fractal's shaded side, and the glass bends the sky.
#[must_use]
pub fn global_illumination() -> Scene {
    let bulb = Node::from(Mandelbulb::new(8.0).iterations(8))
        .rotate(DVec3::X, -FRAC_PI_2)
        .scale(0.8)
        .color(dvec3(0.95, 0.75, 0.5))
        .translate(dvec3(-0.2, 0.0, 0.0));
    let wall = round_box(dvec3(2.2, 1.2, 0.1), 0.04)
        .color(dvec3(0.9, 0.9, 0.88))
        .translate(dvec3(0.0, 0.4, -1.3));
    let red = sphere(0.4)
        .color(dvec3(0.85, 0.12, 0.08))
        .material(Material::lambert())
        .translate(dvec3(1.3, -0.4, -0.6));
    let glass = sphere(0.32)
        .material(Material::glass(1.5))
        .translate(dvec3(-1.45, -0.48, 0.5));
    let ground = plane(DVec3::Y, 0.8).color(dvec3(0.7, 0.68, 0.64));
    let shapes = [bulb, wall, red, glass, ground]
        .into_iter()
        .reduce(Node::union)
        .expect("five shapes");
    Scene::new(shapes)
        .with_camera(Camera::look_at(dvec3(0.6, 0.7, 4.2), dvec3(0.0, -0.15, -0.2)).fov(42.0))
        .with_lights([])
        .with_environment(sky())
}

/// A Mandelbulb animated by keyframes alone: its `power` eases from 8 down
/// to 5 and springs back up to 9, a plane whose offset `cut` steps from
/// outside the fractal to through it opens it at 2 s, and the camera
/// ([`keyframes_path`]) flies in, narrowing its view and rolling. Its
/// first keyframe's camera is the scene's.
#[must_use]
pub fn keyframes() -> Scene {
    let bulb = Node::from(Mandelbulb::new(param("power", 8.0)).iterations(8))
        .rotate(DVec3::X, -FRAC_PI_2)
        .color(dvec3(0.55, 0.75, 0.95))
        .cut_plane(dvec3(0.4, 0.0, 1.0), param("cut", -1.5));
    Scene::new(bulb.union(floor(1.15)))
        .with_camera(Camera::look_at(dvec3(0.0, 1.2, 4.2), dvec3(0.0, -0.1, 0.0)).fov(50.0))
        .with_lights(key_and_fill())
}

/// The `keyframes` scene's tracks ([`Motion::Keys`]): `power` eases from
/// 8 to 5 over 2 s, then runs straight to 9 at 4 s; `cut` holds outside
/// the fractal until 2 s, then steps to 0.35 and, at 3 s, to 0.
#[must_use]
pub fn keyframes_motions() -> Vec<Motion> {
    use crate::animation::{Interpolation, Key};
    vec![
        Motion::Keys {
            name: "power".into(),
            keys: vec![
                Key::new(0.0, 8.0).interpolation(Interpolation::EaseInOut),
                Key::new(2.0, 5.0).interpolation(Interpolation::Linear),
                Key::new(4.0, 9.0),
            ],
        },
        Motion::Keys {
            name: "cut".into(),
            keys: vec![
                Key::new(0.0, -1.5).interpolation(Interpolation::Step),
                Key::new(2.0, 0.35).interpolation(Interpolation::Step),
                Key::new(3.0, 0.0),
            ],
        },
    ]
}

/// The `keyframes` scene's camera: from straight ahead at 50° it eases in
/// and round to the side at 35°, rolling 12°, then swings up above on a
/// spline as the roll eases back.
///
/// # Errors
/// None in practice: the keyframes are constants that validate.
pub fn keyframes_path() -> Result<CameraPath> {
    use crate::animation::{Interpolation, Keyframe};
    let target = dvec3(0.0, -0.1, 0.0);
    CameraPath::new(vec![
        Keyframe::new(0.0, dvec3(0.0, 1.2, 4.2), target)
            .interpolation(Interpolation::EaseInOut)
            .fov(50.0)
            .roll(0.0),
        Keyframe::new(2.0, dvec3(3.0, 1.0, 3.0), target)
            .fov(38.0)
            .roll(12.0),
        Keyframe::new(4.0, dvec3(2.2, 3.4, -2.4), target)
            .fov(44.0)
            .roll(0.0),
    ])
}

/// The animated dynamic parameters of the gallery scene `name` (empty for
/// a still scene): `fractal_mix`'s Mandelbulb breathes (its `power`),
/// `benchmark`'s sphere orbits the fractals (its `orbit`), and
/// `cross_section`'s cut sweeps through its Mandelbulb (its `cut`).
///
/// ```
/// use fractal_sdf::gallery;
/// assert!(gallery::motions("mandelbulb").is_empty());
/// for (name, value) in gallery::motions("fractal_mix")[0].values(1.5) {
///     assert_eq!(name, "power");
///     assert!((6.0..=10.0).contains(&value));
/// }
/// ```
#[must_use]
pub fn motions(name: &str) -> Vec<Motion> {
    match name {
        "fractal_mix" => vec![Motion::Oscillate {
            name: "power".into(),
            center: 8.0,
            amplitude: 2.0,
            period: 6.0,
        }],
        "cross_section" => vec![Motion::Oscillate {
            name: "cut".into(),
            center: 0.0,
            amplitude: 0.5,
            period: 8.0,
        }],
        "benchmark" => vec![Motion::Orbit {
            name: "orbit".into(),
            center: dvec3(0.0, 0.25, 0.0),
            radius: 1.35,
            period: 5.0,
        }],
        "keyframes" => keyframes_motions(),
        _ => Vec::new(),
    }
}

/// The gallery's scene `name` as a scene file: the scene, production
/// quality with 2×2 supersampling (4×4 for a camera with a lens, whose
/// blur needs more samples; brute-force steps of 2 footprints for a scene
/// with inside shapes), the default effects with a pale blue
/// glow, its [`motions`], and for `benchmark` its [`benchmark_path`] and
/// for `keyframes` its [`keyframes_path`]. The
/// crate's `scenes/` folder holds these files (`scenes/NAME.ron`), as
/// [`SceneFile::to_text`] writes them.
#[must_use]
pub fn file(name: &str) -> Option<SceneFile> {
    let scene = by_name(name)?;
    let samples = if scene.camera.aperture > 0.0 { 4 } else { 2 };
    let mut quality = Quality::production().supersampling(samples);
    if scene.compile().is_ok_and(|c| c.ir().has_inside_shapes()) {
        // Brute-force steps of 2 footprints: the four jittered samples of
        // a pixel average their noise.
        quality = quality.brute_step(2.0);
    }
    let effects = match name {
        // Lit by its sky alone: path traced, without the glow.
        "gi" => Effects::default().global_illumination(GlobalIllumination::default()),
        _ => Effects::default().glow(Glow::new(dvec3(0.6, 0.75, 1.0), 0.6)),
    };
    Some(SceneFile {
        scene,
        quality: Some(quality),
        effects,
        path: match name {
            "benchmark" => Some(benchmark_path().expect("a constant path")),
            "keyframes" => Some(keyframes_path().expect("a constant path")),
            _ => None,
        },
        motions: motions(name),
    })
}

/// The gallery scene called `name`, if there is one.
#[must_use]
pub fn by_name(name: &str) -> Option<Scene> {
    all().into_iter().find(|(n, _)| *n == name).map(|(_, s)| s)
}

/// The names of the gallery scenes.
#[must_use]
pub fn names() -> Vec<&'static str> {
    all().into_iter().map(|(n, _)| n).collect()
}

fn floor(height: f64) -> Node {
    plane(DVec3::Y, height).color(dvec3(0.55, 0.55, 0.6))
}

fn key_and_fill() -> Vec<Light> {
    vec![
        Light::directional(dvec3(0.5, 0.8, 0.35))
            .color(dvec3(1.0, 0.95, 0.85))
            .softness(0.06),
        Light::directional(dvec3(-0.6, 0.35, -0.4))
            .color(dvec3(0.6, 0.7, 1.0))
            .intensity(0.3),
    ]
}

/// A power-8 Mandelbulb standing on its axis.
#[must_use]
pub fn mandelbulb() -> Scene {
    let bulb = Node::from(Mandelbulb::new(8.0).iterations(10))
        .rotate(DVec3::X, -FRAC_PI_2)
        .color(dvec3(0.9, 0.6, 0.35));
    Scene::new(bulb)
        .with_camera(Camera::look_at(dvec3(2.05, 1.45, 2.8), dvec3(0.0, -0.12, 0.0)).fov(40.0))
        .with_lights(key_and_fill())
}

/// A level-4 Menger sponge on a floor.
#[must_use]
pub fn menger_sponge() -> Scene {
    let sponge = menger(4)
        .rotate(DVec3::Y, 0.5)
        .color(dvec3(0.85, 0.85, 0.8));
    Scene::new(sponge.union(floor(1.0)))
        .with_camera(Camera::look_at(dvec3(2.6, 1.9, 3.2), dvec3(0.0, -0.1, 0.0)).fov(42.0))
        .with_lights(key_and_fill())
}

/// A quaternion Julia set.
#[must_use]
pub fn quaternion_julia() -> Scene {
    let set = Node::from(
        QuaternionJulia::new([(-0.2).into(), 0.6.into(), 0.2.into(), 0.2.into()]).iterations(11),
    )
    .color(dvec3(0.45, 0.7, 0.95));
    Scene::new(set)
        .with_camera(Camera::look_at(dvec3(0.0, 1.2, 2.6), DVec3::ZERO).fov(45.0))
        .with_lights(key_and_fill())
}

/// A level-7 Sierpinski tetrahedron on a floor.
#[must_use]
pub fn sierpinski_tetrahedron() -> Scene {
    let tet = sierpinski(7).color(dvec3(0.95, 0.75, 0.45));
    Scene::new(tet.union(floor(1.0)))
        .with_camera(Camera::look_at(dvec3(2.4, 1.4, 3.0), dvec3(0.0, -0.1, 0.0)).fov(45.0))
        .with_lights(key_and_fill())
}

/// Five Menger sponges in a row, seen through a lens focused on the
/// middle one: the nearer and farther ones blur, more with distance from
/// the plane in focus (render with supersampling or progressive passes).
#[must_use]
pub fn depth_of_field() -> Scene {
    let colors = [
        dvec3(0.35, 0.6, 0.95),
        dvec3(0.5, 0.7, 0.9),
        dvec3(0.85, 0.85, 0.8),
        dvec3(0.95, 0.75, 0.5),
        dvec3(0.95, 0.55, 0.35),
    ];
    let row = (-2..=2)
        .zip(colors)
        .map(|(i, color)| {
            let t = f64::from(i);
            menger(3)
                .rotate(DVec3::Y, 0.35 * t)
                .scale(0.36)
                .color(color)
                .translate(dvec3(0.62 * t, 0.0, -0.95 * t))
        })
        .reduce(Node::union)
        .expect("five sponges");
    let camera = Camera::look_at(dvec3(-0.6, 1.0, 4.3), dvec3(0.0, -0.15, 0.0)).fov(38.0);
    let in_focus = (camera.target - camera.position).length();
    Scene::new(row.union(floor(0.36)))
        .with_camera(camera.lens(0.1).focus(in_focus))
        .with_lights(key_and_fill())
}

/// A power-8 Mandelbulb cut open by a plane facing the camera: the cut
/// face shows the inside coloured by its orbit traps. The plane's offset
/// is the dynamic parameter `cut` (0: through the centre), so it moves
/// without a new program.
#[must_use]
pub fn cross_section() -> Scene {
    let bulb = Node::from(Mandelbulb::new(8.0).iterations(10))
        .rotate(DVec3::X, -FRAC_PI_2)
        .color(dvec3(0.95, 0.7, 0.45))
        .cut_plane(dvec3(0.0, 0.3, 1.0), param("cut", 0.0));
    Scene::new(bulb.union(floor(1.15)))
        .with_camera(Camera::look_at(dvec3(2.5, 1.7, 2.9), dvec3(0.0, -0.2, 0.0)).fov(40.0))
        .with_lights(key_and_fill())
}

/// The shading models and the secondary rays, side by side on a polished
/// floor that mirrors them: from the left, a rough clay sphere
/// (Oren–Nayar), a glossy one (Blinn–Phong), a waxy lens whose thin rim
/// glows with the light behind it (subsurface), a glass sphere whose
/// index is the dynamic parameter `ior` (1.5) and a mirror sphere; a
/// Mandelbulb behind them shows in the glass and the mirror.
#[must_use]
pub fn materials() -> Scene {
    let at = |x: f64, z: f64| dvec3(x, 0.0, z);
    let clay = sphere(0.42)
        .color(dvec3(0.8, 0.45, 0.3))
        .material(Material::oren_nayar(0.9))
        .translate(at(-1.9, 0.2));
    let glossy = sphere(0.42)
        .color(dvec3(0.25, 0.45, 0.9))
        .material(Material::blinn_phong(0.9, 80.0))
        .translate(at(-0.95, 0.2));
    let wax = ellipsoid(dvec3(0.45, 0.45, 0.16))
        .color(dvec3(0.95, 0.8, 0.5))
        .material(Material::subsurface(1.0, 0.3))
        .rotate(DVec3::Y, -0.5)
        .translate(at(0.0, 0.2));
    let glass = sphere(0.42)
        .material(Material::glass(param("ior", 1.5)))
        .translate(at(0.95, 0.35));
    let mirror = sphere(0.42)
        .material(Material::mirror())
        .translate(at(1.9, 0.2));
    let bulb = Node::from(Mandelbulb::new(8.0).iterations(8))
        .rotate(DVec3::X, -FRAC_PI_2)
        .scale(0.7)
        .color(dvec3(0.95, 0.7, 0.45))
        .translate(dvec3(0.5, 0.25, -1.3));
    let polished = floor(0.45).material(Material::default().reflectivity(0.25));
    let shapes = [clay, glossy, wax, glass, mirror, bulb]
        .into_iter()
        .reduce(Node::union)
        .expect("six shapes");
    Scene::new(shapes.union(polished))
        .with_camera(Camera::look_at(dvec3(0.0, 1.1, 4.4), dvec3(0.0, -0.05, -0.2)).fov(42.0))
        .with_lights(vec![
            Light::directional(dvec3(0.5, 0.8, 0.6))
                .color(dvec3(1.0, 0.95, 0.85))
                .softness(0.06),
            Light::directional(dvec3(-0.3, 0.35, -0.9))
                .color(dvec3(1.0, 0.85, 0.7))
                .intensity(0.8),
        ])
}

/// The gallery's [`mandelbulb`] drawn from its escape-time test alone:
/// an [`InsideShape::mandelbulb`] of power 8 and 10 iterations, marched by
/// brute force, with the same camera and lights. Its surface is the set's
/// own, rougher than the estimate's, which is drawn DETAIL pixels out.
#[must_use]
pub fn mandelbulb_escape() -> Scene {
    let bulb = InsideShape::mandelbulb()
        .node([8.0, 10.0])
        .rotate(DVec3::X, -FRAC_PI_2)
        .color(dvec3(0.9, 0.6, 0.35));
    let reference = mandelbulb();
    Scene::new(bulb)
        .with_camera(reference.camera)
        .with_lights(reference.lights)
}

/// The classic Mandelbox (scale 2, 16 iterations) standing on a floor,
/// drawn from its distance estimate. Scale 2 fills the cube `[-6, 6]^3`;
/// the scene shrinks it to the cube `[-1, 1]^3`.
#[must_use]
pub fn mandelbox() -> Scene {
    let boxed = crate::scene::mandelbox(2.0)
        .rotate(DVec3::Y, 0.6)
        .scale(1.0 / 6.0)
        .color(dvec3(0.5, 0.62, 0.85));
    Scene::new(boxed.union(floor(1.0)))
        .with_camera(Camera::look_at(dvec3(2.9, 2.0, 3.8), dvec3(0.0, -0.2, 0.0)).fov(40.0))
        .with_lights(key_and_fill())
}

/// The four kaleidoscopic IFS folds with their classic settings (the
/// Sierpinski tetrahedron, octahedron and icosahedron, the Menger sponge),
/// and in front a Menger fold turned before and after its folds.
#[must_use]
pub fn kifs() -> Scene {
    let classic = [
        (KifsFold::Tetrahedral, 0.33, dvec3(0.9, 0.55, 0.3)),
        (KifsFold::Octahedral, 0.55, dvec3(0.55, 0.8, 0.4)),
        (KifsFold::Icosahedral, 0.55, dvec3(0.35, 0.65, 0.9)),
        (KifsFold::Menger, 0.32, dvec3(0.75, 0.45, 0.85)),
    ];
    let row = classic
        .into_iter()
        .enumerate()
        .map(|(i, (fold, size, color))| {
            #[allow(clippy::cast_precision_loss)]
            let x = (i as f64 - 1.5) * 1.3;
            crate::scene::kifs(fold)
                .scale(size)
                .rotate(DVec3::Y, 0.4)
                .color(color)
                .translate(dvec3(x, 0.0, -0.5))
        })
        .reduce(Node::union)
        .expect("four folds");
    let turned = Node::from(
        Kifs::new(KifsFold::Menger)
            .rotate_before([0.2, 0.1, 0.0])
            .rotate_after([0.0, 0.0, 0.2]),
    )
    .scale(0.3)
    .color(dvec3(0.95, 0.8, 0.35))
    .translate(dvec3(0.0, -0.1, 0.9));
    Scene::new(row.union(turned).union(floor(0.6)))
        .with_camera(Camera::look_at(dvec3(0.0, 1.4, 3.7), dvec3(0.0, -0.2, 0.0)).fov(45.0))
        .with_lights(key_and_fill())
}

/// Three hybrids ([`Hybrid`]): an Abox-Mod (the Mandelbox's folds at
/// scale −1.5 with a turn in each iteration), the Mandelbox at scale −1.5
/// three times then the power-8 Mandelbulb once, and a tile of Amazing
/// Surf (Kali's box fold on `x` and `y` only: a slab, cut to a square).
#[must_use]
pub fn hybrid() -> Scene {
    let abox = Hybrid::new()
        .stage(
            1,
            [
                HybridOp::box_fold(1.0),
                HybridOp::sphere_fold(0.5, 1.0),
                HybridOp::scale(-1.5),
                HybridOp::AddPoint,
                HybridOp::rotate([0.15, 0.3, 0.0]),
            ],
        )
        .iterations(12);
    let bulb_box = Hybrid::new()
        .stage(3, Hybrid::mandelbox(-1.5).stages[0].ops.clone())
        .stage(1, [HybridOp::power(8.0), HybridOp::AddPoint])
        .iterations(8);
    let surf = Node::from(Hybrid::amazing_surf(1.5, [0.0, 0.0, 0.3]).iterations(10))
        .intersect(cuboid(dvec3(2.5, 2.5, 1.0)))
        .rotate(DVec3::X, -1.2);
    let row = [
        (Node::from(abox), 1.0 / 3.0, dvec3(0.85, 0.55, 0.3)),
        (Node::from(bulb_box), 0.3, dvec3(0.4, 0.7, 0.9)),
        (surf, 1.0 / 3.0, dvec3(0.6, 0.85, 0.45)),
    ]
    .into_iter()
    .enumerate()
    .map(|(i, (node, size, color))| {
        #[allow(clippy::cast_precision_loss)]
        let x = (i as f64 - 1.0) * 1.7;
        node.scale(size)
            .rotate(DVec3::Y, 0.5)
            .color(color)
            .translate(dvec3(x, 0.0, 0.0))
    })
    .reduce(Node::union)
    .expect("three hybrids");
    Scene::new(row.union(floor(1.0)))
        .with_camera(Camera::look_at(dvec3(0.0, 1.8, 4.4), dvec3(0.0, -0.2, 0.0)).fov(45.0))
        .with_lights(key_and_fill())
}

/// The two Mandelbulb variants written as hybrids: the classic power-2
/// Mandelbulb ([`Hybrid::power2_mandelbulb`], its latitude doubled and its
/// `z` negated) standing on its axis, and the quaternion Mandelbrot set
/// ([`Hybrid::quaternion_mandelbrot`], the Mandelbrot set turned about its
/// real axis) lying along `x`.
#[must_use]
pub fn bulb_variants() -> Scene {
    let bulb = Node::from(Hybrid::power2_mandelbulb().iterations(10).bailout(4.0))
        .rotate(DVec3::X, -FRAC_PI_2)
        .scale(0.42)
        .color(dvec3(0.85, 0.55, 0.3))
        .translate(dvec3(-1.05, -0.15, 0.0));
    let quaternion = Node::from(Hybrid::quaternion_mandelbrot().iterations(10).bailout(4.0))
        .rotate(DVec3::Y, 0.2)
        .scale(0.55)
        .color(dvec3(0.4, 0.7, 0.9))
        .translate(dvec3(1.05, -0.38, 0.2));
    // Hard shadows: a soft shadow's penumbra comes from the estimate, and
    // the power-2 bulb's is far below the distance (see the guide).
    let lights: Vec<Light> = key_and_fill()
        .into_iter()
        .map(|l| l.softness(0.0))
        .collect();
    Scene::new(bulb.union(quaternion).union(floor(1.0)))
        .with_camera(Camera::look_at(dvec3(0.0, 1.5, 4.6), dvec3(0.0, -0.2, 0.0)).fov(45.0))
        .with_lights(lights)
}

/// Knighty's pseudo-Kleinian fractal ([`PseudoKleinian`], his published
/// preset) seen from inside, where its spheres nest in ever smaller
/// circles, lit by a lamp beside the camera.
#[must_use]
pub fn kleinian() -> Scene {
    let eye = dvec3(0.5, 0.4, 0.6);
    let set = Node::from(PseudoKleinian::new().iterations(10)).color(dvec3(0.9, 0.78, 0.6));
    Scene::new(set)
        .with_camera(Camera::look_at(eye, dvec3(-1.0, -0.4, -0.5)).fov(50.0))
        .with_lights([
            Light::point(eye + dvec3(0.05, 0.1, 0.0))
                .intensity(0.3)
                .softness(0.02),
            Light::directional(dvec3(-0.6, 0.35, -0.4))
                .color(dvec3(0.6, 0.7, 1.0))
                .intensity(0.25),
        ])
}

/// Four fractals coloured by their orbits ([`Node::orbit_trap`]): the
/// Mandelbulb by the plane through its equator (fire), the Mandelbox by a
/// sphere (viridis), a quaternion Julia set by a line (ocean) and an
/// icosahedral KIFS by a point (magma).
#[must_use]
pub fn orbit_traps() -> Scene {
    let bulb = Node::from(Mandelbulb::new(8.0).iterations(10))
        .orbit_coloring(
            OrbitColoring::new(Trap::plane([0.0, 0.0, 1.0], 0.0), Palette::fire()).range(0.0, 0.8),
        )
        .rotate(DVec3::X, -FRAC_PI_2)
        .scale(0.55);
    let boxed = crate::scene::mandelbox(2.0)
        .orbit_coloring(
            OrbitColoring::new(Trap::sphere([0.0, 0.0, 0.0], 2.0), Palette::viridis())
                .range(0.0, 2.0),
        )
        .rotate(DVec3::Y, 0.6)
        .scale(0.11);
    let set = julia([-0.2, 0.6, 0.2, 0.2])
        .orbit_coloring(
            OrbitColoring::new(
                Trap::line([0.0, 0.0, 0.0], [1.0, 0.0, 0.0]),
                Palette::ocean(),
            )
            .range(0.0, 0.9),
        )
        .scale(0.6);
    let ifs = crate::scene::kifs(KifsFold::Icosahedral)
        .orbit_coloring(
            OrbitColoring::new(Trap::point([0.0, 0.0, 0.0]), Palette::magma()).range(0.3, 1.6),
        )
        .rotate(DVec3::Y, 0.4)
        .scale(0.6);
    // Two rows: the Mandelbox and the KIFS behind, the Mandelbulb and the
    // Julia set in front.
    let at = [
        dvec3(-0.95, 0.0, 0.75),
        dvec3(-0.75, 0.0, -0.95),
        dvec3(0.85, -0.1, 0.8),
        dvec3(1.05, 0.0, -0.95),
    ];
    let all = [bulb, boxed, set, ifs]
        .into_iter()
        .zip(at)
        .map(|(node, at)| node.translate(at))
        .reduce(Node::union)
        .expect("four fractals");
    Scene::new(all.union(floor(0.7)))
        .with_camera(Camera::look_at(dvec3(0.0, 2.7, 4.3), dvec3(0.0, -0.25, 0.0)).fov(42.0))
        .with_lights(key_and_fill())
}

/// Solids made from plane profiles ([`extrude`], [`revolve`]): a star and
/// an arrow extruded, a goblet, a lampshade, a ring of rounded-square
/// section and a spheroid (an ellipse) revolved.
#[must_use]
pub fn profiles() -> Scene {
    let star = extrude(
        Profile::polygon((0..10).map(|i| {
            let r = if i % 2 == 0 { 0.42 } else { 0.17 };
            let a = f64::from(i) * std::f64::consts::PI / 5.0;
            [r * a.sin(), r * a.cos()]
        })),
        0.06,
    )
    .color(dvec3(0.95, 0.7, 0.2))
    .rotate(DVec3::Y, 0.35)
    .translate(dvec3(-1.3, -0.03, -0.45));
    let goblet = revolve(
        Profile::polygon([
            [0.0, -0.45],
            [0.3, -0.45],
            [0.3, -0.41],
            [0.05, -0.36],
            [0.04, 0.0],
            [0.3, 0.12],
            [0.33, 0.45],
            [0.3, 0.45],
            [0.27, 0.15],
            [0.0, 0.06],
        ]),
        0.0,
    )
    .color(dvec3(0.75, 0.85, 0.95))
    .translate(dvec3(-0.45, 0.0, -0.6));
    let shade = revolve(Profile::segment([0.32, -0.2], [0.14, 0.2], 0.025), 0.0)
        .color(dvec3(0.9, 0.35, 0.3))
        .translate(dvec3(0.5, -0.225, -0.55));
    let ring = revolve(Profile::round_rect(0.09, 0.09, 0.03), 0.3)
        .color(dvec3(0.3, 0.6, 0.95))
        .rotate(DVec3::X, 1.2)
        .translate(dvec3(1.3, -0.085, -0.45));
    let arrow = extrude(
        Profile::polygon([
            [-0.5, -0.07],
            [0.15, -0.07],
            [0.15, -0.2],
            [0.45, 0.0],
            [0.15, 0.2],
            [0.15, 0.07],
            [-0.5, 0.07],
        ]),
        0.05,
    )
    .color(dvec3(0.4, 0.8, 0.45))
    .rotate(DVec3::X, -FRAC_PI_2)
    .translate(dvec3(0.5, -0.4, 0.5));
    let spheroid = revolve(Profile::ellipse(0.2, 0.32), 0.0)
        .color(dvec3(0.85, 0.55, 0.85))
        .translate(dvec3(-0.6, -0.13, 0.6));
    let all = [star, goblet, shade, ring, arrow, spheroid]
        .into_iter()
        .reduce(Node::union)
        .expect("six solids");
    Scene::new(all.union(floor(0.45)))
        .with_camera(Camera::look_at(dvec3(0.0, 1.2, 3.0), dvec3(0.0, -0.2, -0.1)).fov(48.0))
        .with_lights(key_and_fill())
}

/// Smooth union, subtraction and intersection of transformed primitives.
#[must_use]
pub fn csg() -> Scene {
    let blend = sphere(0.55)
        .smooth_union(
            cuboid(dvec3(0.35, 0.35, 0.35)).translate(dvec3(0.45, 0.0, 0.0)),
            0.25,
        )
        .color(dvec3(0.95, 0.45, 0.2))
        .translate(dvec3(-1.3, 0.0, 0.0));
    let carved = round_box(dvec3(0.5, 0.5, 0.5), 0.08)
        .smooth_subtract(sphere(0.62), 0.08)
        .color(dvec3(0.3, 0.65, 0.95))
        .rotate(DVec3::Y, 0.6);
    let lens = sphere(0.6)
        .translate(dvec3(0.0, 0.0, 0.3))
        .smooth_intersect(sphere(0.6).translate(dvec3(0.0, 0.0, -0.3)), 0.1)
        .color(dvec3(0.4, 0.85, 0.45))
        .rotate(DVec3::X, 0.9)
        .translate(dvec3(1.3, 0.0, 0.0));
    Scene::new(blend.union(carved).union(lens).union(floor(0.6)))
        .with_camera(Camera::look_at(dvec3(0.0, 1.5, 3.6), dvec3(0.0, -0.1, 0.0)).fov(45.0))
        .with_lights(key_and_fill())
}

/// One of every bounded primitive, in four rows (the plane is the
/// floor).
#[must_use]
pub fn primitives() -> Scene {
    let items = [
        sphere(0.35),
        cuboid(dvec3(0.3, 0.3, 0.3)),
        round_box(dvec3(0.3, 0.3, 0.3), 0.08),
        torus(0.28, 0.1),
        cylinder(0.25, 0.35),
        capsule(dvec3(0.0, -0.2, 0.0), dvec3(0.0, 0.2, 0.0), 0.18),
        octahedron(0.4),
        capped_cone(0.35, 0.3, 0.1),
        ellipsoid(dvec3(0.35, 0.2, 0.25)),
        hex_prism(0.28, 0.3),
        round_cone(0.22, 0.22, 0.1),
        link(0.14, 0.2, 0.07).rotate(DVec3::Y, 0.5),
        cut_sphere(0.35, 0.15).translate(dvec3(0.0, 0.05, 0.0)),
        solid_angle(0.6, 0.45).translate(dvec3(0.0, -0.3, 0.0)),
        capped_torus(2.2, 0.25, 0.07),
        cylinder_between(dvec3(-0.2, -0.3, 0.0), dvec3(0.15, 0.25, 0.0), 0.12),
        cone_between(dvec3(0.2, -0.25, 0.0), dvec3(-0.15, 0.3, 0.0), 0.22, 0.05),
        round_cone_between(dvec3(-0.15, -0.2, 0.0), dvec3(0.2, 0.25, 0.0), 0.16, 0.07),
        triangle(
            dvec3(-0.3, -0.35, 0.0),
            dvec3(0.3, -0.35, 0.0),
            dvec3(0.0, 0.3, 0.0),
            0.03,
        )
        .rotate(DVec3::Y, 0.4),
        quad(
            dvec3(-0.28, -0.35, -0.12),
            dvec3(0.28, -0.35, -0.12),
            dvec3(0.2, 0.3, 0.1),
            dvec3(-0.2, 0.3, 0.1),
            0.03,
        ),
        pyramid(0.3, 0.55)
            .rotate(DVec3::Y, 0.5)
            .translate(dvec3(0.0, -0.4, 0.0)),
        rhombus(0.36, 0.22, 0.06, 0.04)
            .rotate(DVec3::Y, 0.6)
            .translate(dvec3(0.0, -0.34, 0.0)),
        tri_prism(0.17, 0.3).translate(dvec3(0.0, -0.1, 0.0)),
        rounded_cylinder(0.28, 0.2, 0.08).translate(dvec3(0.0, -0.2, 0.0)),
        cone(0.28, 0.6).translate(dvec3(0.0, 0.2, 0.0)),
        cut_hollow_sphere(0.32, 0.12, 0.02).translate(dvec3(0.0, -0.06, 0.0)),
        death_star(0.32, 0.25, 0.3)
            .rotate(DVec3::Y, -FRAC_PI_2)
            .translate(dvec3(0.0, -0.08, 0.0)),
        box_frame(dvec3(0.28, 0.28, 0.28), 0.05)
            .rotate(DVec3::Y, 0.5)
            .translate(dvec3(0.0, -0.12, 0.0)),
    ];
    let count = items.len();
    let row = items
        .into_iter()
        .enumerate()
        .map(|(i, node)| {
            #[allow(clippy::cast_precision_loss)]
            let t = i as f64 / (count - 1) as f64;
            let hue = dvec3(
                0.9 - 0.6 * t,
                0.45 + 0.35 * (1.0 - (2.0 * t - 1.0).abs()),
                0.3 + 0.6 * t,
            );
            // Seven in each of four rows, 0.85 apart.
            #[allow(clippy::cast_precision_loss)]
            let (column, row) = ((i % 7) as f64 - 3.0, (i / 7) as f64 - 1.5);
            node.color(hue)
                .translate(dvec3(column * 0.85, 0.0, row * 0.95))
        })
        .reduce(Node::union)
        .expect("twenty-eight primitives");
    Scene::new(row.union(floor(0.4)))
        .with_camera(Camera::look_at(dvec3(0.0, 4.6, 7.2), dvec3(0.0, -0.15, 0.3)).fov(36.0))
        .with_lights(key_and_fill())
}

/// Twist, bend, repetition, shells, elongation and mirroring.
#[must_use]
pub fn domain_ops() -> Scene {
    // A twist keeps the distance from the y axis and the height, and a bend
    // the distance from the origin, so exact bounding shapes clip their
    // (conservative) distance bounds far away: faster marching, no false
    // hits at coarse thresholds.
    let twisted = cuboid(dvec3(0.25, 0.6, 0.25))
        .twist(2.0)
        .intersect(cylinder(0.36, 0.6))
        .color(dvec3(0.9, 0.4, 0.4))
        .translate(dvec3(-1.5, 0.0, 0.0));
    let bent = cuboid(dvec3(0.6, 0.1, 0.2))
        .bend(0.8)
        .intersect(sphere(0.65))
        .color(dvec3(0.4, 0.9, 0.5))
        .translate(dvec3(-0.4, 0.0, 0.0));
    let shell = sphere(0.45)
        .onion(0.04)
        .subtract(cuboid(dvec3(1.0, 1.0, 1.0)).translate(dvec3(0.0, 1.2, 0.0)))
        .color(dvec3(0.4, 0.6, 0.95))
        .translate(dvec3(0.65, 0.0, 0.0));
    let pills = sphere(0.12)
        .elongate(dvec3(0.0, 0.15, 0.0))
        .repeat_limited(dvec3(0.35, 0.0, 0.35), [1, 0, 1])
        .color(dvec3(0.95, 0.8, 0.3))
        .translate(dvec3(1.6, -0.25, 0.0));
    let mirrored = torus(0.2, 0.06)
        .rotate(DVec3::X, FRAC_PI_2)
        .translate(dvec3(0.5, 0.0, 0.0))
        .mirror(Axis::X)
        .round(0.01)
        .color(dvec3(0.8, 0.5, 0.9))
        .translate(dvec3(0.0, 0.85, -0.8));
    Scene::new(
        twisted
            .union(bent)
            .union(shell)
            .union(pills)
            .union(mirrored)
            .union(floor(0.6)),
    )
    .with_camera(Camera::look_at(dvec3(0.0, 1.6, 3.8), dvec3(0.0, 0.0, 0.0)).fov(45.0))
    .with_lights(key_and_fill())
}

/// All four fractals blended with smooth CSG, transforms and a dynamic
/// parameter (`power`).
#[must_use]
pub fn fractal_mix() -> Scene {
    let bulb = Node::from(Mandelbulb::new(param("power", 8.0)).iterations(8))
        .rotate(DVec3::X, -FRAC_PI_2)
        .scale(0.5)
        .color(dvec3(0.9, 0.55, 0.3))
        .translate(dvec3(-1.1, 0.0, 0.0));
    let sponge = menger(3)
        .scale(0.45)
        .smooth_subtract(sphere(0.55), 0.05)
        .color(dvec3(0.8, 0.8, 0.75))
        .translate(dvec3(0.0, 0.0, -0.6));
    let set = julia([-0.2, 0.6, 0.2, 0.2])
        .scale(0.5)
        .color(dvec3(0.4, 0.7, 0.95))
        .translate(dvec3(1.1, 0.0, 0.0));
    let tet = sierpinski(5)
        .scale(0.35)
        .color(dvec3(0.95, 0.8, 0.4))
        .translate(dvec3(0.0, 0.0, 0.7));
    let fractals = bulb
        .smooth_union(sponge, 0.1)
        .smooth_union(set, 0.1)
        .smooth_union(tet, 0.1);
    Scene::new(fractals.union(floor(0.55)))
        .with_camera(Camera::look_at(dvec3(0.0, 1.6, 3.2), dvec3(0.0, -0.1, 0.0)).fov(45.0))
        .with_lights(key_and_fill())
}

/// The performance benchmark's scene: a Mandelbulb on a pedestal between a
/// Menger sponge and a torus, a sphere orbiting them (the dynamic parameter
/// `orbit`, see [`motions`]), a floor and two soft-shadowed lights. Seen
/// along [`benchmark_path`].
#[must_use]
pub fn benchmark() -> Scene {
    let bulb = Node::from(Mandelbulb::new(8.0).iterations(8))
        .rotate(DVec3::X, -FRAC_PI_2)
        .scale(0.6)
        .color(dvec3(0.9, 0.6, 0.35))
        .translate(dvec3(0.0, 0.05, 0.0));
    let pedestal = cylinder(0.35, 0.2)
        .smooth_union(
            cuboid(dvec3(0.5, 0.05, 0.5)).translate(dvec3(0.0, -0.2, 0.0)),
            0.05,
        )
        .color(dvec3(0.5, 0.5, 0.55))
        .translate(dvec3(0.0, -0.75, 0.0));
    let sponge = menger(3)
        .scale(0.4)
        .rotate(DVec3::Y, 0.4)
        .color(dvec3(0.85, 0.85, 0.8))
        .translate(dvec3(-1.5, -0.55, -0.3));
    let ring = torus(0.35, 0.1)
        .rotate(DVec3::X, 1.2)
        .color(dvec3(0.4, 0.75, 0.95))
        .translate(dvec3(1.5, -0.5, -0.2));
    let moon = sphere(0.18)
        .color(dvec3(0.95, 0.4, 0.3))
        .translate(param3("orbit", dvec3(1.35, 0.25, 0.0)));
    let geometry = bulb
        .union(pedestal)
        .union(sponge)
        .union(ring)
        .union(moon)
        .union(floor(0.95));
    Scene::new(geometry)
        .with_camera(Camera::look_at(dvec3(0.0, 1.4, 3.6), dvec3(0.0, -0.3, 0.0)).fov(45.0))
        .with_lights(key_and_fill())
}

/// The benchmark's fixed camera path: one 10-second turn around the scene,
/// 3.6 units out and 1.7 up, looking just below the Mandelbulb.
///
/// # Errors
/// None in practice: the path is constant (the `Result` is
/// [`CameraPath::orbit`]'s).
pub fn benchmark_path() -> Result<CameraPath> {
    CameraPath::orbit(dvec3(0.0, -0.3, 0.0), 3.6, 1.7, 10.0, 16)
}
