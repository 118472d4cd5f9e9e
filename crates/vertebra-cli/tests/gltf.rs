//! `vertebra scene --gltf FILE`: the file read back with the `gltf` crate
//! and checked against the same scene run here through the scenes API:
//! every body a node with its shape's mesh, its animation the simulated
//! poses bit for bit, the skins' bones where the mapped skeleton is.

use std::path::{Path, PathBuf};
use std::process::Command;

use base64::Engine as _;
use glam::{Mat4, Quat, Vec3};
use gltf::animation::util::{ReadOutputs, Rotations};
use gltf::animation::{Interpolation, Property};
use vertebra_collide::ColliderShape;
use vertebra_ragdoll::{ModelPose, RagdollError, Skeleton, SpineMode};
use vertebra_scenes::{FRAME_DT, Scene, SceneConfig, SceneWorld, SkeletonOut};
use vertebra_world::Shape;

/// Runs the command; its exit code and stderr.
fn vertebra(args: &[&str]) -> (i32, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_vertebra"))
        .args(args)
        .output()
        .expect("the binary runs");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn temp(name: &str) -> PathBuf {
    Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("gltf-{}-{name}", std::process::id()))
}

/// `scene` with `spine` for `frames` frames written to `path` by the
/// command.
fn write(scene: &str, spine: &str, frames: usize, path: &Path) {
    let frames = frames.to_string();
    let args = [
        "scene", scene, "--spine", spine, "--frames", &frames, "--gltf",
    ];
    let (code, stderr) = vertebra(&[&args[..], &[path.to_str().unwrap()]].concat());
    assert_eq!(code, 0, "{stderr}");
}

/// A file as read back: the document and its one buffer (a GLB's binary
/// chunk, or a `.gltf`'s base64 data URI decoded).
struct Loaded {
    doc: gltf::Document,
    buffer: Vec<u8>,
    /// Per node: its keyframes, and its parent.
    tracks: Vec<Track>,
    parents: Vec<Option<usize>>,
}

fn load(path: &Path) -> Loaded {
    let bytes = std::fs::read(path).unwrap();
    let file = gltf::Gltf::from_slice(&bytes).expect("a valid glTF file");
    assert_eq!(file.buffers().count(), 1, "one buffer");
    let buffer = match (file.blob.clone(), file.buffers().next().unwrap().source()) {
        (Some(blob), gltf::buffer::Source::Bin) => blob,
        (None, gltf::buffer::Source::Uri(uri)) => {
            let data = uri
                .strip_prefix("data:application/octet-stream;base64,")
                .expect("an embedded buffer");
            base64::engine::general_purpose::STANDARD
                .decode(data)
                .unwrap()
        }
        _ => panic!("neither a GLB's binary chunk nor a data URI"),
    };
    let mut loaded = Loaded {
        doc: file.document,
        buffer,
        tracks: Vec::new(),
        parents: Vec::new(),
    };
    loaded.tracks = loaded.doc.nodes().map(|n| track(&loaded, &n)).collect();
    loaded.parents = loaded
        .doc
        .nodes()
        .map(|n| {
            loaded
                .doc
                .nodes()
                .find(|p| p.children().any(|c| c.index() == n.index()))
                .map(|p| p.index())
        })
        .collect();
    loaded
}

/// A body's name, shape, and pose (position, m; orientation) each frame.
type BodyRun = (String, Shape, Vec<(Vec3, Quat)>);

/// What the scenes API gives for the same run: per ragdoll, each built
/// body's name, shape and pose every frame; every frame's mapped skeleton
/// poses (if the ragdolls map); the bodies with colliders outside the
/// ragdolls, with their pose.
struct Expected {
    bodies: Vec<Vec<BodyRun>>,
    skeletons: Option<Vec<Vec<ModelPose>>>,
    scenery: Vec<(ColliderShape, Vec3, Quat)>,
}

