//! `vertebra`: reproduce the paper's results on the reference humanoid
//! (`vertebra reproduce`), run one scene, the paper's or one on the
//! anatomical humanoid (`vertebra scene NAME ...`), or check a ragdoll or
//! skeleton file (`vertebra check FILE`).

mod check;
mod gltf_out;
mod output;
mod plots;
mod render;
mod reproduce;
mod skeleton_csv;
mod stagger;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::error::ErrorKind;
use clap::{Parser, Subcommand, ValueEnum};
use vertebra_math::BackendChoice;
use vertebra_ragdoll::{RagdollDesc, RagdollError, SpineMode};
use vertebra_scenes::{MAX_FRAMES, Scene, SceneConfig, SceneRun, Seeded};
use vertebra_world::{JointSolver, PinContacts, SleepSettings, SolverConfig};

use gltf_out::GltfOut;
use skeleton_csv::{Failed, SkeletonCsv};

#[derive(Parser)]
#[command(
    name = "vertebra",
    version,
    about = "Rod constraints for simplified ragdolls: the paper's scenes",
    arg_required_else_help = true
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Runs every scene both ways and writes tables, plots and pictures.
    Reproduce {
        /// Where to write the results (default: out, or out-direct with
        /// --joints direct, so that the two runs sit side by side).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Seeded starts per scene and spine (0 .. K): every figure is
        /// given as its median and spread over them.
        #[arg(long, default_value_t = reproduce::DEFAULT_SEEDS)]
        seeds: u64,
        /// How the joints are solved: iterative (each joint on its own, as
        /// the paper) or direct (every joint of a ragdoll at once).
        #[arg(long, value_enum, default_value_t = Joints::Iterative)]
        joints: Joints,
    },
    /// Runs one scene.
    Scene {
        /// passive-bending, ragdoll-drop, controllability (the paper's),
        /// hit-reaction, anatomical-drop (the anatomical humanoid),
        /// heavy-chain (1 kg links holding a 1000 kg body), or stagger (the
        /// anatomical humanoid standing and walking with capped drives,
        /// hit on the chest: a table of hits of 20 to 150 N s from four
        /// sides over --seeds, 5 unless given; with --frames, --gltf or
        /// --skeleton-out, its one run: standing, walking, one hit).
        name: String,
        /// rod (simplified) or sockets (standard).
        #[arg(long)]
        spine: Spine,
        /// How the joints are solved: iterative (each joint on its own, as
        /// the paper) or direct (every joint of a ragdoll at once). The
        /// paper's scenes, and any scene with --joints iterative, start
        /// from the paper's settings (iterative, 1 substep x 20
        /// iterations, contacts not relaxed); the others from the world's
        /// default (direct, 1 x 8, relaxed). Each flag given replaces its
        /// setting.
        #[arg(long, value_enum)]
        joints: Option<Joints>,
        /// Position iterations per substep (substeps x iterations at most
        /// 10000; unless given, as --joints says).
        #[arg(long)]
        iterations: Option<u32>,
        /// Substeps per frame (unless given, as --joints says).
        #[arg(long)]
        substeps: Option<u32>,
        /// Frames to run, 1 to 1000000 (the scene's own count by default).
        #[arg(long)]
        frames: Option<usize>,
        /// auto, scalar, portable, sse4, avx2x4, avx2, neon or simd128.
        #[arg(long, default_value = "auto")]
        backend: String,
        /// Worker threads, 1 to 256.
        #[arg(long, default_value_t = 1)]
        threads: usize,
        /// A ragdoll description (TOML, at most 1 MiB) instead of the
        /// reference humanoid.
        #[arg(long)]
        ragdoll: Option<PathBuf>,
        /// The start: 0 is the paper's scene exactly; any other seed moves
        /// each ragdoll by at most 1 mm and 0.1 degree.
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// hit-reaction: the drive's natural frequency (Hz, above 0).
        #[arg(long, default_value_t = 16.0, allow_negative_numbers = true)]
        drive_frequency: f32,
        /// hit-reaction: the drive's damping ratio (1 is critical).
        #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
        damping_ratio: f32,
        /// hit-reaction: the drive's torque limit per joint (N m; inf is
        /// unlimited).
        #[arg(long, default_value_t = f32::INFINITY, allow_negative_numbers = true)]
        max_torque: f32,
        /// Run from K seeds (--seed .. --seed + K - 1) and give every
        /// figure's median and spread over them (stagger: every hit from
        /// each seed).
        #[arg(long)]
        seeds: Option<u64>,
        /// Let still islands sleep (the world's default: a body's mass
        /// moving at 0.05 m/s on average over 0.5 s). Off by default: the
        /// paper's figures step every body every frame.
        #[arg(long)]
        sleep: bool,
        /// Relax the contacts (true or false; alone: true): they take
        /// back the speed their push-out gives. Unless given, as --joints
        /// says.
        #[arg(long, num_args = 0..=1, default_missing_value = "true")]
        relax_contacts: Option<bool>,
        /// Which ragdolls' contacts with the static world are solved in
        /// their direct joint solve: never, driven (a ragdoll with a
        /// drive) or always (alone: always; always needs --joints
        /// direct). Unless given: driven for the stagger under the direct
        /// solve (its feet stand on them), never otherwise.
        #[arg(long, value_enum, num_args = 0..=1, default_missing_value = "always")]
        pin_contacts: Option<Pins>,
        /// One JSON object on stdout.
        #[arg(long)]
        json: bool,
        /// Writes every frame's reference-skeleton bones (63 per ragdoll,
        /// mapped from the bodies) to this CSV file:
        /// frame,ragdoll,bone,x,y,z,qx,qy,qz,qw (m, world).
        #[arg(long)]
        skeleton_out: Option<PathBuf>,
        /// Writes the run as an animated glTF 2.0 file: FILE.glb (binary)
        /// or FILE.gltf (JSON, buffer embedded); every body with its shape,
        /// each ragdoll's reference skeleton as a skin (docs/gltf.md).
        #[arg(long, value_name = "FILE")]
        gltf: Option<PathBuf>,
    },
    /// Checks a ragdoll file (with its skeleton), a ragdoll generator file
    /// or a skeleton file and prints what it holds (or generates), or
    /// every problem found, one a line, with its file and line.
    Check {
        /// A ragdoll file (`[[body]]` tables with a `name`), a generator
        /// file (`[[body]]` tables with a `bone` and no `name`) or a
        /// skeleton file (`[[bone]]` tables only), TOML, at most 1 MiB.
        file: PathBuf,
        /// For a generator file: the skeleton file it is read against
        /// (default: the reference skeleton shipped with vertebra).
        #[arg(long)]
        skeleton: Option<PathBuf>,
    },
}

