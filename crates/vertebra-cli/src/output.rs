//! What `vertebra` prints and writes: summaries, JSON, CSV, SVG plots in
//! the style of the paper's figure 8, and side-view pictures.

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::Path;

use plotters::prelude::*;
use serde_json::json;
use vertebra_ragdoll::{Pose, RagdollDesc, SpineMode};
use vertebra_scenes::{Scene, SceneConfig, SceneRun, kinematics};

/// `rod` or `sockets`.
pub fn spine_name(spine: SpineMode) -> &'static str {
    match spine {
        SpineMode::Rod => "rod",
        SpineMode::Sockets => "sockets",
    }
}

/// Mean, max and final of the residual errors.
pub struct Summary {
    pub mean_lin: f32,
    pub max_lin: f32,
    pub final_lin: f32,
    pub mean_ang: f32,
    pub max_ang: f32,
    pub final_ang: f32,
}

impl Summary {
    pub fn of(run: &SceneRun) -> Self {
        let n = run.frames.len().max(1) as f32;
        let lin = run.frames.iter().map(|f| f.eps_lin_cm);
        let ang = run.frames.iter().map(|f| f.eps_ang_rad);
        let last = run.frames.last().copied().unwrap_or_default();
        Self {
            mean_lin: lin.clone().sum::<f32>() / n,
            max_lin: lin.fold(0.0, f32::max),
            final_lin: last.eps_lin_cm,
            mean_ang: ang.clone().sum::<f32>() / n,
            max_ang: ang.fold(0.0, f32::max),
            final_ang: last.eps_ang_rad,
        }
    }
}

/// The `--json` record of one run.
pub fn run_json(config: &SceneConfig, run: &SceneRun) -> serde_json::Value {
    let s = Summary::of(run);
    json!({
        "scene": config.scene.name(),
        "spine": spine_name(config.spine),
        "iterations": config.iterations,
        "substeps": config.substeps,
        "backend": run.backend.name(),
        "threads": config.threads,
        "seed": config.seed,
        "frames": run.frames.iter().map(|f| json!({
            "eps_lin_cm": f.eps_lin_cm,
            "eps_ang_rad": f.eps_ang_rad,
            "deviation_cm": f.deviation_cm,
            "deviation_rad": f.deviation_rad,
        })).collect::<Vec<_>>(),
        "summary": {
            "mean_eps_lin_cm": s.mean_lin,
            "max_eps_lin_cm": s.max_lin,
            "mean_eps_ang_rad": s.mean_ang,
            "max_eps_ang_rad": s.max_ang,
            "ms_per_step": run.ms_per_step,
        },
        "state_hash": format!("{:016x}", run.state_hash),
    })
}

fn io(e: impl std::fmt::Display) -> String {
    format!("cannot write the results: {e}")
}

/// Renders the SVG at `svg` to a PNG beside it (same name, `.png`), with
/// the system's fonts (DejaVu on the project's machines; without fonts the
/// text is left out and the rest is drawn).
fn to_png(svg: &Path, options: &resvg::usvg::Options) -> Result<(), String> {
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

fn font_options() -> resvg::usvg::Options<'static> {
    let mut options = resvg::usvg::Options::default();
    let fonts = options.fontdb_mut();
    fonts.load_system_fonts();
    fonts.set_sans_serif_family("DejaVu Sans");
    options
}

/// Runs every scene both ways and writes everything under `out`.
pub fn reproduce(out: &Path) -> Result<(), String> {
    std::fs::create_dir_all(out).map_err(|e| io(format!("{}: {e}", out.display())))?;
    let fonts = font_options();
    let mut summary = Vec::new();
    let mut table = String::new();
    writeln!(
        table,
        "{:<16} {:<8} {:>10} {:>10} {:>10} {:>11} {:>11} {:>11} {:>9}",
        "scene",
        "spine",
        "mean lin",
        "max lin",
        "final lin",
        "mean ang",
        "max ang",
        "final ang",
        "ms/step"
    )
    .ok();
    for scene in Scene::ALL {
        let mut runs = Vec::new();
        for spine in [SpineMode::Sockets, SpineMode::Rod] {
            let config = SceneConfig::new(scene, spine);
            let label = format!("{scene} ({})", spine_name(spine));
            let run =
                vertebra_scenes::run(&config, |frame, frames| progress(&label, frame, frames))
                    .map_err(|e| e.to_string())?;
            eprintln!();
            write_csv(
                &out.join(format!("{scene}-{}.csv", spine_name(spine))),
                &run,
            )?;
            let s = Summary::of(&run);
            writeln!(
                table,
                "{:<16} {:<8} {:>10.4} {:>10.4} {:>10.4} {:>11.5} {:>11.5} {:>11.5} {:>9.3}",
                scene.name(),
                spine_name(spine),
                s.mean_lin,
                s.max_lin,
                s.final_lin,
                s.mean_ang,
                s.max_ang,
                s.final_ang,
                run.ms_per_step
            )
            .ok();
            summary.push(run_json(&config, &run));
            runs.push((spine, run));
        }
        let (sockets, rod) = (Summary::of(&runs[0].1), Summary::of(&runs[1].1));
        writeln!(
            table,
            "{:<16} {:<8} {:>10} {:>10.2}x {:>30} {:>10.2}x",
            "",
            "ratio",
            "",
            ratio(sockets.mean_lin, rod.mean_lin),
            "",
            ratio(sockets.mean_ang, rod.mean_ang)
        )
        .ok();
        let (chart, poses) = (
            out.join(format!("{scene}.svg")),
            out.join(format!("{scene}-poses.svg")),
        );
        plot(&chart, scene, &runs)?;
        picture(&poses, scene, &runs)?;
        to_png(&chart, &fonts)?;
        to_png(&poses, &fonts)?;
    }
    let locus = kinematics(0.45, 60f32.to_radians(), 61);
    plot_locus(&out.join("kinematics.svg"), &locus)?;
    to_png(&out.join("kinematics.svg"), &fonts)?;
    let mut csv = String::from("chain,largest_gap_m\n");
    for (name, _, gap) in &locus.chains {
        writeln!(csv, "{name},{gap}").ok();
    }
    std::fs::write(out.join("kinematics.csv"), csv).map_err(io)?;
    let document = json!({ "runs": summary, "kinematics": locus.chains.iter().map(|(n, _, g)| json!({"chain": n, "largest_gap_m": g})).collect::<Vec<_>>() });
    std::fs::write(
        out.join("summary.json"),
        serde_json::to_string_pretty(&document).map_err(io)?,
    )
    .map_err(io)?;
    println!("{table}");
    for (name, _, gap) in &locus.chains {
        println!(
            "kinematics: {name:<20} largest gap to the rod's end {:.2} mm",
            gap * 1e3
        );
    }
    println!("results in {}", out.display());
    Ok(())
}

