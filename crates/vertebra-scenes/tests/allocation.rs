//! A steady world allocates nothing per step. The 30-ragdoll drop with
//! collision detection, its pile settled (the same bodies, joints and about
//! the same contacts every frame), runs frame after frame of finding
//! contacts (`Collisions::find_contacts_into`), handing them over
//! (`World::swap_contacts`) and stepping (residuals measured, as the scenes
//! do) without one allocation, counted by a global allocator that forwards
//! to the system's.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

use vertebra_ragdoll::SpineMode;
use vertebra_scenes::{Scene, SceneConfig, SceneWorld, build};
use vertebra_world::JointSolver;

/// The system allocator, counting allocations (and reallocations).
struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

// SAFETY: every method forwards the caller's arguments to the system
// allocator unchanged (so `System`'s guarantees are this allocator's); the
// count is an atomic, touched by no other code.
unsafe impl GlobalAlloc for Counting {
    // SAFETY: a forwarding method (see the impl).
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        // SAFETY: the caller keeps `GlobalAlloc::alloc`'s contract.
        unsafe { System.alloc(layout) }
    }

    // SAFETY: a forwarding method (see the impl).
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        // SAFETY: the caller keeps `GlobalAlloc::alloc_zeroed`'s contract.
        unsafe { System.alloc_zeroed(layout) }
    }

    // SAFETY: a forwarding method (see the impl).
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        // SAFETY: the caller keeps `GlobalAlloc::realloc`'s contract.
        unsafe { System.realloc(ptr, layout, new_size) }
    }

    // SAFETY: a forwarding method (see the impl).
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: the caller keeps `GlobalAlloc::dealloc`'s contract.
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static COUNTING: Counting = Counting;

const DT: f32 = 1.0 / 60.0;

/// The drop with `threads` threads and its joints solved by `joints`,
/// `frames` frames in.
fn settled(spine: SpineMode, joints: JointSolver, threads: usize, frames: usize) -> SceneWorld {
    let mut config = SceneConfig::new(Scene::RagdollDrop, spine);
    (config.threads, config.joints) = (threads, joints);
    let mut scene = build(&config).expect("the drop");
    for _ in 0..frames {
        frame(&mut scene);
    }
    scene
}

/// One frame: find the contacts, hand them over, step. Returns how many
/// contacts the step had.
fn frame(scene: &mut SceneWorld) -> usize {
    scene.detect(DT).expect("contacts");
    let contacts = scene.world.contacts().len();
    scene.world.step(DT).expect("a step");
    contacts
}

/// Allocations over `frames` frames, and the fewest contacts a step had.
fn allocations_over(scene: &mut SceneWorld, frames: usize) -> (usize, usize) {
    let before = ALLOCATIONS.load(Ordering::Relaxed);
    let fewest = (0..frames).map(|_| frame(scene)).min().unwrap_or(0);
    (ALLOCATIONS.load(Ordering::Relaxed) - before, fewest)
}

/// Settled: four seconds in, the pile lies still; its contacts (about 800)
/// change a little every frame, never beyond what the buffers grew to.
const SETTLE: usize = 240;
const FRAMES: usize = 126;

/// One test (the count is global, and a second test building its scene
/// at the same time would be counted too). On one thread: nothing. At two
/// threads the world's code allocates nothing either; rayon does, and
/// cannot be kept from it: each substep (one here) launches the world's
/// workers once (`ThreadPool::install` from outside the pool, in
/// `RayonTasks::parallel_for`), which pushes one job onto the pool's
/// injector queue (crossbeam-deque's `Injector`), and that queue allocates
/// a new block of 63 slots every 63 pushes. So the bound there is one
/// allocation per 63 steps; an engine's task system whose queue does not
/// grow would have none (the solver stages inside allocate nothing).
#[test]
fn a_settled_drop_allocates_nothing_per_frame_but_rayons_queue_blocks() {
    let solves = [JointSolver::Iterative, JointSolver::Direct];
    for (spine, joints) in [SpineMode::Rod, SpineMode::Sockets]
        .into_iter()
        .flat_map(|spine| solves.map(|joints| (spine, joints)))
    {
        let mut scene = settled(spine, joints, 1, SETTLE);
        let (allocations, fewest) = allocations_over(&mut scene, FRAMES);
        assert!(fewest > 500, "{spine:?}: the pile has its contacts");
        assert_eq!(
            allocations, 0,
            "{spine:?}, {joints:?}, 1 thread: {FRAMES} frames"
        );
        let mut scene = settled(spine, joints, 2, SETTLE);
        let (allocations, fewest) = allocations_over(&mut scene, FRAMES);
        assert!(fewest > 500, "{spine:?}: the pile has its contacts");
        assert!(
            allocations <= FRAMES.div_ceil(63),
            "{spine:?}, {joints:?}, 2 threads: {allocations} allocations in {FRAMES} frames"
        );
    }
    // The frame a game runs: `Collisions::step` (detection, step,
    // continuous collision, events, the query tree), the events read and
    // a ray cast at the pile, from the drop's start.
    let mut config = SceneConfig::new(Scene::RagdollDrop, SpineMode::Rod);
    config.joints = JointSolver::Direct;
    let mut scene = build(&config).expect("the drop");
    let game_frame = |scene: &mut SceneWorld| {
        let set = scene.collisions.as_mut().expect("the drop collides");
        set.step(&mut scene.world, DT).expect("a frame");
        let hit = set
            .cast_ray(
                &scene.world,
                glam::Vec3::new(0.0, 3.0, 0.0),
                -glam::Vec3::Y,
                10.0,
                &vertebra_collide::QueryFilter::default(),
            )
            .expect("a query");
        set.events().touching().len() + usize::from(hit.is_some())
    };
    for _ in 0..SETTLE {
        game_frame(&mut scene);
    }
    let before = ALLOCATIONS.load(Ordering::Relaxed);
    let touching = (0..FRAMES)
        .map(|_| game_frame(&mut scene))
        .min()
        .unwrap_or(0);
    let allocations = ALLOCATIONS.load(Ordering::Relaxed) - before;
    assert!(touching > 100, "the pile's pairs touch: {touching}");
    assert_eq!(allocations, 0, "Collisions::step: {FRAMES} frames");
}
