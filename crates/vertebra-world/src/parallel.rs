//! Body rows and threads: the one place rows are shared between threads.
//!
//! Rows are cells that the SIMD kernels load and store with plain vector
//! moves, so they are not `Sync` (`vertebra_math::row`): safe code cannot
//! race on them. Solving a colour on several threads needs every worker to
//! reach the rows, and that is sound only because no row a worker writes is
//! read or written by another worker at the same time. The condition is not
//! taken on trust from the colouring (a restored snapshot carries one): each
//! layout checks it when it is built ([`colour_is_disjoint`]) and a layout
//! that fails the check runs one chunk at a time (`step.rs`).

use std::sync::{Mutex, PoisonError};

use vertebra_kernels::body::{BodyPairs, BodyRows};
use vertebra_math::row::NO_WRITE;

/// The world's body rows: scratch of a step, reached only through
/// `&mut World`. The mutex is never locked (`get_mut` takes no lock): it
/// keeps `World` `Sync`, which rows alone are not.
#[derive(Debug, Default)]
pub(crate) struct Scratch(Mutex<BodyRows>);

impl Scratch {
    /// The rows (no lock: `&mut self` is exclusive already).
    pub fn get(&mut self) -> &mut BodyRows {
        self.0.get_mut().unwrap_or_else(PoisonError::into_inner)
    }
}

/// Rows handed to the workers of a substep's stages (`stages.rs`).
pub(crate) struct Shared<'a>(&'a BodyRows);

impl<'a> Shared<'a> {
    /// Lends `rows` to the workers of a substep. The stages that reach them
    /// must keep this module's rule (see the `Sync` impl).
    pub fn new(rows: &'a BodyRows) -> Self {
        Self(rows)
    }

    /// The rows, on a worker (a method, so closures capture `Shared`).
    pub fn rows(&self) -> &'a BodyRows {
        self.0
    }
}

// `Shared` lends the rows to the stages of one substep (`step.rs`), which
// runs at once only: chunks of one colour's blocks of a layout that passed
// `colour_is_disjoint` (every row one block writes is read and written by
// that block's lane alone; rows nobody writes, static, kinematic and the
// null row, are only read); chunks of bodies, each touching the rows of
// its own bodies only; and solve bins `1..` (`bins.rs`), each run whole by
// one worker, once every lane of every bin was checked to read and write
// only its own bin's rows and to read nothing else but rows nobody writes
// (`step::bins_apart`, `Bins::owns`, every step). Everything else (the
// scalar overflow set, a layout that failed a check) is a stage of one
// chunk, and stages run one after another (the stage counters' release
// and acquire order them).
// SAFETY: so no two workers touch a row that one of them writes at the
// same time, and the kernels' plain loads and stores of rows never race.
unsafe impl Sync for Shared<'_> {}

/// Whether one colour's blocks may run on several threads at once: every
/// lane writes only its own body's row (or nothing), and a row that is
/// written is read by no other lane of the colour. True for every colouring
/// `vertebra_scheduler` makes; a crafted one fails it. `reads` is scratch
/// (each row's readers), kept by the caller so that a check every step
/// allocates nothing once it has grown to the row count.
pub(crate) fn colour_is_disjoint<'a>(
    pairs: impl Iterator<Item = &'a BodyPairs> + Clone,
    reads: &mut Vec<u32>,
) -> bool {
    reads.clear();
    for p in pairs.clone() {
        for &row in p.body_a.iter().chain(&p.body_b) {
            let row = row as usize;
            if row >= reads.len() {
                reads.resize(row + 1, 0);
            }
            reads[row] += 1;
        }
    }
    let alone =
        |read: u32, write: u32| write == NO_WRITE || (write == read && reads[read as usize] == 1);
    pairs.into_iter().all(|p| {
        (0..p.body_a.len())
            .all(|l| alone(p.body_a[l], p.write_a[l]) && alone(p.body_b[l], p.write_b[l]))
    })
}

#[cfg(test)]
mod tests {
    use glam::Vec3;
    use vertebra_kernels::body::{LaneBlock, PairLane};
    use vertebra_scheduler::Colouring;

    use super::*;
    use crate::layout::Layout;
    use crate::{BodyDesc, JointDesc, Shape, SolverConfig, World};

    #[test]
    fn the_world_stays_send_and_sync() {
        fn send_sync<T: Send + Sync>() {}
        send_sync::<World>();
    }

    #[test]
    fn a_colouring_that_shares_a_dynamic_body_in_a_colour_runs_on_one_thread() {
        let mut world = World::new(SolverConfig::default()).unwrap();
        let fixed = world.add_body(BodyDesc::fixed()).unwrap();
        let mass = Shape::Sphere { radius: 0.1 }
            .mass_properties_with_mass(1.0)
            .unwrap();
        let bob = world.add_body(BodyDesc::dynamic(mass)).unwrap();
        let other = world.add_body(BodyDesc::dynamic(mass)).unwrap();
        for (a, b) in [(fixed, bob), (bob, other)] {
            let desc = JointDesc::socket_at_world_anchor(world.bodies(), a, b, Vec3::ZERO, Vec3::Y);
            world.add_joint(desc.unwrap()).unwrap();
        }
        world.refresh_layout();
        assert!(world.layout.disjoint, "the scheduler's colouring passes");
        // A crafted colouring (a snapshot carries one) with both sockets,
        // which share the dynamic `bob`, in colour 0.
        let mut crafted = Colouring::new();
        crafted.add(0, [None, None]);
        crafted.add(1, [None, None]);
        let asleep = world.islands.asleep();
        let layout = Layout::build(
            &crafted,
            &world.joints,
            &world.rods,
            &world.bodies,
            asleep,
            (&crate::bins::Bins::default(), None),
        );
        assert_eq!(layout.bins[0].colours.len(), 1);
        assert!(!layout.disjoint);
    }

    fn pairs(lanes: &[(u32, u32, bool, bool)]) -> BodyPairs {
        // A padding block's pairs: the null row, written nowhere.
        let mut p = vertebra_kernels::socket::SocketBlock::padding().bodies;
        for (lane, &(body_a, body_b, dynamic_a, dynamic_b)) in lanes.iter().enumerate() {
            let pair = PairLane {
                body_a,
                body_b,
                dynamic_a,
                dynamic_b,
            };
            p.set(lane, &pair);
        }
        p
    }

    #[test]
    fn shared_static_rows_are_disjoint_shared_dynamic_rows_are_not() {
        // Row 1 static (read by both blocks), rows 2..5 dynamic, once each.
        let good = [
            pairs(&[(1, 2, false, true), (3, 4, true, true)]),
            pairs(&[(1, 5, false, true)]),
        ];
        assert!(colour_is_disjoint(good.iter(), &mut Vec::new()));
        // Row 2 written by one lane and read by another (another block).
        let written_twice = [pairs(&[(1, 2, false, true)]), pairs(&[(2, 5, false, true)])];
        assert!(!colour_is_disjoint(written_twice.iter(), &mut Vec::new()));
        // Two lanes of one block writing row 3.
        let in_one_block = [pairs(&[(3, 4, true, true), (3, 5, true, true)])];
        assert!(!colour_is_disjoint(in_one_block.iter(), &mut Vec::new()));
        // A lane writing a row it does not read.
        let mut stray = pairs(&[(1, 2, false, true)]);
        stray.write_a[0] = 6;
        assert!(!colour_is_disjoint([stray].iter(), &mut Vec::new()));
    }
}
