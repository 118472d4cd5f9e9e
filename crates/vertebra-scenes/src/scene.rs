//! The scenes: their names on the command line and their frame counts.

use core::fmt;
use core::str::FromStr;

use vertebra_ragdoll::SpineMode;

/// A scene: the paper's three, three on the anatomical humanoid, and a
/// chain with a large mass ratio.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Scene {
    /// Figures 2 and 8 (left): the hips fixed, the upper body slumps.
    PassiveBending,
    /// Figures 1 and 8 (right): 30 ragdolls dropped into a pit.
    RagdollDrop,
    /// Figure 7: the hips fixed, every joint driven to the bind pose, the
    /// chest pushed.
    Controllability,
    /// The anatomical humanoid, hips held, every joint driven to the bind
    /// pose by a spring, hit on the chest and then on the head
    /// ([`crate::HIT_FRAMES`]).
    HitReaction,
    /// The ragdoll drop with the anatomical humanoid.
    AnatomicalDrop,
    /// A chain of 1 kg links hanging from a fixed anchor with a 1000 kg
    /// body at its end ([`crate::heavy_chain`]): a 1:1000 mass ratio
    /// across a joint. No spine: built with sockets only (a rod spine is
    /// refused, naming the chain's description).
    HeavyChain,
    /// The anatomical humanoid standing on flat ground with nothing
    /// kinematic, following a standing and then a walking animation with
    /// capped drives ([`crate::stagger_profile`]), hit on the chest
    /// ([`crate::STAGGER_HIT`]; the sweep of hits: [`crate::StaggerSweep`]).
    Stagger,
}

impl Scene {
    /// The paper's scenes (what `vertebra reproduce` runs).
    pub const PAPER: [Scene; 3] = [
        Scene::PassiveBending,
        Scene::RagdollDrop,
        Scene::Controllability,
    ];

    /// Every simulated scene.
    pub const ALL: [Scene; 7] = [
        Scene::PassiveBending,
        Scene::RagdollDrop,
        Scene::Controllability,
        Scene::HitReaction,
        Scene::AnatomicalDrop,
        Scene::HeavyChain,
        Scene::Stagger,
    ];

    /// The name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Scene::PassiveBending => "passive-bending",
            Scene::RagdollDrop => "ragdoll-drop",
            Scene::Controllability => "controllability",
            Scene::HitReaction => "hit-reaction",
            Scene::AnatomicalDrop => "anatomical-drop",
            Scene::HeavyChain => "heavy-chain",
            Scene::Stagger => "stagger",
        }
    }

    /// Whether the scene is one of the paper's, on the reference humanoid
    /// (the others are on the anatomical one).
    pub fn is_paper(self) -> bool {
        Scene::PAPER.contains(&self)
    }

    /// The spines its ragdolls are built with: both, but only sockets for
    /// the heavy chain, whose description has no `[spine]` for a rod to
    /// replace (`SpineMode::Rod` is refused for it).
    pub fn spines(self) -> &'static [SpineMode] {
        match self {
            Scene::HeavyChain => &[SpineMode::Sockets],
            _ => &[SpineMode::Sockets, SpineMode::Rod],
        }
    }

    /// Frames the paper's figure runs (the new scenes: 4 s, 10 s, 5 s and
    /// 8 s).
    pub fn default_frames(self) -> usize {
        match self {
            Scene::PassiveBending => 300,
            Scene::RagdollDrop => 600,
            Scene::Controllability => 240,
            Scene::HitReaction => 240,
            Scene::AnatomicalDrop => 600,
            Scene::HeavyChain => 300,
            Scene::Stagger => 480,
        }
    }
}

impl fmt::Display for Scene {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Scene {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Scene::ALL.into_iter().find(|x| x.name() == s).ok_or_else(|| {
            format!("unknown scene `{s}` (expected passive-bending, ragdoll-drop, controllability, hit-reaction, anatomical-drop, heavy-chain or stagger)")
        })
    }
}
