//! A labelled contact sheet of render tiles (the `deep_zoom` study).

use fractal_sdf::image::{self, RgbaImage};
use plotters::prelude::*;

/// Row names of [`contact_sheet`], top to bottom.
pub const ROWS: [&str; 5] = ["F32", "F32 moved", "F64", "F64 moved", "F64 + AO"];

const LEFT: u32 = 90;
const TOP: u32 = 24;

/// Lays out `columns` (one per magnification decade, one tile per row, in
/// the order of [`ROWS`]) with the decade above each column and the row
/// names on the left.
pub fn contact_sheet(columns: &[[RgbaImage; ROWS.len()]], tile: (u32, u32)) -> RgbaImage {
    let cols = u32::try_from(columns.len()).expect("a few columns");
    let rows = u32::try_from(ROWS.len()).expect("a few rows");
    let (w, h) = (LEFT + cols * (tile.0 + 2), TOP + rows * (tile.1 + 2));
    let mut sheet = RgbaImage::from_pixel(w, h, image::Rgba([255, 255, 255, 255]));
    for (c, tiles) in (0..cols).zip(columns) {
        for (r, img) in (0..rows).zip(tiles) {
            let x = LEFT + c * (tile.0 + 2);
            let y = TOP + r * (tile.1 + 2);
            image::imageops::replace(&mut sheet, img, i64::from(x), i64::from(y));
        }
    }
    // Labels, drawn with the font from the `dejavu` crate.
    let _ =
        plotters::style::register_font("sans-serif", FontStyle::Normal, dejavu::sans::regular());
    let mut rgb: Vec<u8> = sheet.pixels().flat_map(|p| [p[0], p[1], p[2]]).collect();
    {
        let area = BitMapBackend::with_buffer(&mut rgb, (w, h)).into_drawing_area();
        let style = ("sans-serif", 15).into_font().color(&BLACK);
        for c in 0..cols {
            let x = i32::try_from(LEFT + c * (tile.0 + 2) + tile.0 / 2 - 14).unwrap_or(0);
            area.draw_text(&format!("1e{c}"), &style, (x, 4))
                .expect("draw into memory");
        }
        for (r, name) in (0..rows).zip(ROWS) {
            let y = i32::try_from(TOP + r * (tile.1 + 2) + tile.1 / 2 - 8).unwrap_or(0);
            area.draw_text(name, &style, (6, y))
                .expect("draw into memory");
        }
        area.present().expect("draw into memory");
    }
    let rgba = rgb
        .chunks_exact(3)
        .flat_map(|p| [p[0], p[1], p[2], 255])
        .collect();
    RgbaImage::from_raw(w, h, rgba).expect("buffer has w * h pixels")
}
