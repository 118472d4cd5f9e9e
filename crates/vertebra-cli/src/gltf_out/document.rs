//! A glTF document under construction: the JSON (`gltf::json`'s types)
//! and its one binary buffer, each accessor's data in a buffer view of
//! its own, little-endian, every view starting on a 4-byte boundary.

use gltf::json::accessor::{ComponentType, GenericComponentType, Type};
use gltf::json::buffer::{Target, View};
use gltf::json::validation::{Checked::Valid, USize64};
use gltf::json::{self, Accessor, Buffer, Index, Root};

/// The JSON being built and the bytes of its buffer.
pub struct Document {
    /// The glTF JSON so far (its buffer is pushed by [`Document::finish`]).
    pub root: Root,
    bin: Vec<u8>,
}

/// The buffer every view is in: the only one, pushed last.
const BUFFER: u32 = 0;

impl Document {
    /// An empty glTF 2.0 document, naming vertebra as its generator.
    pub fn new() -> Self {
        let mut root = Root::default();
        root.asset.generator = Some(format!("vertebra {}", env!("CARGO_PKG_VERSION")));
        Self {
            root,
            bin: Vec::new(),
        }
    }

    /// `bytes` appended to the buffer as a view of their own.
    fn view(&mut self, bytes: &[u8], target: Option<Target>) -> Index<View> {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let offset = self.bin.len();
        self.bin.extend_from_slice(bytes);
        self.root.push(View {
            buffer: Index::new(BUFFER),
            byte_length: USize64::from(bytes.len()),
            byte_offset: Some(USize64::from(offset)),
            byte_stride: None,
            name: None,
            target: target.map(Valid),
            extensions: None,
            extras: Default::default(),
        })
    }

    /// An accessor of `count` elements of `type_` in `component`s, tightly
    /// packed in `bytes`, with per-component `bounds` if given.
    fn accessor(
        &mut self,
        bytes: &[u8],
        (component, type_, count): (ComponentType, Type, usize),
        target: Option<Target>,
        bounds: Option<(Vec<f32>, Vec<f32>)>,
    ) -> Index<Accessor> {
        let view = self.view(bytes, target);
        let (min, max) = bounds.map_or((None, None), |(min, max)| {
            (Some(json::Value::from(min)), Some(json::Value::from(max)))
        });
        self.root.push(Accessor {
            buffer_view: Some(view),
            byte_offset: None,
            count: USize64::from(count),
            component_type: Valid(GenericComponentType(component)),
            type_: Valid(type_),
            min,
            max,
            name: None,
            normalized: false,
            sparse: None,
            extensions: None,
            extras: Default::default(),
        })
    }

    /// Floats as elements of `N` components (`type_`: `Scalar`, `Vec3`,
    /// `Vec4` or `Mat4` for 1, 3, 4, 16), vertex data when `target` says
    /// so; with their per-component minimum and maximum when `bounds`.
    pub fn floats<const N: usize>(
        &mut self,
        elements: &[[f32; N]],
        type_: Type,
        target: Option<Target>,
        bounds: bool,
    ) -> Index<Accessor> {
        let bytes: Vec<u8> = elements
            .iter()
            .flatten()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let bounds = bounds.then(|| per_component_bounds(elements));
        self.accessor(
            &bytes,
            (ComponentType::F32, type_, elements.len()),
            target,
            bounds,
        )
    }

    /// Triangle indices (unsigned 32-bit).
    pub fn indices(&mut self, indices: &[u32]) -> Index<Accessor> {
        let bytes: Vec<u8> = indices.iter().flat_map(|v| v.to_le_bytes()).collect();
        let shape = (ComponentType::U32, Type::Scalar, indices.len());
        self.accessor(&bytes, shape, Some(Target::ElementArrayBuffer), None)
    }

    /// Four joint indices a vertex (unsigned 16-bit).
    pub fn joints(&mut self, joints: &[[u16; 4]]) -> Index<Accessor> {
        let bytes: Vec<u8> = joints
            .iter()
            .flatten()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let shape = (ComponentType::U16, Type::Vec4, joints.len());
        self.accessor(&bytes, shape, Some(Target::ArrayBuffer), None)
    }

    /// The JSON with its buffer (of `uri`, or none: a GLB's binary chunk)
    /// and the buffer's bytes, padded to a multiple of 4.
    pub fn finish(mut self, uri: impl FnOnce(&[u8]) -> Option<String>) -> (Root, Vec<u8>) {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let buffer = self.root.push(Buffer {
            byte_length: USize64::from(self.bin.len()),
            uri: uri(&self.bin),
            name: None,
            extensions: None,
            extras: Default::default(),
        });
        debug_assert_eq!(buffer.value(), BUFFER as usize);
        (self.root, self.bin)
    }
}

/// Each component's minimum and maximum over `elements`.
fn per_component_bounds<const N: usize>(elements: &[[f32; N]]) -> (Vec<f32>, Vec<f32>) {
    let mut min = [f32::INFINITY; N];
    let mut max = [f32::NEG_INFINITY; N];
    for e in elements {
        for k in 0..N {
            min[k] = min[k].min(e[k]);
            max[k] = max[k].max(e[k]);
        }
    }
    (min.to_vec(), max.to_vec())
}
