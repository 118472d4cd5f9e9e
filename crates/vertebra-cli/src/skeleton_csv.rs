//! `vertebra scene --skeleton-out FILE`: every frame, every ragdoll's
//! reference-skeleton bones in the world, as CSV
//! (`frame,ragdoll,bone,x,y,z,qx,qy,qz,qw`; metres, unit quaternions).

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use vertebra_ragdoll::RagdollError;
use vertebra_scenes::{SceneWorld, SkeletonOut};

/// A run's error as the command prints it.
pub struct Failed(pub String);

impl From<RagdollError> for Failed {
    fn from(e: RagdollError) -> Self {
        Failed(e.to_string())
    }
}

/// The open file and, from the first frame on, the scene's mappers.
pub struct SkeletonCsv {
    path: PathBuf,
    out: BufWriter<File>,
    bones: Option<SkeletonOut>,
}

impl SkeletonCsv {
    /// Creates the file and writes the header; refused, naming the path,
    /// when it cannot be written.
    pub fn create(path: &Path) -> Result<Self, String> {
        let mut csv = Self {
            path: path.to_owned(),
            out: BufWriter::new(File::create(path).map_err(|e| cannot(path, e))?),
            bones: None,
        };
        writeln!(csv.out, "frame,ragdoll,bone,x,y,z,qx,qy,qz,qw").map_err(|e| cannot(path, e))?;
        Ok(csv)
    }

    /// One row per ragdoll and bone of `scene` after frame `frame`.
    pub fn frame(&mut self, frame: usize, scene: &SceneWorld) -> Result<(), Failed> {
        if self.bones.is_none() {
            self.bones = Some(SkeletonOut::new(scene)?);
        }
        let bones = self.bones.as_ref().expect("made above");
        let names = bones.skeleton().bones();
        for (ragdoll, pose) in bones.poses(scene)?.iter().enumerate() {
            for (bone, t) in names.iter().zip(&pose.bones) {
                let [x, y, z] = t.translation.to_array();
                let [qx, qy, qz, qw] = t.rotation.to_array();
                writeln!(
                    self.out,
                    "{frame},{ragdoll},{},{x},{y},{z},{qx},{qy},{qz},{qw}",
                    bone.name
                )
                .map_err(|e| Failed(cannot(&self.path, e)))?;
            }
        }
        Ok(())
    }

    /// Writes out what is buffered.
    pub fn finish(mut self) -> Result<(), String> {
        self.out.flush().map_err(|e| cannot(&self.path, e))
    }
}

fn cannot(path: &Path, e: std::io::Error) -> String {
    format!(
        "cannot write the skeleton poses to `{}`: {e}",
        path.display()
    )
}
