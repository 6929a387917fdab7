//! Host memory: what a frame needs on the host, and what the host has, so
//! that a frame too large for the machine is refused with the numbers
//! instead of ending the process.

use std::fs;
use std::path::Path;

use super::aov::Outputs;
use super::device::{DeviceInfo, DeviceKind};
use crate::error::{Error, Result};

/// Bytes per pixel of the host copies of a frame's outputs: RGBA only, or
/// with the AOVs (RGBA 4, depth 4, hit 1, normals 12, steps 4, evaluations
/// 4), plus the hit mask as `bool`s and the normals as `[f32; 3]`s made
/// while the flat copies are alive; with the layers, their flat copies
/// (linear 16, layers 36) and the vectors made from them (52).
const fn readback_per_pixel(outputs: Outputs) -> u64 {
    match outputs {
        Outputs::Image => 4,
        Outputs::Aovs => 29 + 1 + 12,
        Outputs::Layers => 29 + 1 + 12 + 52 + 52,
    }
}

/// The host memory a `width` × `height` frame needs, in bytes: the
/// readback vectors and the image, and — where the device's memory is the
/// host's (a CPU device, such as PoCL's) and its output buffers are to be
/// allocated — the `device_buffers` bytes too.
pub(crate) fn frame_host_bytes(
    info: &DeviceInfo,
    width: u32,
    height: u32,
    outputs: Outputs,
    device_buffers: Option<u64>,
) -> u64 {
    let pixels = u64::from(width) * u64::from(height);
    let readback = pixels * readback_per_pixel(outputs);
    let on_host = match (info.kind, device_buffers) {
        (DeviceKind::Cpu, Some(bytes)) => bytes,
        _ => 0,
    };
    readback + on_host
}

/// [`Error::Resolution`] with the numbers if a frame needing `needed`
/// bytes of host memory does not fit in `available` (unknown: no check).
pub(crate) fn check_host_memory(
    width: u32,
    height: u32,
    needed: u64,
    available: Option<u64>,
) -> Result<()> {
    let mib = |b: u64| b.div_ceil(1 << 20);
    match available {
        Some(available) if needed > available => Err(Error::Resolution {
            width,
            height,
            reason: format!(
                "too large for this machine: the frame needs {} MiB of host memory \
                 but {} MiB are available",
                mib(needed),
                available >> 20
            ),
        }),
        _ => Ok(()),
    }
}

/// The host memory this process can still use, in bytes: `MemAvailable`
/// from `/proc/meminfo`, lowered to the room under the process's memory
/// cgroup limit (v2 `memory.max`, v1 `memory.limit_in_bytes`) where it has
/// one. `None` where none of these can be read (outside Linux): frames are
/// then limited by the device's memory only.
pub(crate) fn available_host_memory() -> Option<u64> {
    let meminfo = fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|t| mem_available(&t));
    let cgroup = fs::read_to_string("/proc/self/cgroup")
        .ok()
        .and_then(|t| cgroup_room(&t, Path::new("/sys/fs/cgroup")));
    match (meminfo, cgroup) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    }
}

/// `MemAvailable` of `/proc/meminfo` text, in bytes.
fn mem_available(meminfo: &str) -> Option<u64> {
    let line = meminfo.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let mut words = line.split_whitespace().skip(1);
    let value: u64 = words.next()?.parse().ok()?;
    match words.next() {
        Some("kB") => value.checked_mul(1024),
        None => Some(value),
        Some(_) => None,
    }
}

