//! Cortex-M4F firmware: the symmetry search on the built-in scene, measured, under QEMU.
//!
//! ```text
//! cargo run --release --example firmware --target thumbv7em-none-eabihf   # QEMU mps2-an386
//! cargo run --release --example firmware                                  # the same search on the host
//! cargo run --release --example firmware -- --write-scene                 # regenerate the scene file
//! ```
//! (`bash ci/firmware.sh` does all of it and compares the two digests.)
//!
//! Both builds run `support::harness::run` on the same depth image with the same engine
//! capacity and poll budget, and print the same `digest:` line (FNV-1a over every bit of the
//! result): equal digests show that host and target compute the same bits.
//!
//! The firmware also shows, by linking at all, that nothing in the dependency graph allocates
//! (there is no `#[global_allocator]`), and that the engine fits an STM32F4-class RAM budget
//! (`memory.x`: 192 KiB, at least 16 KiB of it stack). It measures
//! - instructions: with `-icount shift=N` QEMU's clock advances exactly 2^N ns per executed
//!   instruction, and SysTick (core clock: 25 MHz, 40 ns, on this board) counts executed
//!   instructions exactly and repeatably: one tick per 40 instructions at `shift=0`, per 5 at
//!   `shift=3`, which the runner uses for the finer resolution (at `shift=4` and up a tick is
//!   no longer a whole number of instructions). The firmware measures the ratio at start-up on
//!   two loops of known length, and refuses to run without `-icount`. (DWT CYCCNT reads 0 in
//!   QEMU.) Instructions are not cycles: on silicon, flash wait states and the software `sqrtf`
//!   and f64 routines cost more per instruction; the counts are for comparing and budgeting.
//! - peak stack: cortex-m-rt's `paint-stack` fills the whole stack with `0xCCCC_CCCC` before
//!   `main`; at the end the deepest overwritten word marks the peak.
//!
//! Data placement: the engine and the output buffer are `static`s in RAM, handed out once as
//! `&'static mut` by `static_cell::ConstStaticCell` (const-initialised, so never built on the
//! stack and moved). The engine is in `.data`: its initialiser holds the `Config`, which is not
//! all zero bits, so its whole initial image (`MEMORY_BYTES`) is also in flash and copied at boot.
//! The output buffer is all-zero bits, so it is `.bss`. The 150 KiB depth image is a `static` in
//! flash (see `firmware_support/scene_file.rs`): RAM holds only engine, output and stack.

#![cfg_attr(target_os = "none", no_std, no_main)]

#[path = "firmware_support/mod.rs"]
mod support;

#[cfg(target_os = "none")]
mod firmware {
    use core::sync::atomic::{AtomicU32, Ordering};

    use cortex_m::peripheral::syst::SystClkSource;
    use cortex_m::peripheral::{SCB, SYST};
    use cortex_m_rt::{entry, exception};
    use cortex_m_semihosting::{debug, hio, hprintln};
    use panic_semihosting as _;
    use shape_from_symmetry::{CompletedPoint, Config};
    use static_cell::ConstStaticCell;

    use crate::support::{self, OUTPUT_BYTES, OUTPUT_POINTS, SearchEngine, harness, scene_file};

    static ENGINE: ConstStaticCell<SearchEngine<'static>> =
        ConstStaticCell::new(SearchEngine::new(Config::DEFAULT));
    /// All-zero bits, so that the output buffer is `.bss` (a `CompletedPoint::ZERO` initialiser,
    /// whose `symmetry` is 255, would put 40 KiB of initial values in flash and copy them at boot).
    const BLANK: CompletedPoint = CompletedPoint {
        symmetry: 0,
        ..CompletedPoint::ZERO
    };
    static OUTPUT: ConstStaticCell<[CompletedPoint; OUTPUT_POINTS]> =
        ConstStaticCell::new([BLANK; OUTPUT_POINTS]);

    /// SysTick wraps (every 2^24 ticks).
    static WRAPS: AtomicU32 = AtomicU32::new(0);

    #[exception]
    fn SysTick() {
        WRAPS.fetch_add(1, Ordering::Relaxed);
    }

    /// SysTick ticks since it was started: a 64-bit count from the 24-bit down-counter and the
    /// wrap count. A wrap that happened but whose exception is still pending is counted too.
    fn ticks() -> u64 {
        cortex_m::interrupt::free(|_| {
            let mut wraps = WRAPS.load(Ordering::Relaxed);
            let mut current = SYST::get_current();
            if SCB::is_pendst_pending() {
                wraps += 1;
                current = SYST::get_current();
            }
            ((wraps as u64) << 24) + (0x00FF_FFFF - current) as u64
        })
    }

