//! The run as one glTF animation: a keyframe per frame (frame `k` at
//! `k * FRAME_DT` seconds), a translation and a rotation channel per
//! moving node, linearly interpolated.

use gltf::json::accessor::Type;
use gltf::json::animation::{Channel, Interpolation, Property, Sampler, Target};
use gltf::json::validation::Checked::Valid;
use gltf::json::{Accessor, Animation, Index, Node};
use vertebra_scenes::FRAME_DT;

use super::document::Document;

/// The channels so far and the keyframe times they share.
pub struct Animator {
    times: Index<Accessor>,
    channels: Vec<Channel>,
    samplers: Vec<Sampler>,
}

impl Animator {
    /// Keyframes at frames `0 .. frames`: their times (s), with the bounds
    /// an animation's input must have.
    pub fn new(doc: &mut Document, frames: usize) -> Self {
        let times: Vec<[f32; 1]> = (0..frames).map(|k| [k as f32 * FRAME_DT]).collect();
        Self {
            times: doc.floats(&times, Type::Scalar, None, true),
            channels: Vec::new(),
            samplers: Vec::new(),
        }
    }

    /// `node` moved to `translations` (m, its parent's frame) and turned
    /// to `rotations` (unit quaternions `x, y, z, w`), one a keyframe.
    pub fn animate(
        &mut self,
        doc: &mut Document,
        node: Index<Node>,
        translations: &[[f32; 3]],
        rotations: &[[f32; 4]],
    ) {
        let outputs = [
            (
                doc.floats(translations, Type::Vec3, None, false),
                Property::Translation,
            ),
            (
                doc.floats(rotations, Type::Vec4, None, false),
                Property::Rotation,
            ),
        ];
        for (output, property) in outputs {
            let sampler = Index::push(
                &mut self.samplers,
                Sampler {
                    input: self.times,
                    interpolation: Valid(Interpolation::Linear),
                    output,
                    extensions: None,
                    extras: Default::default(),
                },
            );
            self.channels.push(Channel {
                sampler,
                target: Target {
                    node,
                    path: Valid(property),
                    extensions: None,
                    extras: Default::default(),
                },
                extensions: None,
                extras: Default::default(),
            });
        }
    }

    /// The animation, named `run`, in `doc` (none if nothing moves).
    pub fn finish(self, doc: &mut Document) {
        if self.channels.is_empty() {
            return;
        }
        doc.root.push(Animation {
            name: Some("run".to_owned()),
            channels: self.channels,
            samplers: self.samplers,
            extensions: None,
            extras: Default::default(),
        });
    }
}
