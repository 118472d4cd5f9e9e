//! The boundary: the only place raw pointers become references, and the
//! catch that keeps a panic from crossing into C.
//!
//! Every exported function runs its body in [`call`]. An object a call
//! works on is [`enter`]ed: poisoned while the call runs and cleared when
//! it returns, so a panic (a bug; never a caller's input) leaves it
//! poisoned and every later call on it refused with
//! [`VtResult::Poisoned`], not run on a half-updated state.

use std::ffi::{CStr, c_char};
use std::ops::{Deref, DerefMut};
use std::panic::{AssertUnwindSafe, catch_unwind};

use crate::error::{Failure, VtResult, remember};

/// Runs a function's body: its result, or its refusal's code with the
/// message kept for `vt_last_error_message`; a panic becomes
/// [`VtResult::Panic`].
pub(crate) fn call(body: impl FnOnce() -> Result<(), Failure>) -> VtResult {
    let failure = match catch_unwind(AssertUnwindSafe(body)) {
        Ok(Ok(())) => return VtResult::Ok,
        Ok(Err(failure)) => failure,
        Err(payload) => {
            let what = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_default();
            Failure::new(VtResult::Panic, format!("vertebra panicked: {what}"))
        }
    };
    remember(&failure.message);
    failure.code
}

/// An object C holds by pointer that a panic can poison.
pub(crate) trait Object {
    /// Its name in messages, e.g. `world`.
    const NAME: &'static str;
    /// Its poison flag.
    fn poisoned(&mut self) -> &mut bool;
}

/// An object lent to one call: poisoned until the call returns normally.
pub(crate) struct Entered<'a, T: Object>(&'a mut T);

impl<T: Object> Deref for Entered<'_, T> {
    type Target = T;
    fn deref(&self) -> &T {
        self.0
    }
}

impl<T: Object> DerefMut for Entered<'_, T> {
    fn deref_mut(&mut self) -> &mut T {
        self.0
    }
}

impl<T: Object> Drop for Entered<'_, T> {
    fn drop(&mut self) {
        if !std::thread::panicking() {
            *self.0.poisoned() = false;
        }
    }
}

/// Refuses a null or misaligned pointer, naming `what`.
fn check<T>(ptr: *const T, what: &str) -> Result<(), Failure> {
    if ptr.is_null() {
        return Err(Failure::new(
            VtResult::NullPointer,
            format!("{what} is null"),
        ));
    }
    if !ptr.is_aligned() {
        return Err(Failure::new(
            VtResult::NullPointer,
            format!("{what} is not aligned for its type"),
        ));
    }
    Ok(())
}

/// The object at `ptr`, lent to this call and poisoned while it runs.
///
/// # Safety
/// `ptr` is null or points to a live object of this type made by its
/// create function and not destroyed, used by no other call at once.
pub(crate) unsafe fn enter<'a, T: Object>(ptr: *mut T) -> Result<Entered<'a, T>, Failure> {
    check(ptr, T::NAME)?;
    // SAFETY: checked non-null and aligned; live and unshared by the
    // caller's contract.
    let object = unsafe { &mut *ptr };
    if *object.poisoned() {
        return Err(Failure::new(
            VtResult::Poisoned,
            format!(
                "the {} was poisoned by an earlier panic, or is inside a call still running (a callback calling back into it)",
                T::NAME
            ),
        ));
    }
    *object.poisoned() = true;
    Ok(Entered(object))
}

/// A read-only object (a description, skeleton or mapper).
///
/// # Safety
/// `ptr` is null or points to a live object of this type made by its
/// create function and not destroyed.
pub(crate) unsafe fn shared<'a, T>(ptr: *const T, what: &str) -> Result<&'a T, Failure> {
    check(ptr, what)?;
    // SAFETY: checked non-null and aligned; live by the caller's contract.
    Ok(unsafe { &*ptr })
}

/// A copy of the input struct at `ptr`.
///
/// # Safety
/// `ptr` is null or points to a readable, initialised `T`.
pub(crate) unsafe fn read<T: Copy>(ptr: *const T, what: &str) -> Result<T, Failure> {
    check(ptr, what)?;
    // SAFETY: checked non-null and aligned; readable by the contract. Every
    // input struct is plain numbers, so any bits are a valid `T`.
    Ok(unsafe { ptr.read() })
}