fn simulate(scene: Scene, spine: SpineMode, frames: usize) -> Expected {
    let mut config = SceneConfig::new(scene, spine);
    config.frames = Some(frames);
    let mut expected: Option<(Expected, Option<SkeletonOut>)> = None;
    vertebra_scenes::run_observed(
        &config,
        |_, _| {},
        |_, world: &SceneWorld| -> Result<(), RagdollError> {
            let (e, mapper) = expected.get_or_insert_with(|| start(world));
            for (ragdoll, bodies) in world.ragdolls.iter().zip(&mut e.bodies) {
                let built = ragdoll.bodies.iter().flatten();
                for (handle, (_, _, poses)) in built.zip(bodies.iter_mut()) {
                    let state = world.world.body(*handle)?;
                    poses.push((state.position, state.orientation));
                }
            }
            if let (Some(mapper), Some(skeletons)) = (mapper, &mut e.skeletons) {
                skeletons.push(mapper.poses(world)?);
            }
            Ok(())
        },
    )
    .unwrap();
    expected.unwrap().0
}

/// The bodies, mapper and scenery of a scene at its first frame.
fn start(world: &SceneWorld) -> (Expected, Option<SkeletonOut>) {
    let bodies = world
        .ragdolls
        .iter()
        .map(|r| {
            let defs = r.description().bodies.iter().zip(&r.bodies);
            defs.filter(|(_, b)| b.is_some())
                .map(|(def, _)| (def.name.clone(), def.shape(), Vec::new()))
                .collect()
        })
        .collect();
    let ragdoll_bodies: Vec<_> = world
        .ragdolls
        .iter()
        .flat_map(|r| r.bodies.iter().flatten())
        .collect();
    let scenery = world
        .collisions
        .iter()
        .flat_map(|c| c.colliders())
        .filter(|c| !ragdoll_bodies.contains(&&c.body))
        .map(|c| {
            let state = world.world.body(c.body).unwrap();
            (c.shape, state.position, state.orientation)
        })
        .collect();
    let mapper = SkeletonOut::new(world).ok();
    let skeletons = mapper.as_ref().map(|_| Vec::new());
    (
        Expected {
            bodies,
            skeletons,
            scenery,
        },
        mapper,
    )
}

/// The scene's root node called `name`.
fn root_node<'a>(doc: &'a gltf::Document, name: &str) -> gltf::Node<'a> {
    let scene = doc.default_scene().expect("a default scene");
    scene
        .nodes()
        .find(|n| n.name() == Some(name))
        .unwrap_or_else(|| panic!("no root node `{name}`"))
}

/// A node's keyframes: times, and translations and rotations (`None` for
/// a node without that channel).
#[derive(Clone)]
struct Track {
    times: Vec<f32>,
    translations: Option<Vec<[f32; 3]>>,
    rotations: Option<Vec<[f32; 4]>>,
}

fn track(file: &Loaded, node: &gltf::Node) -> Track {
    let mut t = Track {
        times: Vec::new(),
        translations: None,
        rotations: None,
    };
    let channels = file
        .doc
        .animations()
        .flat_map(|a| a.channels().collect::<Vec<_>>());
    for channel in channels.filter(|c| c.target().node().index() == node.index()) {
        assert_eq!(channel.sampler().interpolation(), Interpolation::Linear);
        let reader = channel.reader(|_| Some(&file.buffer));
        t.times = reader.read_inputs().unwrap().collect();
        match (channel.target().property(), reader.read_outputs().unwrap()) {
            (Property::Translation, ReadOutputs::Translations(v)) => {
                t.translations = Some(v.collect())
            }
            (Property::Rotation, ReadOutputs::Rotations(Rotations::F32(v))) => {
                t.rotations = Some(v.collect())
            }
            (p, _) => panic!("node {:?}: an unexpected channel {p:?}", node.name()),
        }
    }
    t
}

fn bits<const N: usize>(v: [f32; N]) -> [u32; N] {
    v.map(f32::to_bits)
}

/// Every keyframe time is `frame * FRAME_DT`, one per frame.
fn check_times(times: &[f32], frames: usize) {
    let want: Vec<u32> = (0..frames)
        .map(|k| (k as f32 * FRAME_DT).to_bits())
        .collect();
    assert_eq!(times.iter().map(|t| t.to_bits()).collect::<Vec<_>>(), want);
}

/// The closest point of the segment `-h .. h` to `p`.
fn on_segment(h: Vec3, p: Vec3) -> Vec3 {
    if h == Vec3::ZERO {
        return Vec3::ZERO;
    }
    h * (p.dot(h) / h.length_squared()).clamp(-1.0, 1.0)
}

