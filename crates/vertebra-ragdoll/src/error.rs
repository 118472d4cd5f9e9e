//! Why a ragdoll file or build was refused. Every variant names the item
//! and the field, so a designer can fix the file from the message alone.

use core::fmt;

/// A refused ragdoll description or build.
#[derive(Clone, Debug, PartialEq)]
pub enum RagdollError {
    /// Not TOML, a missing or mistyped field, or an unknown one (the
    /// parser's message names the line and the field).
    Syntax {
        /// What the file holds: `ragdoll`, `skeleton` or `generator`.
        file: &'static str,
        /// The parser's message.
        message: String,
    },
    /// A ragdoll or skeleton file that could not be read: missing,
    /// unreadable, not a regular file (a FIFO, a device, a directory), or
    /// not UTF-8 (one larger than `MAX_FILE_BYTES` is
    /// [`RagdollError::TooLarge`]).
    Unreadable {
        /// What the file holds: `ragdoll`, `skeleton` or `generator`.
        file: &'static str,
        /// Why.
        reason: String,
    },
    /// A ragdoll, generator or skeleton text (a file, or a string given to
    /// a `from_toml`) longer than [`MAX_FILE_BYTES`](crate::MAX_FILE_BYTES):
    /// refused before it is parsed.
    TooLarge {
        /// What the text holds: `ragdoll`, `skeleton` or `generator`.
        file: &'static str,
        /// The most bytes a text may have (bytes).
        limit: u64,
    },
    /// An error in the ragdoll or skeleton file at `path`.
    File {
        /// The file, as given.
        path: String,
        /// What is wrong with it.
        error: Box<RagdollError>,
    },
    /// A body, joint or bone name used twice.
    DuplicateName {
        /// The line of its second use (`None` for a description built in
        /// code or checked by `RagdollDesc::validate`).
        line: Option<usize>,
        /// `body`, `joint` or `bone`.
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
    /// A name that refers to no bone of the skeleton.
    UnknownBone {
        /// Where it was used, e.g. `body `hand_l``.
        context: String,
        /// The field, e.g. `bone`.
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
    /// outside its interval, two bodies on one bone, ...).
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
    /// The world refused a body or joint: which one (and which field,
    /// where the world's error does not name it), and the world's reason.
    World {
        /// The item, e.g. `body `hips``; empty for a call that was not
        /// about one item of a ragdoll.
        context: String,
        /// The world's error, which names the field.
        error: vertebra_world::Error,
    },
    /// A call on a ragdoll that [`Ragdoll::remove`](crate::Ragdoll::remove)
    /// took out of its world (or that a removal through the collision
    /// layer did): it has no bodies, joints or rod left to act on, read or
    /// remove. Build a new one.
    Removed {
        /// The ragdoll's description's name.
        ragdoll: String,
    },
    /// A ragdoll that cannot be removed as it is (nothing was removed).
    NotRemovable {
        /// The item, e.g. `body `hips`` or `joint `knee_l``.
        item: String,
        /// Why, e.g. `is no longer in the world`.
        reason: &'static str,
    },
}

impl RagdollError {
    /// The world's `error`, raised for the item `context`.
    pub(crate) fn world(context: &str, error: vertebra_world::Error) -> Self {
        RagdollError::World {
            context: context.to_owned(),
            error,
        }
    }
}

impl fmt::Display for RagdollError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RagdollError::Syntax { file, message } => write!(f, "malformed {file} file: {message}"),
            RagdollError::Unreadable { file, reason } => {
                write!(f, "cannot read the {file} file: {reason}")
            }
            RagdollError::TooLarge { file, limit } => write!(
                f,
                "the {file} text is larger than MAX_FILE_BYTES ({limit} bytes) and is refused before it is parsed; a {file} file is a few KB"
            ),
            RagdollError::File { path, error } => write!(f, "{path}: {error}"),
            RagdollError::DuplicateName { line, kind, name } => {
                if let Some(line) = line {
                    write!(f, "line {line}: ")?;
                }
                write!(f, "{kind} name `{name}` is used twice")
            }
            RagdollError::UnknownBody {
                context,
                field,
                name,
            } => {
                write!(f, "{context}: {field} `{name}` is not a body")
            }
            RagdollError::UnknownBone {
                context,
                field,
                name,
            } => {
                write!(
                    f,
                    "{context}: {field} `{name}` is not a bone of the skeleton"
                )
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
            RagdollError::World { context, error } if context.is_empty() => write!(f, "{error}"),
            RagdollError::World { context, error } => write!(f, "{context}: {error}"),
            RagdollError::Removed { ragdoll } => write!(
                f,
                "ragdoll `{ragdoll}` has been removed from the world; build it again"
            ),
            RagdollError::NotRemovable { item, reason } => {
                write!(f, "the ragdoll cannot be removed: {item} {reason}")
            }
        }
    }
}

