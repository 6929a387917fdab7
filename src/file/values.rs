//! Parameters and counts as a scene file writes them.

use std::fmt;

use glam::DVec3;
use serde::de::{self, Deserializer, MapAccess, SeqAccess, Visitor};
use serde::ser::{SerializeTupleVariant, Serializer};
use serde::{Deserialize, Serialize};

use crate::error::fmt_value;
use crate::scene::{Param, Param3, param3};

// ---------------------------------------------------------------------------
// Parameters: a number, or `param("name", default)`; vectors `(x, y, z)`,
// one number, or `param3("name", (x, y, z))`.

impl Serialize for Param {
    fn serialize<S: Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        match self {
            Param::Value(v) => s.serialize_f64(*v),
            Param::Dynamic { name, default } => {
                // A tuple variant, so that RON writes its name.
                let mut t = s.serialize_tuple_variant("Param", 1, "param", 2)?;
                t.serialize_field(name)?;
                t.serialize_field(default)?;
                t.end()
            }
        }
    }
}

/// What one item of a parameter's syntax is: a number, a name (the first
/// item of `param3(..)`), or a dynamic parameter.
pub(super) enum Item {
    Param(Param),
    Name(String),
}

pub(super) struct ItemVisitor;

impl<'de> Visitor<'de> for ItemVisitor {
    type Value = Item;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a number or param(\"name\", default)")
    }

    fn visit_f64<E>(self, v: f64) -> std::result::Result<Item, E> {
        Ok(Item::Param(Param::Value(v)))
    }

    #[allow(clippy::cast_precision_loss)] // Integers in a file are sizes and counts.
    fn visit_i64<E>(self, v: i64) -> std::result::Result<Item, E> {
        Ok(Item::Param(Param::Value(v as f64)))
    }

    #[allow(clippy::cast_precision_loss)]
    fn visit_u64<E>(self, v: u64) -> std::result::Result<Item, E> {
        Ok(Item::Param(Param::Value(v as f64)))
    }

    fn visit_str<E>(self, v: &str) -> std::result::Result<Item, E> {
        Ok(Item::Name(v.to_string()))
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> std::result::Result<Item, A::Error> {
        let name: String = seq
            .next_element()?
            .ok_or_else(|| de::Error::invalid_length(0, &"param(\"name\", default)"))?;
        let default: f64 = seq
            .next_element()?
            .ok_or_else(|| de::Error::invalid_length(1, &"param(\"name\", default)"))?;
        if seq.next_element::<de::IgnoredAny>()?.is_some() {
            return Err(de::Error::invalid_length(3, &"param(\"name\", default)"));
        }
        Ok(Item::Param(Param::Dynamic { name, default }))
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> std::result::Result<Item, A::Error> {
        let (mut name, mut default) = (None, None);
        while let Some(key) = map.next_key::<String>()? {
            match key.as_str() {
                "name" => name = Some(map.next_value::<String>()?),
                "default" => default = Some(map.next_value::<f64>()?),
                other => return Err(de::Error::unknown_field(other, &["name", "default"])),
            }
        }
        Ok(Item::Param(Param::Dynamic {
            name: name.ok_or_else(|| de::Error::missing_field("name"))?,
            default: default.ok_or_else(|| de::Error::missing_field("default"))?,
        }))
    }
}

impl<'de> Deserialize<'de> for Item {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        d.deserialize_any(ItemVisitor)
    }
}

impl<'de> Deserialize<'de> for Param {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        match Item::deserialize(d)? {
            Item::Param(p) => Ok(p),
            Item::Name(name) => Err(de::Error::custom(format!(
                "expected a number or param(\"name\", default), found the string \"{name}\""
            ))),
        }
    }
}

impl Param3 {
    /// The name `n` if the three components are `param3(n, ..)`'s slots.
    fn vector_name(&self) -> Option<&str> {
        let name = self.x.name()?.strip_suffix(".x")?;
        (self.y.name()?.strip_suffix(".y")? == name && self.z.name()?.strip_suffix(".z")? == name)
            .then_some(name)
    }
}

impl Serialize for Param3 {
    fn serialize<S: Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        if let Some(name) = self.vector_name() {
            let mut t = s.serialize_tuple_variant("Param3", 1, "param3", 2)?;
            t.serialize_field(name)?;
            t.serialize_field(&self.default_value())?;
            t.end()
        } else {
            (&self.x, &self.y, &self.z).serialize(s)
        }
    }
}

pub(super) struct Param3Visitor;

