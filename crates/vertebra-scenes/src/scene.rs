//! The scenes: their names on the command line and their frame counts.

use core::fmt;
use core::str::FromStr;

/// A scene of the paper.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Scene {
    /// Figures 2 and 8 (left): the hips fixed, the upper body slumps.
    PassiveBending,
    /// Figures 1 and 8 (right): 30 ragdolls dropped into a pit.
    RagdollDrop,
    /// Figure 7: the hips fixed, every joint driven to the bind pose, the
    /// chest pushed.
    Controllability,
}

impl Scene {
    /// Every simulated scene.
    pub const ALL: [Scene; 3] = [
        Scene::PassiveBending,
        Scene::RagdollDrop,
        Scene::Controllability,
    ];

    /// The name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Scene::PassiveBending => "passive-bending",
            Scene::RagdollDrop => "ragdoll-drop",
            Scene::Controllability => "controllability",
        }
    }

    /// Frames the paper's figure runs.
    pub fn default_frames(self) -> usize {
        match self {
            Scene::PassiveBending => 300,
            Scene::RagdollDrop => 600,
            Scene::Controllability => 240,
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
            format!("unknown scene `{s}` (expected passive-bending, ragdoll-drop or controllability)")
        })
    }
}
