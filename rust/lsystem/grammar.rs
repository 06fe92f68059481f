//! Module strings, productions and the rule text format.
//!
//! A *module* is a symbol (any one character except whitespace, `(`, `)` and
//! `,`; case-sensitive) with an optional list of real parameters, written
//! `A` or `A(1, 2.5)` (Prusinkiewicz and Lindenmayer 1990, section 1.10).
//!
//! A production is written
//!
//! ```text
//! [left <] pred [> right] [: condition] -> successor
//! [left <] pred [> right] [: condition] -(weight)-> successor
//! ```
//!
//! * `pred` is one module; `A(x, y)` binds formal parameters and matches only
//!   modules `A` with exactly two parameters, a bare `A` matches `A` with any
//!   number of parameters (and binds none);
//! * `left` and `right` are context strings of patterns (`*` means none);
//!   the right context may contain brackets (`B > [C]D`);
//! * `condition` is an expression over the formal parameters;
//! * successor parameters are expressions over the formal parameters;
//! * several productions with the same left-hand side text and a weight
//!   `-(w)->` form one stochastic production: a successor is picked with
//!   probability weight / sum of weights. Conditions cannot end in `-(...)`.
//!
//! Productions are tried in the order given; the first that matches applies;
//! a module that no production matches is copied (identity production).
//!
//! The text format (one item a line, `#` starts a comment):
//!
//! ```text
//! axiom: F
//! ignore: +-F            # symbols skipped by context matching
//! n: 5                   # any `key: value` line before or between rules
//! angle: 25.7            # is kept as a directive for the caller
//! F -> F[+F]F[-F]F
//! ```
use super::expr::{parse_expr, Expr};
use crate::error::{CoreError, CoreResult};
use std::collections::HashMap;

/// A string of modules in struct-of-arrays form.
///
/// `pstart` is empty when no module has parameters; otherwise it has one
/// entry more than `syms` and the parameters of module `i` are
/// `params[pstart[i]..pstart[i+1]]`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ModString {
    pub syms: Vec<char>,
    pub pstart: Vec<u32>,
    pub params: Vec<f64>,
}

impl ModString {
    /// Number of modules.
    pub fn len(&self) -> usize {
        self.syms.len()
    }
    /// True when there is no module.
    pub fn is_empty(&self) -> bool {
        self.syms.is_empty()
    }
    /// Parameters of module `i`.
    #[inline]
    pub fn params(&self, i: usize) -> &[f64] {
        if self.pstart.is_empty() {
            &[]
        } else {
            &self.params[self.pstart[i] as usize..self.pstart[i + 1] as usize]
        }
    }
    /// Number of modules with symbol `c`.
    pub fn count(&self, c: char) -> usize {
        self.syms.iter().filter(|&&s| s == c).count()
    }
    /// Text form: `A(1,2.5)B`; parameters printed with Rust's shortest
    /// round-trip formatting.
    pub fn to_text(&self) -> String {
        let mut s = String::with_capacity(self.len());
        for (i, &c) in self.syms.iter().enumerate() {
            s.push(c);
            let p = self.params(i);
            if !p.is_empty() {
                s.push('(');
                for (k, v) in p.iter().enumerate() {
                    if k > 0 {
                        s.push(',');
                    }
                    s.push_str(&format!("{v}"));
                }
                s.push(')');
            }
        }
        s
    }
    /// For each bracket, the index of its mate (`u32::MAX` elsewhere).
    /// Errors on unbalanced brackets.
    pub fn bracket_mates(&self, param: &str) -> CoreResult<Vec<u32>> {
        let mut mates = vec![u32::MAX; self.len()];
        let mut stack = Vec::new();
        for (i, &c) in self.syms.iter().enumerate() {
            if c == '[' {
                stack.push(i);
            } else if c == ']' {
                let j = stack.pop().ok_or_else(|| {
                    CoreError::invalid(
                        param,
                        format!("unbalanced brackets: ']' at module {i} closes nothing"),
                    )
                })?;
                mates[i] = j as u32;
                mates[j] = i as u32;
            }
        }
        if let Some(j) = stack.pop() {
            return Err(CoreError::invalid(
                param,
                format!("unbalanced brackets: '[' at module {j} is never closed"),
            ));
        }
        Ok(mates)
    }
}

