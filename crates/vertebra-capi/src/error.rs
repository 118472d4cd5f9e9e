//! What every function returns, and the message beside it.
//!
//! A call returns [`VtResult::Ok`] or the code of its refusal; the refusal's
//! message (which names the item and the field, as the Rust API's errors
//! do) is kept per thread until that thread's next refusal and read with
//! `vt_last_error_message`. A refused call leaves every object as it was.

use std::cell::RefCell;
use std::ffi::{CString, c_char};

use vertebra_ragdoll::RagdollError;
use vertebra_world::Error;

/// The result of a call: 0 on success, the reason otherwise.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VtResult {
    /// Done.
    Ok = 0,
    /// A pointer that must not be null was null.
    NullPointer = 1,
    /// An enum field or argument outside its values.
    InvalidEnum = 2,
    /// A string that is not UTF-8.
    NotUtf8 = 3,
    /// An output array shorter than the result: its needed length was
    /// written where the call says, nothing else.
    BufferTooSmall = 4,
    /// A value that must be finite was NaN or infinite.
    NonFinite = 5,
    /// A quaternion or direction that must have unit length did not.
    NotNormalized = 6,
    /// A mass, density or dimension that must be positive was not.
    NonPositive = 7,
    /// An inertia tensor that is not symmetric positive definite.
    InvalidInertia = 8,
    /// A shape with no volume.
    DegenerateShape = 9,
    /// A joint or rod between a body and itself.
    SameBody = 10,
    /// A handle whose item was removed, or that never existed; a ragdoll
    /// removed from its world (`vt_ragdoll_remove`), by every call but its
    /// destroy.
    StaleHandle = 11,
    /// A handle issued by another world.
    ForeignHandle = 12,
    /// A body that joints or rods still use.
    BodyInUse = 13,
    /// A joint between two bodies neither of which is dynamic.
    NoDynamicBody = 14,
    /// A call only a dynamic body takes (an impulse).
    NotDynamic = 15,
    /// A call the body's kind does not take.
    WrongKind = 16,
    /// A limit range whose lower end is above its upper end, or outside
    /// its angle range.
    InvalidLimit = 17,
    /// A solver setting out of its range.
    InvalidConfig = 18,
    /// A joint or rod setting it does not take (a drive on a fixed joint,
    /// other bodies for a rod).
    InvalidJoint = 19,
    /// A finite value beyond what the solver works with.
    OutOfRange = 20,
    /// A snapshot of another build or format.
    IncompatibleSnapshot = 21,
    /// A snapshot whose bytes are damaged or describe an impossible state.
    CorruptSnapshot = 22,
    /// A collider refused, or whose body is gone.
    Collider = 23,
    /// A ragdoll, skeleton or mapping refused: its file and line, the body,
    /// joint or bone, and the field are in the message.
    Ragdoll = 24,
    /// A bug in vertebra: a panic, caught at the boundary. The object the
    /// call was working on is poisoned; destroy it.
    Panic = 25,
    /// An object a panic left poisoned: every call on it but its destroy
    /// is refused.
    Poisoned = 26,
    /// A collision layer used with, or restored for, a world it does not
    /// serve: the world restored a snapshot without the layer's snapshot
    /// taken with it, it is another world, or the layer's snapshot was
    /// taken with another state of the world (other bodies).
    WorldMismatch = 27,
}

/// A refusal: its code and message.
#[derive(Debug)]
pub struct Failure {
    /// The code the call returns.
    pub code: VtResult,
    /// The message `vt_last_error_message` gives.
    pub message: String,
}

impl Failure {
    /// A refusal with this code and message.
    pub fn new(code: VtResult, message: impl Into<String>) -> Self {
        Self {
            code,
            message: message.into(),
        }
    }
}

