//! CPU time, the figure benchmarks are judged on (this process's, a thread's, and the
//! waited-for children's, the EDA tools a benchmark runs): on a shared machine the wall-clock rate
//! drops with the load, the CPU time of the measured thread or process does not.

/// CPU time this thread has run (ns), from the scheduler's statistics
/// (`/proc/thread-self/schedstat`, Linux). `None` elsewhere.
pub fn thread_cpu_ns() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    text.split_whitespace().next()?.parse().ok()
}

/// [`thread_cpu_ns`] in seconds: the work "on one core" of the calling thread, which wall
/// time on a shared machine inflates by contention; `None` off Linux.
pub fn thread_cpu_seconds() -> Option<f64> {
    thread_cpu_ns().map(|ns| ns as f64 * 1e-9)
}

/// User + system CPU seconds of this process (Linux /proc; 100 ticks/s, the kernel's
/// USER_HZ on every mainstream architecture). `None` elsewhere.
pub fn process_cpu_seconds() -> Option<f64> {
    stat_seconds(11)
}

/// User + system CPU seconds of this process's waited-for children (the tools a command
/// runs: Verilator, the C++ compiler, a harness), as [`process_cpu_seconds`].
pub fn children_cpu_seconds() -> Option<f64> {
    stat_seconds(13)
}

/// The sum of the two tick counts at `first` and `first + 1` of /proc/self/stat's fields
/// after the parenthesised command name (state is 0 there: utime 11, stime 12, cutime 13,
/// cstime 14), in seconds.
fn stat_seconds(first: usize) -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    let rest = stat.rsplit_once(')')?.1;
    let f: Vec<&str> = rest.split_whitespace().collect();
    let user: f64 = f.get(first)?.parse().ok()?;
    let system: f64 = f.get(first + 1)?.parse().ok()?;
    Some((user + system) / 100.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn children_time_grows_by_a_busy_child() {
        // A child that spins ≈ 0.3 s of CPU: the children's figure grows, this process's
        // own does not by as much (it only waits).
        let before = children_cpu_seconds().unwrap();
        let st = std::process::Command::new("sh")
            .args(["-c", "i=0; while [ $i -lt 300000 ]; do i=$((i+1)); done"])
            .status()
            .unwrap();
        assert!(st.success());
        let grew = children_cpu_seconds().unwrap() - before;
        assert!(grew >= 0.05, "children grew {grew} s");
        assert!(process_cpu_seconds().unwrap() >= 0.0);
    }
}
