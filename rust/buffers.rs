//! Large output buffers.
//!
//! A fresh zeroed `Vec` of hundreds of megabytes is mapped lazily by the
//! kernel: the first write to each 4 KiB page faults, and for a kernel that
//! writes every sample once those faults cost about as much as the
//! arithmetic. [`zeroed`] asks Linux for transparent huge pages on such a
//! buffer (`madvise(MADV_HUGEPAGE)`, a hint: one fault per 2 MiB where the
//! system allows it, ignored elsewhere). The contents are zeros either way.
//!
//! Buffers whose size grows with an argument are allocated fallibly
//! ([`try_zeroed`], [`try_filled`], [`try_with_capacity`]): a size that
//! overflows or that the allocator refuses becomes
//! [`CoreError::OutOfMemory`] naming the parameter (a Python `MemoryError`),
//! never an abort of the process.
use crate::error::{CoreError, CoreResult};

/// Buffers from this size on are advised (smaller ones are left alone).
const HUGE_FROM: usize = 8 << 20;

/// `vec![0.0; n]`, on Linux with transparent huge pages advised when the
/// buffer is large (the values are the same).
pub fn zeroed(n: usize) -> Vec<f64> {
    let mut v = vec![0.0f64; n];
    advise_huge_pages(&mut v);
    v
}

/// `vec![0u8; n]` with transparent huge pages advised when the buffer is
/// large, as [`zeroed`].
pub fn zeroed_bytes(n: usize) -> Vec<u8> {
    let mut v = vec![0u8; n];
    advise_huge_pages(&mut v);
    v
}

/// `n` zeros as [`zeroed`] does, or [`CoreError::OutOfMemory`] naming
/// `param` when the buffer cannot be allocated. Zeroed pages come from the
/// allocator (`calloc`-like: not touched here), as with `vec![0.0; n]`.
pub fn try_zeroed(n: usize, param: &str) -> CoreResult<Vec<f64>> {
    let oom = || CoreError::out_of_memory(param, n, std::mem::size_of::<f64>());
    if n == 0 {
        return Ok(Vec::new());
    }
    let layout = std::alloc::Layout::array::<f64>(n).map_err(|_| oom())?;
    // SAFETY: `layout` has a non-zero size (n > 0, f64 is 8 bytes). A
    // non-null pointer from `alloc_zeroed` with this layout owns `n`
    // initialised f64 zeros (all-zero bits are 0.0), so `Vec::from_raw_parts`
    // with length and capacity `n` takes ownership of exactly that
    // allocation; the global allocator frees it with the same layout.
    let mut v = unsafe {
        let ptr = std::alloc::alloc_zeroed(layout) as *mut f64;
        if ptr.is_null() {
            return Err(oom());
        }
        Vec::from_raw_parts(ptr, n, n)
    };
    advise_huge_pages(&mut v);
    Ok(v)
}

/// `vec![value; n]`, or [`CoreError::OutOfMemory`] naming `param`.
pub fn try_filled<T: Clone>(n: usize, value: T, param: &str) -> CoreResult<Vec<T>> {
    let mut v = try_with_capacity(n, param)?;
    v.resize(n, value);
    Ok(v)
}

/// An empty `Vec` with room for `n` elements, or
/// [`CoreError::OutOfMemory`] naming `param`.
pub fn try_with_capacity<T>(n: usize, param: &str) -> CoreResult<Vec<T>> {
    let mut v = Vec::new();
    v.try_reserve_exact(n)
        .map_err(|_| CoreError::out_of_memory(param, n, std::mem::size_of::<T>()))?;
    Ok(v)
}

/// `a * b` elements, or [`CoreError::OutOfMemory`] naming `param` when the
/// product overflows `usize`.
pub fn checked_len(a: usize, b: usize, param: &str) -> CoreResult<usize> {
    a.checked_mul(b).ok_or_else(|| CoreError::OutOfMemory {
        param: param.to_string(),
        bytes: a as u128 * b as u128 * 8,
    })
}

#[cfg(target_os = "linux")]
fn advise_huge_pages<T>(v: &mut [T]) {
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
fn advise_huge_pages<T>(_v: &mut [T]) {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zeroed_is_zeros() {
        for n in [0, 1, 1000, (HUGE_FROM / 8) + 12345] {
            let v = zeroed(n);
            assert_eq!(v.len(), n);
            assert!(v.iter().all(|x| x.to_bits() == 0));
            let w = try_zeroed(n, "n").unwrap();
            assert_eq!(w.len(), n);
            assert!(w.iter().all(|x| x.to_bits() == 0));
        }
    }

    #[test]
    fn impossible_sizes_are_errors_not_aborts() {
        for n in [usize::MAX, usize::MAX / 8, 1usize << 60] {
            match try_zeroed(n, "n") {
                Err(CoreError::OutOfMemory { param, bytes }) => {
                    assert_eq!(param, "n");
                    assert_eq!(bytes, n as u128 * 8);
                }
                other => panic!("expected OutOfMemory, got {:?}", other.map(|v| v.len())),
            }
            assert!(matches!(
                try_filled(n, 0u32, "shape"),
                Err(CoreError::OutOfMemory { .. })
            ));
        }
        assert!(checked_len(usize::MAX, 2, "shape").is_err());
        assert_eq!(checked_len(3, 4, "shape").unwrap(), 12);
        assert_eq!(try_filled(3, 7u8, "n").unwrap(), vec![7, 7, 7]);
    }
}
