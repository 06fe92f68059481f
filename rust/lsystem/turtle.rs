//! Turtle interpretation of module strings in 2D and 3D (Prusinkiewicz and
//! Lindenmayer 1990, sections 1.2, 1.5 and 5.1).
//!
//! The turtle state is a position and an orthonormal frame: heading `H`,
//! left `L` and up `U = H x L`, plus a segment width and a colour index.
//!
//! | symbol | action |
//! |---|---|
//! | `F`, `G` (the `draw` set) | move forward by `step` (or the first parameter) and draw a segment |
//! | `f`, `g` (the `move` set) | move forward without drawing |
//! | `+` / `-` | turn left / right by `angle` (or the parameter), about `U`: `H` rotates towards `L` for `+` |
//! | `&` / `^` | pitch down / up about `L` (`H` rotates towards `-U` for `&`) |
//! | `\` / `/` | roll left / right about `H` (`L` rotates towards `U` for `\`) |
//! | `\|` | turn around (180 degrees about `U`) |
//! | `$` | roll about `H` so that `L` is horizontal (`L = V x H / \|V x H\|`, `V` = +z) |
//! | `[` / `]` | push / pop the state |
//! | `!` | set the width to the parameter, or multiply it by `width_factor` |
//! | `'` | set the colour index to the parameter, or add 1 |
//! | `{` / `}` | start / end a polygon (a leaf) |
//! | `.` | record the position as a polygon vertex |
//!
//! Inside `{ }` no segment is drawn; the polygon's vertices are the
//! positions recorded by `.`, or, when there is none, the start position and
//! the end of every move. Tropism (ABOP section 2.3.2): after every drawn
//! step the frame rotates about `H x T` by `elasticity * |H x T|`. Angles are
//! in degrees. Other symbols are ignored.
use super::grammar::ModString;
use crate::error::{CoreError, CoreResult};
use glam::{DQuat, DVec3};

/// Marker for "no ring" in [`State::tag`].
pub const NO_TAG: u32 = u32::MAX;

/// Options of the turtle.
#[derive(Debug, Clone, PartialEq)]
pub struct TurtleParams {
    pub angle: f64,
    pub step: f64,
    pub width: f64,
    pub width_factor: f64,
    pub tropism: DVec3,
    pub elasticity: f64,
    pub heading: DVec3,
    pub left: DVec3,
    pub draw: Vec<char>,
    pub moves: Vec<char>,
}

impl TurtleParams {
    /// Defaults for the plane: heading +y, left -x (so `+` turns
    /// counter-clockwise), up +z.
    pub fn planar(angle: f64, step: f64) -> Self {
        TurtleParams {
            angle,
            step,
            width: 1.0,
            width_factor: 0.7,
            tropism: DVec3::ZERO,
            elasticity: 0.0,
            heading: DVec3::Y,
            left: DVec3::NEG_X,
            draw: vec!['F', 'G'],
            moves: vec!['f', 'g'],
        }
    }
    /// Defaults in space: heading +z (up), left -x, up -y; turns with `+`
    /// and `-` alone draw in the x-z plane as [`TurtleParams::planar`] does in x-y.
    pub fn spatial(angle: f64, step: f64) -> Self {
        TurtleParams {
            heading: DVec3::Z,
            left: DVec3::NEG_X,
            ..Self::planar(angle, step)
        }
    }
    /// Check the values; errors name the parameter.
    pub fn validate(&self) -> CoreResult<()> {
        for (name, v) in [
            ("angle", self.angle),
            ("step", self.step),
            ("width", self.width),
            ("width_factor", self.width_factor),
            ("elasticity", self.elasticity),
        ] {
            if !v.is_finite() {
                return Err(CoreError::invalid(name, format!("must be finite, got {v}")));
            }
        }
        if self.step <= 0.0 {
            return Err(CoreError::invalid(
                "step",
                format!("must be positive, got {}", self.step),
            ));
        }
        if self.width < 0.0 {
            return Err(CoreError::invalid(
                "width",
                format!("must be >= 0, got {}", self.width),
            ));
        }
        if !self.tropism.is_finite() {
            return Err(CoreError::invalid("tropism", "must be finite"));
        }
        let (h, l) = (self.heading, self.left);
        if !h.is_finite()
            || !l.is_finite()
            || h.length() < 1e-12
            || l.length() < 1e-12
            || h.normalize().dot(l.normalize()).abs() > 1e-9
        {
            return Err(CoreError::invalid(
                "heading",
                "heading and left must be finite, nonzero and perpendicular",
            ));
        }
        Ok(())
    }
}

/// The turtle's state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct State {
    pub pos: DVec3,
    pub h: DVec3,
    pub l: DVec3,
    pub u: DVec3,
    pub width: f64,
    pub color: u32,
    /// Free for the sink (the mesh builder keeps the ring to continue from).
    pub tag: u32,
}

