//! DEM work: shaded relief. (Lakes are a threshold plus contour tracing and
//! live on the Python side with scikit-image.)
pub mod hillshade;
