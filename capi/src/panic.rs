//! The `#[panic_handler]` for C firmware (feature `panic-handler`, bare-metal targets only): it
//! calls the C hook [`sfs_panic_hook`](crate::sfs_panic_hook), then spins for the watchdog.

use crate::sfs_panic_hook;

#[panic_handler]
fn panic(info: &core::panic::PanicInfo<'_>) -> ! {
    let (file, line) = info.location().map_or(("", 0), |l| (l.file(), l.line()));
    // SAFETY: the hook's C signature is the one declared above (documented in the header);
    // `file` points to `file.len()` bytes of static, immutable data.
    unsafe { sfs_panic_hook(file.as_ptr().cast(), file.len(), line) };
    // The hook returned: stop here for good (a watchdog, if any, resets the part).
    loop {
        core::hint::spin_loop();
    }
}

// The weak default hook: returns at once. A strong definition in the firmware replaces it.
#[cfg(target_arch = "arm")]
core::arch::global_asm!(
    ".section .text.sfs_panic_hook,\"ax\",%progbits",
    ".weak sfs_panic_hook",
    ".type sfs_panic_hook,%function",
    ".thumb_func",
    "sfs_panic_hook:",
    "bx lr",
    ".size sfs_panic_hook, . - sfs_panic_hook",
);
