//! How an image is cut into launches: tiles, and work-group sizes.

/// The default tile side in pixels: small enough that one launch finishes
/// quickly (no display-driver watchdog), large enough to fill a GPU.
pub const DEFAULT_TILE_SIZE: u32 = 256;

/// The largest image side accepted (pixel indices stay within `i32`).
pub const MAX_IMAGE_SIDE: u32 = 32_768;

/// The work-group shape the kernel is launched with.
const PREFERRED_LOCAL: (usize, usize) = (8, 8);

/// One rectangle of the image, launched on its own.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Tile {
    pub x: u32,
    pub y: u32,
    pub width: u32,
    pub height: u32,
}

/// The tiles of a `width` × `height` image, row by row; edge tiles are cut
/// to the image.
pub(crate) fn tiles(width: u32, height: u32, side: u32) -> impl Iterator<Item = Tile> {
    let side = side.max(1);
    (0..height.div_ceil(side)).flat_map(move |row| {
        (0..width.div_ceil(side)).map(move |col| {
            let (x, y) = (col * side, row * side);
            Tile {
                x,
                y,
                width: side.min(width - x),
                height: side.min(height - y),
            }
        })
    })
}

/// An 8 × 8 work group, shrunk (width first halved last) until it fits in
/// `max_group` work items; at least 1 × 1.
pub(crate) fn local_size(max_group: usize) -> (usize, usize) {
    let (mut w, mut h) = PREFERRED_LOCAL;
    while w * h > max_group.max(1) {
        if h >= w {
            h /= 2;
        } else {
            w /= 2;
        }
    }
    (w.max(1), h.max(1))
}

/// The global size for a tile: the tile rounded up to whole work groups
/// (the kernel skips the work items past the tile).
pub(crate) fn global_size(tile: Tile, local: (usize, usize)) -> (usize, usize) {
    (
        (tile.width as usize).next_multiple_of(local.0),
        (tile.height as usize).next_multiple_of(local.1),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_cover_the_image_exactly_once() {
        for (w, h, side) in [(1, 1, 256), (7, 3, 2), (97, 61, 16), (256, 512, 256)] {
            let mut covered = vec![0u8; (w * h) as usize];
            for t in tiles(w, h, side) {
                assert!(t.width >= 1 && t.height >= 1 && t.width <= side && t.height <= side);
                for y in t.y..t.y + t.height {
                    for x in t.x..t.x + t.width {
                        covered[(y * w + x) as usize] += 1;
                    }
                }
            }
            assert!(covered.iter().all(|&c| c == 1), "{w}x{h} tiles of {side}");
        }
        assert_eq!(tiles(7680, 4320, 256).count(), 30 * 17);
    }

    #[test]
    fn local_size_fits_the_device() {
        assert_eq!(local_size(1024), (8, 8));
        assert_eq!(local_size(64), (8, 8));
        assert_eq!(local_size(32), (8, 4));
        assert_eq!(local_size(16), (4, 4));
        assert_eq!(local_size(1), (1, 1));
        assert_eq!(local_size(0), (1, 1));
    }

    #[test]
    fn global_size_rounds_up() {
        let t = Tile {
            x: 0,
            y: 0,
            width: 97,
            height: 1,
        };
        assert_eq!(global_size(t, (8, 8)), (104, 8));
    }
}