fn ratio(sockets: f32, rod: f32) -> f32 {
    if rod > 0.0 {
        sockets / rod
    } else {
        f32::INFINITY
    }
}

fn progress(label: &str, frame: usize, frames: usize) {
    if frame.is_multiple_of(10) || frame == frames {
        let width = 30;
        let done = width * frame / frames.max(1);
        eprint!(
            "\r{label:<28} [{}{}] {frame}/{frames}",
            "#".repeat(done),
            ".".repeat(width - done)
        );
        std::io::stderr().flush().ok();
    }
}

fn write_csv(path: &Path, run: &SceneRun) -> Result<(), String> {
    let mut csv = String::from("frame,eps_lin_cm,eps_ang_rad,deviation_cm,deviation_rad\n");
    for (k, f) in run.frames.iter().enumerate() {
        writeln!(
            csv,
            "{k},{},{},{},{}",
            f.eps_lin_cm, f.eps_ang_rad, f.deviation_cm, f.deviation_rad
        )
        .ok();
    }
    std::fs::write(path, csv).map_err(io)
}

/// One quantity of a frame.
type Measure = fn(&vertebra_scenes::Frame) -> f32;

/// Figure 8's layout: linear error on top, angular below; sockets blue,
/// rod red. Controllability plots its deviation from the target instead.
fn plot(path: &Path, scene: Scene, runs: &[(SpineMode, SceneRun)]) -> Result<(), String> {
    let root = SVGBackend::new(path, (800, 600)).into_drawing_area();
    root.fill(&WHITE).map_err(io)?;
    let panels = root.split_evenly((2, 1));
    let deviation = scene == Scene::Controllability;
    let series: [(&str, Measure); 2] = if deviation {
        [
            ("deviation (cm)", |f| f.deviation_cm),
            ("deviation (rad)", |f| f.deviation_rad),
        ]
    } else {
        [
            ("eps_lin (cm)", |f| f.eps_lin_cm),
            ("eps_ang (rad)", |f| f.eps_ang_rad),
        ]
    };
    for (panel, (label, value)) in panels.iter().zip(series) {
        let frames = runs[0].1.frames.len();
        let top = runs
            .iter()
            .flat_map(|(_, r)| r.frames.iter().map(value))
            .fold(1e-6f32, f32::max)
            * 1.05;
        let mut chart = ChartBuilder::on(panel)
            .caption(format!("{scene}: {label}"), ("sans-serif", 18))
            .margin(10)
            .x_label_area_size(30)
            .y_label_area_size(60)
            .build_cartesian_2d(0..frames, 0f32..top)
            .map_err(io)?;
        chart.configure_mesh().x_desc("frame").draw().map_err(io)?;
        for (spine, run) in runs {
            let colour = if *spine == SpineMode::Rod { RED } else { BLUE };
            chart
                .draw_series(LineSeries::new(
                    run.frames.iter().enumerate().map(|(k, f)| (k, value(f))),
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

fn plot_locus(path: &Path, locus: &vertebra_scenes::Locus) -> Result<(), String> {
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
/// (mid-push for controllability) and last frame, both ways: figures 2
/// and 7.
fn picture(path: &Path, scene: Scene, runs: &[(SpineMode, SceneRun)]) -> Result<(), String> {
    let desc = RagdollDesc::reference_humanoid();
    // Three columns of 300 px, one 400 px row per spine; hips at 160 px
    // from the row's top (bodies reach about 1 m = 120 px either way).
    let (width, height, scale) = (300.0 * 3.0, 400.0 * 2.0, 120.0f32);
    let mut svg = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{width}\" height=\"{height}\"><rect width=\"100%\" height=\"100%\" fill=\"white\"/>"
    );
    for (row, (spine, run)) in runs.iter().enumerate() {
        let colour = if *spine == SpineMode::Rod {
            "red"
        } else {
            "blue"
        };
        for (col, pose) in run.snapshots.iter().enumerate() {
            let (ox, oy) = (150.0 + 300.0 * col as f32, 200.0 + 400.0 * row as f32);
            draw_pose(&mut svg, &desc, pose, ox, oy, scale, colour);
        }
        writeln!(svg, "<text x=\"10\" y=\"{}\" font-family=\"sans-serif\" font-size=\"16\">{scene} ({}): first, middle, last frame</text>", 24 + 400 * row, spine_name(*spine)).ok();
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
