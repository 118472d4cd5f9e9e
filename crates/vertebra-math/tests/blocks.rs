//! Lane blocks: bytemuck casts and per-backend loads and stores.

use vertebra_math::block::{BLOCK_LANES, LaneSlices, QuatBlock, Vec3Block, for_live_slices};
use vertebra_math::{Backend, Lane, LaneKernel};

#[test]
fn blocks_cast_to_and_from_plain_floats() {
    let mut blocks = vec![Vec3Block::default(); 3];
    blocks[1].set(5, glam::Vec3::new(1.0, 2.0, 3.0));
    let floats: &[f32] = bytemuck::cast_slice(&blocks);
    assert_eq!(floats.len(), 3 * 3 * BLOCK_LANES);
    // Block 1, component y, item 5.
    assert_eq!(floats[3 * BLOCK_LANES + BLOCK_LANES + 5], 2.0);
    let back: &[Vec3Block] = bytemuck::cast_slice(floats);
    assert_eq!(back[1].get(5), glam::Vec3::new(1.0, 2.0, 3.0));
    assert_eq!(core::mem::align_of::<QuatBlock>(), 32);
}

/// Rotates every vector of a block by the matching quaternion, `L::WIDTH`
/// items at a time.
struct RotateBlock<'a> {
    q: &'a QuatBlock,
    v: &'a mut Vec3Block,
}

impl LaneKernel for RotateBlock<'_> {
    type Output = ();
    #[inline(always)]
    fn run<L: Lane>(self) {
        for start in (0..BLOCK_LANES).step_by(L::WIDTH) {
            let rotated = self.q.load::<L>(start).rotate(self.v.load::<L>(start));
            self.v.store(start, rotated);
        }
    }
}

#[test]
fn every_backend_reads_and_writes_whole_blocks() {
    let mut q = QuatBlock::default();
    let mut v = Vec3Block::default();
    for i in 0..BLOCK_LANES {
        q.set(i, glam::Quat::from_rotation_z(0.3 * i as f32));
        v.set(i, glam::Vec3::new(1.0, i as f32, -0.5));
    }
    let mut expected = v;
    Backend::Scalar.dispatch(RotateBlock {
        q: &q,
        v: &mut expected,
    });
    for backend in Backend::available() {
        let mut actual = v;
        backend.dispatch(RotateBlock {
            q: &q,
            v: &mut actual,
        });
        let a: &[u32] = bytemuck::cast_slice(core::slice::from_ref(&actual));
        let e: &[u32] = bytemuck::cast_slice(core::slice::from_ref(&expected));
        assert_eq!(a, e, "{backend}");
        for i in 0..BLOCK_LANES {
            assert!(
                (actual.get(i) - q.get(i) * v.get(i)).length() < 1e-5,
                "{backend} item {i}"
            );
        }
    }
}

#[test]
fn backend_names_parse_and_unavailable_ones_are_refused() {
    use vertebra_math::BackendChoice;
    for b in Backend::ALL {
        assert_eq!(
            b.name().parse::<BackendChoice>(),
            Ok(BackendChoice::Forced(b))
        );
        assert_eq!(BackendChoice::Forced(b).resolve().is_ok(), b.is_available());
    }
    assert_eq!("auto".parse::<BackendChoice>(), Ok(BackendChoice::Auto));
    assert!(BackendChoice::Auto.resolve().unwrap().is_available());
    let err = "avx512".parse::<BackendChoice>().unwrap_err();
    assert!(
        err.to_string().contains("unknown backend `avx512`"),
        "{err}"
    );
}

/// Records every slice [`for_live_slices`] runs: (start, width).
struct Recorder(Vec<(usize, usize)>);

impl LaneSlices for Recorder {
    fn slice<L: Lane>(&mut self, start: usize) {
        self.0.push((start, L::WIDTH));
    }
}

/// Walks one block with the padding mask `padding` on the backend.
struct Walk(u32);

impl LaneKernel for Walk {
    type Output = Vec<(usize, usize)>;
    #[inline(always)]
    fn run<L: Lane>(self) -> Self::Output {
        let mut recorder = Recorder(Vec::new());
        for_live_slices::<L, _>(self.0, &mut recorder);
        recorder.0
    }
}

/// For every padding mask: each live lane is solved exactly once, no slice
/// solved is all padding, and the 8-lane backend runs a block with a half
/// of padding four lanes wide (the other backends at their own width).
#[test]
fn live_slices_cover_every_live_lane_once_and_skip_padding() {
    for backend in Backend::available() {
        for padding in 0..1u32 << BLOCK_LANES {
            let slices = backend.dispatch(Walk(padding));
            let mut solved = [0; BLOCK_LANES];
            for &(start, width) in &slices {
                assert!(start + width <= BLOCK_LANES, "{backend}: {slices:?}");
                let lanes = start..start + width;
                assert!(
                    lanes.clone().any(|lane| padding & (1 << lane) == 0),
                    "{backend}, padding {padding:08b}: slice {start}+{width} is all padding"
                );
                lanes.for_each(|lane| solved[lane] += 1);
            }
            for (lane, &count) in solved.iter().enumerate() {
                let live = padding & (1 << lane) == 0;
                assert!(
                    !live || count == 1,
                    "{backend}, padding {padding:08b}: lane {lane} solved {count} times"
                );
            }
            let half = |mask: u32| padding & mask == mask;
            let narrow = half(0x0F) || half(0xF0);
            let widths: Vec<_> = slices.iter().map(|&(_, w)| w).collect();
            let expected = match backend.lanes() {
                8 if narrow => 4,
                lanes => lanes,
            };
            assert!(
                widths.iter().all(|&w| w == expected),
                "{backend}, padding {padding:08b}: widths {widths:?}"
            );
        }
    }
}
