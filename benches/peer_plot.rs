//! The peer bench's error-versus-cost plot: one point per engine and
//! setting, its wall time per step against its mean joint error (summed
//! separation on top, angular violation below, both on log scales), and
//! the same points as CSV.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use plotters::coord::Shift;
use plotters::prelude::*;
use vertebra_ragdoll::SpineMode;
use vertebra_scenes::Scene;
use vertebra_world::JointSolver;

/// An engine and setting's series: vertebra with a joint solve and a
/// spine, or rapier (socket spines: it has no rod).
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Series {
    /// vertebra, its joints solved by the [`JointSolver`], with the spine.
    Vertebra(JointSolver, SpineMode),
    /// vertebra as a game gets it, `SolverConfig::default()` (the direct
    /// solve at 1x8 with relaxed contacts), with this spine.
    Default(SpineMode),
    /// rapier3d.
    Rapier,
}

impl Series {
    /// In drawing order.
    const ALL: [Series; 7] = [
        Series::Vertebra(JointSolver::Iterative, SpineMode::Rod),
        Series::Vertebra(JointSolver::Iterative, SpineMode::Sockets),
        Series::Vertebra(JointSolver::Direct, SpineMode::Rod),
        Series::Vertebra(JointSolver::Direct, SpineMode::Sockets),
        Series::Default(SpineMode::Rod),
        Series::Default(SpineMode::Sockets),
        Series::Rapier,
    ];

    /// The CSV's engine, joints and spine columns (rapier's joints: its
    /// own solver).
    fn columns(self) -> [&'static str; 3] {
        let spine = |s| match s {
            SpineMode::Rod => "rod",
            SpineMode::Sockets => "socket",
        };
        match self {
            Series::Vertebra(JointSolver::Iterative, s) => ["vertebra", "iterative", spine(s)],
            Series::Vertebra(JointSolver::Direct, s) => ["vertebra", "direct", spine(s)],
            Series::Default(s) => ["vertebra", "default", spine(s)],
            Series::Rapier => ["rapier", "rapier", "socket"],
        }
    }

    /// The legend's name: `vertebra direct, rod spine`, `rapier, socket
    /// spine`.
    fn label(self) -> String {
        match self.columns() {
            ["rapier", _, spine] => format!("rapier, {spine} spine"),
            [engine, "default", spine] => {
                format!("{engine} default (direct, relaxed contacts), {spine} spine")
            }
            [engine, joints, spine] => format!("{engine} {joints}, {spine} spine"),
        }
    }

    /// Rod red, sockets blue, rapier black; iterative hollow and larger,
    /// direct filled, so a direct point on top of its iterative one shows
    /// both; the default a wide thick ring, marking it among the direct
    /// points. The marker's radius in pixels.
    fn style(self) -> (ShapeStyle, u32) {
        match self {
            Series::Default(spine) => {
                let colour = if spine == SpineMode::Rod { RED } else { BLUE };
                (colour.stroke_width(3), 11)
            }
            Series::Vertebra(joints, spine) => {
                let colour = if spine == SpineMode::Rod { RED } else { BLUE };
                match joints {
                    JointSolver::Iterative => (colour.stroke_width(2), 7),
                    JointSolver::Direct => (colour.filled(), 4),
                }
            }
            Series::Rapier => (BLACK.filled(), 4),
        }
    }
}

/// One engine and setting: its series, its split (`substeps x
/// iterations`, rapier's `solver x pgs`), and its figures, each the median
/// over `seeds` seeded runs.
pub struct Point {
    /// Which engine, joint solve and spine.
    pub series: Series,
    /// e.g. `1x20`.
    pub split: String,
    /// Seeded runs the medians are over.
    pub seeds: u64,
    /// Wall time per step, collision detection included (ms).
    pub ms_per_step: f64,
    /// Mean summed joint separation per frame (cm).
    pub eps_lin_cm: f64,
    /// Mean summed angular violation per frame (rad).
    pub eps_ang_rad: f64,
}

