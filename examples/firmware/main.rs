//! Cortex-M4F firmware: the symmetry search on the built-in scene, measured, then run as a 1 kHz
//! control loop, under QEMU.
//!
//! ```text
//! cargo run --release --example firmware --target thumbv7em-none-eabihf                   # QEMU mps2-an386
//! cargo run --release --example firmware --target thumbv7em-none-eabihf --features defmt  # the same, logging through defmt
//! cargo run --release --example firmware                                                  # the same search on the host
//! cargo run --release --example firmware -- --write-scene                                 # regenerate the scene file
//! ```
//! (`bash ci/firmware.sh` does all of it and compares the digests.)
//!
//! Both builds run `sfs_testkit::harness::run` on the same depth image with the same engine
//! capacity and poll budget, and print the same `digest:` line (FNV-1a over every bit of the
//! result): equal digests show that host and target compute the same bits.
//!
//! The firmware also shows, by linking at all, that nothing in the dependency graph allocates
//! (there is no `#[global_allocator]`), and that the engine fits an STM32F4-class RAM budget
//! (`memory.x`: 192 KiB, at least 16 KiB of it stack). It runs the search twice.
//!
//! **1. The measuring run**: the polls back to back, nothing between them but the clock readings.
//! It measures
//! - instructions: with `-icount shift=N` QEMU's clock advances exactly 2^N ns per executed
//!   instruction, and SysTick (core clock: 25 MHz, 40 ns, on this board) counts executed
//!   instructions exactly and repeatably: one tick per 40 instructions at `shift=0`, per 5 at
//!   `shift=3`, which the runner uses for the finer resolution (at `shift=4` and up a tick is
//!   no longer a whole number of instructions). The firmware measures the ratio at start-up on
//!   two loops of known length, and refuses to run without `-icount`. (DWT CYCCNT reads 0 in
//!   QEMU.) Instructions are not cycles: on silicon, flash wait states and the software `sqrtf`
//!   and f64 routines cost more per instruction; the counts are for comparing and budgeting.
//! - peak stack: cortex-m-rt's `paint-stack` fills the whole stack with `0xCCCC_CCCC` before
//!   `main`; right after the measuring run the deepest overwritten word marks the peak.
//!
//! **2. The control loop**: the same search again, the way a controller runs it: one poll with
//! `RECOMMENDED_BUDGET` per 1 kHz tick, then wait for the next tick. The tick comes from the same
//! free-running SysTick count (tick `k` begins at `k` × 25 000 counts, 1 ms; see
//! `examples/firmware/tick.rs`), and the loop waits through embedded-hal 1.0's `DelayNs`, which
//! the firmware implements on SysTick. Under `-icount shift=3` a millisecond is 125 000
//! instructions, a 125 MIPS core. The firmware checks that the loop's result has the measuring
//! run's digest, and reports the ticks it took, the ticks whose poll overran (ran into the next
//! tick; CI requires none) and the least time left in a tick. The measuring run is kept apart so
//! that the waiting (and in the defmt build, the progress logs) cannot shift its figures.
//!
//! **Output.** By default, text over semihosting (`hprintln!`). With `--features defmt`, every
//! line goes out as a defmt frame instead (the library's types through their `defmt::Format`
//! derives; timestamps are the SysTick clock in microseconds of emulated time), carried over
//! semihosting by `defmt-semihosting`; the runner (`examples/firmware/qemu-run.sh`) pipes them
//! through `defmt-print` (`cargo install defmt-print --version 1.2.0 --locked`). The control loop
//! then also logs its progress. The two must not mix: a text line would corrupt the frames, so
//! the defmt build prints no text, and has its own panic handler (a defmt `error!`, then exit).
//! The defmt build needs defmt's linker script, `defmt.x`: see the `#[link]` item in `firmware`.
//!
//! Data placement: the engine and the output buffer are `static`s in RAM, handed out once by
//! `static_cell::ConstStaticCell` (const-initialised, so never built on the stack and moved). The
//! engine is in `.data`: its initialiser holds the `Config`, which is not all zero bits, so its
//! whole initial image (`MEMORY_BYTES`) is also in flash and copied at boot. The output buffer is
//! all-zero bits, so it is `.bss`. The 150 KiB depth image is a `static` in flash (see
//! `sfs_testkit::scene_file`): RAM holds only engine, output and stack.