/// Receives the geometry the turtle draws.
pub trait Sink {
    /// A segment from `from.pos` to `to.pos`; returns the tag for `to`.
    fn segment(&mut self, from: &State, to: &State) -> u32;
    /// A closed polygon (at least 3 vertices).
    fn polygon(&mut self, pts: &[DVec3], color: u32);
    /// The pen was lifted (a move or a pop).
    fn pen_up(&mut self) {}
}

#[inline]
fn rot(a: DVec3, b: DVec3, c: f64, s: f64) -> (DVec3, DVec3) {
    // rotate a towards b by the angle with cosine c and sine s
    (a * c + b * s, b * c - a * s)
}

struct Poly {
    dots: Vec<DVec3>,
    auto: Vec<DVec3>,
    color: u32,
}

/// Interpret `s` with the turtle, sending the geometry to `sink`.
pub fn interpret<S: Sink>(s: &ModString, p: &TurtleParams, sink: &mut S) -> CoreResult<()> {
    p.validate()?;
    let h = p.heading.normalize();
    let l = p.left.normalize();
    let mut st = State {
        pos: DVec3::ZERO,
        h,
        l,
        u: h.cross(l),
        width: p.width,
        color: 0,
        tag: NO_TAG,
    };
    let mut stack: Vec<State> = Vec::new();
    let mut polys: Vec<Poly> = Vec::new();
    let (ds, dc) = p.angle.to_radians().sin_cos();
    let trop = p.elasticity != 0.0 && p.tropism != DVec3::ZERO;
    let is_draw = |c: char| p.draw.contains(&c);
    let is_move = |c: char| p.moves.contains(&c);
    let mut draw_ascii = [false; 128];
    let mut move_ascii = [false; 128];
    for c in 0..128u8 {
        draw_ascii[c as usize] = is_draw(c as char);
        move_ascii[c as usize] = is_move(c as char);
    }
    for i in 0..s.len() {
        let c = s.syms[i];
        let prm = s.params(i);
        let (dr, mv) = if (c as u32) < 128 {
            (draw_ascii[c as usize], move_ascii[c as usize])
        } else {
            (is_draw(c), is_move(c))
        };
        if dr || mv {
            let len = prm.first().copied().unwrap_or(p.step);
            let mut to = st;
            to.pos = st.pos + st.h * len;
            if let Some(poly) = polys.last_mut() {
                poly.auto.push(to.pos);
                to.tag = NO_TAG;
            } else if dr {
                if trop {
                    let axis = to.h.cross(p.tropism);
                    let m = axis.length();
                    if m > 1e-12 {
                        let q = DQuat::from_axis_angle(axis / m, p.elasticity * m);
                        to.h = (q * to.h).normalize();
                        to.l = (q * to.l).normalize();
                        to.u = to.h.cross(to.l);
                    }
                }
                to.tag = sink.segment(&st, &to);
            } else {
                to.tag = NO_TAG;
                sink.pen_up();
            }
            st = to;
            continue;
        }
        let angle = |default: (f64, f64)| -> (f64, f64) {
            match prm.first() {
                Some(a) => a.to_radians().sin_cos(),
                None => default,
            }
        };
        match c {
            '+' => {
                let (s_, c_) = angle((ds, dc));
                (st.h, st.l) = rot(st.h, st.l, c_, s_);
            }
            '-' => {
                let (s_, c_) = angle((ds, dc));
                (st.h, st.l) = rot(st.h, st.l, c_, -s_);
            }
            '&' => {
                let (s_, c_) = angle((ds, dc));
                (st.h, st.u) = rot(st.h, st.u, c_, -s_);
            }
            '^' => {
                let (s_, c_) = angle((ds, dc));
                (st.h, st.u) = rot(st.h, st.u, c_, s_);
            }
            '\\' => {
                let (s_, c_) = angle((ds, dc));
                (st.l, st.u) = rot(st.l, st.u, c_, s_);
            }
            '/' => {
                let (s_, c_) = angle((ds, dc));
                (st.l, st.u) = rot(st.l, st.u, c_, -s_);
            }
            '|' => {
                st.h = -st.h;
                st.l = -st.l;
            }
            '$' => {
                let v = DVec3::Z.cross(st.h);
                let m = v.length();
                if m > 1e-12 {
                    st.l = v / m;
                    st.u = st.h.cross(st.l);
                }
            }
            '[' => {
                stack.push(st);
                st.tag = NO_TAG; // a branch starts its own tube
            }
            ']' => {
                st = stack.pop().ok_or_else(|| {
                    CoreError::invalid("lstring", format!("unbalanced ']' at module {i}"))
                })?;
                sink.pen_up();
            }
            '!' => {
                st.width = match prm.first() {
                    Some(&w) => w,
                    None => st.width * p.width_factor,
                };
            }
            '\'' => {
                st.color = match prm.first() {
                    Some(&k) if k >= 0.0 => k as u32,
                    Some(_) => 0,
                    None => st.color.saturating_add(1),
                };
            }
            '{' => polys.push(Poly {
                dots: Vec::new(),
                auto: vec![st.pos],
                color: st.color,
            }),
            '.' => {
                if let Some(poly) = polys.last_mut() {
                    poly.dots.push(st.pos);
                }
            }
            '}' => {
                let poly = polys.pop().ok_or_else(|| {
                    CoreError::invalid("lstring", format!("unbalanced '}}' at module {i}"))
                })?;
                let pts = if poly.dots.is_empty() {
                    poly.auto
                } else {
                    poly.dots
                };
                if pts.len() >= 3 {
                    sink.polygon(&pts, poly.color);
                }
                st.tag = NO_TAG;
            }
            _ => {}
        }
    }
    if !stack.is_empty() {
        return Err(CoreError::invalid(
            "lstring",
            "unbalanced '[': the string ends inside a branch",
        ));
    }
    Ok(())
}