/// Check that brackets balance (never close more than opened, all closed).
pub fn check_brackets(syms: impl Iterator<Item = char>, param: &str, what: &str) -> CoreResult<()> {
    let mut depth = 0i64;
    for c in syms {
        if c == '[' {
            depth += 1;
        } else if c == ']' {
            depth -= 1;
            if depth < 0 {
                return Err(CoreError::invalid(
                    param,
                    format!("unbalanced brackets in {what}: ']' closes nothing"),
                ));
            }
        }
    }
    if depth != 0 {
        return Err(CoreError::invalid(
            param,
            format!("unbalanced brackets in {what}: {depth} '[' never closed"),
        ));
    }
    Ok(())
}

/// A module as written in a rule: a symbol and the raw text of its arguments.
#[derive(Debug, Clone, PartialEq)]
pub struct RawModule {
    pub sym: char,
    /// `None` when written without parentheses.
    pub args: Option<Vec<String>>,
}

fn is_symbol(c: char) -> bool {
    !(c.is_whitespace() || c == '(' || c == ')' || c == ',')
}

/// Split a module string `A(x,y)B[C]` into modules with raw argument text.
pub fn split_modules(src: &str, param: &str) -> CoreResult<Vec<RawModule>> {
    let chars: Vec<char> = src.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        if c.is_whitespace() {
            i += 1;
            continue;
        }
        if !is_symbol(c) {
            return Err(CoreError::invalid(
                param,
                format!("unexpected {c:?} at character {i} of {src:?}"),
            ));
        }
        i += 1;
        // optional argument list, possibly after spaces only if directly attached
        if i < chars.len() && chars[i] == '(' {
            let mut depth = 0;
            let mut args = Vec::new();
            let mut cur = String::new();
            let mut closed = false;
            i += 1;
            while i < chars.len() {
                let d = chars[i];
                i += 1;
                match d {
                    '(' => {
                        depth += 1;
                        cur.push(d);
                    }
                    ')' if depth == 0 => {
                        closed = true;
                        break;
                    }
                    ')' => {
                        depth -= 1;
                        cur.push(d);
                    }
                    ',' if depth == 0 => args.push(std::mem::take(&mut cur)),
                    _ => cur.push(d),
                }
            }
            if !closed {
                return Err(CoreError::invalid(
                    param,
                    format!("unclosed '(' after {c:?} in {src:?}"),
                ));
            }
            args.push(cur);
            if args.iter().any(|a| a.trim().is_empty()) {
                return Err(CoreError::invalid(
                    param,
                    format!("empty parameter in module {c:?} of {src:?}"),
                ));
            }
            out.push(RawModule {
                sym: c,
                args: Some(args),
            });
        } else {
            out.push(RawModule { sym: c, args: None });
        }
    }
    Ok(out)
}

/// Parse a string of modules whose parameters are constant expressions
/// (an axiom).
pub fn parse_module_string(src: &str, param: &str) -> CoreResult<ModString> {
    let mods = split_modules(src, param)?;
    let none = |_: &str| None;
    let mut ms = ModString::default();
    let parametric = mods.iter().any(|m| m.args.is_some());
    if parametric {
        ms.pstart.push(0);
    }
    for m in &mods {
        ms.syms.push(m.sym);
        if let Some(args) = &m.args {
            for a in args {
                let v = parse_expr(a, param, &none)?.eval(&[]);
                if !v.is_finite() {
                    return Err(CoreError::invalid(
                        param,
                        format!("parameter {a:?} of {:?} is not finite", m.sym),
                    ));
                }
                ms.params.push(v);
            }
        }
        if parametric {
            ms.pstart.push(ms.params.len() as u32);
        }
    }
    check_brackets(ms.syms.iter().copied(), param, "the axiom")?;
    Ok(ms)
}