    /// SysTick ticks for a register-only countdown loop of `2 * n` instructions (`subs` + `bne`),
    /// plus the clock readings around it.
    fn countdown_ticks(n: u32) -> u64 {
        let t0 = ticks();
        // SAFETY: a register-only countdown loop; touches no memory and no stack.
        unsafe {
            core::arch::asm!("2:", "subs {n}, #1", "bne 2b", n = inout(reg) n => _, options(nomem, nostack));
        }
        ticks() - t0
    }

    /// Executed instructions per SysTick tick: two countdown loops whose lengths differ by
    /// exactly 2 000 000 instructions; the clock-reading overhead is the same in both and cancels.
    /// Returns (instructions, ticks) of the difference.
    fn calibrate() -> (u64, u64) {
        const SHORT: u32 = 100_000;
        const LONG: u32 = SHORT + 1_000_000;
        let short = countdown_ticks(SHORT);
        let long = countdown_ticks(LONG);
        (2 * (LONG - SHORT) as u64, long.saturating_sub(short))
    }

    /// The painted stack region and the deepest word the program has overwritten.
    fn stack_usage() -> (usize, usize) {
        unsafe extern "C" {
            // cortex-m-rt's linker symbols: the stack is [_stack_end, _stack_start).
            static _stack_start: u32;
            static _stack_end: u32;
        }
        let top = &raw const _stack_start as usize;
        let bottom = &raw const _stack_end as usize;
        let mut p = bottom;
        while p < top {
            // SAFETY: [bottom, top) is RAM reserved for the stack by the linker script; the words
            // below the current stack pointer are not in use, reading them is harmless.
            if unsafe { core::ptr::read_volatile(p as *const u32) }
                != cortex_m_rt::STACK_PAINT_VALUE
            {
                break;
            }
            p += 4;
        }
        (top - bottom, top - p)
    }

    fn fail(what: &dyn core::fmt::Display) -> ! {
        hprintln!("FAILED: {}", what);
        debug::exit(debug::EXIT_FAILURE);
        #[allow(clippy::empty_loop)]
        loop {}
    }

    #[entry]
    fn main() -> ! {
        let mut cp = cortex_m::Peripherals::take().unwrap_or_else(|| fail(&"peripherals taken"));
        cp.SYST.set_clock_source(SystClkSource::Core);
        cp.SYST.set_reload(0x00FF_FFFF);
        cp.SYST.clear_current();
        cp.SYST.enable_counter();
        // The counter holds 0 until its first tick loads the reload value; only then does
        // `ticks()` count from 0. Enable the wrap exception after that, so it sees only wraps.
        while SYST::get_current() == 0 {}
        cp.SYST.enable_interrupt();

        let (cal_instructions, cal_ticks) = calibrate();
        if cal_ticks == 0 {
            fail(&"SysTick does not count (run QEMU with -icount shift=3)");
        }
        let per_tick = (cal_instructions + cal_ticks / 2) / cal_ticks;
        // Under `-icount` the difference is a whole number of ticks, give or take the phase of
        // the tick at each end. Anything else means SysTick follows the host's clock (no
        // `-icount`), and the figures would be neither instructions nor repeatable.
        if cal_instructions.abs_diff(cal_ticks * per_tick) > 2 * per_tick {
            fail(&"SysTick does not count instructions (run QEMU with -icount shift=3)");
        }

        let engine = ENGINE.take();
        let output = OUTPUT.take();
        let outcome = match harness::run(engine, scene_file::scene(), output, ticks) {
            Ok(outcome) => outcome,
            Err(e) => fail(&e),
        };
        let (stack_region, stack_peak) = stack_usage();

        hprintln!("shape-from-symmetry firmware: Cortex-M4F (QEMU mps2-an386)");
        let Ok(mut out) = hio::hstdout() else {
            fail(&"no semihosting stdout")
        };
        if harness::describe(&mut out, engine.report(), &outcome).is_err() {
            fail(&"semihosting write");
        }
        hprintln!(
            "clock: SysTick {} ticks for {} calibration instructions = {} instructions/tick",
            cal_ticks,
            cal_instructions,
            per_tick
        );
        hprintln!(
            "instructions total: {} (start: {}; {} ticks, resolution {} instructions)",
            outcome.total * per_tick,
            outcome.start * per_tick,
            outcome.total,
            per_tick
        );
        hprintln!(
            "instructions max poll: {} (poll #{}: {} of {} work units)",
            outcome.max_poll * per_tick,
            outcome.max_poll_index,
            outcome.max_poll_units,
            harness::POLL_BUDGET
        );
        hprintln!("polls: {}", outcome.polls);
        for (name, cost) in harness::STAGE_NAMES.iter().zip(outcome.stages) {
            hprintln!(
                "stage {}: {} polls, {} units, {} instructions ({} per unit), max poll {}",
                name,
                cost.polls,
                cost.units,
                cost.clock * per_tick,
                cost.clock * per_tick / cost.units.max(1),
                cost.max_poll * per_tick
            );
        }
        hprintln!("peak stack: {} bytes of {} bytes", stack_peak, stack_region);
        hprintln!(
            "ram: engine {} bytes (POINTS {}, VOXELS {}, CELLS {}), output {} bytes ({} points)",
            SearchEngine::MEMORY_BYTES,
            support::POINTS,
            support::VOXELS,
            support::CELLS,
            OUTPUT_BYTES,
            OUTPUT_POINTS
        );
        hprintln!(
            "flash: depth image {} bytes",
            core::mem::size_of_val(&scene_file::DEPTH)
        );
        debug::exit(debug::EXIT_SUCCESS);
        #[allow(clippy::empty_loop)]
        loop {}
    }
}