/// 2D polylines: the x, y of every drawn vertex and where each polyline
/// starts (`offsets`, one more entry than polylines).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Polylines {
    pub xy: Vec<[f64; 2]>,
    pub offsets: Vec<u32>,
    open: bool,
    last: DVec3,
    pub polygons: Vec<Vec<[f64; 2]>>,
}

impl Sink for Polylines {
    fn segment(&mut self, from: &State, to: &State) -> u32 {
        if self.offsets.is_empty() {
            self.offsets.push(0);
        }
        if !self.open || self.last != from.pos {
            let n = self.xy.len() as u32;
            if n > *self.offsets.last().unwrap() {
                self.offsets.push(n);
            }
            self.xy.push([from.pos.x, from.pos.y]);
            self.open = true;
        }
        self.xy.push([to.pos.x, to.pos.y]);
        self.last = to.pos;
        0
    }
    fn polygon(&mut self, pts: &[DVec3], _color: u32) {
        self.polygons.push(pts.iter().map(|p| [p.x, p.y]).collect());
        self.open = false;
    }
    fn pen_up(&mut self) {
        self.open = false;
    }
}

impl Polylines {
    /// Close the last polyline; an empty drawing has offsets `[0]`.
    pub fn finish(mut self) -> Self {
        if self.offsets.is_empty() {
            self.offsets.push(0);
        }
        let n = self.xy.len() as u32;
        if n > *self.offsets.last().unwrap() {
            self.offsets.push(n);
        }
        self
    }
}

/// 3D segments with widths and colour indices.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Segments {
    pub starts: Vec<[f64; 3]>,
    pub ends: Vec<[f64; 3]>,
    pub widths: Vec<f64>,
    pub colors: Vec<u32>,
    pub polygons: Vec<Vec<[f64; 3]>>,
}

impl Sink for Segments {
    fn segment(&mut self, from: &State, to: &State) -> u32 {
        self.starts.push(from.pos.to_array());
        self.ends.push(to.pos.to_array());
        self.widths.push(from.width);
        self.colors.push(from.color);
        0
    }
    fn polygon(&mut self, pts: &[DVec3], _color: u32) {
        self.polygons
            .push(pts.iter().map(|p| p.to_array()).collect());
    }
}

/// Interpret in the plane (see [`TurtleParams::planar`]).
pub fn polylines(s: &ModString, p: &TurtleParams) -> CoreResult<Polylines> {
    let mut sink = Polylines::default();
    interpret(s, p, &mut sink)?;
    Ok(sink.finish())
}