impl std::error::Error for RagdollError {}

/// A world error from a call about no one item of a ragdoll (creating a
/// world, stepping it): the world's error alone.
impl From<vertebra_world::Error> for RagdollError {
    fn from(error: vertebra_world::Error) -> Self {
        RagdollError::world("", error)
    }
}

/// Every problem found in a description or a file, each with the line of
/// its item (`None` for one about no single line, or built in code), so
/// that a checker lists them all in file order and a loader refuses with
/// the first.
#[derive(Debug, Default)]
pub(crate) struct Problems(Vec<(Option<usize>, RagdollError)>);

impl Problems {
    /// `result`'s value, or `None` with its error kept as a problem of the
    /// item at `line`.
    pub(crate) fn note<T>(
        &mut self,
        line: Option<usize>,
        result: Result<T, RagdollError>,
    ) -> Option<T> {
        result.map_err(|e| self.0.push((line, e))).ok()
    }

    /// Whether none has been found.
    pub(crate) fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// `Ok` if no problem was found, else the problems in file order: by
    /// line (in the order found within a line), those without a line after
    /// them.
    pub(crate) fn done(mut self) -> Result<(), Vec<RagdollError>> {
        if self.0.is_empty() {
            return Ok(());
        }
        self.0.sort_by_key(|&(line, _)| line.unwrap_or(usize::MAX));
        Err(self.0.into_iter().map(|(_, e)| e).collect())
    }
}

/// The first of a refusal's problems: what the single-error loaders say.
pub(crate) fn first(problems: Vec<RagdollError>) -> RagdollError {
    problems
        .into_iter()
        .next()
        .expect("a refusal has at least one problem")
}

/// `Ok` when every one of `values` is finite, else the error naming
/// `context` and `field`.
pub(crate) fn finite(
    context: &str,
    field: &'static str,
    values: &[f32],
) -> Result<(), RagdollError> {
    if values.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(RagdollError::NonFinite {
            context: context.to_owned(),
            field,
        })
    }
}

/// `Ok` when `ok`, else the error naming `context` and `field`, with
/// `reason`.
pub(crate) fn range(
    context: &str,
    field: &'static str,
    ok: bool,
    reason: &str,
) -> Result<(), RagdollError> {
    if ok {
        Ok(())
    } else {
        Err(RagdollError::OutOfRange {
            context: context.to_owned(),
            field,
            reason: reason.to_owned(),
        })
    }
}

/// `Ok` when the world takes `spring` as `of` ([`Spring::check`]), else
/// the error naming `context` and `field`, with the world's reason (which
/// names the number and its range).
///
/// [`Spring::check`]: vertebra_world::Spring::check
pub(crate) fn check_spring(
    context: &str,
    field: &'static str,
    spring: vertebra_world::Spring,
    of: vertebra_world::SpringField,
) -> Result<(), RagdollError> {
    spring.check(of).map_err(|e| RagdollError::OutOfRange {
        context: context.to_owned(),
        field,
        reason: format!("is refused: {e}"),
    })
}