/// A module pattern of a predecessor or a context.
#[derive(Debug, Clone, PartialEq)]
pub struct Pattern {
    pub sym: char,
    /// `Some(k)`: matches modules with exactly k parameters and binds them to
    /// slots `first_slot..first_slot+k`; `None`: any arity, binds nothing.
    pub arity: Option<usize>,
    pub first_slot: usize,
}

/// A successor module with its parameter expressions.
#[derive(Debug, Clone, PartialEq)]
pub struct SuccModule {
    pub sym: char,
    pub args: Vec<Expr>,
}

/// One successor of a production.
#[derive(Debug, Clone, PartialEq)]
pub struct Successor {
    pub modules: Vec<SuccModule>,
    /// The symbols alone (fast path for non-parametric successors).
    pub syms: Vec<char>,
    pub parametric: bool,
}

/// A compiled production (possibly stochastic: several weighted successors).
#[derive(Debug, Clone, PartialEq)]
pub struct Rule {
    pub text: String,
    pub left: Vec<Pattern>,
    pub pred: Pattern,
    pub right: Vec<Pattern>,
    pub cond: Option<Expr>,
    pub successors: Vec<Successor>,
    /// Cumulative normalised weights (last = 1); one entry per successor.
    pub cum_weights: Vec<f64>,
    pub n_slots: usize,
}

impl Rule {
    /// True when the production needs context.
    pub fn has_context(&self) -> bool {
        !self.left.is_empty() || !self.right.is_empty()
    }
}

/// One production line split into parts (before compilation).
#[derive(Debug, Clone)]
struct RawRule {
    lhs: String,
    weight: Option<f64>,
    succ: String,
}

fn split_rule(line: &str) -> CoreResult<RawRule> {
    let Some(arrow) = line.find("->") else {
        return Err(CoreError::invalid(
            "rules",
            format!("malformed rule {line:?}: no '->'"),
        ));
    };
    let mut lhs = line[..arrow].trim_end().to_string();
    let succ = line[arrow + 2..].trim().to_string();
    let mut weight = None;
    // weighted arrow "-(w)->": lhs ends with "-(w)"
    if lhs.ends_with(')') {
        let bytes: Vec<char> = lhs.chars().collect();
        let mut depth = 0;
        let mut open = None;
        for k in (0..bytes.len()).rev() {
            match bytes[k] {
                ')' => depth += 1,
                '(' => {
                    depth -= 1;
                    if depth == 0 {
                        open = Some(k);
                        break;
                    }
                }
                _ => {}
            }
        }
        if let Some(k) = open {
            if k > 0 && bytes[k - 1] == '-' {
                let inner: String = bytes[k + 1..bytes.len() - 1].iter().collect();
                let none = |_: &str| None;
                let w = parse_expr(&inner, "rules", &none)
                    .map_err(|e| {
                        CoreError::invalid("rules", format!("bad weight in rule {line:?}: {e}"))
                    })?
                    .eval(&[]);
                if !w.is_finite() || w < 0.0 {
                    return Err(CoreError::invalid(
                        "rules",
                        format!("weight {w} of rule {line:?} must be finite and >= 0"),
                    ));
                }
                weight = Some(w);
                lhs = bytes[..k - 1]
                    .iter()
                    .collect::<String>()
                    .trim_end()
                    .to_string();
            }
        }
    }
    if lhs.trim().is_empty() {
        return Err(CoreError::invalid(
            "rules",
            format!("malformed rule {line:?}: no predecessor"),
        ));
    }
    Ok(RawRule { lhs, weight, succ })
}

