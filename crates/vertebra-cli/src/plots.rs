//! Pictures: figure 8's plots with the spread over seeds as a band, figure
//! 6's loci, and side views of every ragdoll; PNGs rendered from the SVGs.

use std::fmt::Write as _;
use std::path::Path;

use glam::Vec3;
use plotters::prelude::*;
use vertebra_ragdoll::{Pose, RagdollDesc, SpineMode};
use vertebra_scenes::{Quantity, Scene, Seeded};

use crate::output::{io, spine_name};
use crate::render::capsules;
use crate::render::colour::{hex, ragdoll_colour};

/// Renders the SVG at `svg` to a PNG beside it (same name, `.png`), with
/// the system's fonts (DejaVu on the project's machines; without fonts the
/// text is left out and the rest is drawn).
pub fn to_png(svg: &Path, options: &resvg::usvg::Options) -> Result<(), String> {
    let data = std::fs::read(svg).map_err(io)?;
    let tree = resvg::usvg::Tree::from_data(&data, options).map_err(io)?;
    let size = tree.size().to_int_size();
    let mut pixmap =
        resvg::tiny_skia::Pixmap::new(size.width(), size.height()).ok_or("empty picture")?;
    resvg::render(
        &tree,
        resvg::tiny_skia::Transform::default(),
        &mut pixmap.as_mut(),
    );
    pixmap.save_png(svg.with_extension("png")).map_err(io)
}

pub fn font_options() -> resvg::usvg::Options<'static> {
    let mut options = resvg::usvg::Options::default();
    let fonts = options.fontdb_mut();
    fonts.load_system_fonts();
    fonts.set_sans_serif_family("DejaVu Sans");
    options
}

fn colour(spine: SpineMode) -> RGBColor {
    if spine == SpineMode::Rod { RED } else { BLUE }
}

/// Figure 8's layout: linear error on top, angular below; sockets blue,
/// rod red. Controllability plots its deviation from the target instead.
/// Each line is the median over the seeds, the shaded band their spread
/// (10th to 90th percentile, or min to max under ten seeds).
pub fn plot(path: &Path, scene: Scene, runs: &[(SpineMode, Seeded)]) -> Result<(), String> {
    let root = SVGBackend::new(path, (800, 600)).into_drawing_area();
    root.fill(&WHITE).map_err(io)?;
    let panels = root.split_evenly((2, 1));
    let seeds = runs[0].1.runs.len();
    for (panel, quantity) in panels.iter().zip(Quantity::compared(scene)) {
        let bands: Vec<_> = runs
            .iter()
            .map(|(spine, seeded)| (*spine, seeded.band(quantity)))
            .collect();
        let frames = bands[0].1.len();
        let top = bands
            .iter()
            .flat_map(|(_, b)| b.iter().map(|s| s.range().1 as f32))
            .fold(1e-6f32, f32::max)
            * 1.05;
        let caption = if seeds > 1 {
            format!(
                "{scene}: {quantity}, median and {} over {seeds} seeds",
                vertebra_scenes::Spread::band_name(seeds)
            )
        } else {
            format!("{scene}: {quantity}")
        };
        let mut chart = ChartBuilder::on(panel)
            .caption(caption, ("sans-serif", 18))
            .margin(10)
            .x_label_area_size(30)
            .y_label_area_size(60)
            .build_cartesian_2d(0..frames, 0f32..top)
            .map_err(io)?;
        chart.configure_mesh().x_desc("frame").draw().map_err(io)?;
        for (spine, band) in &bands {
            let colour = colour(*spine);
            let outline: Vec<(usize, f32)> = band
                .iter()
                .enumerate()
                .map(|(k, s)| (k, s.range().1 as f32))
                .chain(
                    band.iter()
                        .enumerate()
                        .rev()
                        .map(|(k, s)| (k, s.range().0 as f32)),
                )
                .collect();
            chart
                .draw_series(std::iter::once(Polygon::new(outline, colour.mix(0.2))))
                .map_err(io)?;
            chart
                .draw_series(LineSeries::new(
                    band.iter().enumerate().map(|(k, s)| (k, s.median as f32)),
                    colour,
                ))
                .map_err(io)?
                .label(spine_name(*spine))
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour));
        }
        chart
            .configure_series_labels()
            .background_style(WHITE)
            .border_style(BLACK)
            .draw()
            .map_err(io)?;
    }
    root.present().map_err(io)
}

pub fn plot_locus(path: &Path, locus: &vertebra_scenes::Locus) -> Result<(), String> {
    let root = SVGBackend::new(path, (600, 600)).into_drawing_area();
    root.fill(&WHITE).map_err(io)?;
    let mut chart = ChartBuilder::on(&root)
        .caption("figure 6: end-point loci (m)", ("sans-serif", 18))
        .margin(10)
        .x_label_area_size(30)
        .y_label_area_size(50)
        .build_cartesian_2d(-0.02f32..0.45, 0.2f32..0.47)
        .map_err(io)?;
    chart
        .configure_mesh()
        .x_desc("forward")
        .y_desc("up")
        .draw()
        .map_err(io)?;
    let points = |p: &[[f32; 2]]| p.iter().map(|q| (q[0], q[1])).collect::<Vec<_>>();
    chart
        .draw_series(LineSeries::new(points(&locus.rod), RED.stroke_width(3)))
        .map_err(io)?
        .label("rod")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED));
    let palette = [BLUE, CYAN, GREEN, MAGENTA, BLACK];
    for ((name, p, _), colour) in locus.chains.iter().zip(palette) {
        chart
            .draw_series(LineSeries::new(points(p), colour))
            .map_err(io)?
            .label(name.clone())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE)
        .border_style(BLACK)
        .draw()
        .map_err(io)?;
    root.present().map_err(io)
}

