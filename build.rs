//! Build script: linker arguments for the bare-metal firmware example, and nothing else.
//!
//! For targets without an OS (`thumbv7em-none-eabihf`), the examples are linked with
//! cortex-m-rt's `link.x`, which includes `memory.x` from the crate root (copied to `OUT_DIR`
//! so that the linker finds it wherever cargo runs it). Host builds and the library itself are
//! untouched: `rustc-link-arg-examples` applies to examples only.

use std::{env, fs, path::PathBuf};

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=memory.x");
    if env::var("CARGO_CFG_TARGET_OS").as_deref() != Ok("none") {
        return;
    }
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    fs::copy("memory.x", out.join("memory.x")).expect("memory.x at the crate root");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rustc-link-arg-examples=-Tlink.x");
}