/// The code of one of the world's errors (a refused contact's is its
/// reason's: the message names the contact).
fn code(error: &Error) -> VtResult {
    match error {
        Error::NonFinite(_) => VtResult::NonFinite,
        Error::NotNormalized(_) => VtResult::NotNormalized,
        Error::NonPositive(_) => VtResult::NonPositive,
        Error::InvalidInertia => VtResult::InvalidInertia,
        Error::DegenerateShape(_) => VtResult::DegenerateShape,
        Error::SameBody => VtResult::SameBody,
        Error::StaleHandle(_) => VtResult::StaleHandle,
        Error::ForeignHandle(_) => VtResult::ForeignHandle,
        Error::BodyInUse => VtResult::BodyInUse,
        Error::NoDynamicBody => VtResult::NoDynamicBody,
        Error::NotDynamic(_) => VtResult::NotDynamic,
        Error::WrongKind(_) => VtResult::WrongKind,
        Error::InvalidLimit(_) => VtResult::InvalidLimit,
        Error::InvalidConfig(_) => VtResult::InvalidConfig,
        Error::InvalidJoint(_) => VtResult::InvalidJoint,
        Error::OutOfRange(_) => VtResult::OutOfRange,
        Error::IncompatibleSnapshot(_) => VtResult::IncompatibleSnapshot,
        Error::CorruptSnapshot(_) => VtResult::CorruptSnapshot,
        Error::Collider { .. } => VtResult::Collider,
        Error::Contact { reason, .. } => code(reason),
        Error::WorldMismatch(_) => VtResult::WorldMismatch,
    }
}

impl From<Error> for Failure {
    fn from(error: Error) -> Self {
        Self::new(code(&error), error.to_string())
    }
}

impl From<RagdollError> for Failure {
    /// A ragdoll error that wraps one of the world's keeps the world's
    /// code (a stale handle stays a stale handle); a removed ragdoll is a
    /// stale handle too; the rest are [`VtResult::Ragdoll`].
    fn from(error: RagdollError) -> Self {
        let code = match &error {
            RagdollError::World { error, .. } => code(error),
            RagdollError::Removed { .. } => VtResult::StaleHandle,
            _ => VtResult::Ragdoll,
        };
        Self::new(code, error.to_string())
    }
}

thread_local! {
    static LAST: RefCell<CString> = RefCell::new(CString::default());
}

/// Keeps `message` as this thread's last refusal (a NUL inside becomes
/// `?`, so the message reads whole in C).
pub(crate) fn remember(message: &str) {
    let text = CString::new(message.replace('\0', "?")).unwrap_or_default();
    LAST.with(|last| *last.borrow_mut() = text);
}

/// The message of this thread's last refused call ("" if none): which
/// item, which field, and why.
///
/// The string belongs to vertebra; it stays valid on this thread until its
/// next refused call. Copy it to keep it.
#[unsafe(no_mangle)]
pub extern "C" fn vt_last_error_message() -> *const c_char {
    LAST.with(|last| last.borrow().as_ptr())
}

/// The name of a result code, e.g. `"VT_RESULT_STALE_HANDLE"` (static
/// string; "VT_RESULT_UNKNOWN" for a value that is not a code).
#[unsafe(no_mangle)]
pub extern "C" fn vt_result_name(result: u32) -> *const c_char {
    let name: &'static core::ffi::CStr = match result {
        0 => c"VT_RESULT_OK",
        1 => c"VT_RESULT_NULL_POINTER",
        2 => c"VT_RESULT_INVALID_ENUM",
        3 => c"VT_RESULT_NOT_UTF8",
        4 => c"VT_RESULT_BUFFER_TOO_SMALL",
        5 => c"VT_RESULT_NON_FINITE",
        6 => c"VT_RESULT_NOT_NORMALIZED",
        7 => c"VT_RESULT_NON_POSITIVE",
        8 => c"VT_RESULT_INVALID_INERTIA",
        9 => c"VT_RESULT_DEGENERATE_SHAPE",
        10 => c"VT_RESULT_SAME_BODY",
        11 => c"VT_RESULT_STALE_HANDLE",
        12 => c"VT_RESULT_FOREIGN_HANDLE",
        13 => c"VT_RESULT_BODY_IN_USE",
        14 => c"VT_RESULT_NO_DYNAMIC_BODY",
        15 => c"VT_RESULT_NOT_DYNAMIC",
        16 => c"VT_RESULT_WRONG_KIND",
        17 => c"VT_RESULT_INVALID_LIMIT",
        18 => c"VT_RESULT_INVALID_CONFIG",
        19 => c"VT_RESULT_INVALID_JOINT",
        20 => c"VT_RESULT_OUT_OF_RANGE",
        21 => c"VT_RESULT_INCOMPATIBLE_SNAPSHOT",
        22 => c"VT_RESULT_CORRUPT_SNAPSHOT",
        23 => c"VT_RESULT_COLLIDER",
        24 => c"VT_RESULT_RAGDOLL",
        25 => c"VT_RESULT_PANIC",
        26 => c"VT_RESULT_POISONED",
        27 => c"VT_RESULT_WORLD_MISMATCH",
        _ => c"VT_RESULT_UNKNOWN",
    };
    name.as_ptr()
}