impl<'de> Visitor<'de> for Param3Visitor {
    type Value = Param3;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a vector (x, y, z), a number, or param3(\"name\", (x, y, z))")
    }

    fn visit_f64<E>(self, v: f64) -> std::result::Result<Param3, E> {
        Ok(Param3::from(v))
    }

    #[allow(clippy::cast_precision_loss)]
    fn visit_i64<E>(self, v: i64) -> std::result::Result<Param3, E> {
        Ok(Param3::from(v as f64))
    }

    #[allow(clippy::cast_precision_loss)]
    fn visit_u64<E>(self, v: u64) -> std::result::Result<Param3, E> {
        Ok(Param3::from(v as f64))
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> std::result::Result<Param3, A::Error> {
        let short = |n| de::Error::invalid_length(n, &Param3Visitor);
        match seq.next_element::<Item>()?.ok_or_else(|| short(0))? {
            Item::Name(name) => {
                let default: DVec3 = seq.next_element()?.ok_or_else(|| short(1))?;
                if seq.next_element::<de::IgnoredAny>()?.is_some() {
                    return Err(short(3));
                }
                Ok(param3(&name, default))
            }
            Item::Param(x) => {
                let y: Param = seq.next_element()?.ok_or_else(|| short(1))?;
                let z: Param = seq.next_element()?.ok_or_else(|| short(2))?;
                if seq.next_element::<de::IgnoredAny>()?.is_some() {
                    return Err(short(4));
                }
                Ok(Param3 { x, y, z })
            }
        }
    }
}

impl<'de> Deserialize<'de> for Param3 {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        d.deserialize_any(Param3Visitor)
    }
}

// ---------------------------------------------------------------------------
// Counts: whole numbers, read from any number so that `iterations: 4.5`
// says what is wrong with it rather than failing on the `.5`.

/// A number as written, before it is known to be whole.
struct Number(f64);

struct NumberVisitor;

impl Visitor<'_> for NumberVisitor {
    type Value = Number;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a whole number")
    }

    fn visit_f64<E>(self, v: f64) -> std::result::Result<Number, E> {
        Ok(Number(v))
    }

    #[allow(clippy::cast_precision_loss)] // Only compared with u32's range.
    fn visit_i64<E>(self, v: i64) -> std::result::Result<Number, E> {
        Ok(Number(v as f64))
    }

    #[allow(clippy::cast_precision_loss)]
    fn visit_u64<E>(self, v: u64) -> std::result::Result<Number, E> {
        Ok(Number(v as f64))
    }
}

impl<'de> Deserialize<'de> for Number {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        d.deserialize_any(NumberVisitor)
    }
}

/// `value` as a count, or the message naming `field`.
fn whole(field: &str, value: f64) -> std::result::Result<u32, String> {
    if value.fract() == 0.0 && (0.0..=f64::from(u32::MAX)).contains(&value) {
        // Whole and in range: the conversion is exact.
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
        return Ok(value as u32);
    }
    Err(format!(
        "`{field}` must be a whole number from 0 to {}, got {}",
        u32::MAX,
        fmt_value(value)
    ))
}

/// Readers of the counts of a file, one per field so that each error
/// names its field (serde's `deserialize_with` takes a function).
pub(super) mod count {
    use serde::Deserialize;
    use serde::de::{self, Deserializer};

    use super::{Number, whole};

    macro_rules! counts {
        ($($field:ident),*) => {$(
            /// The field's count.
            pub(in crate::file) fn $field<'de, D: Deserializer<'de>>(
                d: D,
            ) -> Result<u32, D::Error> {
                let Number(v) = Number::deserialize(d)?;
                whole(stringify!($field), v).map_err(de::Error::custom)
            }
        )*};
    }

    macro_rules! optional_counts {
        ($($name:ident => $field:literal),*) => {$(
            /// The field's count, where the file gives one.
            pub(in crate::file) fn $name<'de, D: Deserializer<'de>>(
                d: D,
            ) -> Result<Option<u32>, D::Error> {
                match Option::<Number>::deserialize(d)? {
                    Some(Number(v)) => whole($field, v).map(Some).map_err(de::Error::custom),
                    None => Ok(None),
                }
            }
        )*};
    }

    counts!(iterations);
    optional_counts!(
        max_steps => "max_steps",
        ao_samples => "ao_samples",
        shadow_steps => "shadow_steps",
        fractal_iterations => "fractal_iterations",
        optional_iterations => "iterations",
        supersampling => "supersampling",
        resolution_scale => "resolution_scale",
        cone_tile => "cone_tile",
        bounces => "bounces"
    );

    /// A limited repetition's `limit`: three counts.
    pub(in crate::file) fn limit<'de, D: Deserializer<'de>>(d: D) -> Result<[u32; 3], D::Error> {
        let [x, y, z] = <[Number; 3]>::deserialize(d)?;
        let mut out = [0; 3];
        for (slot, Number(v)) in out.iter_mut().zip([x, y, z]) {
            *slot = whole("limit", v).map_err(|_| {
                de::Error::custom(format!(
                    "`limit` must be whole numbers from 0 to {}, got {}",
                    u32::MAX,
                    crate::error::fmt_value(v)
                ))
            })?;
        }
        Ok(out)
    }
}
