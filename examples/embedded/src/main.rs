//! truenorth on a Cortex-M4F: the quaternion filter over a real BROAD slice and a calibrated
//! compass heading, then the online ellipse calibrator learning a compass from a simulated
//! turn ([`shared_run`], the same file the host twin runs), first in `f32` (the product path
//! on this single-precision FPU), then in `f64` for comparison, printed over semihosting;
//! after each part, the instructions one filter update (one calibrator push) takes, counted
//! with the SysTick timer under QEMU's `-icount shift=0` (virtual time advances one step per
//! instruction).
//!
//! Run (QEMU's `mps2-an386`, see `.cargo/config.toml`): `cargo run --release`.
#![no_std]
#![no_main]

mod shared_run;

use core::alloc::{GlobalAlloc, Layout};
use core::fmt::Write as _;

use cortex_m::peripheral::SYST;
use cortex_m::peripheral::syst::SystClkSource;
use cortex_m_rt::entry;
use cortex_m_semihosting::{debug, hio};
use panic_semihosting as _;

use shared_run::UpdateMeter;
use truenorth_fusion::{QuaternionFilter, QuaternionFilterConfig};

/// The library links `alloc` (truenorth-calib's saved states hold `Vec`s) but the filter, the
/// compass and the online calibrator (its pushes and its solve) never allocate. This allocator refuses every request, so the run proves it:
/// an allocation would end it with an allocation-error panic and a failing exit status.
struct NoHeap;

// SAFETY: returning null is how `GlobalAlloc::alloc` reports failure; `dealloc` is never
// given a pointer, since no allocation ever succeeds.
unsafe impl GlobalAlloc for NoHeap {
    unsafe fn alloc(&self, _: Layout) -> *mut u8 {
        core::ptr::null_mut()
    }
    unsafe fn dealloc(&self, _: *mut u8, _: Layout) {}
}

#[global_allocator]
static HEAP: NoHeap = NoHeap;

/// The SysTick reload: the full 24 bits, 16.7 M ticks between wraps.
const SYST_RELOAD: u32 = 0x00FF_FFFF;

/// Ticks elapsed between two readings of the down-counting SysTick (at most one wrap).
fn ticks_between(start: u32, end: u32) -> u32 {
    start.wrapping_sub(end) & SYST_RELOAD
}

/// Instructions in [`known_block`]: 400 passes of 250 `nop`s, `subs` and `bne`.
const KNOWN_BLOCK_INSTRUCTIONS: u32 = 400 * 252;

/// A block of exactly [`KNOWN_BLOCK_INSTRUCTIONS`] instructions, to learn how many
/// instructions one SysTick tick stands for (25 MHz clock, 1 ns per instruction: 40).
#[inline(never)]
fn known_block() {
    // SAFETY: only `nop`s and a loop counter in a scratch register; no memory, no stack.
    unsafe {
        core::arch::asm!(
            "2:",
            ".rept 250",
            "nop",
            ".endr",
            "subs {n}, {n}, #1",
            "bne 2b",
            n = inout(reg) 400u32 => _,
            options(nomem, nostack),
        );
    }
}

/// Sums the SysTick ticks of each measured update, and separately those of the updates
/// classified as the steady path (after the start-up; a push without a refresh stage).
struct SysTickMeter {
    ticks: u64,
    updates: u32,
    last_ticks: u32,
    steady_ticks: u64,
    steady: u32,
}

impl SysTickMeter {
    fn new() -> Self {
        Self {
            ticks: 0,
            updates: 0,
            last_ticks: 0,
            steady_ticks: 0,
            steady: 0,
        }
    }

    /// Mean instructions per measured update, over all and over the steady ones.
    fn per_update(&self, calibration: &Calibration) -> (f64, f64) {
        (
            calibration.instructions(self.ticks, self.updates),
            calibration.instructions(self.steady_ticks, self.steady),
        )
    }
}

impl UpdateMeter for SysTickMeter {
    fn measure<T>(&mut self, update: impl FnOnce() -> T) -> T {
        let start = SYST::get_current();
        let result = update();
        let end = SYST::get_current();
        self.last_ticks = ticks_between(start, end);
        self.ticks += u64::from(self.last_ticks);
        self.updates += 1;
        result
    }

