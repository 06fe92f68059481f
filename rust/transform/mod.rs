//! Fractal transform: maps of local fractal dimension over a moving window
//! (paper section 4.2, figure 10).
//!
//! * [`variation`]: increment estimators (variogram, madogram, square
//!   increments) with summed-area tables, so the cost per pixel does not grow
//!   with the window.
//! * [`lacunarity`]: gliding-box lacunarity per window.
//! * [`mass`]: Voss's P(m, L) mass dimension per window (the box masses are
//!   `crate::dimension::mass`'s).
//! * [`blanket`]: Peleg's covering blanket per window (the growth step is
//!   `crate::dimension::blanket`'s).
//! * [`gls`]: GLS fit of H over the log quadratic variations of increment
//!   filters (summed-area tables).
//! * [`driver`]: the moving-window driver (grid, bands, gate, fit, result)
//!   every map kernel runs on (`crate::window::driver`, re-exported).
//! * [`dbc`]: differential box counting per window (sliding min/max and
//!   summed-area tables strided by the box size).

pub mod blanket;
pub mod dbc;
pub mod gls;
pub mod lacunarity;
pub mod mass;
mod sliding;
pub mod variation;

pub use crate::window::driver;
use crate::window::sat;
