//! The fixed-vertex predicate of the CLI contract: `x|y|z`, then `<`, `<=`,
//! `>` or `>=`, then a number in mesh units (e.g. `z<0.001`).

use core::fmt;
use core::str::FromStr;

/// A half-space test on one rest coordinate; a vertex satisfying any of the
/// given predicates is fixed (zero displacement).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FixPredicate {
    axis: usize,
    op: Comparison,
    value: f64,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Comparison {
    Less,
    LessEq,
    Greater,
    GreaterEq,
}

/// The fixed flag of every vertex: matching any of `fix` at rest, or in
/// `unreferenced` (kept so the numbering stays the file's, fixed because no
/// tet gives them stiffness or mass). Also returns how many a predicate
/// matched.
pub fn fixed_vertices(
    positions: &[[f64; 3]],
    fix: &[FixPredicate],
    unreferenced: &[u32],
) -> (Vec<bool>, usize) {
    let mut fixed: Vec<bool> = positions
        .iter()
        .map(|p| fix.iter().any(|f| f.matches(p)))
        .collect();
    let by_predicate = fixed.iter().filter(|&&f| f).count();
    for &v in unreferenced {
        if let Some(f) = fixed.get_mut(v as usize) {
            *f = true;
        }
    }
    (fixed, by_predicate)
}

impl FixPredicate {
    /// `true` if the rest position `p` (mesh units) satisfies the predicate.
    pub fn matches(&self, p: &[f64; 3]) -> bool {
        let c = p[self.axis];
        match self.op {
            Comparison::Less => c < self.value,
            Comparison::LessEq => c <= self.value,
            Comparison::Greater => c > self.value,
            Comparison::GreaterEq => c >= self.value,
        }
    }
}

impl FromStr for FixPredicate {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let s = s.trim();
        let bad = || {
            format!(
                "bad --fix predicate '{s}': expected x|y|z then <, <=, > or >= then a number, e.g. 'z<0.001'"
            )
        };
        let mut chars = s.chars();
        let axis = match chars.next() {
            Some('x') => 0,
            Some('y') => 1,
            Some('z') => 2,
            _ => return Err(bad()),
        };
        let rest = chars.as_str();
        let (op, number) = if let Some(n) = rest.strip_prefix("<=") {
            (Comparison::LessEq, n)
        } else if let Some(n) = rest.strip_prefix(">=") {
            (Comparison::GreaterEq, n)
        } else if let Some(n) = rest.strip_prefix('<') {
            (Comparison::Less, n)
        } else if let Some(n) = rest.strip_prefix('>') {
            (Comparison::Greater, n)
        } else {
            return Err(bad());
        };
        let value: f64 = number.trim().parse().map_err(|_| bad())?;
        if !value.is_finite() {
            return Err(bad());
        }
        Ok(Self { axis, op, value })
    }
}

impl fmt::Display for FixPredicate {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let axis = ["x", "y", "z"][self.axis];
        let op = match self.op {
            Comparison::Less => "<",
            Comparison::LessEq => "<=",
            Comparison::Greater => ">",
            Comparison::GreaterEq => ">=",
        };
        write!(f, "{axis}{op}{}", self.value)
    }
}
