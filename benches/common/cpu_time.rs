//! The process's CPU time, which another process's load does not inflate: what the benchmarks
//! run on a shared machine (`benches/mesh_overlap.rs`, `benches/interface.rs`) time besides
//! criterion's wall-clock medians.

/// The process's CPU time in seconds (every thread).
pub fn cpu_seconds() -> f64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid, writable timespec; the clock id is a constant of the platform.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut ts) };
    assert_eq!(rc, 0, "clock_gettime(CLOCK_PROCESS_CPUTIME_ID)");
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}