/// An output place, checked before the call computes anything, written
/// only when it succeeds.
pub(crate) struct Out<T>(*mut T);

impl<T> Out<T> {
    /// Writes the result.
    pub(crate) fn set(self, value: T) {
        // SAFETY: checked non-null and aligned in `out`; writable by the
        // caller's contract.
        unsafe { self.0.write(value) }
    }

    /// Writes the result, as a call's last step.
    pub(crate) fn done(self, value: T) -> Result<(), Failure> {
        self.set(value);
        Ok(())
    }
}

/// The output place `ptr`.
///
/// # Safety
/// `ptr` is null or points to writable memory for a `T`.
pub(crate) unsafe fn out<T>(ptr: *mut T, what: &str) -> Result<Out<T>, Failure> {
    check(ptr, what)?;
    Ok(Out(ptr))
}

/// The output place `ptr`, or none for null (an output the caller does
/// not want).
///
/// # Safety
/// `ptr` is null or points to writable memory for a `T`.
pub(crate) unsafe fn optional<T>(ptr: *mut T, what: &str) -> Result<Option<Out<T>>, Failure> {
    match ptr.is_null() {
        true => Ok(None),
        // SAFETY: the function's contract.
        false => unsafe { out(ptr, what) }.map(Some),
    }
}

/// Refuses a count of `T`s no array can hold (more than `isize::MAX`
/// bytes, as a slice may span at most): a caller's mistake (a negative
/// count cast to `size_t`, a garbage length) that must not reach
/// `from_raw_parts`, where it is undefined behaviour.
fn check_len<T>(len: usize, what: &str) -> Result<(), Failure> {
    let bytes = len.checked_mul(size_of::<T>());
    match bytes.is_some_and(|b| b <= isize::MAX as usize) {
        true => Ok(()),
        false => Err(Failure::new(
            VtResult::OutOfRange,
            format!("{what} has a count of {len}; no array holds that many"),
        )),
    }
}

/// `len` items at `ptr` (any pointer when `len` is 0).
///
/// # Safety
/// `ptr` points to `len` readable, initialised items (or `len` is 0).
pub(crate) unsafe fn slice<'a, T>(
    ptr: *const T,
    len: usize,
    what: &str,
) -> Result<&'a [T], Failure> {
    if len == 0 {
        return Ok(&[]);
    }
    check(ptr, what)?;
    check_len::<T>(len, what)?;
    // SAFETY: checked non-null and aligned; `len` readable items by the
    // contract. Every item type is plain numbers.
    Ok(unsafe { std::slice::from_raw_parts(ptr, len) })
}

/// `len` writable items at `ptr` (any pointer when `len` is 0).
///
/// # Safety
/// `ptr` points to `len` writable items (or `len` is 0), which no other
/// argument of the call points into.
pub(crate) unsafe fn slice_mut<'a, T>(
    ptr: *mut T,
    len: usize,
    what: &str,
) -> Result<&'a mut [T], Failure> {
    if len == 0 {
        return Ok(&mut []);
    }
    check(ptr, what)?;
    check_len::<T>(len, what)?;
    // SAFETY: checked non-null and aligned; `len` writable items, not
    // aliased, by the contract. Every item type is plain numbers.
    Ok(unsafe { std::slice::from_raw_parts_mut(ptr, len) })
}

/// The NUL-terminated UTF-8 string at `ptr`.
///
/// # Safety
/// `ptr` is null or points to a NUL-terminated string.
pub(crate) unsafe fn text<'a>(ptr: *const c_char, what: &str) -> Result<&'a str, Failure> {
    check(ptr, what)?;
    // SAFETY: checked non-null; NUL-terminated by the contract.
    let text = unsafe { CStr::from_ptr(ptr) };
    text.to_str()
        .map_err(|e| Failure::new(VtResult::NotUtf8, format!("{what} is not UTF-8: {e}")))
}

