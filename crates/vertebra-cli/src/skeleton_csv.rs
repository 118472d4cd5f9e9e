//! `vertebra scene --skeleton-out FILE`: every frame, every ragdoll's
//! reference-skeleton bones in the world, as CSV
//! (`frame,ragdoll,bone,x,y,z,qx,qy,qz,qw`; metres, unit quaternions).

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use vertebra_ragdoll::{RagdollError, Skeleton};
use vertebra_scenes::{SceneWorld, SkeletonOut};

/// A run's error as the command prints it.
pub struct Failed(pub String);

impl From<RagdollError> for Failed {
    fn from(e: RagdollError) -> Self {
        Failed(e.to_string())
    }
}

/// Where the poses go and, from the first frame on, the scene's mappers
/// with the open file.
pub struct SkeletonCsv {
    path: PathBuf,
    open: Option<(SkeletonOut, BufWriter<File>)>,
}

impl SkeletonCsv {
    /// Poses to be written to `path`, which is created at the first frame,
    /// once the scene's ragdolls map onto the reference skeleton.
    pub fn new(path: &Path) -> Self {
        Self {
            path: path.to_owned(),
            open: None,
        }
    }

    /// One row per ragdoll and bone of `scene` after frame `frame`.
    pub fn frame(&mut self, frame: usize, scene: &SceneWorld) -> Result<(), Failed> {
        if self.open.is_none() {
            self.open = Some(self.open(scene)?);
        }
        let (bones, out) = self.open.as_mut().expect("opened above");
        let names = bones.skeleton().bones();
        for (ragdoll, pose) in bones.poses(scene)?.iter().enumerate() {
            for (bone, t) in names.iter().zip(&pose.bones) {
                let [x, y, z] = t.translation.to_array();
                let [qx, qy, qz, qw] = t.rotation.to_array();
                writeln!(
                    out,
                    "{frame},{ragdoll},{},{x},{y},{z},{qx},{qy},{qz},{qw}",
                    bone.name
                )
                .map_err(|e| Failed(cannot(&self.path, e)))?;
            }
        }
        Ok(())
    }

    /// The mappers of `scene`'s ragdolls onto the reference skeleton, then
    /// the file with its header: a ragdoll that does not map (a
    /// `--ragdoll` file whose bodies are not named after its bones) is
    /// refused, saying so, before there is a file to leave behind.
    fn open(&self, scene: &SceneWorld) -> Result<(SkeletonOut, BufWriter<File>), Failed> {
        let bones = SkeletonOut::new(scene).map_err(|e| {
            Failed(format!(
                "--skeleton-out maps each ragdoll onto the reference skeleton ({} bones) by body name: {e}",
                Skeleton::reference().len()
            ))
        })?;
        let path = &self.path;
        let mut out = BufWriter::new(File::create(path).map_err(|e| Failed(cannot(path, e)))?);
        writeln!(out, "frame,ragdoll,bone,x,y,z,qx,qy,qz,qw")
            .map_err(|e| Failed(cannot(path, e)))?;
        Ok((bones, out))
    }

    /// Writes out what is buffered.
    pub fn finish(self) -> Result<(), String> {
        match self.open {
            Some((_, mut out)) => out.flush().map_err(|e| cannot(&self.path, e)),
            None => Ok(()),
        }
    }
}

fn cannot(path: &Path, e: std::io::Error) -> String {
    format!(
        "cannot write the skeleton poses to `{}`: {e}",
        path.display()
    )
}