/// Side views (z forward, y up, seen from -x) of every ragdoll at the
/// first, middle (mid-push for controllability) and last frame, both
/// ways, from the first seed's run: figures 2 and 7, and the drop's pile.
/// Every panel has the same scale (at most 120 px/m), fit to all the
/// picture's poses.
pub fn picture(path: &Path, scene: Scene, runs: &[(SpineMode, Seeded)]) -> Result<(), String> {
    let desc = RagdollDesc::reference_humanoid();
    let frames: Vec<&[Vec<Pose>]> = runs.iter().map(|(_, s)| &s.runs[0].snapshots[..]).collect();
    let all = frames.iter().flat_map(|f| f.iter().flatten());
    let (min, max) = all.flat_map(|pose| capsules(&desc, pose)).fold(
        (Vec3::INFINITY, Vec3::NEG_INFINITY),
        |(lo, hi), ([a, b], r)| (lo.min(a.min(b) - r), hi.max(a.max(b) + r)),
    );
    let (min, max) = (min - 0.1, max + 0.1);
    let size = max - min;
    let scale = 120f32.min(280.0 / size.z).min(520.0 / size.y);
    // Panels at least 300 px wide (the row's caption), the poses centred.
    let (panel_w, panel_h) = ((size.z * scale + 20.0).max(300.0), size.y * scale + 40.0);
    let left = 0.5 * (panel_w - size.z * scale);
    let columns = frames.iter().map(|f| f.len()).max().unwrap_or(0) as f32;
    let (width, height) = (panel_w * columns.max(1.0), panel_h * runs.len() as f32);
    let mut svg = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{width:.0}\" height=\"{height:.0}\"><rect width=\"100%\" height=\"100%\" fill=\"white\"/>"
    );
    for (row, ((spine, seeded), poses)) in runs.iter().zip(&frames).enumerate() {
        for (col, ragdolls) in poses.iter().enumerate() {
            let at = |p: Vec3| {
                (
                    col as f32 * panel_w + left + (p.z - min.z) * scale,
                    row as f32 * panel_h + 30.0 + (max.y - p.y) * scale,
                )
            };
            draw_ragdolls(&mut svg, &desc, ragdolls, *spine, at, scale);
        }
        let count = poses.first().map_or(0, Vec::len);
        let who = if count > 1 {
            format!("all {count} ragdolls, ")
        } else {
            String::new()
        };
        writeln!(svg, "<text x=\"10\" y=\"{:.0}\" font-family=\"sans-serif\" font-size=\"16\">{scene} ({}, seed {}): {who}first, middle, last frame</text>", 22.0 + panel_h * row as f32, spine_name(*spine), seeded.first).ok();
    }
    svg.push_str("</svg>");
    std::fs::write(path, svg).map_err(io)
}

/// One panel's ragdolls, each body a round-capped line as wide as its
/// capsule, placed by `at` (m, world to px) at `scale` px/m. A lone
/// ragdoll is drawn in its spine's colour (as in the plots) at 60%
/// opacity; several each in its own colour (figure 1's), the farther
/// (larger x, seen from -x) first, at 85% so those behind show a little.
fn draw_ragdolls(
    svg: &mut String,
    desc: &RagdollDesc,
    ragdolls: &[Pose],
    spine: SpineMode,
    at: impl Fn(Vec3) -> (f32, f32),
    scale: f32,
) {
    let mut order: Vec<usize> = (0..ragdolls.len()).collect();
    let depth = |k: usize| ragdolls[k].bones.iter().map(|b| b.0.x).sum::<f32>();
    order.sort_by(|&a, &b| depth(b).total_cmp(&depth(a)));
    for k in order {
        let (colour, opacity) = match ragdolls.len() {
            1 => (colour_name(spine).to_owned(), 0.6),
            _ => (hex(ragdoll_colour(k)), 0.85),
        };
        for ([a, b], radius) in capsules(desc, &ragdolls[k]) {
            let ((x1, y1), (x2, y2)) = (at(a), at(b));
            writeln!(
                svg,
                "<line x1=\"{x1:.1}\" y1=\"{y1:.1}\" x2=\"{x2:.1}\" y2=\"{y2:.1}\" stroke=\"{colour}\" stroke-width=\"{:.1}\" stroke-linecap=\"round\" opacity=\"{opacity}\"/>",
                2.0 * radius * scale
            )
            .ok();
        }
    }
}

fn colour_name(spine: SpineMode) -> &'static str {
    if spine == SpineMode::Rod {
        "red"
    } else {
        "blue"
    }
}
