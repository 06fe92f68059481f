//! Arithmetic and logical expressions of parametric L-systems
//! (Prusinkiewicz and Lindenmayer 1990, section 1.10).
//!
//! Grammar, loosest binding first:
//!
//! ```text
//! expr    := or
//! or      := and  (("||" | "or") and)*
//! and     := cmp  (("&&" | "and") cmp)*
//! cmp     := sum  (("<" | "<=" | ">" | ">=" | "==" | "=" | "!=") sum)?
//! sum     := prod (("+" | "-") prod)*
//! prod    := unary (("*" | "/" | "%") unary)*
//! unary   := ("-" | "+" | "!" | "not") unary | power
//! power   := atom ("^" unary)?            (right associative)
//! atom    := number | name | name "(" expr ("," expr)* ")" | "(" expr ")"
//! ```
//!
//! Names are the formal parameters of the rule (resolved to slots when the
//! rule is compiled, so an unknown name is an error at parse time) and the
//! constants `pi` and `e`. Functions: `sin cos tan asin acos atan atan2 sqrt
//! abs exp log floor ceil round min max sign`; trigonometric functions take
//! degrees, as in cpfg. Comparisons and logic return 1 or 0; a condition
//! holds when its value is nonzero.
use crate::error::{CoreError, CoreResult};

/// Binary operators.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BinOp {
    Add,
    Sub,
    Mul,
    Div,
    Rem,
    Pow,
    Lt,
    Le,
    Gt,
    Ge,
    Eq,
    Ne,
    And,
    Or,
}

/// Built-in functions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Func {
    Sin,
    Cos,
    Tan,
    Asin,
    Acos,
    Atan,
    Atan2,
    Sqrt,
    Abs,
    Exp,
    Log,
    Floor,
    Ceil,
    Round,
    Min,
    Max,
    Sign,
}

impl Func {
    fn from_name(s: &str) -> Option<(Func, usize)> {
        Some(match s {
            "sin" => (Func::Sin, 1),
            "cos" => (Func::Cos, 1),
            "tan" => (Func::Tan, 1),
            "asin" => (Func::Asin, 1),
            "acos" => (Func::Acos, 1),
            "atan" => (Func::Atan, 1),
            "atan2" => (Func::Atan2, 2),
            "sqrt" => (Func::Sqrt, 1),
            "abs" => (Func::Abs, 1),
            "exp" => (Func::Exp, 1),
            "log" => (Func::Log, 1),
            "floor" => (Func::Floor, 1),
            "ceil" => (Func::Ceil, 1),
            "round" => (Func::Round, 1),
            "min" => (Func::Min, 2),
            "max" => (Func::Max, 2),
            "sign" => (Func::Sign, 1),
            _ => return None,
        })
    }
}

/// A compiled expression; variables are slots of the rule's binding array.
#[derive(Debug, Clone, PartialEq)]
pub enum Expr {
    Num(f64),
    Var(usize),
    Neg(Box<Expr>),
    Not(Box<Expr>),
    Bin(BinOp, Box<Expr>, Box<Expr>),
    Call(Func, Vec<Expr>),
}

impl Expr {
    /// Evaluate with the bound variable values `vars`.
    pub fn eval(&self, vars: &[f64]) -> f64 {
        match self {
            Expr::Num(v) => *v,
            Expr::Var(i) => vars[*i],
            Expr::Neg(a) => -a.eval(vars),
            Expr::Not(a) => b2f(a.eval(vars) == 0.0),
            Expr::Bin(op, a, b) => {
                let x = a.eval(vars);
                match op {
                    BinOp::And => return b2f(x != 0.0 && b.eval(vars) != 0.0),
                    BinOp::Or => return b2f(x != 0.0 || b.eval(vars) != 0.0),
                    _ => {}
                }
                let y = b.eval(vars);
                match op {
                    BinOp::Add => x + y,
                    BinOp::Sub => x - y,
                    BinOp::Mul => x * y,
                    BinOp::Div => x / y,
                    BinOp::Rem => x % y,
                    BinOp::Pow => x.powf(y),
                    BinOp::Lt => b2f(x < y),
                    BinOp::Le => b2f(x <= y),
                    BinOp::Gt => b2f(x > y),
                    BinOp::Ge => b2f(x >= y),
                    BinOp::Eq => b2f(x == y),
                    BinOp::Ne => b2f(x != y),
                    BinOp::And | BinOp::Or => unreachable!(),
                }
            }
            Expr::Call(f, args) => {
                let a = args[0].eval(vars);
                match f {
                    Func::Sin => a.to_radians().sin(),
                    Func::Cos => a.to_radians().cos(),
                    Func::Tan => a.to_radians().tan(),
                    Func::Asin => a.asin().to_degrees(),
                    Func::Acos => a.acos().to_degrees(),
                    Func::Atan => a.atan().to_degrees(),
                    Func::Atan2 => a.atan2(args[1].eval(vars)).to_degrees(),
                    Func::Sqrt => a.sqrt(),
                    Func::Abs => a.abs(),
                    Func::Exp => a.exp(),
                    Func::Log => a.ln(),
                    Func::Floor => a.floor(),
                    Func::Ceil => a.ceil(),
                    Func::Round => a.round(),
                    Func::Min => a.min(args[1].eval(vars)),
                    Func::Max => a.max(args[1].eval(vars)),
                    Func::Sign => {
                        if a > 0.0 {
                            1.0
                        } else if a < 0.0 {
                            -1.0
                        } else {
                            0.0
                        }
                    }
                }
            }
        }
    }

