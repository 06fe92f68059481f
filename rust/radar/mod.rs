//! Radar: multiplicative speckle and the side-looking geometry of synthetic
//! SAR scenes (local incidence, radar shadow, slant-range projection with
//! layover). The backscatter models themselves are closed forms evaluated
//! on the Python side.
pub mod geometry;
pub mod speckle;
