//! Snapshots: a world's (and a collision layer's) whole state as bytes,
//! restored bit for bit in any process of the same build; and the byte
//! buffers vertebra hands out.

use vertebra_world::Snapshot;

use crate::error::VtResult;
use crate::ffi::{boxed, call, free, out, shared, slice};
use crate::world::{VtWorld, with_world};

/// Bytes vertebra made and the caller owns (opaque; read them with
/// `vt_bytes_data`, free them with `vt_bytes_destroy`).
pub struct VtBytes {
    pub(crate) bytes: Vec<u8>,
}

/// Writes the address and length of `bytes`' data into `data` and
/// `length`; the data stays valid until `vt_bytes_destroy`.
///
/// # Safety
/// `bytes` is live; `data` and `length` are writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_bytes_data(
    bytes: *const VtBytes,
    data: *mut *const u8,
    length: *mut usize,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let (bytes, data, length) = unsafe {
            (
                shared(bytes, "bytes")?,
                out(data, "data")?,
                out(length, "length")?,
            )
        };
        data.set(bytes.bytes.as_ptr());
        length.set(bytes.bytes.len());
        Ok(())
    })
}

/// Frees bytes vertebra made (null does nothing).
///
/// # Safety
/// `bytes` is null or live, and not used afterwards.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_bytes_destroy(bytes: *mut VtBytes) {
    // SAFETY: the function's contract.
    unsafe { free(bytes) }
}

/// Writes a snapshot of the world (bodies, joints, rods, contacts, sleep
/// and solver state) into `snapshot`, owned by the caller
/// (`vt_bytes_destroy`).
///
/// # Safety
/// `world` is a live world; `snapshot` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_world_snapshot(
    world: *mut VtWorld,
    snapshot: *mut *mut VtBytes,
) -> VtResult {
    // SAFETY: the function's contract.
    let snapshot = unsafe { out(snapshot, "snapshot") };
    // SAFETY: the function's contract.
    unsafe {
        with_world(world, |w| {
            let bytes = w.snapshot().as_bytes().to_vec();
            snapshot?.set(boxed(VtBytes { bytes }));
            Ok(())
        })
    }
}

/// Restores the world from `length` bytes of a snapshot (copied; the
/// caller keeps them). Refused, with the world unchanged, for bytes of
/// another build or any state the API could not have produced. The world
/// takes the snapshot's handles: those of the world that took it work. A
/// collision layer serving the world refuses it from then on
/// (`VT_RESULT_WORLD_MISMATCH`) until the layer's snapshot taken with this
/// one is restored after it (`vt_collisions_restore`).
///
/// # Safety
/// `world` is a live world; `data` points to `length` readable bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_world_restore(
    world: *mut VtWorld,
    data: *const u8,
    length: usize,
) -> VtResult {
    // SAFETY: the function's contract.
    let data = unsafe { slice(data, length, "data") };
    // SAFETY: the function's contract.
    unsafe {
        with_world(world, |w| {
            Ok(w.restore(&Snapshot::from_bytes(data?.to_vec()))?)
        })
    }
}