    fn classify_last(&mut self, steady: bool) {
        if steady {
            self.steady_ticks += u64::from(self.last_ticks);
            self.steady += 1;
        }
    }
}

/// Ticks an empty measurement costs, averaged over many (a tick is tens of instructions).
fn meter_overhead_ticks() -> f64 {
    const N: u32 = 1000;
    let mut meter = SysTickMeter::new();
    for _ in 0..N {
        meter.measure(|| core::hint::black_box(0));
    }
    meter.ticks as f64 / f64::from(N)
}

#[entry]
fn main() -> ! {
    let code = match run() {
        Ok(()) => debug::EXIT_SUCCESS,
        Err(e) => {
            if let Ok(mut err) = hio::hstderr() {
                let _ = writeln!(err, "error: {e}");
            }
            debug::EXIT_FAILURE
        }
    };
    debug::exit(code);
    #[allow(clippy::empty_loop)] // semihosting's exit does not return under QEMU
    loop {}
}

/// The shared run in `f32`, then in `f64`, each followed by the measured cost of an update;
/// between them, the cost of the `f32` filter with its σ switched off and of Madgwick's.
fn run() -> Result<(), shared_run::RunError> {
    let mut out = hio::hstdout().map_err(|()| shared_run::RunError::Output(core::fmt::Error))?;
    let mut syst = cortex_m::Peripherals::take()
        .ok_or(shared_run::RunError::Output(core::fmt::Error))?
        .SYST;
    syst.set_clock_source(SystClkSource::Core);
    syst.set_reload(SYST_RELOAD);
    syst.clear_current();
    syst.enable_counter();

    let start = SYST::get_current();
    known_block();
    let known_ticks = ticks_between(start, SYST::get_current());
    let calibration = Calibration {
        instructions_per_tick: f64::from(KNOWN_BLOCK_INSTRUCTIONS) / f64::from(known_ticks),
        overhead_ticks: meter_overhead_ticks(),
    };

    run_measured::<f32>(&mut out, &calibration)?;
    calibrate_measured::<f32>(&mut out, &calibration)?;
    sigma_off_measured(&mut out, &calibration)?;
    madgwick_measured(&mut out, &calibration)?;
    run_measured::<f64>(&mut out, &calibration)?;
    calibrate_measured::<f64>(&mut out, &calibration)
}

/// What turns summed SysTick ticks into instructions.
struct Calibration {
    /// Instructions one tick stands for (from [`known_block`]).
    instructions_per_tick: f64,
    /// Ticks an empty measurement costs ([`meter_overhead_ticks`]).
    overhead_ticks: f64,
}

impl Calibration {
    /// Mean instructions of `n` measurements that took `ticks` in all.
    fn instructions(&self, ticks: u64, n: u32) -> f64 {
        (ticks as f64 / f64::from(n) - self.overhead_ticks) * self.instructions_per_tick
    }
}

/// The shared run in the float type `R`, then a `measured` line with the mean instructions
/// of one filter update, over all updates and over those after the start-up.
fn run_measured<R: truenorth_core::Real>(
    out: &mut impl core::fmt::Write,
    calibration: &Calibration,
) -> Result<(), shared_run::RunError> {
    let mut meter = SysTickMeter::new();
    shared_run::run::<R>(out, &mut meter)?;
    let (all, steady) = meter.per_update(calibration);
    writeln!(
        out,
        "measured instructions_per_update={all:.0} after_startup={steady:.0} updates={} float={} \
         instructions_per_tick={:.3} meter_overhead_ticks={:.3}",
        meter.updates,
        core::any::type_name::<R>(),
        calibration.instructions_per_tick,
        calibration.overhead_ticks,
    )?;
    Ok(())
}

