//! The process's peak resident set size, from the kernel's own account.

/// Peak resident set size of this process (bytes): `VmHWM` of `/proc/self/status` (Linux).
/// `None` where the file or the field is missing (another OS), never a guess.
pub fn peak_rss_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: u64 = line
        .trim_start_matches("VmHWM:")
        .trim()
        .trim_end_matches("kB")
        .trim()
        .parse()
        .ok()?;
    Some(kib * 1024)
}