/// The mesh's positions (body frame), after checking the primitive's
/// POSITION accessor has its bounds and they are the positions'.
fn positions(file: &Loaded, mesh: &gltf::Mesh) -> Vec<Vec3> {
    let primitive = mesh.primitives().next().expect("a primitive");
    let accessor = primitive.get(&gltf::Semantic::Positions).expect("POSITION");
    let reader = primitive.reader(|_| Some(&file.buffer));
    let points: Vec<Vec3> = reader.read_positions().unwrap().map(Vec3::from).collect();
    assert!(reader.read_normals().is_some(), "normals");
    let bound = |v: Option<gltf::json::Value>| -> Vec3 {
        let v: Vec<f32> = serde_json::from_value(v.expect("POSITION has min and max")).unwrap();
        Vec3::from_slice(&v)
    };
    let (min, max) = (bound(accessor.min()), bound(accessor.max()));
    let (lo, hi) = points
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(l, h), p| {
            (l.min(*p), h.max(*p))
        });
    assert_eq!((min, max), (lo, hi), "POSITION bounds");
    points
}

/// A mesh lies on `shape`'s surface: a capsule's vertices at its radius
/// from its segment and reaching its ends; a box's at its corners.
fn check_mesh(points: &[Vec3], shape: Shape, what: &str) {
    match shape {
        Shape::Capsule {
            half_segment,
            radius,
        } => {
            for p in points {
                let d = p.distance(on_segment(half_segment, *p));
                assert!(
                    (d - radius).abs() < 1e-5,
                    "{what}: {p} is {d} m from the segment, radius {radius}"
                );
            }
            let axis = half_segment.normalize();
            let reach = points.iter().map(|p| p.dot(axis)).fold(f32::MIN, f32::max);
            assert!(
                (reach - half_segment.length() - radius).abs() < 1e-5,
                "{what}: reach {reach}"
            );
        }
        Shape::Box { half_extents } => {
            assert!(
                points.iter().all(|p| p.abs() == half_extents),
                "{what}: not its box"
            );
            assert_eq!(
                points.iter().map(|p| p.x).fold(f32::MIN, f32::max),
                half_extents.x
            );
        }
        Shape::Sphere { radius } => {
            assert!(
                points.iter().all(|p| (p.length() - radius).abs() < 1e-5),
                "{what}"
            );
        }
    }
}

/// Every ragdoll's group holds a node per built body, in order, with its
/// shape's mesh and, per frame, the body's simulated pose bit for bit.
fn check_bodies(file: &Loaded, expected: &Expected, frames: usize) {
    for (k, bodies) in expected.bodies.iter().enumerate() {
        let group = root_node(&file.doc, &format!("ragdoll {k}"));
        assert_eq!(
            group.transform().decomposed(),
            ([0.0; 3], [0.0, 0.0, 0.0, 1.0], [1.0; 3])
        );
        let nodes: Vec<_> = group.children().filter(|n| n.mesh().is_some()).collect();
        assert_eq!(nodes.len(), bodies.len(), "ragdoll {k}: a node per body");
        for (node, (name, shape, poses)) in nodes.iter().zip(bodies) {
            assert_eq!(node.name(), Some(name.as_str()));
            check_mesh(&positions(file, &node.mesh().unwrap()), *shape, name);
            let t = file.tracks[node.index()].clone();
            check_times(&t.times, frames);
            let want_t: Vec<_> = poses.iter().map(|p| bits(p.0.to_array())).collect();
            let want_r: Vec<_> = poses.iter().map(|p| bits(p.1.to_array())).collect();
            let got_t: Vec<_> = t
                .translations
                .expect("a translation channel")
                .into_iter()
                .map(bits)
                .collect();
            let got_r: Vec<_> = t
                .rotations
                .expect("a rotation channel")
                .into_iter()
                .map(bits)
                .collect();
            assert_eq!(got_t, want_t, "ragdoll {k} `{name}`: translations");
            assert_eq!(got_r, want_r, "ragdoll {k} `{name}`: rotations");
        }
    }
}

/// A node's transform at keyframe `frame`: its channels' values if it has
/// them, else its own.
fn local_at(file: &Loaded, node: &gltf::Node, frame: usize) -> Mat4 {
    let (t, r, s) = node.transform().decomposed();
    assert_eq!(s, [1.0; 3], "no scale");
    let track = &file.tracks[node.index()];
    let t = track.translations.as_ref().map_or(t, |v| v[frame]);
    let r = track.rotations.as_ref().map_or(r, |v| v[frame]);
    Mat4::from_rotation_translation(Quat::from_array(r), Vec3::from(t))
}

