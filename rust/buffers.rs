//! Large output buffers.
//!
//! A fresh zeroed `Vec` of hundreds of megabytes is mapped lazily by the
//! kernel: the first write to each 4 KiB page faults, and for a kernel that
//! writes every sample once those faults cost about as much as the
//! arithmetic. [`zeroed`] asks Linux for transparent huge pages on such a
//! buffer (`madvise(MADV_HUGEPAGE)`, a hint: one fault per 2 MiB where the
//! system allows it, ignored elsewhere). The contents are zeros either way.

/// Buffers from this size on are advised (smaller ones are left alone).
const HUGE_FROM: usize = 8 << 20;

/// `vec![0.0; n]`, on Linux with transparent huge pages advised when the
/// buffer is large (the values are the same).
pub fn zeroed(n: usize) -> Vec<f64> {
    let mut v = vec![0.0f64; n];
    advise_huge_pages(&mut v);
    v
}

#[cfg(target_os = "linux")]
fn advise_huge_pages(v: &mut [f64]) {
    const HUGE: usize = 2 << 20;
    let bytes = std::mem::size_of_val(v);
    if bytes < HUGE_FROM {
        return;
    }
    // The whole 2 MiB pages inside the buffer.
    let start = v.as_mut_ptr() as usize;
    let lo = start.next_multiple_of(HUGE);
    let hi = (start + bytes) / HUGE * HUGE;
    if hi > lo {
        // SAFETY: [lo, hi) lies inside `v`'s allocation, which `v` borrows
        // mutably; MADV_HUGEPAGE only changes how pages are backed, never
        // their contents. The result is ignored: it is a hint (EINVAL when
        // transparent huge pages are disabled).
        unsafe {
            libc::madvise(lo as *mut libc::c_void, hi - lo, libc::MADV_HUGEPAGE);
        }
    }
}

#[cfg(not(target_os = "linux"))]
fn advise_huge_pages(_v: &mut [f64]) {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zeroed_is_zeros() {
        for n in [0, 1, 1000, (HUGE_FROM / 8) + 12345] {
            let v = zeroed(n);
            assert_eq!(v.len(), n);
            assert!(v.iter().all(|x| x.to_bits() == 0));
        }
    }
}
