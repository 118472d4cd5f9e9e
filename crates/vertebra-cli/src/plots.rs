//! Pictures: figure 8's plots with the spread over seeds as a band, figure
//! 6's loci, and side views of the ragdolls; PNGs rendered from the SVGs.

use std::fmt::Write as _;
use std::path::Path;

use plotters::prelude::*;
use vertebra_ragdoll::{Pose, RagdollDesc, SpineMode};
use vertebra_scenes::{Quantity, Scene, Seeded};

use crate::output::{io, spine_name};

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

/// Side views (z forward, y up) of the first ragdoll at the first, middle
/// (mid-push for controllability) and last frame, both ways, from the
/// first seed's run: figures 2 and 7.
pub fn picture(path: &Path, scene: Scene, runs: &[(SpineMode, Seeded)]) -> Result<(), String> {
    let desc = RagdollDesc::reference_humanoid();
    // Three columns of 300 px, one 400 px row per spine; hips at 160 px
    // from the row's top (bodies reach about 1 m = 120 px either way).
    let (width, height, scale) = (300.0 * 3.0, 400.0 * 2.0, 120.0f32);
    let mut svg = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{width}\" height=\"{height}\"><rect width=\"100%\" height=\"100%\" fill=\"white\"/>"
    );
    for (row, (spine, seeded)) in runs.iter().enumerate() {
        let run = &seeded.runs[0];
        let colour = if *spine == SpineMode::Rod {
            "red"
        } else {
            "blue"
        };
        for (col, pose) in run.snapshots.iter().enumerate() {
            let (ox, oy) = (150.0 + 300.0 * col as f32, 200.0 + 400.0 * row as f32);
            draw_pose(&mut svg, &desc, pose, ox, oy, scale, colour);
        }
        writeln!(svg, "<text x=\"10\" y=\"{}\" font-family=\"sans-serif\" font-size=\"16\">{scene} ({}, seed {}): first, middle, last frame</text>", 24 + 400 * row, spine_name(*spine), seeded.first).ok();
    }
    svg.push_str("</svg>");
    std::fs::write(path, svg).map_err(io)
}

fn draw_pose(
    svg: &mut String,
    desc: &RagdollDesc,
    pose: &Pose,
    ox: f32,
    oy: f32,
    scale: f32,
    colour: &str,
) {
    let centre = pose.bones[desc.root].0;
    for (i, body) in desc.bodies.iter().enumerate() {
        let (p, q) = pose.bones[i];
        let c = body.centre();
        let [a, b] = body.segment.map(|s| p + q * (s - c) - centre);
        writeln!(
            svg,
            "<line x1=\"{:.1}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\" stroke=\"{colour}\" stroke-width=\"{:.1}\" stroke-linecap=\"round\" opacity=\"0.6\"/>",
            ox + a.z * scale,
            oy - a.y * scale,
            ox + b.z * scale,
            oy - b.y * scale,
            2.0 * body.radius * scale
        )
        .ok();
    }
}