/// The `f32` filter with `sigma: false` over the same recording: a `measured` line of the
/// same form as [`run_measured`]'s, with `filter=quaternion_sigma_off`.
fn sigma_off_measured(
    out: &mut impl core::fmt::Write,
    calibration: &Calibration,
) -> Result<(), shared_run::RunError> {
    let config = QuaternionFilterConfig {
        sigma: false,
        ..QuaternionFilterConfig::default()
    };
    let mut filter = QuaternionFilter::<f32>::with_precision(config)?;
    let mut meter = SysTickMeter::new();
    for s in shared_run::samples::<f32>()? {
        meter.measure(|| shared_run::update(&mut filter, &s))?;
        meter.classify_last(s.since_first_s >= config.startup_s);
    }
    let q = filter.attitude();
    peer_measured(
        out,
        calibration,
        &meter,
        "quaternion_sigma_off",
        [q.w, q.i, q.j, q.k],
    )
}

/// The `measured` line of a filter run beside the quaternion filter's: its mean instructions
/// per update (all, and after the start-up), its name and its final quaternion.
fn peer_measured(
    out: &mut impl core::fmt::Write,
    calibration: &Calibration,
    meter: &SysTickMeter,
    filter: &str,
    [w, i, j, k]: [f32; 4],
) -> Result<(), shared_run::RunError> {
    let (all, steady) = meter.per_update(calibration);
    writeln!(
        out,
        "measured peer_instructions_per_update={all:.0} after_startup={steady:.0} updates={} \
         filter={filter} float=f32 final_q={w} {i} {j} {k}",
        meter.updates
    )?;
    Ok(())
}

/// A vector as `ahrs` names it: with nalgebra 0.34, the crate's own dependency.
type AhrsVector = ahrs_nalgebra::Vector3<f32>;

/// One update of Madgwick's filter by gyro `g`, accelerometer `a` and field `m`, made as
/// [`shared_run::update`] makes the quaternion filter's. A zero accelerometer or field
/// reading is refused and leaves the filter as it was: the recording has none.
#[inline(never)]
fn madgwick_update(
    filter: &mut ahrs::Madgwick<f32>,
    g: &AhrsVector,
    a: &AhrsVector,
    m: &AhrsVector,
) {
    use ahrs::Ahrs as _;
    let _ = core::hint::black_box(filter).update(g, a, m);
}

/// Madgwick's filter (the `ahrs` crate, β = 0.12 as the peers bench runs it, 9-D `update`)
/// in `f32` over the same recording: a `measured` line of the same form, with
/// `filter=madgwick`. Its start-up is no different from the rest, so `after_startup`
/// counts the same updates as the quaternion filter's.
fn madgwick_measured(
    out: &mut impl core::fmt::Write,
    calibration: &Calibration,
) -> Result<(), shared_run::RunError> {
    let dt = shared_run::SAMPLE_INTERVAL_S as f32;
    let mut filter = ahrs::Madgwick::new(dt, 0.12f32);
    let mut meter = SysTickMeter::new();
    let startup_s = QuaternionFilterConfig::default().startup_s;
    let v = |v: nalgebra::Vector3<f32>| AhrsVector::new(v.x, v.y, v.z);
    for s in shared_run::samples::<f32>()? {
        let (g, a, m) = (v(s.gyr_rps), v(s.acc_mps2), v(s.mag_ut));
        meter.measure(|| madgwick_update(&mut filter, &g, &a, &m));
        meter.classify_last(s.since_first_s >= startup_s);
    }
    let q = filter.quat;
    peer_measured(out, calibration, &meter, "madgwick", [q.w, q.i, q.j, q.k])
}

/// The online ellipse calibrator's part of the shared run in the float type `R`, then a
/// `measured` line with the mean instructions of one push: over all pushes (refresh stages,
/// which fit in `f64` in both precisions, included) and over the pushes that ran the
/// per-sample path alone (sums and slot, in `R`).
fn calibrate_measured<R: truenorth_core::Real>(
    out: &mut impl core::fmt::Write,
    calibration: &Calibration,
) -> Result<(), shared_run::RunError> {
    let mut meter = SysTickMeter::new();
    shared_run::calibrate::<R>(out, &mut meter)?;
    let (all, steady) = meter.per_update(calibration);
    writeln!(
        out,
        "measured instructions_per_push={all:.0} per_sample_path={steady:.0} pushes={} per_sample_pushes={} float={}",
        meter.updates,
        meter.steady,
        core::any::type_name::<R>()
    )?;
    Ok(())
}
