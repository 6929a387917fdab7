//! Surface materials: how a surface answers light.
//!
//! A [`Material`] is nine numbers, each a [`Param`] (so any of them can be
//! dynamic), that the renderer's one shading formula reads:
//!
//! - **diffuse**: Oren–Nayar with facet roughness σ ([`Material::roughness`],
//!   radians); σ = 0 is Lambert exactly;
//! - **highlight**: Blinn–Phong, `specular · (n·h)^shininess`;
//! - **subsurface**: light from behind a thin part shows through it, scaled
//!   by how thin the shape is below the surface, sampled along the inward
//!   normal to [`Material::scatter_depth`];
//! - **reflections and transparency**: a share of the surface's colour
//!   comes from a reflected ray, and a share from a refracted one (index
//!   [`Material::ior`], with Fresnel's reflectance), traced up to
//!   [`Quality::bounces`](crate::quality::Quality::bounces) deep;
//! - **emission**: the surface gives off light of its own, its colour
//!   times [`Material::emission`]: seen in every mode, and lighting the
//!   scene under [global illumination](crate::quality::GlobalIllumination).
//!
//! The four shading models of the constructors are points in that space:
//! [`Material::lambert`], [`Material::oren_nayar`], [`Material::blinn_phong`]
//! and [`Material::subsurface`]. Because they are terms of one formula they
//! also combine (a rough surface with a highlight), and smooth booleans
//! blend materials across their seams value by value, as they blend
//! colours.
//!
//! ```
//! use fractal_sdf::prelude::*;
//!
//! let chrome = sphere(1.0).material(Material::mirror());
//! let glass = sphere(1.0).material(Material::glass(1.5));
//! let clay = sphere(1.0).material(Material::oren_nayar(param("rough", 0.6)));
//! let wax = sphere(1.0).material(Material::subsurface(0.8, 0.3).reflectivity(0.05));
//! # let _ = (chrome, glass, clay, wax);
//! ```

use super::param::Param;
use super::rule::{ParamSpec, Rule, spec};

/// How a surface answers light: the values that the renderer's one
/// shading formula reads (Oren–Nayar diffuse, a Blinn–Phong highlight,
/// subsurface light through thin parts, reflections and refraction; see
/// [`Node::material`](super::Node::material) and [the guide](crate::guide::materials)).
///
/// `Material::default()` is the look of every surface without a material:
/// Lambert diffuse with a Blinn–Phong highlight of strength 0.25 and
/// shininess 32, nothing reflected or transmitted.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Material<S = Param> {
    /// Oren–Nayar roughness σ, the spread of the microfacets' slopes in
    /// radians (at least 0; 0 is Lambert, 0.3 chalky, 1 very rough): rough
    /// surfaces look flatter, brighter towards the light's side at grazing
    /// views.
    pub roughness: S,
    /// Strength of the Blinn–Phong highlight (at least 0; 0: none).
    pub specular: S,
    /// Blinn–Phong exponent: larger is a smaller, sharper highlight (at
    /// least 0).
    pub shininess: S,
    /// Strength of the light that passes through thin parts from behind
    /// (at least 0; 0: none).
    pub subsurface: S,
    /// How deep below the surface the thickness is sampled, in scene units
    /// (at least 0): parts thinner than this let light through.
    pub scatter_depth: S,
    /// The share of the colour a mirror reflection gives, in `[0, 1]`.
    pub reflectivity: S,
    /// The share of what is left that passes into the surface, refracted,
    /// in `[0, 1]` (1 with reflectivity 0: clear glass).
    pub transparency: S,
    /// Index of refraction (greater than 0; 1.5 for glass, 1.33 water, 1
    /// passes rays straight through).
    pub ior: S,
    /// Light the surface gives off, as a multiple of its colour (at least
    /// 0; 0: none): a white surface of emission 1 is as bright as a white
    /// surface lit square on by a light of intensity 1. The camera,
    /// mirrors and glass see it in every mode; it lights other surfaces
    /// only under global illumination, where every bounce of a path also
    /// draws a direction towards each emissive shape's bounding sphere
    /// (up to 16 shapes with a bound; others are found by the bounces
    /// alone), weighted against the bounce's own by the power heuristic.
    pub emission: S,
}

/// How many numbers a material has, in [`Material::values`] order (the
/// kernels carry them in a `real16`, the rest zero).
pub const MATERIAL_LEN: usize = 9;

impl Material {
    /// Lambert diffuse and nothing else: matte.
    #[must_use]
    pub fn lambert() -> Self {
        Material {
            specular: 0.0.into(),
            ..Self::default()
        }
    }

    /// Oren–Nayar diffuse with roughness σ in radians (see
    /// [`Material::roughness`]); no highlight.
    #[must_use]
    pub fn oren_nayar(roughness: impl Into<Param>) -> Self {
        Material {
            roughness: roughness.into(),
            ..Self::lambert()
        }
    }

    /// Lambert diffuse with a Blinn–Phong highlight.
    #[must_use]
    pub fn blinn_phong(specular: impl Into<Param>, shininess: impl Into<Param>) -> Self {
        Material {
            specular: specular.into(),
            shininess: shininess.into(),
            ..Self::default()
        }
    }

    /// Lambert diffuse with light through thin parts: `strength` of the
    /// light behind passes where the shape is thinner than `depth` below
    /// the surface.
    #[must_use]
    pub fn subsurface(strength: impl Into<Param>, depth: impl Into<Param>) -> Self {
        Material {
            subsurface: strength.into(),
            scatter_depth: depth.into(),
            ..Self::lambert()
        }
    }

