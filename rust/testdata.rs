//! Test inputs shared by the kernels' unit tests (compiled for tests only).

/// `n` uniform numbers in [0, 1) from a 64-bit linear congruential
/// generator (Knuth's MMIX constants) started at `seed`: a fixed, portable
/// stream that the tests of several kernels draw their rough surfaces from.
pub fn uniform(n: usize, seed: u64) -> Vec<f64> {
    let mut state = seed;
    (0..n)
        .map(|_| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        })
        .collect()
}