/// The host build: the same search, printed with std; `--write-scene` regenerates the scene file.
#[cfg(not(target_os = "none"))]
fn main() -> std::process::ExitCode {
    use std::process::ExitCode;

    use shape_from_symmetry::{CompletedPoint, Config};
    use support::{OUTPUT_POINTS, SearchEngine, generate, harness, scene_file};

    let expected = generate::expected_file();
    if std::env::args().skip(1).any(|a| a == "--write-scene") {
        if let Err(e) = std::fs::write(scene_file::FILE_PATH, &expected) {
            eprintln!("cannot write {}: {e}", scene_file::FILE_PATH);
            return ExitCode::FAILURE;
        }
        println!(
            "wrote {} ({} bytes); rebuild to embed it",
            scene_file::FILE_PATH,
            expected.len()
        );
        return ExitCode::SUCCESS;
    }
    if expected != scene_file::FILE {
        eprintln!(
            "FAILED: {} is not the current render of the built-in scene;\n\
             regenerate it with `cargo run --example firmware -- --write-scene` and commit it",
            scene_file::FILE_PATH
        );
        return ExitCode::FAILURE;
    }

    let mut output = vec![CompletedPoint::ZERO; OUTPUT_POINTS];
    let mut engine = Box::new(SearchEngine::new(Config::DEFAULT));
    let clock = std::time::Instant::now();
    let outcome = match harness::run(&mut engine, scene_file::scene(), &mut output, || {
        clock.elapsed().as_nanos() as u64
    }) {
        Ok(outcome) => outcome,
        Err(e) => {
            eprintln!("FAILED: {e}");
            return ExitCode::FAILURE;
        }
    };
    let mut text = String::new();
    harness::describe(&mut text, engine.report(), &outcome).expect("writing to a String");
    println!("shape-from-symmetry firmware: host build");
    print!("{text}");
    println!(
        "host time: {:.3} ms total (start: {:.3} ms), {:.3} ms max poll (poll #{}: {} units)",
        outcome.total as f64 / 1e6,
        outcome.start as f64 / 1e6,
        outcome.max_poll as f64 / 1e6,
        outcome.max_poll_index,
        outcome.max_poll_units
    );
    for (name, cost) in harness::STAGE_NAMES.iter().zip(outcome.stages) {
        println!(
            "host stage {name}: {} polls, {} units, {:.3} ms, max poll {:.3} ms",
            cost.polls,
            cost.units,
            cost.clock as f64 / 1e6,
            cost.max_poll as f64 / 1e6
        );
    }
    println!(
        "host memory: engine {} bytes, output {} bytes",
        SearchEngine::MEMORY_BYTES,
        support::OUTPUT_BYTES
    );
    ExitCode::SUCCESS
}

#[cfg(all(test, not(target_os = "none")))]
mod tests {
    use super::support::{generate, scene_file};

    #[test]
    fn scene_file_round_trips() {
        let (k, scale, table, depth) = generate::render();
        let bytes = scene_file::encode(&k, scale, table, &depth);
        assert_eq!(bytes.len(), scene_file::HEADER_BYTES + 2 * depth.len());
        assert_eq!(&bytes[..8], &scene_file::MAGIC);
    }

    #[test]
    fn committed_scene_is_current() {
        assert!(
            generate::expected_file() == scene_file::FILE,
            "regenerate with `cargo run --example firmware -- --write-scene`"
        );
        assert_eq!(scene_file::scene().validate(), Ok(()));
    }
}
