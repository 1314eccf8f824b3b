//! The measurement clock shared by the benches (wall time, or the thread's CPU time).

use criterion::Criterion;
use criterion::measurement::{Measurement, ValueFormatter, WallTime};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

/// The clock of the measurements: wall time by default, or with `MICROSURFACE_BENCH_CLOCK=cpu`
/// the CPU time of the benchmarking thread (Linux), which leaves out the time the thread
/// spends preempted when other processes compete for the cores. Reported as durations either
/// way.
#[derive(Debug, Clone, Copy)]
pub enum Clock {
    Wall,
    #[cfg(target_os = "linux")]
    ThreadCpu,
}

#[cfg(target_os = "linux")]
mod thread_cpu {
    use std::time::Duration;

    /// `struct timespec` on Linux (`time_t` and `long` are the pointer width).
    #[repr(C)]
    struct Timespec {
        tv_sec: isize,
        tv_nsec: isize,
    }

    /// `CLOCK_THREAD_CPUTIME_ID` on Linux.
    const CLOCK_THREAD_CPUTIME_ID: i32 = 3;

    unsafe extern "C" {
        fn clock_gettime(clock_id: i32, tp: *mut Timespec) -> i32;
    }

    /// The CPU time consumed by the calling thread.
    pub fn now() -> Duration {
        let mut t = Timespec { tv_sec: 0, tv_nsec: 0 };
        // SAFETY: `t` is a valid `struct timespec` to write to; the clock id is supported
        // by every Linux since 2.6.12.
        let rc = unsafe { clock_gettime(CLOCK_THREAD_CPUTIME_ID, &mut t) };
        assert_eq!(rc, 0, "clock_gettime(CLOCK_THREAD_CPUTIME_ID) failed");
        Duration::new(t.tv_sec as u64, t.tv_nsec as u32)
    }
}

impl Clock {
    fn from_env() -> Self {
        match std::env::var("MICROSURFACE_BENCH_CLOCK").as_deref() {
            #[cfg(target_os = "linux")]
            Ok("cpu") => Self::ThreadCpu,
            Ok("wall") | Err(_) => Self::Wall,
            Ok(other) => panic!("MICROSURFACE_BENCH_CLOCK={other}: expected `wall` or `cpu`"),
        }
    }

    /// The time since an arbitrary fixed origin.
    fn now(self) -> Duration {
        static ORIGIN: OnceLock<Instant> = OnceLock::new();
        match self {
            Self::Wall => ORIGIN.get_or_init(Instant::now).elapsed(),
            #[cfg(target_os = "linux")]
            Self::ThreadCpu => thread_cpu::now(),
        }
    }
}

impl Measurement for Clock {
    type Intermediate = Duration;
    type Value = Duration;

    fn start(&self) -> Duration {
        self.now()
    }

    fn end(&self, start: Duration) -> Duration {
        self.now().saturating_sub(start)
    }

    fn add(&self, v1: &Duration, v2: &Duration) -> Duration {
        *v1 + *v2
    }

    fn zero(&self) -> Duration {
        Duration::ZERO
    }

    fn to_f64(&self, value: &Duration) -> f64 {
        value.as_nanos() as f64
    }

    fn formatter(&self) -> &dyn ValueFormatter {
        static WALL: WallTime = WallTime;
        WALL.formatter()
    }
}

/// The CPU time of the calling thread (Linux; the wall time since a fixed origin elsewhere):
/// the clock of the report's efficiency table of the invariance-principle estimator, which
/// leaves out the time the thread spends preempted on a shared machine.
pub fn thread_time() -> Duration {
    #[cfg(target_os = "linux")]
    let clock = Clock::ThreadCpu;
    #[cfg(not(target_os = "linux"))]
    let clock = Clock::Wall;
    clock.now()
}

/// Short runs: the matrix is large, and the whole suite should finish in a few minutes.
pub fn config() -> Criterion<Clock> {
    Criterion::default()
        .with_measurement(Clock::from_env())
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(1))
        .sample_size(20)
        .nresamples(20_000)
        .without_plots()
}
