//! The memory a render may take: the least of what the machine, the process's own limit
//! and its job's control group leave ([`available_memory`]).

/// The memory this process can still take (bytes), on Linux the least of:
/// - the machine's `MemAvailable` (`/proc/meminfo`);
/// - the process's own limit on its address space (`ulimit -v`, "Max address space" in
///   `/proc/self/limits`) less what it already maps (`VmSize`, `/proc/self/status`);
/// - its control group's limit (cgroup v2 `memory.max`, or v1
///   `memory.limit_in_bytes`, of the group `/proc/self/cgroup` names, as a Slurm job
///   step runs in) less the group's use (`memory.current`, `memory.usage_in_bytes`).
///
/// Without the limits a render that fits the machine but not the job was not refused up
/// front: the allocation failed half way and the process aborted. `None` elsewhere, or
/// when not even `MemAvailable` can be read (then nothing is checked); a limit that cannot
/// be read is left out.
pub fn available_memory() -> Option<u64> {
    let read = |p: &str| std::fs::read_to_string(p).ok();
    let group = read("/proc/self/cgroup").and_then(|c| {
        let (v2, v1) = cgroup_paths(&c);
        let at = |dir: &str, max: &str, used: &str| {
            let (m, u) = (read(&format!("{dir}/{max}"))?, read(&format!("{dir}/{used}"))?);
            Some((m, u))
        };
        v2.and_then(|d| at(&format!("/sys/fs/cgroup{d}"), "memory.max", "memory.current"))
            .or_else(|| {
                v1.and_then(|d| {
                    at(
                        &format!("/sys/fs/cgroup/memory{d}"),
                        "memory.limit_in_bytes",
                        "memory.usage_in_bytes",
                    )
                })
            })
    });
    least_available(
        &read("/proc/meminfo")?,
        read("/proc/self/limits").as_deref(),
        read("/proc/self/status").as_deref(),
        group.as_ref().map(|(m, u)| (m.as_str(), u.as_str())),
    )
}

/// The cgroup v2 and v1 (memory controller) paths of `/proc/self/cgroup`'s text.
fn cgroup_paths(text: &str) -> (Option<&str>, Option<&str>) {
    let mut v2 = None;
    let mut v1 = None;
    for line in text.lines() {
        let mut f = line.splitn(3, ':');
        let (_, ctl, path) = (f.next(), f.next(), f.next());
        match (ctl, path) {
            (Some(""), Some(p)) => v2 = Some(p),
            (Some(c), Some(p)) if c.split(',').any(|c| c == "memory") => v1 = Some(p),
            _ => {}
        }
    }
    (v2, v1)
}

/// [`available_memory`] from the texts of `/proc/meminfo`, `/proc/self/limits`,
/// `/proc/self/status` and the cgroup's limit and use files.
fn least_available(
    meminfo: &str,
    limits: Option<&str>,
    status: Option<&str>,
    group: Option<(&str, &str)>,
) -> Option<u64> {
    // The first number after `key` on its line, times `unit`.
    let field = |text: &str, key: &str, unit: u64| -> Option<u64> {
        let line = text.lines().find(|l| l.starts_with(key))?;
        line[key.len()..]
            .split_whitespace()
            .next()?
            .parse::<u64>()
            .ok()?
            .checked_mul(unit)
    };
    let mut least = field(meminfo, "MemAvailable:", 1024)?;
    // "unlimited" does not parse: no limit.
    let address = limits.and_then(|l| field(l, "Max address space", 1));
    let mapped = status.and_then(|s| field(s, "VmSize:", 1024));
    if let (Some(limit), Some(mapped)) = (address, mapped) {
        least = least.min(limit.saturating_sub(mapped));
    }
    // "max" (v2) does not parse: no limit; v1 writes a huge number for none.
    if let Some((max, used)) = group
        && let (Ok(max), Ok(used)) = (max.trim().parse::<u64>(), used.trim().parse::<u64>())
    {
        least = least.min(max.saturating_sub(used));
    }
    Some(least)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_process_limit_or_a_job_limit_bounds_the_memory() {
        let meminfo = "MemTotal:       24000000 kB\nMemAvailable:   20000000 kB\n";
        let gb20 = 20_000_000 * 1024;
        assert_eq!(least_available(meminfo, None, None, None), Some(gb20));
        // `ulimit -v 600000` (KiB) with 100 MiB mapped already.
        let limits = "Limit                     Soft Limit           Hard Limit           Units\n\
                      Max address space         614400000            614400000            bytes\n";
        let status = "Name:\tcovtrace\nVmPeak:\t  204800 kB\nVmSize:\t  102400 kB\n";
        assert_eq!(
            least_available(meminfo, Some(limits), Some(status), None),
            Some(614_400_000 - 102_400 * 1024)
        );
        let unlimited = "Max address space         unlimited            unlimited            bytes\n";
        assert_eq!(
            least_available(meminfo, Some(unlimited), Some(status), None),
            Some(gb20)
        );
        // A job step's cgroup: 4 GiB, 1 GiB used; none ("max").
        let g = (4u64 << 30).to_string();
        let u = (1u64 << 30).to_string();
        assert_eq!(
            least_available(meminfo, None, None, Some((&g, &u))),
            Some(3 << 30)
        );
        assert_eq!(
            least_available(meminfo, None, None, Some(("max\n", "123\n"))),
            Some(gb20)
        );
        // No MemAvailable: nothing is checked.
        assert_eq!(
            least_available("MemTotal: 1 kB\n", Some(limits), Some(status), None),
            None
        );
        // The paths of /proc/self/cgroup, v2 and v1.
        assert_eq!(
            cgroup_paths("0::/slurm/uid_0/job_7/step_0\n"),
            (Some("/slurm/uid_0/job_7/step_0"), None)
        );
        assert_eq!(
            cgroup_paths("12:cpu,cpuacct:/a\n9:memory:/slurm/job_7\n"),
            (None, Some("/slurm/job_7"))
        );
    }
}