#[derive(Clone, Copy, ValueEnum)]
enum Spine {
    Rod,
    Sockets,
}

#[derive(Clone, Copy, ValueEnum)]
enum Joints {
    Iterative,
    Direct,
}

#[derive(Clone, Copy, ValueEnum)]
enum Pins {
    Never,
    Driven,
    Always,
}

impl From<Pins> for PinContacts {
    fn from(p: Pins) -> Self {
        match p {
            Pins::Never => PinContacts::Never,
            Pins::Driven => PinContacts::Driven,
            Pins::Always => PinContacts::Always,
        }
    }
}

impl From<Joints> for JointSolver {
    fn from(j: Joints) -> Self {
        match j {
            Joints::Iterative => JointSolver::Iterative,
            Joints::Direct => JointSolver::Direct,
        }
    }
}

impl From<Spine> for SpineMode {
    fn from(s: Spine) -> Self {
        match s {
            Spine::Rod => SpineMode::Rod,
            Spine::Sockets => SpineMode::Sockets,
        }
    }
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) if e.kind() == ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
            // No arguments at all: the usage, as a usage error.
            eprint!("{e}");
            return ExitCode::from(2);
        }
        Err(e) if !e.use_stderr() => {
            // --help and --version.
            print!("{e}");
            return ExitCode::SUCCESS;
        }
        Err(e) => {
            // One line: clap's message without its usage block and tips.
            let text = e.to_string();
            let message = text.split("\n\nUsage:").next().unwrap_or("bad arguments");
            let message = message.split("\n\n  tip:").next().unwrap_or(message);
            let line = message.split_whitespace().collect::<Vec<_>>().join(" ");
            eprintln!("vertebra: {}", line.trim_start_matches("error: "));
            return ExitCode::from(2);
        }
    };
    match execute(cli.command) {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            // One line per problem (`vertebra check` may find several).
            for line in message.lines() {
                eprintln!("vertebra: {line}");
            }
            ExitCode::from(1)
        }
    }
}

