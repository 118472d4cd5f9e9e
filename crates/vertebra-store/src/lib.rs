//! Rigid bodies for vertebra: shapes and their mass properties, stable
//! generational handles, the structure-of-arrays body store, and the errors
//! that bad input gets instead of a panic.
//!
//! Units: metres, kilograms, seconds, radians. Positions are of the centre
//! of mass, in the world frame; inertia is about the centre of mass, in the
//! body frame.

mod error;
mod handle;
mod shape;
mod slots;
mod store;

pub use error::{
    Error, MAX_COORDINATE, MAX_TIME_STEP, MIN_TIME_STEP, check_coordinate, check_finite,
    check_point, check_positive, check_unit_quat, check_unit_vec,
};
pub use handle::{BodyHandle, BodyTag, Handle, serialize_physical_only};
pub use shape::{MASS_RANGE, MassProperties, SIZE_RANGE, Shape};
pub use slots::{MAX_GENERATION, Slots};
pub use store::{BodyDesc, BodyKind, BodyState, BodyStore};