/// The room left under the memory limits of the cgroup that
/// `/proc/self/cgroup` text names, read below `root`: the smallest
/// `limit − usage` of the group and its ancestors that have a limit.
fn cgroup_room(self_cgroup: &str, root: &Path) -> Option<u64> {
    let read = |p: &Path| -> Option<u64> { fs::read_to_string(p).ok()?.trim().parse().ok() };
    let mut room: Option<u64> = None;
    for line in self_cgroup.lines() {
        let mut parts = line.splitn(3, ':');
        let (_, controllers, path) = (parts.next()?, parts.next()?, parts.next()?);
        let (dir, limit, usage) = if controllers.is_empty() {
            (root.to_path_buf(), "memory.max", "memory.current")
        } else if controllers.split(',').any(|c| c == "memory") {
            (
                root.join("memory"),
                "memory.limit_in_bytes",
                "memory.usage_in_bytes",
            )
        } else {
            continue;
        };
        let mut group = dir.join(path.trim_start_matches('/'));
        // The group and its ancestors, up to the hierarchy's root.
        while group.starts_with(&dir) {
            // An unlimited group reads `max` (v2) or a huge number (v1).
            if let (Some(limit), Some(usage)) = (read(&group.join(limit)), read(&group.join(usage)))
            {
                let left = limit.saturating_sub(usage);
                room = Some(room.map_or(left, |r| r.min(left)));
            }
            if !group.pop() {
                break;
            }
        }
    }
    room
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::device::tests::fake;

    const GIB: u64 = 1 << 30;

    #[test]
    fn frames_too_large_for_the_host_are_refused_with_the_numbers() {
        let cpu = fake("Portable Computing Language", "cpu", DeviceKind::Cpu);
        let gpu = fake("NVIDIA CUDA", "gpu", DeviceKind::Gpu);
        let side = 16384;
        let pixels = 16384 * 16384;
        let device = 29 * pixels;
        // With AOVs on a CPU device: 29 bytes per pixel of device buffers
        // and 42 of host copies, 17.75 GiB in all.
        let needed = frame_host_bytes(&cpu, side, side, Outputs::Aovs, Some(device));
        assert_eq!(needed, 71 * pixels);
        assert_eq!(needed, 18176 << 20);
        let err = check_host_memory(side, side, needed, Some(16 * GIB)).unwrap_err();
        assert!(matches!(
            err,
            Error::Resolution {
                width: 16384,
                height: 16384,
                ..
            }
        ));
        assert_eq!(
            err.to_string(),
            "invalid resolution 16384x16384: too large for this machine: the frame needs \
             18176 MiB of host memory but 16384 MiB are available"
        );
        check_host_memory(side, side, needed, Some(32 * GIB)).unwrap();
        // Unknown: no check.
        check_host_memory(side, side, needed, None).unwrap();
        // Buffers already allocated, or on a GPU, are not counted again.
        assert_eq!(
            frame_host_bytes(&cpu, side, side, Outputs::Aovs, None),
            42 * pixels
        );
        assert_eq!(
            frame_host_bytes(&gpu, side, side, Outputs::Aovs, Some(device)),
            42 * pixels
        );
        // Colour only: 4 bytes per pixel, 1 GiB.
        assert_eq!(
            frame_host_bytes(&gpu, side, side, Outputs::Image, None),
            GIB
        );
        // With the layers: 52 more bytes of flat copies and 52 of vectors.
        assert_eq!(
            frame_host_bytes(&gpu, side, side, Outputs::Layers, None),
            146 * pixels
        );
        check_host_memory(side, side, GIB, Some(GIB)).unwrap();
        assert!(check_host_memory(side, side, GIB + 1, Some(GIB)).is_err());
    }

    #[test]
    fn meminfo_is_read_in_bytes() {
        let text = "MemTotal:       24567890 kB\nMemFree:  100 kB\nMemAvailable:   23684856 kB\n";
        assert_eq!(mem_available(text), Some(23_684_856 * 1024));
        assert_eq!(mem_available("MemTotal: 5 kB\n"), None);
        assert_eq!(mem_available("MemAvailable: lots kB\n"), None);
        assert_eq!(mem_available("MemAvailable: 7 MB\n"), None);
        assert_eq!(
            mem_available("MemAvailable: 18446744073709551615 kB\n"),
            None
        );
        if Path::new("/proc/meminfo").exists() {
            let available = available_host_memory().unwrap();
            assert!(available > 0, "{available}");
        }
    }

    #[test]
    fn cgroup_limits_lower_the_room() {
        let root = std::env::temp_dir().join(format!("fractal-sdf-cgroup-{}", std::process::id()));
        let _ = fs::remove_dir_all(&root);
        let write = |dir: &Path, name: &str, text: &str| {
            fs::create_dir_all(dir).unwrap();
            fs::write(dir.join(name), text).unwrap();
        };
        // v2: the group is unlimited, its parent allows 3 GiB and uses 1.
        let parent = root.join("app");
        let group = parent.join("job");
        write(&group, "memory.max", "max\n");
        write(&group, "memory.current", "1000\n");
        write(&parent, "memory.max", &format!("{}\n", 3 * GIB));
        write(&parent, "memory.current", &format!("{GIB}\n"));
        assert_eq!(cgroup_room("0::/app/job\n", &root), Some(2 * GIB));
        // v1: the memory controller's own hierarchy.
        let v1 = root.join("memory/box");
        write(&v1, "memory.limit_in_bytes", &format!("{GIB}\n"));
        write(&v1, "memory.usage_in_bytes", &format!("{}\n", GIB / 4));
        let text = "4:memory:/box\n3:cpu:/elsewhere\n";
        assert_eq!(cgroup_room(text, &root), Some(GIB * 3 / 4));
        // No limit anywhere, or no files: no room to report.
        assert_eq!(cgroup_room("0::/\n", &root.join("none")), None);
        assert_eq!(cgroup_room("", &root), None);
        fs::remove_dir_all(root).unwrap();
    }
}
