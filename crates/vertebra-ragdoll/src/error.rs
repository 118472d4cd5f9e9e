//! Why a ragdoll file or build was refused. Every variant names the item
//! and the field, so a designer can fix the file from the message alone.

use core::fmt;

/// A refused ragdoll description or build.
#[derive(Clone, Debug, PartialEq)]
pub enum RagdollError {
    /// Not TOML, a missing or mistyped field, or an unknown one (the
    /// parser's message names the line and the field).
    Syntax(String),
    /// A body or joint name used twice.
    DuplicateName {
        /// `body` or `joint`.
        kind: &'static str,
        /// The name.
        name: String,
    },
    /// A name that refers to no body.
    UnknownBody {
        /// Where it was used, e.g. `joint `knee_l``.
        context: String,
        /// The field, e.g. `parent`.
        field: &'static str,
        /// The name.
        name: String,
    },
    /// A value that is NaN or infinite.
    NonFinite {
        /// The item, e.g. `body `hips``.
        context: String,
        /// The field.
        field: &'static str,
    },
    /// A value out of its range (negative mass, zero radius, a limit
    /// outside its interval, a total mass that does not add up, ...).
    OutOfRange {
        /// The item.
        context: String,
        /// The field.
        field: &'static str,
        /// What the range is.
        reason: String,
    },
    /// A joint axis of zero length.
    ZeroAxis {
        /// The joint's name.
        joint: String,
    },
    /// The joints do not form one tree (a body with two parents, a cycle,
    /// a body joined to itself, or several roots).
    NotATree(String),
    /// The `[spine]` is not a chain that a rod can replace.
    SpineNotChain(String),
    /// A pose that does not fit the description (wrong bone count,
    /// non-finite or non-normalised transforms).
    BadPose(String),
    /// The world refused a body or joint.
    World(vertebra_world::Error),
    /// A ragdoll that cannot be removed as it is (nothing was removed).
    NotRemovable {
        /// The item, e.g. `body `hips`` or `joint `knee_l``.
        item: String,
        /// Why, e.g. `is no longer in the world`.
        reason: &'static str,
    },
}

impl fmt::Display for RagdollError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RagdollError::Syntax(m) => write!(f, "malformed ragdoll file: {m}"),
            RagdollError::DuplicateName { kind, name } => {
                write!(f, "{kind} name `{name}` is used twice")
            }
            RagdollError::UnknownBody {
                context,
                field,
                name,
            } => {
                write!(f, "{context}: {field} `{name}` is not a body")
            }
            RagdollError::NonFinite { context, field } => {
                write!(f, "{context}: {field} is not finite")
            }
            RagdollError::OutOfRange {
                context,
                field,
                reason,
            } => write!(f, "{context}: {field} {reason}"),
            RagdollError::ZeroAxis { joint } => write!(f, "joint `{joint}`: axis has zero length"),
            RagdollError::NotATree(m) => write!(f, "the joints do not form a tree: {m}"),
            RagdollError::SpineNotChain(m) => write!(f, "[spine]: {m}"),
            RagdollError::BadPose(m) => write!(f, "bad pose: {m}"),
            RagdollError::World(e) => write!(f, "{e}"),
            RagdollError::NotRemovable { item, reason } => {
                write!(f, "the ragdoll cannot be removed: {item} {reason}")
            }
        }
    }
}

impl std::error::Error for RagdollError {}

impl From<vertebra_world::Error> for RagdollError {
    fn from(e: vertebra_world::Error) -> Self {
        RagdollError::World(e)
    }
}