    /// True when the expression uses no variable (its value is a constant).
    pub fn is_constant(&self) -> bool {
        match self {
            Expr::Num(_) => true,
            Expr::Var(_) => false,
            Expr::Neg(a) | Expr::Not(a) => a.is_constant(),
            Expr::Bin(_, a, b) => a.is_constant() && b.is_constant(),
            Expr::Call(_, args) => args.iter().all(|a| a.is_constant()),
        }
    }
}

#[inline]
fn b2f(b: bool) -> f64 {
    if b {
        1.0
    } else {
        0.0
    }
}

#[derive(Debug, Clone, PartialEq)]
enum Tok {
    Num(f64),
    Name(String),
    Op(&'static str),
}

fn tokenize(src: &str, param: &str) -> CoreResult<Vec<Tok>> {
    let chars: Vec<char> = src.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    const OPS2: [&str; 6] = ["<=", ">=", "==", "!=", "&&", "||"];
    const OPS1: [&str; 12] = ["+", "-", "*", "/", "%", "^", "(", ")", ",", "<", ">", "!"];
    while i < chars.len() {
        let c = chars[i];
        if c.is_whitespace() {
            i += 1;
            continue;
        }
        if c.is_ascii_digit() || (c == '.' && chars.get(i + 1).is_some_and(|d| d.is_ascii_digit()))
        {
            let start = i;
            while i < chars.len() && (chars[i].is_ascii_digit() || chars[i] == '.') {
                i += 1;
            }
            if i < chars.len() && (chars[i] == 'e' || chars[i] == 'E') {
                let mut j = i + 1;
                if j < chars.len() && (chars[j] == '+' || chars[j] == '-') {
                    j += 1;
                }
                if j < chars.len() && chars[j].is_ascii_digit() {
                    i = j;
                    while i < chars.len() && chars[i].is_ascii_digit() {
                        i += 1;
                    }
                }
            }
            let s: String = chars[start..i].iter().collect();
            let v: f64 = s.parse().map_err(|_| {
                CoreError::invalid(param, format!("bad number {s:?} in expression {src:?}"))
            })?;
            out.push(Tok::Num(v));
            continue;
        }
        if c.is_alphabetic() || c == '_' {
            let start = i;
            while i < chars.len() && (chars[i].is_alphanumeric() || chars[i] == '_') {
                i += 1;
            }
            out.push(Tok::Name(chars[start..i].iter().collect()));
            continue;
        }
        if i + 1 < chars.len() {
            let two: String = chars[i..i + 2].iter().collect();
            if let Some(op) = OPS2.iter().find(|&&o| o == two) {
                out.push(Tok::Op(op));
                i += 2;
                continue;
            }
        }
        if c == '=' {
            out.push(Tok::Op("=="));
            i += 1;
            continue;
        }
        let s = c.to_string();
        if let Some(op) = OPS1.iter().find(|&&o| o == s) {
            out.push(Tok::Op(op));
            i += 1;
            continue;
        }
        return Err(CoreError::invalid(
            param,
            format!("unexpected character {c:?} in expression {src:?}"),
        ));
    }
    Ok(out)
}

/// Deepest nesting of parentheses and unary operators accepted (the parser
/// is recursive; this keeps it far from the stack limit).
pub const MAX_DEPTH: usize = 200;

struct Parser<'a> {
    toks: Vec<Tok>,
    pos: usize,
    depth: usize,
    src: &'a str,
    param: &'a str,
    lookup: &'a dyn Fn(&str) -> Option<usize>,
}