#![cfg_attr(target_os = "none", no_std, no_main)]

mod capacity;
#[cfg(target_os = "none")]
mod tick;

#[cfg(target_os = "none")]
mod firmware {
    use cortex_m_rt::entry;
    use cortex_m_semihosting::debug;
    use embedded_hal::delay::DelayNs;
    #[cfg(not(feature = "defmt"))]
    use panic_semihosting as _;
    use shape_from_symmetry::{CompletedPoint, Config, RECOMMENDED_BUDGET, Status};
    use static_cell::ConstStaticCell;

    use sfs_testkit::{harness, scene_file};

    use crate::capacity::{self, OUTPUT_BYTES, OUTPUT_POINTS, SearchEngine};
    use crate::tick::{self, SysTickDelay, Ticker, ticks};

    /// One line of output: text over semihosting, or with `--features defmt` a defmt `info!`
    /// frame (the same format string: `{}` only, with arguments that are both `Display` and
    /// `defmt::Format`).
    macro_rules! say {
        ($($arg:tt)*) => {{
            #[cfg(not(feature = "defmt"))]
            cortex_m_semihosting::hprintln!($($arg)*);
            #[cfg(feature = "defmt")]
            defmt::info!($($arg)*);
        }};
    }

    // defmt's linker script, for the defmt build only.
    //
    // defmt needs `-Tdefmt.x` (it places the interned log strings); defmt's build script writes
    // the file and puts its folder on the linker's search path. Passing it in `rustflags` would
    // put it in every link of this target, with or without the feature; build.rs passes only
    // this package's own `-Tlink.x`. So the defmt build names the script where it uses defmt:
    // as a verbatim link input (`-l:defmt.x`), which the linker (rust-lld, this target's) reads
    // as a linker script because it is neither an object nor an archive: the same as `-T`.
    // Without the feature this item does not exist and the link is the same as ever.
    #[cfg(feature = "defmt")]
    #[link(name = "defmt.x", kind = "static", modifiers = "+verbatim,-bundle")]
    unsafe extern "C" {}

    #[cfg(feature = "defmt")]
    use defmt_semihosting as _;

    // defmt timestamps: the SysTick clock, in microseconds (of QEMU's emulated time).
    #[cfg(feature = "defmt")]
    defmt::timestamp!("{=u64:us}", ticks() / (tick::CLOCK_HZ / 1_000_000));

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

    fn exit_failure() -> ! {
        debug::exit(debug::EXIT_FAILURE);
        #[allow(clippy::empty_loop)]
        loop {}
    }

    fn fail(what: &dyn core::fmt::Display) -> ! {
        #[cfg(not(feature = "defmt"))]
        cortex_m_semihosting::hprintln!("FAILED: {}", what);
        #[cfg(feature = "defmt")]
        defmt::error!("FAILED: {}", defmt::Display2Format(what));
        exit_failure()
    }

    /// The defmt build's panic handler: the message as a defmt frame (text would corrupt the
    /// frame stream), then a failing exit. A panic inside it (say, while the logger is held)
    /// exits without logging.
    #[cfg(feature = "defmt")]
    #[panic_handler]
    fn panic(info: &core::panic::PanicInfo) -> ! {
        use core::sync::atomic::{AtomicBool, Ordering};
        static PANICKED: AtomicBool = AtomicBool::new(false);
        if !PANICKED.swap(true, Ordering::Relaxed) {
            defmt::error!("panicked: {}", defmt::Display2Format(info));
        }
        exit_failure()
    }

