//! The C API of shape-from-symmetry: the only crate of the workspace with `unsafe` code.
//!
//! The header `include/shape_from_symmetry.h` is generated from this file by cbindgen
//! (`cbindgen.toml`; `ci/c_api.sh` fails when the committed header is stale), so the doc comments
//! below are also the C documentation. `capi/README.md` shows a poll loop.
//!
//! # Design
//!
//! - **Storage.** The caller provides the engine's memory: [`sfs_engine_size`] bytes aligned to
//!   [`sfs_engine_align`] (both at most [`SFS_ENGINE_STORAGE_BYTES`] and
//!   [`SFS_ENGINE_STORAGE_ALIGN`], compile-time constants for a `static` buffer). [`sfs_init`]
//!   checks pointer, size and alignment and copies a fresh `DefaultEngine` there behind a
//!   magic number (from a constant image in flash: no stack, no allocation), and hands out the
//!   same address as the opaque `SfsEngine *` handle. Every
//!   other call checks the handle (null, alignment, magic) before it touches the engine, so a
//!   handle to storage that was never initialised is an error, not undefined behaviour — as
//!   long as the storage's bytes are defined (static storage is zeroed; see [`sfs_init`]).
//! - **Lifetime contract.** [`sfs_set_input`] copies the [`SfsScene`] description (the struct
//!   itself may be reused at once) but *borrows* the buffers it points to: depth, mask and output
//!   must stay valid, and depth and mask unchanged, until the next `sfs_set_input` or `sfs_init`
//!   on the same storage (or until the storage is no longer used). This is the one promise Rust
//!   cannot check; it is where the engine's `'static` borrows of depth and mask come from (see
//!   the `SAFETY` comments in `sfs_set_input`). The output is not borrowed across calls: the
//!   handle keeps a raw pointer, and each `sfs_poll` makes the only reference to the buffer
//!   for that call alone (`Engine::poll_into`), so C may read it between polls.
//! - **Points.** The completed points are written into the caller's output buffer as the search
//!   completes; [`sfs_points_written`] tells how many are valid. No copy and no second buffer
//!   (20 bytes a point), and the buffer is the caller's own
//!   `SfsPoint` array, read directly. The caller reads it between calls and never writes it
//!   while a search owns it.
//! - **Misuse** is reported with a status code: null pointers, misaligned pointers, storage too
//!   small, an uninitialised handle, buffers that overlap each other or the engine, lengths that
//!   do not match `width * height` or that overflow, polling before input, an unknown symmetry
//!   index. Results may be read at any time: before the search ends they hold the best result so
//!   far.
//! - **Panics.** The library is written not to panic (every input error is a status), but a bug
//!   could. A panic must never unwind into C: on the host the staticlib links `std`, and a panic
//!   that reaches an `extern "C"` function aborts the process. On bare-metal targets the feature
//!   `panic-handler` adds the `#[panic_handler]` a C firmware cannot write: it calls the C
//!   hook `sfs_panic_hook(file, file_len, line)` (a weak default on ARM does nothing; the
//!   firmware overrides it to log, reset or stop the actuators) and then spins forever, for the
//!   watchdog. It is a separate feature because a Rust firmware has its own panic handler.
//! - **Threads.** An engine is not reentrant: one caller at a time per handle (a control loop and
//!   an interrupt must not both use it). Different handles are independent.
//!
//! Input structures read from C contain only integers, floats and pointers (no `bool`, no
//! enum), so that every bit pattern C can write is a valid value; flags are "non-zero = yes".

#![no_std]
#![warn(missing_docs)]

// A staticlib for a hosted target needs a panic handler and unwinding support: linking `std`
// provides both (and a panic that reaches an `extern "C"` function aborts the process).
// Bare-metal builds never link it (see `panic`).
#[cfg(not(target_os = "none"))]
extern crate std;

mod calls;
mod checks;
#[cfg(all(feature = "panic-handler", target_os = "none"))]
mod panic;
mod status;
#[cfg(test)]
mod tests;
mod types;

pub use calls::*;
pub use status::*;
pub use types::*;