/// The world transform of `index` at keyframe `frame`: its chain of
/// parents' transforms, from the scene's root down.
fn world_at(file: &Loaded, index: usize, frame: usize) -> Mat4 {
    let local = local_at(file, &file.doc.nodes().nth(index).unwrap(), frame);
    match file.parents[index] {
        Some(p) => world_at(file, p, frame) * local,
        None => local,
    }
}

/// Each ragdoll's skin: the reference skeleton's bones, named as it names
/// them, inverse bind matrices undoing the bind pose, and every bone's
/// world transform at keyframes `at` the mapped skeleton's pose.
fn check_skins(file: &Loaded, expected: &Expected, at: &[usize]) {
    let skeleton = Skeleton::reference();
    let bind = skeleton.bind_pose().to_model(&skeleton).unwrap();
    let mapped = expected.skeletons.as_ref().expect("the ragdolls map");
    let skins: Vec<_> = file.doc.skins().collect();
    assert_eq!(skins.len(), expected.bodies.len(), "a skin per ragdoll");
    for (k, skin) in skins.iter().enumerate() {
        let joints: Vec<_> = skin.joints().collect();
        assert_eq!(joints.len(), 63);
        let names: Vec<_> = joints.iter().map(|j| j.name().unwrap()).collect();
        let want: Vec<_> = skeleton.bones().iter().map(|b| b.name.as_str()).collect();
        assert_eq!(names, want, "skin {k}: the reference skeleton's bones");
        let inverse_binds: Vec<_> = skin
            .reader(|_| Some(&file.buffer))
            .read_inverse_bind_matrices()
            .expect("inverse bind matrices")
            .collect();
        for (m, b) in inverse_binds.iter().zip(&bind.bones) {
            let product = Mat4::from_cols_array_2d(m)
                * Mat4::from_rotation_translation(b.rotation, b.translation);
            assert!(
                product.abs_diff_eq(Mat4::IDENTITY, 1e-5),
                "skin {k}: {product}"
            );
        }
        let drawn = root_node(&file.doc, &format!("ragdoll {k} bones"));
        assert_eq!(drawn.skin().map(|s| s.index()), Some(skin.index()));
        assert!(drawn.mesh().is_some(), "the skin is drawn");
        for &frame in at {
            for (joint, want) in joints.iter().zip(&mapped[frame][k].bones) {
                let (_, r, t) =
                    world_at(file, joint.index(), frame).to_scale_rotation_translation();
                let angle = 2.0 * (r.inverse() * want.rotation).xyz().length();
                assert!(
                    t.distance(want.translation) < 2e-5 && angle < 2e-4,
                    "ragdoll {k} bone `{}` at frame {frame}: {t} {r} against {want:?}",
                    joint.name().unwrap()
                );
            }
        }
    }
}

#[test]
fn a_glb_of_the_ragdoll_drop_holds_every_body_its_poses_and_the_skins() {
    let (frames, path) = (24, temp("drop.glb"));
    write("ragdoll-drop", "sockets", frames, &path);
    let file = load(&path);
    let expected = simulate(Scene::RagdollDrop, SpineMode::Sockets, frames);
    assert_eq!(expected.bodies.len(), 30);
    check_bodies(&file, &expected, frames);
    check_skins(&file, &expected, &[0, frames / 2, frames - 1]);
    // The ground, four walls and three boxes, where the scene has them.
    let scene = file.doc.default_scene().unwrap();
    let scenery: Vec<_> = scene
        .nodes()
        .filter(|n| n.mesh().is_some() && n.skin().is_none())
        .collect();
    assert_eq!(scenery.len(), expected.scenery.len());
    assert_eq!(scenery.len(), 8);
    for (node, (shape, position, orientation)) in scenery.iter().zip(&expected.scenery) {
        let (t, r, _) = node.transform().decomposed();
        assert_eq!(
            (bits(t), bits(r)),
            (bits(position.to_array()), bits(orientation.to_array()))
        );
        let points = positions(&file, &node.mesh().unwrap());
        match shape {
            ColliderShape::Solid(s) => check_mesh(&points, *s, node.name().unwrap()),
            ColliderShape::Plane(normal) => {
                assert_eq!(node.name(), Some("ground"));
                assert!(points.iter().all(|p| p.dot(*normal).abs() < 1e-6));
                assert!(
                    points.iter().all(|p| p.length() > 3.0),
                    "reaches past the pit"
                );
            }
        }
    }
    std::fs::remove_file(path).ok();
}

