//! Workspace-wide invariants live in `tidy.rs`; this library is empty.
