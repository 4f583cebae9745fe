//! The CPU time of the calling thread, shared by the benchmarks that report CPU-seconds
//! (included with `#[path = "common/cpu.rs"] mod cpu;`).

use std::time::Duration;

/// CPU time of the calling thread (wall time where no thread clock is available).
#[cfg(target_os = "linux")]
pub fn cpu_now() -> Duration {
    #[repr(C)]
    struct Timespec {
        tv_sec: i64,
        tv_nsec: i64,
    }
    unsafe extern "C" {
        fn clock_gettime(clock: i32, tp: *mut Timespec) -> i32;
    }
    /// `CLOCK_THREAD_CPUTIME_ID` of Linux.
    const THREAD_CPUTIME: i32 = 3;
    let mut t = Timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `t` is a valid, writable timespec (two i64 on 64-bit Linux, the layout of
    // `struct timespec`), and the clock id is a constant Linux defines.
    let rc = unsafe { clock_gettime(THREAD_CPUTIME, &mut t) };
    assert_eq!(rc, 0, "clock_gettime(CLOCK_THREAD_CPUTIME_ID) failed");
    Duration::new(t.tv_sec as u64, t.tv_nsec as u32)
}

/// CPU time of the calling thread (wall time where no thread clock is available).
#[cfg(not(target_os = "linux"))]
pub fn cpu_now() -> Duration {
    use std::sync::OnceLock;
    use std::time::Instant;
    static START: OnceLock<Instant> = OnceLock::new();
    START.get_or_init(Instant::now).elapsed()
}