/// Split at the first top-level occurrence of `sep` (outside parentheses).
fn split_top(s: &str, sep: char) -> (String, Option<String>) {
    let mut depth = 0;
    for (i, c) in s.char_indices() {
        match c {
            '(' => depth += 1,
            ')' => depth -= 1,
            _ if c == sep && depth == 0 => {
                return (s[..i].to_string(), Some(s[i + c.len_utf8()..].to_string()))
            }
            _ => {}
        }
    }
    (s.to_string(), None)
}

struct Slots {
    names: Vec<String>,
}

impl Slots {
    fn patterns(&mut self, mods: &[RawModule], line: &str) -> CoreResult<Vec<Pattern>> {
        let mut out = Vec::new();
        for m in mods {
            let first = self.names.len();
            let arity = match &m.args {
                None => None,
                Some(args) => {
                    for a in args {
                        let a = a.trim();
                        let ok = a
                            .chars()
                            .next()
                            .is_some_and(|c| c.is_alphabetic() || c == '_')
                            && a.chars().all(|c| c.is_alphanumeric() || c == '_');
                        if !ok {
                            return Err(CoreError::invalid(
                                "rules",
                                format!("formal parameter {a:?} of {:?} in rule {line:?} must be a name", m.sym),
                            ));
                        }
                        if self.names.iter().any(|n| n == a) {
                            return Err(CoreError::invalid(
                                "rules",
                                format!("parameter {a:?} bound twice in rule {line:?}"),
                            ));
                        }
                        self.names.push(a.to_string());
                    }
                    Some(args.len())
                }
            };
            out.push(Pattern {
                sym: m.sym,
                arity,
                first_slot: first,
            });
        }
        Ok(out)
    }
}

fn compile_group(lhs: &str, items: &[(Option<f64>, String)], line: &str) -> CoreResult<Rule> {
    let (ctx, cond) = split_top(lhs, ':');
    let (left_txt, rest) = match split_top(&ctx, '<') {
        (l, Some(r)) => (Some(l), r),
        (l, None) => (None, l),
    };
    let (pred_txt, right_txt) = match split_top(&rest, '>') {
        (p, Some(r)) => (p, Some(r)),
        (p, None) => (p, None),
    };
    let ctx_mods = |t: Option<String>| -> CoreResult<Vec<RawModule>> {
        match t {
            None => Ok(vec![]),
            Some(t) if t.trim() == "*" => Ok(vec![]),
            Some(t) => {
                let m = split_modules(&t, "rules")?;
                if m.is_empty() {
                    return Err(CoreError::invalid(
                        "rules",
                        format!("empty context in rule {line:?} (use '*' for none)"),
                    ));
                }
                Ok(m)
            }
        }
    };
    let left_raw = ctx_mods(left_txt)?;
    let right_raw = ctx_mods(right_txt)?;
    let pred_raw = split_modules(&pred_txt, "rules")?;
    if pred_raw.len() != 1 {
        return Err(CoreError::invalid(
            "rules",
            format!(
                "malformed rule {line:?}: the predecessor must be exactly one module, got {:?}",
                pred_txt.trim()
            ),
        ));
    }
    if matches!(pred_raw[0].sym, '[' | ']') {
        return Err(CoreError::invalid(
            "rules",
            format!("rule {line:?}: brackets cannot be rewritten"),
        ));
    }
    if left_raw.iter().any(|m| matches!(m.sym, '[' | ']')) {
        return Err(CoreError::invalid(
            "rules",
            format!("rule {line:?}: brackets are not allowed in a left context"),
        ));
    }
    let mut slots = Slots { names: vec![] };
    let left = slots.patterns(&left_raw, line)?;
    let pred = slots.patterns(&pred_raw, line)?.remove(0);
    let right = slots.patterns(&right_raw, line)?;
    let names = slots.names.clone();
    let lookup = move |n: &str| names.iter().position(|m| m == n);
    let cond = match cond {
        Some(c) if c.trim() == "*" => None,
        Some(c) => Some(parse_expr(&c, "rules", &lookup)?),
        None => None,
    };
    let mut successors = Vec::new();
    let mut weights = Vec::new();
    for (w, succ_txt) in items {
        let mods = split_modules(succ_txt, "rules")?;
        check_brackets(
            mods.iter().map(|m| m.sym),
            "rules",
            &format!("the successor of rule {line:?}"),
        )?;
        let mut modules = Vec::new();
        let mut parametric = false;
        for m in mods {
            let args = match m.args {
                None => vec![],
                Some(a) => {
                    parametric = true;
                    a.iter()
                        .map(|t| parse_expr(t, "rules", &lookup))
                        .collect::<CoreResult<Vec<_>>>()?
                }
            };
            modules.push(SuccModule { sym: m.sym, args });
        }
        let syms = modules.iter().map(|m| m.sym).collect();
        successors.push(Successor {
            modules,
            syms,
            parametric,
        });
        weights.push(w.unwrap_or(1.0));
    }
    let total: f64 = weights.iter().sum();
    if !(total > 0.0) || !total.is_finite() {
        return Err(CoreError::invalid(
            "rules",
            format!("the weights of the stochastic rule {lhs:?} sum to {total}; they must sum to a positive number"),
        ));
    }
    let mut acc = 0.0;
    let mut cum_weights: Vec<f64> = weights
        .iter()
        .map(|w| {
            acc += w;
            acc / total
        })
        .collect();
    if let Some(last) = cum_weights.last_mut() {
        *last = 1.0;
    }
    Ok(Rule {
        text: line.to_string(),
        left,
        pred,
        right,
        cond,
        successors,
        cum_weights,
        n_slots: slots.names.len(),
    })
}

