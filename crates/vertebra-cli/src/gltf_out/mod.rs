//! `vertebra scene --gltf FILE` and `reproduce`'s `.glb` files: a run as
//! an animated glTF 2.0 file (`docs/gltf.md`). Metres, +Y up, right-handed:
//! the scenes' world frame is glTF's, so poses are written as they are.
//!
//! The file holds, in one scene: a node per body with a shape (a ragdoll's
//! bodies in a node `ragdoll K` each, the ground and the other static
//! shapes at the root) with its mesh; one animation, `run`, with a
//! keyframe per frame (frame `k` at `k / 60` s) and a translation and a
//! rotation channel per moving body, the body's simulated pose as its f32
//! bits; and, where the ragdolls map onto the reference skeleton, a skin
//! per ragdoll: its 63 bones as nodes under the ragdoll's node, animated
//! relative to their parents, drawn by an octahedron per bone.

mod animation;
mod bodies;
mod document;
mod file;
mod meshes;
mod record;
mod shapes;
mod skin;

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use gltf::json::{Index, Node, Scene};
use vertebra_scenes::{SceneConfig, SceneWorld};

use crate::skeleton_csv::Failed;
use animation::Animator;
use bodies::body_nodes;
use document::Document;
use file::Format;
use meshes::{Look, Materials};
use record::Recording;
use skin::{SkinNodes, skins};

/// The most keyframe data a file may hold (bytes): the run is kept in
/// memory until it is written, and a `.glb` ends at 4 GiB.
const MAX_KEYFRAME_BYTES: usize = 1 << 30;

/// Bytes a keyframe takes per node: a translation and a rotation (f32).
const KEYFRAME_BYTES: usize = 7 * 4;

/// A run being gathered for a glTF file.
pub struct GltfOut {
    path: PathBuf,
    format: Format,
    file: File,
    frames: usize,
    recording: Option<Recording>,
}

impl GltfOut {
    /// A run of `frames` frames to be written to `path` (`.glb` or
    /// `.gltf`), created now, so that a path that cannot be written is
    /// refused before the run.
    pub fn create(path: &Path, frames: usize) -> Result<Self, String> {
        let format = Format::of(path)?;
        let file = File::create(path).map_err(|e| cannot(path, e))?;
        Ok(Self {
            path: path.to_owned(),
            format,
            file,
            frames,
            recording: None,
        })
    }

    /// `scene` after one more frame. At the first, the bodies and
    /// skeletons are found, and a run too long to keep is refused.
    pub fn frame(&mut self, scene: &SceneWorld) -> Result<(), Failed> {
        if self.recording.is_none() {
            let recording = Recording::new(scene);
            self.check_size(&recording)?;
            self.recording = Some(recording);
        }
        let recording = self.recording.as_mut().expect("made above");
        Ok(recording.record(scene)?)
    }

    /// Refuses a run whose keyframes would pass [`MAX_KEYFRAME_BYTES`].
    fn check_size(&self, recording: &Recording) -> Result<(), Failed> {
        let bones = recording
            .skeletons
            .as_ref()
            .map_or(0, |s| s.locals.iter().map(Vec::len).sum::<usize>());
        let nodes = recording.bodies.len() + bones;
        let bytes = nodes
            .saturating_mul(self.frames)
            .saturating_mul(KEYFRAME_BYTES);
        if bytes > MAX_KEYFRAME_BYTES {
            return Err(Failed(format!(
                "--gltf: {} frames of {nodes} nodes would take {} MiB of keyframes; at most {} MiB (fewer --frames)",
                self.frames,
                bytes >> 20,
                MAX_KEYFRAME_BYTES >> 20
            )));
        }
        Ok(())
    }

    /// Writes the file; says why there is no skin if there is none.
    pub fn finish(self) -> Result<Option<String>, String> {
        let Some(recording) = self.recording else {
            return Err(format!(
                "--gltf: no frame to write to `{}`",
                self.path.display()
            ));
        };
        let doc = assemble(&recording).map_err(|e| format!("--gltf: {e}"))?;
        let mut out = BufWriter::new(self.file);
        self.format
            .write(doc, &mut out)
            .and_then(|()| out.flush())
            .map_err(|e| cannot(&self.path, e))?;
        Ok(recording.skeletons.err().map(|why| {
            format!("--gltf: no skin: the ragdolls do not map onto the reference skeleton ({why})")
        }))
    }

    /// Removes the file (the run failed).
    pub fn discard(self) {
        drop(self.file);
        std::fs::remove_file(&self.path).ok();
    }
}

/// Runs `config` and writes it to `path` (`.glb` or `.gltf`): what
/// `reproduce` does for each scene and spine.
pub fn write_run(config: &SceneConfig, path: &Path) -> Result<(), String> {
    let frames = config.frames.unwrap_or(config.scene.default_frames());
    let mut out = GltfOut::create(path, frames)?;
    match vertebra_scenes::run_observed(config, |_, _| {}, |_, scene| out.frame(scene)) {
        Ok(_) => out.finish().map(|_| ()),
        Err(Failed(e)) => {
            out.discard();
            Err(e)
        }
    }
}

/// The document of `recording`: materials, bodies, skins, the animation
/// and the scene.
fn assemble(recording: &Recording) -> Result<Document, vertebra_ragdoll::RagdollError> {
    let mut doc = Document::new();
    let mut materials = Materials::default();
    let mut animator = Animator::new(&mut doc, recording.frames);
    let bodies = body_nodes(&mut doc, &mut animator, recording, &mut materials);
    let skins = match &recording.skeletons {
        Ok(skeletons) => {
            let bone = materials.get(&mut doc, Look::Bone);
            skins(&mut doc, &mut animator, skeletons, bone)?
        }
        Err(_) => Vec::new(),
    };
    let mut nodes = bodies.scenery;
    for (k, mut children) in bodies.ragdolls.into_iter().enumerate() {
        if let Some(skin) = skins.get(k) {
            children.extend(&skin.roots);
        }
        nodes.push(doc.root.push(Node {
            name: Some(format!("ragdoll {k}")),
            children: Some(children),
            ..Default::default()
        }));
    }
    nodes.extend(skins.iter().map(|s: &SkinNodes| s.drawn));
    animator.finish(&mut doc);
    let scene: Index<Scene> = doc.root.push(Scene {
        name: Some("run".to_owned()),
        nodes,
        extensions: None,
        extras: Default::default(),
    });
    doc.root.scene = Some(scene);
    Ok(doc)
}

fn cannot(path: &Path, e: std::io::Error) -> String {
    format!("cannot write the glTF file `{}`: {e}", path.display())
}