fn execute(command: Command) -> Result<(), String> {
    match command {
        Command::Reproduce { out, seeds, joints } => {
            let joints = joints.into();
            let out = out.unwrap_or_else(|| reproduce::default_out(joints));
            reproduce::reproduce(&out, seeds, joints)
        }
        Command::Check { file, skeleton } => {
            print!("{}", check::check(&file, skeleton.as_deref())?);
            Ok(())
        }
        Command::Scene {
            name,
            spine,
            joints,
            iterations,
            substeps,
            frames,
            backend,
            threads,
            ragdoll,
            seed,
            drive_frequency,
            damping_ratio,
            max_torque,
            seeds,
            sleep,
            relax_contacts,
            pin_contacts,
            json,
            skeleton_out,
            gltf,
        } => {
            let scene: Scene = name.parse()?;
            let backend: BackendChoice = backend.parse().map_err(|e| format!("{e}"))?;
            backend.resolve().map_err(|e| format!("{e}"))?;
            match frames {
                Some(0) => return Err("--frames must be at least 1".to_owned()),
                Some(n) if n > MAX_FRAMES => {
                    return Err(format!("--frames must be at most {MAX_FRAMES}"));
                }
                _ => {}
            }
            let ragdoll = ragdoll
                .map(|path| {
                    let desc = RagdollDesc::from_file(&path)?;
                    // A rod asked of a file without a [spine]: named with
                    // the file here, as the build would refuse it.
                    desc.check_spine(spine.into())
                        .map_err(|e| RagdollError::File {
                            path: path.display().to_string(),
                            error: Box::new(e),
                        })
                        .map(|()| desc)
                })
                .transpose()
                .map_err(|e| e.to_string())?;
            let mut config = SceneConfig::new(scene, spine.into());
            // The paper's scenes, and any run told to iterate, start from
            // the paper's solver; the others from the world's default.
            let iterated = matches!(joints, Some(Joints::Iterative));
            let solver = if scene.is_paper() || iterated {
                SolverConfig::paper()
            } else {
                SolverConfig::default()
            };
            config.joints = joints.map_or(solver.joints, Into::into);
            config.iterations = iterations.unwrap_or(solver.iterations);
            config.substeps = substeps.unwrap_or(solver.substeps);
            config.relax_contacts = relax_contacts.unwrap_or(solver.relax_contacts);
            let direct = config.joints == JointSolver::Direct;
            let pins = match scene == Scene::Stagger && direct {
                true => PinContacts::Driven,
                false => PinContacts::Never,
            };
            config.pin_contacts = pin_contacts.map_or(pins, Into::into);
            config.frames = frames;
            config.backend = backend;
            config.threads = threads;
            config.ragdoll = ragdoll;
            config.seed = seed;
            config.drive_frequency = drive_frequency;
            config.drive_damping_ratio = damping_ratio;
            config.max_torque = max_torque;
            config.sleep = sleep.then(SleepSettings::default);
            if let (Some(_), Some(_)) = (seeds, &skeleton_out) {
                return Err("--skeleton-out writes one run; not with --seeds".to_owned());
            }
            if let (Some(_), Some(_)) = (seeds, &gltf) {
                return Err("--gltf writes one run; not with --seeds".to_owned());
            }
            let one_run = frames.is_some() || skeleton_out.is_some() || gltf.is_some();
            if scene == Scene::Stagger && !one_run {
                let count = seeds.unwrap_or(stagger::DEFAULT_SEEDS);
                return stagger::sweep(&config, count, json);
            }
            if let Some(count) = seeds {
                let seeded = Seeded::run(&config, count, |_, _| {}).map_err(|e| e.to_string())?;
                if json {
                    println!("{}", output::seeded_json(&config, &seeded));
                } else {
                    output::print_seeded_summary(&config, &seeded);
                }
                return Ok(());
            }
            let run = run_writing(&config, skeleton_out.as_deref(), gltf.as_deref())?;
            if json {
                println!("{}", output::run_json(&config, &run));
            } else {
                output::print_summary(&config, &run);
            }
            Ok(())
        }
    }
}

/// Runs `config` once, writing every frame's skeleton poses as CSV to
/// `skeleton_out` and the run as glTF to `gltf`, where given (the glTF
/// file is created before the run and removed if the run fails).
fn run_writing(
    config: &SceneConfig,
    skeleton_out: Option<&Path>,
    gltf: Option<&Path>,
) -> Result<SceneRun, String> {
    let frames = config.frames.unwrap_or(config.scene.default_frames());
    let mut csv = skeleton_out.map(SkeletonCsv::new);
    let mut gltf = gltf.map(|p| GltfOut::create(p, frames)).transpose()?;
    let run = vertebra_scenes::run_observed(
        config,
        |_, _| {},
        |frame, scene| {
            if let Some(csv) = &mut csv {
                csv.frame(frame, scene)?;
            }
            if let Some(gltf) = &mut gltf {
                gltf.frame(scene)?;
            }
            Ok(())
        },
    );
    let run = match run {
        Ok(run) => run,
        Err(Failed(e)) => {
            if let Some(gltf) = gltf {
                gltf.discard();
            }
            return Err(e);
        }
    };
    if let Some(csv) = csv {
        csv.finish()?;
    }
    if let Some(note) = gltf.map(GltfOut::finish).transpose()?.flatten() {
        eprintln!("vertebra: {note}");
    }
    Ok(run)
}