/// Lines with one left-hand side: (lhs, [(weight, successor)], first line).
type RuleGroup = (String, Vec<(Option<f64>, String)>, String);

/// Compile production lines. Lines with a weighted arrow and the same
/// left-hand side (whitespace ignored) form one stochastic production.
pub fn compile_rules(lines: &[String]) -> CoreResult<Vec<Rule>> {
    let mut groups: Vec<RuleGroup> = Vec::new();
    let mut index: HashMap<String, usize> = HashMap::new();
    for line in lines {
        let line = line.trim();
        if line.is_empty() {
            continue;
        }
        let raw = split_rule(line)?;
        let key: String = raw.lhs.chars().filter(|c| !c.is_whitespace()).collect();
        match (raw.weight, index.get(&key)) {
            (Some(_), Some(&g)) if groups[g].1.iter().all(|(w, _)| w.is_some()) => {
                groups[g].1.push((raw.weight, raw.succ));
            }
            (None, Some(_)) | (Some(_), Some(_)) => {
                return Err(CoreError::invalid(
                    "rules",
                    format!("rule {line:?} repeats the predecessor {:?}; give every alternative a weight -(w)->", raw.lhs),
                ));
            }
            (_, None) => {
                index.insert(key, groups.len());
                groups.push((
                    raw.lhs.clone(),
                    vec![(raw.weight, raw.succ)],
                    line.to_string(),
                ));
            }
        }
    }
    groups
        .iter()
        .map(|(lhs, items, line)| compile_group(lhs, items, line))
        .collect()
}

/// The content of a rule file.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RuleText {
    pub axiom: Option<String>,
    pub ignore: Option<String>,
    pub rules: Vec<String>,
    /// Other `key: value` lines, in order.
    pub directives: Vec<(String, String)>,
}