    /// A perfect mirror: every ray reflected, with a small highlight.
    #[must_use]
    pub fn mirror() -> Self {
        Material {
            reflectivity: 1.0.into(),
            ..Self::default()
        }
    }

    /// Clear glass of refractive index `ior`: light passes in, bent, with
    /// the Fresnel share reflected.
    #[must_use]
    pub fn glass(ior: impl Into<Param>) -> Self {
        Material {
            transparency: 1.0.into(),
            ior: ior.into(),
            ..Self::default()
        }
    }

    /// Lambert diffuse that also gives off its colour times `strength` as
    /// light (see [`Material::emission`]).
    #[must_use]
    pub fn emissive(strength: impl Into<Param>) -> Self {
        Material {
            emission: strength.into(),
            ..Self::lambert()
        }
    }

    /// The same material with roughness σ.
    #[must_use]
    pub fn roughness(mut self, sigma: impl Into<Param>) -> Self {
        self.roughness = sigma.into();
        self
    }

    /// The same material with a Blinn–Phong highlight.
    #[must_use]
    pub fn highlight(mut self, specular: impl Into<Param>, shininess: impl Into<Param>) -> Self {
        self.specular = specular.into();
        self.shininess = shininess.into();
        self
    }

    /// The same material with reflectivity `r`.
    #[must_use]
    pub fn reflectivity(mut self, r: impl Into<Param>) -> Self {
        self.reflectivity = r.into();
        self
    }

    /// The same material, transparent by `t`, with refractive index `ior`.
    #[must_use]
    pub fn transparency(mut self, t: impl Into<Param>, ior: impl Into<Param>) -> Self {
        self.transparency = t.into();
        self.ior = ior.into();
        self
    }

    /// The same material, giving off its colour times `strength` as light.
    #[must_use]
    pub fn emission(mut self, strength: impl Into<Param>) -> Self {
        self.emission = strength.into();
        self
    }
}

impl Default for Material {
    fn default() -> Self {
        Material::from_values(DEFAULT_MATERIAL.map(Param::from))
    }
}

/// [`Material::default`]'s values, in [`Material::values`] order: the
/// kernels' `DEFAULT_MATERIAL` and the CPU reference's.
pub const DEFAULT_MATERIAL: [f64; MATERIAL_LEN] = [0.0, 0.25, 32.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0];

/// Each value's name and rule, in [`Material::values`] order.
pub(crate) const MATERIAL_SPECS: [ParamSpec<'static>; MATERIAL_LEN] = [
    spec("roughness", Rule::NonNegative),
    spec("specular", Rule::NonNegative),
    spec("shininess", Rule::NonNegative),
    spec("subsurface", Rule::NonNegative),
    spec("scatter_depth", Rule::NonNegative),
    spec("reflectivity", Rule::Range(0.0, 1.0)),
    spec("transparency", Rule::Range(0.0, 1.0)),
    spec("ior", Rule::Positive),
    spec("emission", Rule::NonNegative),
];

impl<S> Material<S> {
    /// The values in a fixed order: roughness, specular, shininess,
    /// subsurface, scatter depth, reflectivity, transparency, ior,
    /// emission.
    #[must_use]
    pub fn values(&self) -> [&S; MATERIAL_LEN] {
        [
            &self.roughness,
            &self.specular,
            &self.shininess,
            &self.subsurface,
            &self.scatter_depth,
            &self.reflectivity,
            &self.transparency,
            &self.ior,
            &self.emission,
        ]
    }

    /// A material from its values in [`Material::values`] order.
    #[must_use]
    pub fn from_values(values: [S; MATERIAL_LEN]) -> Self {
        let [
            roughness,
            specular,
            shininess,
            subsurface,
            scatter_depth,
            reflectivity,
            transparency,
            ior,
            emission,
        ] = values;
        Material {
            roughness,
            specular,
            shininess,
            subsurface,
            scatter_depth,
            reflectivity,
            transparency,
            ior,
            emission,
        }
    }

    /// Maps every value with `f`, which also gets its name and rule.
    pub(crate) fn try_map<T, E>(
        &self,
        mut f: impl FnMut(&S, ParamSpec<'static>) -> Result<T, E>,
    ) -> Result<Material<T>, E> {
        let mut out = Vec::with_capacity(MATERIAL_LEN);
        for (value, spec) in self.values().into_iter().zip(MATERIAL_SPECS) {
            out.push(f(value, spec)?);
        }
        let Ok(values) = <[T; MATERIAL_LEN]>::try_from(out) else {
            unreachable!("a material has MATERIAL_LEN values")
        };
        Ok(Material::from_values(values))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_models_are_points_of_one_formula() {
        let values = |m: &Material| m.values().map(Param::default_value);
        assert_eq!(values(&Material::default()), DEFAULT_MATERIAL);
        assert_eq!(values(&Material::lambert())[1], 0.0);
        assert_eq!(values(&Material::oren_nayar(0.5))[0], 0.5);
        assert_eq!(values(&Material::blinn_phong(0.5, 8.0))[1..3], [0.5, 8.0]);
        assert_eq!(values(&Material::subsurface(0.7, 0.2))[3..5], [0.7, 0.2]);
        assert_eq!(values(&Material::mirror())[5], 1.0);
        assert_eq!(values(&Material::glass(1.5))[6..8], [1.0, 1.5]);
        assert_eq!(values(&Material::emissive(3.0))[8], 3.0);
        assert_eq!(values(&Material::emissive(3.0))[1], 0.0);
        let round_trip = Material::from_values(Material::glass(1.33).values().map(Clone::clone));
        assert_eq!(round_trip, Material::glass(1.33));
    }
}
