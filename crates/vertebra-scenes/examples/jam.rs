//! Diagnostic: what holds a jammed pile apart (docs/contacts.md, "The
//! jammed pile").
//!
//! `cargo run --release -p vertebra-scenes --example jam -- S I SEED [FRAMES [EVERY]]`
//! runs the socket ragdoll drop at S substeps x I iterations from SEED and
//! prints: every 50 frames the fastest body and the deepest contact found;
//! at the end the ragdolls out of the pit and the joints that carry the
//! separation; then, every EVERY frames, the worst joint's separation, its
//! two bodies' speeds and their contacts closer than 2 cm (the other body:
//! `r<ragdoll>.<body>`, or `s<index>` for static geometry; the normal from
//! the lower collider to the higher; the depth).

use std::collections::HashMap;

use vertebra_ragdoll::SpineMode;
use vertebra_scenes::{Scene, SceneConfig, SceneWorld, build};
use vertebra_world::{BodyHandle, Contact};

/// One frame's record.
struct Record {
    contacts: Vec<Contact>,
    /// Per body: linear and angular speed as the frame began.
    speeds: HashMap<BodyHandle, (f32, f32)>,
    /// Per joint (parent, child): separation after the frame (cm).
    separations: HashMap<(BodyHandle, BodyHandle), f32>,
}

fn main() {
    let args: Vec<u64> = std::env::args()
        .skip(1)
        .map(|a| a.parse().expect("numbers: S I SEED [FRAMES [EVERY]]"))
        .collect();
    let mut config = SceneConfig::new(Scene::RagdollDrop, SpineMode::Sockets);
    config.substeps = args[0] as u32;
    config.iterations = args[1] as u32;
    config.seed = args[2];
    let frames = args.get(3).map_or(600, |&f| f as usize);
    let every = args.get(4).map_or(50, |&e| e as usize);
    let mut scene = build(&config).expect("the scene builds");
    let names = body_names(&scene);
    let name = |b: &BodyHandle| names.get(b).cloned().unwrap_or(format!("s{}", b.index()));
    let mut records = Vec::new();
    for frame in 0..frames {
        scene.detect(1.0 / 60.0).expect("contacts");
        let contacts = scene.world.contacts().to_vec();
        let speeds = body_speeds(&scene);
        scene.world.step(1.0 / 60.0).expect("a step");
        let record = Record {
            contacts,
            speeds,
            separations: joint_separations(&scene),
        };
        if frame % 50 == 0 {
            let (fast, (v, w)) = record
                .speeds
                .iter()
                .max_by(|x, y| x.1.0.total_cmp(&y.1.0))
                .expect("bodies");
            let deepest = record.contacts.iter().map(|c| c.depth).fold(0.0, f32::max);
            println!(
                "frame {frame:>4}: fastest {} {v:.1} m/s {w:.0} rad/s, deepest contact {:.0} mm",
                name(fast),
                deepest * 1e3
            );
        }
        records.push(record);
    }
    for (k, ragdoll) in scene.ragdolls.iter().enumerate() {
        let hips = scene
            .world
            .body(ragdoll.bodies[0].expect("hips"))
            .expect("live")
            .position;
        if hips.x.abs() > 1.5 || hips.z.abs() > 1.5 {
            println!("ragdoll {k} is out of the pit: hips at {hips:.2}");
        }
    }
    let last = records.last().expect("a frame");
    let mut joints: Vec<_> = last.separations.iter().map(|(&j, &cm)| (j, cm)).collect();
    joints.sort_by(|x, y| y.1.total_cmp(&x.1));
    println!(
        "summed separation {:.3} cm; joints above 0.05 cm:",
        joints.iter().map(|j| j.1).sum::<f32>()
    );
    for &((a, b), cm) in joints.iter().take_while(|j| j.1 > 0.05) {
        println!("  {} - {} {cm:.3} cm", name(&a), name(&b));
    }
    let ((a, b), _) = joints[0];
    println!("the worst joint, {} - {}:", name(&a), name(&b));
    for (frame, r) in records.iter().enumerate().step_by(every.max(1)) {
        let (sa, sb) = (r.speeds[&a], r.speeds[&b]);
        let mut line = format!(
            "  frame {frame:>4} {:.2} cm, speeds {:.1} {:.1} m/s {:.0} {:.0} rad/s |",
            r.separations[&(a, b)],
            sa.0,
            sb.0,
            sa.1,
            sb.1
        );
        for c in r.contacts.iter().filter(|c| c.depth > -0.02) {
            for (own, other) in [(c.body_a, c.body_b), (c.body_b, c.body_a)] {
                if own == a || own == b {
                    let n = c.normal;
                    line += &format!(
                        " {}~{} ({:+.2} {:+.2} {:+.2}) {:+.1} mm;",
                        name(&own),
                        name(&other),
                        n.x,
                        n.y,
                        n.z,
                        c.depth * 1e3
                    );
                }
            }
        }
        println!("{line}");
    }
}

/// Each ragdoll body's name: `r<ragdoll>.<body>`.
fn body_names(scene: &SceneWorld) -> HashMap<BodyHandle, String> {
    let mut names = HashMap::new();
    for (r, ragdoll) in scene.ragdolls.iter().enumerate() {
        for (k, body) in ragdoll.bodies.iter().enumerate() {
            if let Some(b) = body {
                names.insert(*b, format!("r{r}.{}", ragdoll.description().bodies[k].name));
            }
        }
    }
    names
}

/// Every ragdoll body's linear and angular speed (m/s, rad/s).
fn body_speeds(scene: &SceneWorld) -> HashMap<BodyHandle, (f32, f32)> {
    scene
        .ragdolls
        .iter()
        .flat_map(|r| r.bodies.iter().flatten())
        .map(|&b| {
            let s = scene.world.body(b).expect("live");
            (b, (s.linear_velocity.length(), s.angular_velocity.length()))
        })
        .collect()
}

/// Every joint's separation (cm) by its (parent, child) bodies.
fn joint_separations(scene: &SceneWorld) -> HashMap<(BodyHandle, BodyHandle), f32> {
    scene
        .world
        .residuals()
        .expect("a scene measures its residuals every step")
        .joints
        .iter()
        .filter_map(|j| {
            let desc = scene.world.joint(j.joint).ok()?;
            Some(((desc.body_a, desc.body_b), j.linear_cm))
        })
        .collect()
}