/// Parse the rule text format (see the module documentation).
pub fn parse_rule_text(text: &str) -> CoreResult<RuleText> {
    let mut out = RuleText::default();
    for (no, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        if line.contains("->") {
            out.rules.push(line.to_string());
            continue;
        }
        let Some((k, v)) = line.split_once(':') else {
            return Err(CoreError::invalid(
                "text",
                format!(
                    "line {}: expected 'key: value' or a rule 'A -> B', got {line:?}",
                    no + 1
                ),
            ));
        };
        let k = k.trim().to_ascii_lowercase();
        let v = v.trim().to_string();
        if k.is_empty() || !k.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
            return Err(CoreError::invalid(
                "text",
                format!("line {}: bad key {k:?}", no + 1),
            ));
        }
        match k.as_str() {
            "axiom" | "omega" => out.axiom = Some(v),
            "ignore" => out.ignore = Some(v),
            _ => out.directives.push((k, v)),
        }
    }
    if out.axiom.is_none() {
        return Err(CoreError::invalid("text", "no 'axiom:' line"));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn module_strings_parse_and_print() {
        let m = parse_module_string("A(1, 2.5)B[C(3*2)]", "axiom").unwrap();
        assert_eq!(m.syms, vec!['A', 'B', '[', 'C', ']']);
        assert_eq!(m.params(0), &[1.0, 2.5]);
        assert_eq!(m.params(1), &[] as &[f64]);
        assert_eq!(m.params(3), &[6.0]);
        assert_eq!(m.to_text(), "A(1,2.5)B[C(6)]");
        assert!(parse_module_string("A[B", "axiom").is_err());
        assert!(parse_module_string("A]B[", "axiom").is_err());
        assert!(parse_module_string("A(x)", "axiom")
            .unwrap_err()
            .to_string()
            .contains("unknown parameter"));
        assert!(parse_module_string("A(1", "axiom").is_err());
        assert!(parse_module_string("A(1,)", "axiom").is_err());
    }

    #[test]
    fn rules_compile() {
        let r = compile_rules(&["B(a) < A(x, y) > C(z) : x > a && z < y -> A(x+1, y*2)B".into()])
            .unwrap();
        assert_eq!(r.len(), 1);
        assert_eq!(r[0].left[0].sym, 'B');
        assert_eq!(r[0].pred.arity, Some(2));
        assert_eq!(r[0].pred.first_slot, 1);
        assert_eq!(r[0].right[0].first_slot, 3);
        assert_eq!(r[0].n_slots, 4);
        let s = compile_rules(&[
            "F -(1)-> F[+F]F".into(),
            "F -(3)-> F[-F]F".into(),
            "X -> F".into(),
        ])
        .unwrap();
        assert_eq!(s.len(), 2);
        assert_eq!(s[0].cum_weights, vec![0.25, 1.0]);
        for bad in [
            "A B -> C",
            "A -> [B",
            "A -> B]",
            "A(x) -> B(y)",
            "A(x) : y > 1 -> B",
            "-> B",
            "A B",
            "A -(-1)-> B",
            "[ -> B",
            "A(1) -> B",
            "A(x, x) -> B",
        ] {
            let e = compile_rules(&[bad.into()]);
            assert!(e.is_err(), "{bad}");
            assert!(e.unwrap_err().to_string().starts_with("rules:"), "{bad}");
        }
        // weights that sum to zero; unweighted duplicate
        assert!(compile_rules(&["A -(0)-> B".into(), "A -(0)-> C".into()]).is_err());
        assert!(compile_rules(&["A -> B".into(), "A -> C".into()]).is_err());
    }

    #[test]
    fn rule_text_parses() {
        let t = parse_rule_text(
            "# plant\naxiom: X\nignore: +-\nn: 5\nangle: 22.5\nX -> F[+X]F  # comment\nF -> FF\n",
        )
        .unwrap();
        assert_eq!(t.axiom.as_deref(), Some("X"));
        assert_eq!(t.ignore.as_deref(), Some("+-"));
        assert_eq!(
            t.rules,
            vec!["X -> F[+X]F".to_string(), "F -> FF".to_string()]
        );
        assert_eq!(
            t.directives,
            vec![("n".into(), "5".into()), ("angle".into(), "22.5".into())]
        );
        assert!(parse_rule_text("F -> FF").is_err());
        assert!(parse_rule_text("axiom: F\nrubbish").is_err());
    }
}
