//! What this machine offers a run: the memory a scenario may plan to use, and whether the engine's hot loop may use
//! the CPU's newer instructions.
//!
//! The budget is 80 % of the smaller of the physical memory and the memory limit of the process's control group
//! (a Slurm job's allocation, a container's limit), or `GRANFLOW_MEMORY_BYTES` when set (a user sharing a login
//! node; the tests). A scenario whose estimated memory exceeds it is refused before anything is allocated, so that
//! no input, however large, makes the kernel kill this or anyone else's processes.

/// Environment variable that sets the memory budget in bytes, overriding what the machine reports.
pub const MEMORY_BUDGET_ENV: &str = "GRANFLOW_MEMORY_BYTES";

/// The memory, in bytes, that one run may plan to use, and where the figure comes from; `None` when neither the
/// environment nor the system says (then no budget is enforced).
pub fn memory_budget_bytes() -> Option<(u64, &'static str)> {
    if let Some(v) = std::env::var_os(MEMORY_BUDGET_ENV) {
        return v
            .to_str()
            .and_then(|s| s.trim().parse().ok())
            .map(|b| (b, "set by GRANFLOW_MEMORY_BYTES"));
    }
    let total = physical_memory_bytes();
    let limit = cgroup_limit_bytes();
    let smallest = match (total, limit) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    }?;
    Some((
        smallest / 5 * 4,
        "80 % of its memory; GRANFLOW_MEMORY_BYTES sets another",
    ))
}

/// `MemTotal` of `/proc/meminfo`.
fn physical_memory_bytes() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

/// The memory limit of this process's cgroup (v2 `memory.max`, or v1 `memory.limit_in_bytes`), if it sets one.
fn cgroup_limit_bytes() -> Option<u64> {
    let cgroup = std::fs::read_to_string("/proc/self/cgroup").ok()?;
    for line in cgroup.lines() {
        let mut parts = line.splitn(3, ':');
        let (_, controllers, path) = (parts.next()?, parts.next()?, parts.next()?);
        let candidate = if controllers.is_empty() {
            format!("/sys/fs/cgroup{path}/memory.max")
        } else if controllers.split(',').any(|c| c == "memory") {
            format!("/sys/fs/cgroup/memory{path}/memory.limit_in_bytes")
        } else {
            continue;
        };
        if let Some(limit) = std::fs::read_to_string(&candidate)
            .ok()
            .and_then(|s| s.trim().parse::<u64>().ok())
        {
            return Some(limit);
        }
    }
    None
}

/// Bytes in the largest decimal unit that keeps a digit before the point (`41.0 MB`, `3.2 GB`), for messages.
pub fn bytes_text(bytes: f64) -> String {
    let (value, unit) = [(1e12, "TB"), (1e9, "GB"), (1e6, "MB"), (1e3, "kB")]
        .into_iter()
        .find(|(scale, _)| bytes >= *scale)
        .map_or((bytes, "bytes"), |(scale, unit)| (bytes / scale, unit));
    if bytes >= 1e15 {
        return format!("{:.1e} bytes", bytes);
    }
    format!("{value:.1} {unit}")
}

/// Environment variable that, set to `baseline`, keeps the engine on the x86-64 baseline instructions even where the
/// CPU has newer ones (to compare the two paths; results are the same bits).
pub const CPU_ENV: &str = "GRANFLOW_CPU";

/// Whether the engine's force loop runs its x86-64-v3 compilation (AVX2, FMA, BMI1/2, LZCNT, POPCNT, MOVBE): true
/// when the CPU has all of them and `GRANFLOW_CPU` is not `baseline`. Decided once per process.
pub fn cpu_fast_path() -> bool {
    static FAST: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *FAST.get_or_init(|| {
        if std::env::var(CPU_ENV).is_ok_and(|v| v.trim() == "baseline") {
            return false;
        }
        #[cfg(target_arch = "x86_64")]
        {
            std::arch::is_x86_feature_detected!("avx")
                && std::arch::is_x86_feature_detected!("avx2")
                && std::arch::is_x86_feature_detected!("fma")
                && std::arch::is_x86_feature_detected!("bmi1")
                && std::arch::is_x86_feature_detected!("bmi2")
                && std::arch::is_x86_feature_detected!("lzcnt")
                && std::arch::is_x86_feature_detected!("popcnt")
                && std::arch::is_x86_feature_detected!("movbe")
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            false
        }
    })
}