impl<'a> Parser<'a> {
    fn err(&self, msg: &str) -> CoreError {
        CoreError::invalid(self.param, format!("{msg} in expression {:?}", self.src))
    }
    fn peek_op(&self) -> Option<&'static str> {
        match self.toks.get(self.pos) {
            Some(Tok::Op(o)) => Some(o),
            Some(Tok::Name(n)) if n == "and" => Some("&&"),
            Some(Tok::Name(n)) if n == "or" => Some("||"),
            Some(Tok::Name(n)) if n == "not" => Some("!"),
            _ => None,
        }
    }
    fn expect(&mut self, op: &str) -> CoreResult<()> {
        if self.peek_op() == Some(op) {
            self.pos += 1;
            Ok(())
        } else {
            Err(self.err(&format!("expected {op:?}")))
        }
    }
    fn binary(&mut self, level: usize) -> CoreResult<Expr> {
        const LEVELS: [&[(&str, BinOp)]; 4] = [
            &[("||", BinOp::Or)],
            &[("&&", BinOp::And)],
            &[
                ("<", BinOp::Lt),
                ("<=", BinOp::Le),
                (">", BinOp::Gt),
                (">=", BinOp::Ge),
                ("==", BinOp::Eq),
                ("!=", BinOp::Ne),
            ],
            &[("+", BinOp::Add), ("-", BinOp::Sub)],
        ];
        if level == LEVELS.len() {
            return self.product();
        }
        let mut lhs = self.binary(level + 1)?;
        while let Some(op) = self.peek_op() {
            let Some(&(_, b)) = LEVELS[level].iter().find(|(o, _)| *o == op) else {
                break;
            };
            self.pos += 1;
            let rhs = self.binary(level + 1)?;
            lhs = Expr::Bin(b, Box::new(lhs), Box::new(rhs));
            if level == 2 {
                break; // comparisons do not chain
            }
        }
        Ok(lhs)
    }
    fn product(&mut self) -> CoreResult<Expr> {
        let mut lhs = self.unary()?;
        while let Some(op) = self.peek_op() {
            let b = match op {
                "*" => BinOp::Mul,
                "/" => BinOp::Div,
                "%" => BinOp::Rem,
                _ => break,
            };
            self.pos += 1;
            let rhs = self.unary()?;
            lhs = Expr::Bin(b, Box::new(lhs), Box::new(rhs));
        }
        Ok(lhs)
    }
    fn enter(&mut self) -> CoreResult<()> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return Err(self.err(&format!("nesting deeper than {MAX_DEPTH}")));
        }
        Ok(())
    }
    fn unary(&mut self) -> CoreResult<Expr> {
        self.enter()?;
        let r = self.unary_inner();
        self.depth -= 1;
        r
    }
    fn unary_inner(&mut self) -> CoreResult<Expr> {
        match self.peek_op() {
            Some("-") => {
                self.pos += 1;
                Ok(Expr::Neg(Box::new(self.unary()?)))
            }
            Some("+") => {
                self.pos += 1;
                self.unary()
            }
            Some("!") => {
                self.pos += 1;
                Ok(Expr::Not(Box::new(self.unary()?)))
            }
            _ => self.power(),
        }
    }
    fn power(&mut self) -> CoreResult<Expr> {
        let base = self.atom()?;
        if self.peek_op() == Some("^") {
            self.pos += 1;
            let exp = self.unary()?;
            return Ok(Expr::Bin(BinOp::Pow, Box::new(base), Box::new(exp)));
        }
        Ok(base)
    }
    fn atom(&mut self) -> CoreResult<Expr> {
        let tok = self.toks.get(self.pos).cloned();
        match tok {
            Some(Tok::Num(v)) => {
                self.pos += 1;
                Ok(Expr::Num(v))
            }
            Some(Tok::Op("(")) => {
                self.pos += 1;
                let e = self.binary(0)?;
                self.expect(")")?;
                Ok(e)
            }
            Some(Tok::Name(name)) => {
                self.pos += 1;
                if self.peek_op() == Some("(") {
                    let (f, arity) = Func::from_name(&name)
                        .ok_or_else(|| self.err(&format!("unknown function {name:?}")))?;
                    self.pos += 1;
                    let mut args = vec![self.binary(0)?];
                    while self.peek_op() == Some(",") {
                        self.pos += 1;
                        args.push(self.binary(0)?);
                    }
                    self.expect(")")?;
                    if args.len() != arity {
                        return Err(self.err(&format!(
                            "{name} takes {arity} argument(s), got {}",
                            args.len()
                        )));
                    }
                    return Ok(Expr::Call(f, args));
                }
                if let Some(slot) = (self.lookup)(&name) {
                    return Ok(Expr::Var(slot));
                }
                match name.as_str() {
                    "pi" => Ok(Expr::Num(std::f64::consts::PI)),
                    "e" => Ok(Expr::Num(std::f64::consts::E)),
                    _ => Err(self.err(&format!("unknown parameter {name:?}"))),
                }
            }
            Some(Tok::Op(o)) => Err(self.err(&format!("unexpected {o:?}"))),
            None => Err(self.err("unexpected end")),
        }
    }
}

