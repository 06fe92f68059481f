//! L-systems, turtle geometry and iterated function systems.
//!
//! | module | what |
//! |---|---|
//! | [`expr`] | arithmetic and logical expressions of parametric productions |
//! | [`grammar`] | module strings, productions, the rule text format |
//! | [`derive`] | parallel (stochastic, context-sensitive, parametric) rewriting |
//! | [`turtle`] | 2D and 3D turtle interpretation |
//! | [`mesh`] | generalised cylinders and leaf polygons |
//! | [`export`] | OBJ and PLY files (moved to [`crate::io::mesh`]; re-exported) |
//! | [`ifs`] | iterated function systems, presets, Moran's equation |
//! | [`terrain`] | stochastic plants placed on a DEM, one scene mesh |
//!
//! References: P. Prusinkiewicz and A. Lindenmayer, *The Algorithmic Beauty
//! of Plants*, Springer 1990 (ABOP); M. Barnsley, *Fractals Everywhere*,
//! Academic Press 1988; J. E. Hutchinson, Fractals and self-similarity,
//! *Indiana Univ. Math. J.* 30 (1981) 713-747.
// NaN must fail every check: `!(x > 0.0)` is deliberate.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod derive;
pub use crate::io::mesh as export;
pub mod expr;
pub mod grammar;
pub mod ifs;
pub mod mesh;
pub mod terrain;
pub mod turtle;

pub use derive::LSystem;
pub use grammar::ModString;