    /// The result lines, as text: exactly what the host build prints (CI compares them).
    #[cfg(not(feature = "defmt"))]
    fn describe(engine: &SearchEngine<'static>, outcome: &harness::Outcome) {
        let Ok(mut out) = cortex_m_semihosting::hio::hstdout() else {
            fail(&"no semihosting stdout")
        };
        if harness::describe(&mut out, engine.report(), outcome).is_err() {
            fail(&"semihosting write");
        }
    }

    /// The result lines, as defmt frames: the same lines as the text build, and each symmetry
    /// in full through its `defmt::Format` derive.
    #[cfg(feature = "defmt")]
    fn describe(engine: &SearchEngine<'static>, outcome: &harness::Outcome) {
        let report = engine.report();
        defmt::info!(
            "object: {} pixels with depth, {} points sampled",
            report.object_pixels,
            report.sampled_points
        );
        defmt::info!("symmetries: {}", report.symmetries.len());
        for (i, found) in report.symmetries.iter().enumerate() {
            defmt::info!(
                "  #{} {=str} score {} domain {} points: {}",
                i,
                found.symmetry.kind().name(),
                found.score,
                found.domain_points,
                found.symmetry
            );
        }
        defmt::info!(
            "points: {} visible, {} generated, {} dropped (output or dedup table full)",
            report.points_visible,
            report.points_generated,
            report.points_dropped
        );
        defmt::info!(
            "work units: {}, polls: {} at budget {}, most units in a poll: {}",
            report.work_units,
            outcome.polls,
            harness::POLL_BUDGET,
            outcome.most_units
        );
        defmt::info!("digest: {=u64:#018x}", outcome.digest);
    }

    /// The control loop, as a controller runs the search: start it, then one poll of
    /// `RECOMMENDED_BUDGET` work units per tick, waiting for the next tick after each poll that
    /// leaves work. Returns the result's digest and the number of polls. With `--features
    /// defmt` it logs its progress (on every change of stage, and every 1000 polls).
    fn control_loop<D: DelayNs>(
        engine: &mut SearchEngine<'static>,
        output: &'static mut [CompletedPoint],
        ticker: &mut Ticker<D>,
    ) -> Result<Control, harness::RunError> {
        engine
            .start(scene_file::scene(), output)
            .map_err(harness::RunError::Start)?;
        #[cfg(feature = "defmt")]
        let mut stage = engine.stage();
        loop {
            let polls = engine.report().polls;
            if polls == harness::MAX_POLLS {
                return Err(harness::RunError::NoEnd { polls });
            }
            let status = engine
                .poll(RECOMMENDED_BUDGET)
                .map_err(|error| harness::RunError::Poll { poll: polls, error })?;
            if status == Status::Done {
                break;
            }
            #[cfg(feature = "defmt")]
            {
                let report = engine.report();
                if engine.stage() != stage || report.polls % 1000 == 0 {
                    stage = engine.stage();
                    defmt::info!(
                        "control loop: poll {}: {}, {} work units, best so far: {}",
                        report.polls,
                        stage,
                        report.work_units,
                        report.symmetries.first()
                    );
                }
            }
            ticker.wait();
        }
        Ok(Control {
            digest: harness::digest(engine.report(), engine.points()),
            polls: engine.report().polls,
        })
    }

    /// What the control loop leaves behind.
    struct Control {
        digest: u64,
        polls: u32,
    }

