//! Build script: linker arguments for the bare-metal firmware example, and nothing else.
//!
//! For targets without an OS (`thumbv7em-none-eabihf`), this package's examples are linked with
//! cortex-m-rt's `link.x`, which includes `memory.x` from the crate root (copied to `OUT_DIR`,
//! so that the linker finds it wherever cargo runs it). Everything is passed with
//! `rustc-link-arg-examples`, which reaches this package's examples only: the library, host
//! builds, and the firmware of a crate that depends on this one (which has its own `memory.x`)
//! are untouched. A `rustc-link-search` here would leak this `memory.x` into their links.

use std::{env, fs, path::PathBuf};

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=memory.x");
    if env::var("CARGO_CFG_TARGET_OS").as_deref() != Ok("none") {
        return;
    }
    let Ok(memory) = fs::read("memory.x") else {
        // Not in this checkout (e.g. built as a dependency from a trimmed package): there is no
        // firmware example to link either.
        return;
    };
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    fs::write(out.join("memory.x"), memory).expect("OUT_DIR is writable");
    println!("cargo:rustc-link-arg-examples=-L{}", out.display());
    println!("cargo:rustc-link-arg-examples=-Tlink.x");
}
