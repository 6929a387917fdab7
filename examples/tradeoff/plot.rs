//! The trade-off plot: error (PSNR against the reference) over time per
//! frame and over distance evaluations per pixel, one colour per scene.

use fractal_sdf::image::RgbaImage;
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::Row;

const WIDTH: u32 = 1400;
const HEIGHT: u32 = 620;
/// PSNR is drawn up to this; an identical image (the reference itself,
/// infinite PSNR) sits on the top edge.
const TOP_DB: f64 = 80.0;
const COLORS: [RGBColor; 4] = [
    RGBColor(214, 39, 40),
    RGBColor(31, 119, 180),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
];

/// Draws the plot of every row except the anti-aliasing and `detail` ones
/// (those measure a change of look, not of accuracy).
pub fn draw(rows: &[Row], size: (u32, u32), device: &str) -> RgbaImage {
    // The font ships with the `dejavu` crate: no system fonts needed. A
    // second registration fails harmlessly.
    let _ =
        plotters::style::register_font("sans-serif", FontStyle::Normal, dejavu::sans::regular());
    let mut rgb = vec![255u8; (WIDTH * HEIGHT * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (WIDTH, HEIGHT)).into_drawing_area();
        root.fill(&WHITE).expect("draw into memory");
        let title = format!(
            "Error against the reference preset, {}x{} on {device}",
            size.0, size.1
        );
        let root = root
            .titled(&title, ("sans-serif", 20))
            .expect("draw into memory");
        let (left, right) = root.split_horizontally(WIDTH / 2);
        let rows: Vec<&Row> = rows
            .iter()
            .filter(|r| r.group != "aa" && r.group != "detail")
            .collect();
        panel(&left, &rows, "median ms per frame", |r| r.timing.median_ms);
        panel(&right, &rows, "distance evaluations per pixel", |r| {
            r.evaluations
        });
        root.present().expect("draw into memory");
    }
    let rgba = rgb
        .chunks_exact(3)
        .flat_map(|p| [p[0], p[1], p[2], 255])
        .collect();
    RgbaImage::from_raw(WIDTH, HEIGHT, rgba).expect("buffer has WIDTH * HEIGHT pixels")
}

/// One panel; `value` gives a row's x value, drawn on a log10 axis.
fn panel(
    area: &DrawingArea<BitMapBackend, Shift>,
    rows: &[&Row],
    x_desc: &str,
    value: impl Fn(&Row) -> f64,
) {
    let x = |r: &Row| value(r).max(1e-3).log10();
    let xs: Vec<f64> = rows.iter().map(|r| x(r)).collect();
    let lo = xs.iter().copied().fold(f64::INFINITY, f64::min) - 0.1;
    let hi = xs
        .iter()
        .copied()
        .fold(f64::NEG_INFINITY, f64::max)
        .max(lo + 0.5)
        + 0.1;
    let y_lo = rows
        .iter()
        .map(|r| r.errors.psnr)
        .fold(TOP_DB, f64::min)
        .min(30.0)
        .floor()
        - 2.0;
    let mut chart = ChartBuilder::on(area)
        .margin(16)
        .x_label_area_size(40)
        .y_label_area_size(50)
        .build_cartesian_2d(lo..hi, y_lo..TOP_DB + 1.0)
        .expect("draw into memory");
    chart
        .configure_mesh()
        .x_labels(8)
        .x_label_formatter(&|v| format!("{:.0}", 10f64.powf(*v)))
        .x_desc(format!("{x_desc} (log scale)"))
        .y_desc("PSNR against reference (dB)")
        .label_style(("sans-serif", 14))
        .draw()
        .expect("draw into memory");
    // The preview target: 35 dB.
    chart
        .draw_series(LineSeries::new(
            [(lo, 35.0), (hi, 35.0)],
            BLACK.mix(0.4).stroke_width(1),
        ))
        .expect("draw into memory");
    let y = |r: &Row| r.errors.psnr.min(TOP_DB);
    let mut scenes: Vec<&str> = rows.iter().map(|r| r.scene.as_str()).collect();
    scenes.dedup();
    for (i, scene) in scenes.iter().enumerate() {
        let color = COLORS[i % COLORS.len()];
        let of = |group: &str| -> Vec<(f64, f64)> {
            rows.iter()
                .filter(|r| r.scene == *scene && r.group == group)
                .map(|r| (x(r), y(r)))
                .collect()
        };
        let light = color.mix(0.45);
        chart
            .draw_series(LineSeries::new(of("max_steps"), light.stroke_width(1)))
            .expect("draw into memory");
        chart
            .draw_series(
                of("max_steps")
                    .into_iter()
                    .map(|p| Cross::new(p, 4, light.stroke_width(1))),
            )
            .expect("draw into memory");
        chart
            .draw_series(LineSeries::new(of("hit_epsilon"), light.stroke_width(1)))
            .expect("draw into memory");
        chart
            .draw_series(
                of("hit_epsilon")
                    .into_iter()
                    .map(|p| TriangleMarker::new(p, 4, light.stroke_width(1))),
            )
            .expect("draw into memory");
        // The other knobs, one point each.
        for group in [
            "over_relaxation",
            "cone_tile",
            "fast_math",
            "resolution_scale",
        ] {
            chart
                .draw_series(
                    of(group)
                        .into_iter()
                        .map(|p| Circle::new(p, 3, light.stroke_width(1))),
                )
                .expect("draw into memory");
        }
        let presets: Vec<(f64, f64)> = rows
            .iter()
            .filter(|r| r.scene == *scene && r.group == "preset" && r.label != "reference")
            .map(|r| (x(r), y(r)))
            .collect();
        chart
            .draw_series(LineSeries::new(presets, color.stroke_width(2)))
            .expect("draw into memory")
            .label(*scene)
            .legend(move |(lx, ly)| {
                PathElement::new(vec![(lx, ly), (lx + 18, ly)], color.stroke_width(2))
            });
        for r in rows
            .iter()
            .filter(|r| r.scene == *scene && (r.group == "preset" || r.group == "floor"))
        {
            let p = (x(r), y(r));
            let marker = if r.group == "floor" {
                Circle::new(p, 5, color.stroke_width(2))
            } else {
                Circle::new(p, 5, color.filled())
            };
            chart
                .draw_series(std::iter::once(marker))
                .expect("draw into memory");
            if i == 0 {
                chart
                    .draw_series(std::iter::once(Text::new(
                        r.label.clone(),
                        p,
                        ("sans-serif", 13).into_font().color(&BLACK),
                    )))
                    .expect("draw into memory");
            }
        }
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 14))
        .draw()
        .expect("draw into memory");
}
