//! The crate's builder style, written once.
//!
//! An options struct is `#[non_exhaustive]` (a new field is not a breaking
//! change), starts from `Default` or a named preset, and is changed by
//! `#[must_use]` chained setters named after the fields they set, as glam
//! and wgpu do: `RenderOptions::default().quality(q).tile_size(64)`. Its
//! fields stay public to read, and to set in place.

/// Chained setters for plain fields: `setters!(Type { /// doc
/// field: Ty, ... })` gives `Type::field(self, Ty) -> Self` for each.
macro_rules! setters {
    ($ty:ident { $( $(#[$doc:meta])* $field:ident: $t:ty ),* $(,)? }) => {
        impl $ty {
            $(
                $(#[$doc])*
                #[must_use]
                pub fn $field(mut self, $field: $t) -> Self {
                    self.$field = $field;
                    self
                }
            )*
        }
    };
}