/// The NUL-terminated UTF-8 string at `ptr` of at most `max` bytes: a
/// longer one is refused with `too_long()` having read no more than its
/// first `max + 1` bytes (neither measured to its end nor checked as
/// UTF-8), for the strings whose length bounds the work done on them (a
/// ragdoll or skeleton text, `MAX_FILE_BYTES` as a file).
///
/// # Safety
/// `ptr` is null or points to a NUL-terminated string.
pub(crate) unsafe fn bounded_text<'a>(
    ptr: *const c_char,
    what: &str,
    max: usize,
    too_long: impl FnOnce() -> Failure,
) -> Result<&'a str, Failure> {
    check(ptr, what)?;
    let mut len = 0;
    // SAFETY: NUL-terminated by the contract, so every byte up to the NUL
    // is readable, and the scan stops at the NUL (or at byte `max`).
    while unsafe { *ptr.add(len) } != 0 {
        if len == max {
            return Err(too_long());
        }
        len += 1;
    }
    // SAFETY: the `len` bytes before the NUL were just read.
    let bytes = unsafe { std::slice::from_raw_parts(ptr.cast::<u8>(), len) };
    std::str::from_utf8(bytes)
        .map_err(|e| Failure::new(VtResult::NotUtf8, format!("{what} is not UTF-8: {e}")))
}

/// Writes into `index` where `find` finds the name at `name` (a
/// NUL-terminated UTF-8 string); `find` says why it does not.
///
/// # Safety
/// `name` is null or a NUL-terminated string; `index` is null or writable.
pub(crate) unsafe fn index_of(
    name: *const c_char,
    index: *mut usize,
    find: impl FnOnce(&str) -> Result<usize, Failure>,
) -> Result<(), Failure> {
    // SAFETY: the function's contract.
    let (name, index) = unsafe { (text(name, "name")?, out(index, "index")?) };
    index.done(find(name)?)
}

/// Writes `text` with its NUL into `buffer` of `capacity` bytes and its
/// length with the NUL into `length`; refused (`BufferTooSmall`, nothing
/// but `length` written) when it does not fit. `buffer` may be null when
/// `capacity` is 0, to ask the length.
///
/// # Safety
/// `buffer` points to `capacity` writable bytes; `length` is writable.
pub(crate) unsafe fn copy_text(
    text: &str,
    buffer: *mut c_char,
    capacity: usize,
    length: *mut usize,
) -> Result<(), Failure> {
    // SAFETY: the caller's contract.
    let length = unsafe { out(length, "length") }?;
    let needed = text.len() + 1;
    if capacity < needed {
        length.set(needed);
        return Err(Failure::new(
            VtResult::BufferTooSmall,
            format!("the buffer holds {capacity} bytes; the text needs {needed}"),
        ));
    }
    // SAFETY: the caller's contract: `capacity` >= `needed` writable bytes.
    let bytes = unsafe { slice_mut(buffer.cast::<u8>(), needed, "buffer") }?;
    bytes[..text.len()].copy_from_slice(text.as_bytes());
    bytes[text.len()] = 0;
    length.done(needed)
}

/// Copies `items` into the caller's array `place` (room for `capacity`)
/// and writes their number into `count`; refused (`BufferTooSmall`, only
/// `count` written) when they do not fit. A null `place` with `capacity`
/// 0 asks the number.
///
/// # Safety
/// `place` points to `capacity` writable items; `count` is writable.
pub(crate) unsafe fn copy_out<T>(
    items: impl ExactSizeIterator<Item = T>,
    place: *mut T,
    capacity: usize,
    count: *mut usize,
    what: &str,
) -> Result<(), Failure> {
    // SAFETY: the caller's contract.
    let count = unsafe { out(count, "count") }?;
    let needed = items.len();
    if capacity < needed {
        count.set(needed);
        return Err(Failure::new(
            VtResult::BufferTooSmall,
            format!("{what} holds {capacity}; there are {needed}"),
        ));
    }
    // SAFETY: the caller's contract: `capacity` >= `needed` writable items.
    let place = unsafe { slice_mut(place, needed, what) }?;
    for (to, from) in place.iter_mut().zip(items) {
        *to = from;
    }
    count.done(needed)
}

/// A new object for C to own (freed by its destroy function).
pub(crate) fn boxed<T>(value: T) -> *mut T {
    Box::into_raw(Box::new(value))
}

/// Frees an object made by [`boxed`]; null does nothing.
///
/// # Safety
/// `ptr` is null or came from [`boxed`] for this type and was not freed.
pub(crate) unsafe fn free<T>(ptr: *mut T) {
    if !ptr.is_null() {
        // SAFETY: made by `boxed` (Box::into_raw) and not yet freed, by
        // the contract.
        drop(unsafe { Box::from_raw(ptr) });
    }
}
