//! The two ways a glTF file is written, told apart by its name: `.glb`
//! (binary: the JSON and the buffer in one file) or `.gltf` (JSON, the
//! buffer embedded as a base64 data URI). Either is self-contained.

use std::borrow::Cow;
use std::io::Write;
use std::path::Path;

use base64::Engine as _;
use base64::engine::general_purpose::STANDARD;
use gltf::binary::{Glb, Header};
use gltf::json::Root;

use super::document::Document;

/// How the file is laid out.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Format {
    /// `.glb`: binary glTF.
    Binary,
    /// `.gltf`: JSON with the buffer as a data URI.
    Embedded,
}

impl Format {
    /// The format `path`'s extension names (either case), or why there is
    /// none.
    pub fn of(path: &Path) -> Result<Self, String> {
        let extension = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match extension.as_deref() {
            Some("glb") => Ok(Format::Binary),
            Some("gltf") => Ok(Format::Embedded),
            _ => Err(format!(
                "--gltf writes FILE.glb (binary glTF) or FILE.gltf (JSON, buffer embedded); `{}` is neither",
                path.display()
            )),
        }
    }

    /// `doc` laid out in this format, to `out`.
    pub fn write(self, doc: Document, out: impl Write) -> std::io::Result<()> {
        match self {
            Format::Binary => {
                let (root, bin) = doc.finish(|_| None);
                let json = root.to_vec().map_err(std::io::Error::other)?;
                let glb = Glb {
                    // `to_writer` works the header out itself.
                    header: Header {
                        magic: *b"glTF",
                        version: 2,
                        length: 0,
                    },
                    json: Cow::Owned(json),
                    bin: Some(Cow::Owned(bin)),
                };
                glb.to_writer(out).map_err(std::io::Error::other)
            }
            Format::Embedded => {
                let (root, _) = doc.finish(|bin| {
                    Some(format!(
                        "data:application/octet-stream;base64,{}",
                        STANDARD.encode(bin)
                    ))
                });
                write_json(&root, out)
            }
        }
    }
}

fn write_json(root: &Root, out: impl Write) -> std::io::Result<()> {
    root.to_writer(out).map_err(std::io::Error::other)
}
