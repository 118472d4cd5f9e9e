//! Position-level constraint parts, shared by every joint (after Jolt's
//! `ConstraintPart`s, but at the position level of XPBD).
//!
//! Each part measures its error from the current poses and applies one
//! XPBD correction (Macklin et al. 2016; Müller et al. 2020):
//! `dlambda = (-C - alpha~ lambda) / (w_a + w_b + alpha~)`, with
//! `alpha~ = compliance / h^2` for a substep of `h` seconds, and the
//! generalised inverse masses `w` of `crate::body`. Hard parts have
//! `alpha~ = 0` and need no `lambda`. Every part is branch-free: an
//! inactive limit has `C = 0`, and a zero correction moves nothing.
//!
//! The socket uses `point`, `swing`, `twist` and `drive`; the rod its own
//! `rod` parts (curve, length, bend, twist), built on `angle`.

pub mod angle;
pub mod drive;
pub mod point;
pub mod rod;
pub mod swing;
pub mod twist;