#[test]
fn a_gltf_with_its_buffer_embedded_reads_back_the_same() {
    let (frames, path) = (30, temp("bending.gltf"));
    write("passive-bending", "rod", frames, &path);
    assert!(
        std::fs::read_to_string(&path).unwrap().starts_with('{'),
        "JSON"
    );
    let file = load(&path);
    let expected = simulate(Scene::PassiveBending, SpineMode::Rod, frames);
    check_bodies(&file, &expected, frames);
    check_skins(&file, &expected, &[0, frames - 1]);
    std::fs::remove_file(path).ok();
}

#[test]
fn a_scene_that_maps_onto_no_skeleton_has_its_bodies_and_no_skin() {
    let (frames, path) = (10, temp("chain.glb"));
    let (code, stderr) = vertebra(&[
        "scene",
        "heavy-chain",
        "--spine",
        "sockets",
        "--joints",
        "iterative",
        "--frames",
        "10",
        "--gltf",
        path.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stderr.contains("no skin"), "{stderr}");
    let file = load(&path);
    let expected = simulate(Scene::HeavyChain, SpineMode::Sockets, frames);
    check_bodies(&file, &expected, frames);
    assert_eq!(file.doc.skins().count(), 0);
    std::fs::remove_file(path).ok();
}

#[test]
fn a_bad_gltf_path_is_an_error_not_a_panic() {
    let scene = [
        "scene",
        "passive-bending",
        "--spine",
        "rod",
        "--frames",
        "2",
        "--gltf",
    ];
    let missing = temp("no-such-dir").join("run.glb");
    let (code, stderr) = vertebra(&[&scene[..], &[missing.to_str().unwrap()]].concat());
    assert_eq!(code, 1, "{stderr}");
    assert!(
        stderr.starts_with("vertebra: cannot write the glTF file"),
        "{stderr}"
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
    let text = temp("run.txt");
    let (code, stderr) = vertebra(&[&scene[..], &[text.to_str().unwrap()]].concat());
    assert_eq!(code, 1, "{stderr}");
    assert!(
        stderr.contains("FILE.glb") && stderr.contains("FILE.gltf"),
        "{stderr}"
    );
    assert!(!text.exists(), "nothing written");
    let glb = temp("seeds.glb");
    let (code, stderr) = vertebra(&[&scene[..], &[glb.to_str().unwrap(), "--seeds", "2"]].concat());
    assert_eq!(code, 1, "{stderr}");
    assert!(
        stderr.contains("--gltf writes one run; not with --seeds"),
        "{stderr}"
    );
    assert!(!glb.exists(), "nothing written");
}

#[test]
fn a_failed_run_leaves_no_gltf_file() {
    // The drive's setting is checked as the scene is built: after the
    // file was made.
    let path = temp("failed.glb");
    let (code, stderr) = vertebra(&[
        "scene",
        "hit-reaction",
        "--spine",
        "rod",
        "--frames",
        "2",
        "--drive-frequency",
        "-1",
        "--gltf",
        path.to_str().unwrap(),
    ]);
    assert_eq!(code, 1, "{stderr}");
    assert!(
        stderr.contains("drive_frequency"),
        "the scene refused: {stderr}"
    );
    assert!(!path.exists(), "no file left behind");
}

#[test]
fn a_run_too_long_to_keep_is_refused_at_its_first_frame() {
    // 30 ragdolls of 74 nodes and 8 statics, a million frames: 58 GiB of
    // keyframes.
    let path = temp("long.glb");
    let (code, stderr) = vertebra(&[
        "scene",
        "ragdoll-drop",
        "--spine",
        "rod",
        "--frames",
        "1000000",
        "--gltf",
        path.to_str().unwrap(),
    ]);
    assert_eq!(code, 1, "{stderr}");
    assert!(
        stderr.contains("at most 1024 MiB (fewer --frames)"),
        "{stderr}"
    );
    assert!(!path.exists(), "no file left behind");
}