/// Parse `src` into an [`Expr`]; `lookup` maps a parameter name to its slot.
/// Errors name `param` (the user-facing argument that holds the text).
pub fn parse_expr(
    src: &str,
    param: &str,
    lookup: &dyn Fn(&str) -> Option<usize>,
) -> CoreResult<Expr> {
    let toks = tokenize(src, param)?;
    if toks.is_empty() {
        return Err(CoreError::invalid(
            param,
            format!("empty expression in {src:?}"),
        ));
    }
    let mut p = Parser {
        toks,
        pos: 0,
        depth: 0,
        src,
        param,
        lookup,
    };
    let e = p.binary(0)?;
    if p.pos != p.toks.len() {
        return Err(p.err("trailing text"));
    }
    Ok(e)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ev(src: &str, vars: &[(&str, f64)]) -> f64 {
        let names: Vec<&str> = vars.iter().map(|v| v.0).collect();
        let vals: Vec<f64> = vars.iter().map(|v| v.1).collect();
        let look = |n: &str| names.iter().position(|&m| m == n);
        parse_expr(src, "rules", &look).unwrap().eval(&vals)
    }

    #[test]
    fn precedence_and_functions() {
        assert_eq!(ev("1+2*3", &[]), 7.0);
        assert_eq!(ev("(1+2)*3", &[]), 9.0);
        assert_eq!(ev("2^3^2", &[]), 512.0);
        assert_eq!(ev("-2^2", &[]), -4.0);
        assert_eq!(ev("x*y-1", &[("x", 3.0), ("y", 4.0)]), 11.0);
        assert_eq!(ev("t>5 && t<=7", &[("t", 6.0)]), 1.0);
        assert_eq!(ev("t>5 and t<=7 or 0", &[("t", 8.0)]), 0.0);
        assert_eq!(ev("t=2", &[("t", 2.0)]), 1.0);
        assert_eq!(ev("!(t==2)", &[("t", 2.0)]), 0.0);
        assert_eq!(ev("max(1, 2.5e1) % 7", &[]), 4.0);
        assert!((ev("sin(30)", &[]) - 0.5).abs() < 1e-12);
        assert!((ev("sqrt(2)^2", &[]) - 2.0).abs() < 1e-12);
    }

    #[test]
    fn errors_name_the_problem() {
        let look = |_: &str| None;
        for bad in [
            "", "1+", "(1", "foo", "x+1", "sin(1,2)", "1 2", "3 $ 4", "nope(1)",
        ] {
            let e = parse_expr(bad, "rules", &look).unwrap_err();
            assert!(e.to_string().starts_with("rules:"), "{bad}: {e}");
        }
        let deep = format!("{}1{}", "(".repeat(100_000), ")".repeat(100_000));
        assert!(parse_expr(&deep, "rules", &look)
            .unwrap_err()
            .to_string()
            .contains("nesting"));
        assert!(parse_expr(&"-".repeat(100_000), "rules", &look).is_err());
        let e = parse_expr("x+1", "rules", &look).unwrap_err();
        assert!(e.to_string().contains("unknown parameter \"x\""), "{e}");
    }
}
