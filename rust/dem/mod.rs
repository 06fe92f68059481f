//! DEM work: shaded relief, fractal resampling. (Lakes are a threshold plus contour tracing and
//! live on the Python side with scikit-image.)
pub mod hillshade;
pub mod resample;
