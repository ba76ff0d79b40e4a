//! Target only: the firmware's clock and its 1 kHz control tick, both from SysTick.
//!
//! SysTick runs free at the core clock (25 MHz on `mps2-an386`: 40 ns per count), reloading at
//! 2^24, and its exception only counts the wraps. That one counter serves three purposes:
//! - [`ticks`], the measuring clock: under QEMU's `-icount shift=3` it advances one count per 5
//!   executed instructions, so the measuring run's figures are instruction counts;
//! - [`SysTickDelay`], a delay provider: embedded-hal 1.0's [`DelayNs`], waiting on that count;
//! - [`Ticker`], the control loop's 1 kHz tick: tick `k` begins `k` × 25 000 counts (1 ms)
//!   after the loop started, and [`Ticker::wait`] waits for the next one through any [`DelayNs`].
//!
//! Why not a SysTick interrupt every millisecond, as many firmwares have? The measuring run needs
//! SysTick free-running (a handler every millisecond would run inside the measured polls and
//! shift their instruction counts), and one clock with one meaning for the whole program (the
//! defmt timestamps too) is simpler than reprogramming it between the runs. Deadlines on the
//! free-running count give the same 1 kHz tick.
//!
//! Why a busy wait? A firmware on silicon would rather sleep (`wfi`) until a timer interrupt; here
//! the spin is just emulated time under `-icount`, deterministic (a sleeping core would need
//! `-icount sleep=off` to stay so). The control loop only asks for a [`DelayNs`], so a board's
//! own provider (a HAL timer's delay, or one that sleeps) slots in without touching the loop.

use core::sync::atomic::{AtomicU32, Ordering};

use cortex_m::peripheral::syst::SystClkSource;
use cortex_m::peripheral::{SCB, SYST};
use cortex_m_rt::exception;
use embedded_hal::delay::DelayNs;

/// SysTick's clock: the core clock of QEMU's `mps2-an386` (AN386: 25 MHz).
pub const CLOCK_HZ: u64 = 25_000_000;
/// Nanoseconds per SysTick count.
pub const NS_PER_COUNT: u64 = 1_000_000_000 / CLOCK_HZ;
/// The control loop's tick rate.
pub const TICK_HZ: u64 = 1_000;
/// SysTick counts per control tick.
pub const COUNTS_PER_TICK: u64 = CLOCK_HZ / TICK_HZ;

/// SysTick wraps (every 2^24 counts).
static WRAPS: AtomicU32 = AtomicU32::new(0);

#[exception]
fn SysTick() {
    WRAPS.fetch_add(1, Ordering::Relaxed);
}

/// Start SysTick as a free-running 24-bit down-counter at the core clock, counting its wraps.
/// Returns once the counter runs, so that [`ticks`] counts from 0.
pub fn start(syst: &mut SYST) {
    syst.set_clock_source(SystClkSource::Core);
    syst.set_reload(0x00FF_FFFF);
    syst.clear_current();
    syst.enable_counter();
    // The counter holds 0 until its first tick loads the reload value; only then does `ticks()`
    // count from 0. Enable the wrap exception after that, so it sees only wraps.
    while SYST::get_current() == 0 {}
    syst.enable_interrupt();
}

/// SysTick counts since [`start`]: a 64-bit count from the 24-bit down-counter and the wrap
/// count. A wrap that happened but whose exception is still pending is counted too.
pub fn ticks() -> u64 {
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

/// embedded-hal's delay on the SysTick count (which [`start`] must have started): a busy wait,
/// to 40 ns resolution, never shorter than asked.
///
/// Between two readings of the clock it spins in registers (`cortex_m::asm::delay`) for a quarter
/// of the counts still to go: SysTick counts core cycles, and `asm::delay(n)` is `n + 1` turns of
/// a loop of about three cycles on a Cortex-M4, so the spin stays short of the deadline. Reading
/// the clock less often matters under QEMU's `-icount`, where every read of a SysTick or SCB
/// register ends a translation block: spinning on [`ticks`] alone makes the 4 s control loop
/// take 10 s longer to emulate.
pub struct SysTickDelay;

impl DelayNs for SysTickDelay {
    fn delay_ns(&mut self, ns: u32) {
        // The first reading may come just before the count moves on: one count more than `ns`
        // asks for, so that at least `ns` elapse.
        let deadline = ticks() + (ns as u64).div_ceil(NS_PER_COUNT) + 1;
        loop {
            let now = ticks();
            if now >= deadline {
                return;
            }
            cortex_m::asm::delay(((deadline - now) / 4) as u32);
        }
    }
}

/// A fixed-rate tick on the SysTick count: tick `k` begins [`COUNTS_PER_TICK`] × `k` counts
/// after [`Ticker::start`]. The loop does its work for a tick, then calls [`Ticker::wait`].
pub struct Ticker<D> {
    delay: D,
    /// Where the next tick begins, in SysTick counts.
    next: u64,
    /// Ticks begun, the current one included.
    pub ticks: u32,
    /// Ticks whose work was still running when the next tick was due (that tick is then skipped:
    /// the loop waits for the first tick still ahead, as a control loop must).
    pub overruns: u32,
    /// The least time left in a tick when its work was done, in SysTick counts (over the ticks
    /// that did not overrun; `COUNTS_PER_TICK` before the first `wait`).
    pub least_slack: u64,
}

impl<D: DelayNs> Ticker<D> {
    /// Tick 0 begins now.
    pub fn start(delay: D) -> Self {
        Self {
            delay,
            next: ticks() + COUNTS_PER_TICK,
            ticks: 1,
            overruns: 0,
            least_slack: COUNTS_PER_TICK,
        }
    }

    /// Wait until the next tick begins.
    pub fn wait(&mut self) {
        let now = ticks();
        if now >= self.next {
            let late = (now - self.next) / COUNTS_PER_TICK + 1;
            self.overruns += 1;
            self.ticks += late as u32;
            self.next += late * COUNTS_PER_TICK;
        } else {
            self.least_slack = self.least_slack.min(self.next - now);
        }
        // At most one tick (1 ms): fits the u32 of nanoseconds.
        self.delay
            .delay_ns(((self.next - now) * NS_PER_COUNT) as u32);
        self.next += COUNTS_PER_TICK;
        self.ticks += 1;
    }
}