    #[entry]
    fn main() -> ! {
        let mut cp = cortex_m::Peripherals::take().unwrap_or_else(|| fail(&"peripherals taken"));
        tick::start(&mut cp.SYST);
        // (After the clock starts: it gives the defmt timestamps.)
        #[cfg(feature = "defmt")]
        defmt::info!(
            "shape-from-symmetry firmware: Cortex-M4F (QEMU mps2-an386), logging through defmt"
        );

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
        // Both runs write into this one buffer (a second would not fit the RAM budget), and the
        // engine keeps the reference it is given for its whole lifetime (`'static`, as it is a
        // `static`), so the buffer is reached through a raw pointer, once per run.
        let output: *mut [CompletedPoint] = OUTPUT.take();

        #[cfg(feature = "defmt")]
        defmt::info!(
            "measuring run: polls of {} work units back to back",
            harness::POLL_BUDGET
        );
        // SAFETY: `OUTPUT` hands its buffer out once: this pointer is the only way to it, and
        // this is the first reference made from it.
        let outcome =
            match harness::run(engine, scene_file::scene(), unsafe { &mut *output }, ticks) {
                Ok(outcome) => outcome,
                Err(e) => fail(&e),
            };
        let (stack_region, stack_peak) = stack_usage();

        #[cfg(not(feature = "defmt"))]
        cortex_m_semihosting::hprintln!(
            "shape-from-symmetry firmware: Cortex-M4F (QEMU mps2-an386)"
        );
        describe(engine, &outcome);
        say!(
            "clock: SysTick {} ticks for {} calibration instructions = {} instructions/tick",
            cal_ticks,
            cal_instructions,
            per_tick
        );
        say!(
            "instructions total: {} (start: {}; {} ticks, resolution {} instructions)",
            outcome.total * per_tick,
            outcome.start * per_tick,
            outcome.total,
            per_tick
        );
        say!(
            "instructions max poll: {} (poll #{}: {} of {} work units)",
            outcome.max_poll * per_tick,
            outcome.max_poll_index,
            outcome.max_poll_units,
            harness::POLL_BUDGET
        );
        say!("polls: {}", outcome.polls);
        for (name, cost) in harness::STAGE_NAMES.iter().zip(outcome.stages) {
            say!(
                "stage {}: {} polls, {} units, {} instructions ({} per unit), max poll {}",
                name,
                cost.polls,
                cost.units,
                cost.clock * per_tick,
                cost.clock * per_tick / cost.units.max(1),
                cost.max_poll * per_tick
            );
        }
        say!("peak stack: {} bytes of {} bytes", stack_peak, stack_region);
        say!(
            "ram: engine {} bytes (POINTS {}, VOXELS {}, CELLS {}), output {} bytes ({} points)",
            SearchEngine::MEMORY_BYTES,
            capacity::POINTS,
            capacity::VOXELS,
            capacity::CELLS,
            OUTPUT_BYTES,
            OUTPUT_POINTS
        );
        say!(
            "flash: depth image {} bytes",
            core::mem::size_of_val(&scene_file::DEPTH)
        );

        // The control loop: the same search again, one poll per 1 kHz tick.
        #[cfg(feature = "defmt")]
        defmt::info!(
            "control loop: one poll of {} work units per {} Hz SysTick tick",
            harness::POLL_BUDGET,
            tick::TICK_HZ
        );
        let mut ticker = Ticker::start(SysTickDelay);
        // SAFETY: the measuring run is over and nothing reads its output any more; the reference
        // to the buffer it left in the engine is dead: `start` replaces it without reading it.
        // From here on this new reference is the only one in use.
        let control = match control_loop(engine, unsafe { &mut *output }, &mut ticker) {
            Ok(control) => control,
            Err(e) => fail(&e),
        };
        let tick_instructions = tick::COUNTS_PER_TICK * per_tick;
        say!(
            "control loop: {} Hz tick ({} instructions), {} polls in {} ticks, {} overruns, least slack {} instructions",
            tick::TICK_HZ,
            tick_instructions,
            control.polls,
            ticker.ticks,
            ticker.overruns,
            ticker.least_slack * per_tick
        );
        if control.digest != outcome.digest {
            fail(&"the control loop's result differs from the measuring run's");
        }
        #[cfg(not(feature = "defmt"))]
        cortex_m_semihosting::hprintln!(
            "control loop: digest 0x{:016x}, the same as the measuring run's",
            control.digest
        );
        #[cfg(feature = "defmt")]
        defmt::info!(
            "control loop: digest {=u64:#018x}, the same as the measuring run's",
            control.digest
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

    use capacity::{OUTPUT_POINTS, SearchEngine};
    use sfs_testkit::{generate, harness, scene_file};
    use shape_from_symmetry::{CompletedPoint, Config};

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
        capacity::OUTPUT_BYTES
    );
    ExitCode::SUCCESS
}
