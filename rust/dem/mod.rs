//! DEM work: shaded relief, fractal resampling and its local analysis. (Lakes are a threshold plus contour tracing and
//! live on the Python side with scikit-image.)
pub mod analysis;
pub mod hillshade;
pub mod model_nodes;
pub mod resample;
