//! Which trees' contacts are pins this step ([`PinContacts`]).

use crate::body_drive::BodyDrives;
use crate::config::{JointSolver, PinContacts, SolverConfig};
use crate::joint::JointDesc;
use crate::trees::Trees;

/// Marks in `takes` (by tree, as `trees.members`) the trees whose
/// contacts are pins under `config`: every tree, none, or (`Driven`) each
/// tree with a body of a joint's angular drive (both trees of a driven
/// joint that closes a loop between two) or a body's world-space or
/// upright drive. Returns whether the step pins at all; when it does,
/// `ContactLayout::pin` also clears every pin of the step before, so a
/// tree that stops being driven leaves its pins at once.
pub(crate) fn choose(
    config: &SolverConfig,
    trees: &Trees,
    joints: &[Option<JointDesc>],
    body_drives: &[BodyDrives],
    takes: &mut Vec<bool>,
) -> bool {
    let every = match (config.joints, config.pin_contacts) {
        (JointSolver::Iterative, _) | (_, PinContacts::Never) => return false,
        (JointSolver::Direct, PinContacts::Always) => true,
        (JointSolver::Direct, PinContacts::Driven) => false,
    };
    takes.clear();
    takes.resize(trees.members.len(), every);
    if every {
        return true;
    }
    let tree = |slot: usize| trees.bodies.get(slot).copied().flatten().map(|p| p.tree);
    let driven_joints = (joints.iter().flatten())
        .filter(|joint| joint.drive.is_some())
        .flat_map(|joint| [tree(joint.body_a.index()), tree(joint.body_b.index())])
        .flatten();
    let driven_bodies = (body_drives.iter().enumerate())
        .filter(|(_, drives)| drives.any())
        .filter_map(|(slot, _)| tree(slot));
    for t in driven_joints.chain(driven_bodies) {
        takes[t] = true;
    }
    true
}