/// Interpret in space, returning the segments.
pub fn segments(s: &ModString, p: &TurtleParams) -> CoreResult<Segments> {
    let mut sink = Segments::default();
    interpret(s, p, &mut sink)?;
    Ok(sink)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lsystem::derive::{LSystem, DEFAULT_MAX_LENGTH};
    use crate::lsystem::grammar::parse_module_string;

    fn derive(axiom: &str, rules: &[&str], n: usize) -> ModString {
        let r: Vec<String> = rules.iter().map(|s| s.to_string()).collect();
        LSystem::new(axiom, &r, "", 0, DEFAULT_MAX_LENGTH)
            .unwrap()
            .derive(n)
            .unwrap()
    }

    #[test]
    fn square_closes_and_turns_left() {
        let s = parse_module_string("F+F+F+F", "axiom").unwrap();
        let p = polylines(&s, &TurtleParams::planar(90.0, 2.0)).unwrap();
        assert_eq!(p.offsets, vec![0, 5]);
        let want = [[0.0, 0.0], [0.0, 2.0], [-2.0, 2.0], [-2.0, 0.0], [0.0, 0.0]];
        for (a, b) in p.xy.iter().zip(want) {
            assert!(
                (a[0] - b[0]).abs() < 1e-12 && (a[1] - b[1]).abs() < 1e-12,
                "{a:?} {b:?}"
            );
        }
        // f lifts the pen, brackets restore the position
        let s = parse_module_string("F[+F]fF(3)", "axiom").unwrap();
        let p = polylines(&s, &TurtleParams::planar(90.0, 1.0)).unwrap();
        // the branch continues the first polyline; the move starts a new one
        assert_eq!(p.offsets, vec![0, 3, 5]);
        assert_eq!(p.xy[2], [-1.0, 1.0]);
        assert_eq!(p.xy[4], [0.0, 5.0]);
    }

    #[test]
    fn frame_stays_orthonormal() {
        let s = derive("A", &["A -> F&+\\/^|$!'F[-F]A"], 200);
        let mut p = TurtleParams::spatial(37.0, 1.0);
        p.tropism = DVec3::new(0.0, 0.0, -1.0);
        p.elasticity = 0.2;
        let seg = segments(&s, &p).unwrap();
        assert_eq!(seg.starts.len(), 600);
        for (a, b) in seg.starts.iter().zip(&seg.ends) {
            let d = DVec3::from_array(*b) - DVec3::from_array(*a);
            assert!((d.length() - 1.0).abs() < 1e-9);
        }
        assert!(seg.widths.last().unwrap() < &1e-10);
    }

    #[test]
    fn polygons_from_dots_or_moves() {
        let s = parse_module_string("{.f.+f.+f.}{f+f+f}", "axiom").unwrap();
        let seg = segments(&s, &TurtleParams::spatial(90.0, 1.0)).unwrap();
        assert_eq!(seg.polygons.len(), 2);
        assert_eq!(seg.polygons[0].len(), 4);
        assert_eq!(seg.polygons[1].len(), 4);
        assert!(seg.starts.is_empty());
    }

    #[test]
    fn bad_turtle_input() {
        let s = parse_module_string("F", "axiom").unwrap();
        let mut p = TurtleParams::planar(90.0, 0.0);
        assert!(polylines(&s, &p)
            .unwrap_err()
            .to_string()
            .starts_with("step:"));
        p.step = 1.0;
        p.angle = f64::NAN;
        assert!(polylines(&s, &p)
            .unwrap_err()
            .to_string()
            .starts_with("angle:"));
    }
}

#[cfg(test)]
mod hilbert_tests {
    use super::*;
    use crate::lsystem::derive::{LSystem, DEFAULT_MAX_LENGTH};
    use std::collections::HashSet;

    /// ABOP figure 1.16: the 3D Hilbert curve visits every point of the
    /// 4x4x4 lattice exactly once at n = 2, with unit steps.
    #[test]
    fn hilbert_3d_visits_lattice_once() {
        let rules: Vec<String> = [
            "A -> B-F+CFC+F-D&F^D-F+&&CFC+F+B//",
            "B -> A&F^CFB^F^D^^-F-D^|F^B|FC^F^A//",
            "C -> |D^|F^B-F+C^F^A&&FA&F^C+F+B^F^D//",
            "D -> |CFB-F+B|FA&F^A&&FB-F+B|FC//",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        let s = LSystem::new("A", &rules, "", 0, DEFAULT_MAX_LENGTH)
            .unwrap()
            .derive(2)
            .unwrap();
        let seg = segments(&s, &TurtleParams::spatial(90.0, 1.0)).unwrap();
        assert_eq!(seg.starts.len(), 63);
        let mut seen = HashSet::new();
        let key = |p: &[f64; 3]| p.map(|x| x.round() as i64);
        seen.insert(key(&seg.starts[0]));
        for (a, b) in seg.starts.iter().zip(&seg.ends) {
            for k in 0..3 {
                assert!((a[k] - a[k].round()).abs() < 1e-9 && (b[k] - b[k].round()).abs() < 1e-9);
            }
            assert!(seen.insert(key(b)), "vertex {:?} visited twice", key(b));
        }
        assert_eq!(seen.len(), 64);
        for k in 0..3 {
            let lo = seen.iter().map(|p| p[k]).min().unwrap();
            let hi = seen.iter().map(|p| p[k]).max().unwrap();
            assert_eq!(hi - lo, 3);
        }
        // consecutive segments are contiguous
        for w in seg.starts.windows(2).zip(seg.ends.iter()) {
            assert_eq!(key(&w.0[1]), key(w.1));
        }
    }
}
