//! Criterion benchmark of the binary box-counting kernel alone (no Python).
//! Run: `cargo bench --bench boxcount`. The Python-level comparison against
//! numpy and other packages is `benches/bench_boxcount.py`.
use criterion::{criterion_group, criterion_main, Criterion};
use fractalgeo_rs::dimension::boxcount::{box_count, Anchor, ByteVolume};

fn sierpinski(n: usize) -> Vec<u8> {
    (0..n * n).map(|p| ((p / n) & (p % n) == 0) as u8).collect()
}

fn bench(c: &mut Criterion) {
    for n in [1024usize, 4096] {
        let data = sierpinski(n);
        let vol = ByteVolume::new(&data, &[n, n]).unwrap();
        let sizes: Vec<usize> = (0..=n.trailing_zeros()).map(|k| 1usize << k).collect();
        c.bench_function(&format!("box_count_dyadic_{n}"), |b| {
            b.iter(|| box_count(&vol, 2, &sizes, 1, Anchor::BoundingBox).unwrap())
        });
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