/// Where the plots and CSV go: `target/figures/peer/` at the workspace's
/// root, whatever `CARGO_TARGET_DIR` says (`benches/figures.sh` copies it
/// into its dated run).
pub fn out_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("the benches sit in the workspace")
        .join("target/figures/peer")
}

/// Writes `error_vs_cost_<scene>.svg` and `.csv` under [`out_dir`] and
/// returns the SVG's path.
pub fn write(scene: Scene, points: &[Point]) -> Result<PathBuf, Box<dyn std::error::Error>> {
    let dir = out_dir();
    std::fs::create_dir_all(&dir)?;
    let svg = dir.join(format!("error_vs_cost_{scene}.svg"));
    std::fs::write(svg.with_extension("csv"), csv(scene, points))?;
    draw(&svg, scene, points)?;
    Ok(svg)
}

fn csv(scene: Scene, points: &[Point]) -> String {
    let mut out = String::from(
        "scene,engine,joints,spine,split,seeds,ms_per_step,mean_eps_lin_cm,mean_eps_ang_rad\n",
    );
    for p in points {
        let [engine, joints, spine] = p.series.columns();
        writeln!(
            out,
            "{scene},{engine},{joints},{spine},{},{},{},{},{}",
            p.split, p.seeds, p.ms_per_step, p.eps_lin_cm, p.eps_ang_rad
        )
        .ok();
    }
    out
}

/// The two panels, one above the other: separation, angular violation.
fn draw(svg: &Path, scene: Scene, points: &[Point]) -> Result<(), Box<dyn std::error::Error>> {
    let root = SVGBackend::new(svg, (900, 900)).into_drawing_area();
    root.fill(&WHITE)?;
    let panels = root.split_evenly((2, 1));
    let lin = |p: &Point| p.eps_lin_cm;
    let ang = |p: &Point| p.eps_ang_rad;
    panel(&panels[0], scene, points, "mean joint separation (cm)", lin)?;
    panel(
        &panels[1],
        scene,
        points,
        "mean angular violation (rad)",
        ang,
    )?;
    root.present()?;
    Ok(())
}

/// One panel: every point's `error` against its time, each labelled with
/// its split.
fn panel(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    scene: Scene,
    points: &[Point],
    what: &str,
    error: impl Fn(&Point) -> f64,
) -> Result<(), Box<dyn std::error::Error>> {
    let errors = points.iter().map(&error).filter(|e| *e > 0.0);
    let low = errors.clone().fold(f64::INFINITY, f64::min).min(1.0) / 2.0;
    let high = errors.fold(0.0, f64::max).max(low * 4.0) * 2.0;
    let right = points.iter().map(|p| p.ms_per_step).fold(0.0, f64::max) * 1.15;
    let mut chart = ChartBuilder::on(area)
        .caption(format!("{scene}: {what} against cost"), ("sans-serif", 18))
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..right, (low..high).log_scale())?;
    chart
        .configure_mesh()
        .x_desc("ms per step (wall time, collision detection included)")
        .y_desc(what)
        .draw()?;
    for series in Series::ALL {
        let at: Vec<(f64, f64, &str)> = points
            .iter()
            .filter(|p| p.series == series)
            .map(|p| (p.ms_per_step, error(p).max(low), p.split.as_str()))
            .collect();
        let (style, size) = series.style();
        chart
            .draw_series(at.iter().map(|&(x, y, _)| Circle::new((x, y), size, style)))?
            .label(series.label())
            .legend(move |(x, y)| Circle::new((x + 10, y), size, style));
        chart.draw_series(at.iter().map(|&(x, y, split)| {
            EmptyElement::at((x, y))
                + Text::new(split.to_owned(), (8, -12), ("sans-serif", 11).into_font())
        }))?;
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .position(SeriesLabelPosition::UpperRight)
        .draw()?;
    Ok(())
}
