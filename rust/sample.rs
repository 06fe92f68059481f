//! The sample types the raster kernels read.

/// A sample type a kernel reads (`f32` or `f64`), widened to `f64`.
pub trait Sample: Copy + Send + Sync {
    fn to_f64(self) -> f64;
}
impl Sample for f32 {
    #[inline]
    fn to_f64(self) -> f64 {
        self as f64
    }
}
impl Sample for f64 {
    #[inline]
    fn to_f64(self) -> f64 {
        self
    }
}
