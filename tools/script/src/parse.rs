//! Parsing of contacts and sequence lines.

use core::fmt;

use heapless::Vec;
use nalgebra::Vector3;
use palpate_kernel::{Constraint, MAX_CONTACTS, Real};

/// The contacts of one step, at most [`MAX_CONTACTS`].
pub type StepContacts<T> = Vec<Constraint<T>, MAX_CONTACTS>;

/// Why a contact or a sequence line could not be parsed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ParseError {
    /// No `:` between the point and the displacement.
    MissingColon,
    /// A list did not have exactly three comma-separated entries.
    NotThree {
        /// Which list: `"displacement"`, `"vertices"` or `"weights"`.
        what: &'static str,
    },
    /// An entry is not a vertex index (a non-negative integer below 2³²).
    BadVertex,
    /// An entry is not a number.
    BadNumber,
    /// A step names more contacts than [`MAX_CONTACTS`].
    TooManyContacts,
}

impl fmt::Display for ParseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::MissingColon => f.write_str("expected V:dx,dy,dz or A,B,C@ba,bb,bc:dx,dy,dz"),
            Self::NotThree { what } => write!(f, "expected three comma-separated {what}"),
            Self::BadVertex => f.write_str("a vertex index is not a non-negative integer"),
            Self::BadNumber => f.write_str("a value is not a number"),
            Self::TooManyContacts => write!(f, "more than {MAX_CONTACTS} contacts in one step"),
        }
    }
}

impl core::error::Error for ParseError {}

/// Parses three comma-separated values.
fn three<E: core::str::FromStr + Copy + Default>(
    text: &str,
    what: &'static str,
    bad: ParseError,
) -> Result<[E; 3], ParseError> {
    let mut out = [E::default(); 3];
    let mut parts = text.split(',');
    for slot in &mut out {
        let part = parts.next().ok_or(ParseError::NotThree { what })?;
        *slot = part.trim().parse().map_err(|_| bad)?;
    }
    match parts.next() {
        Some(_) => Err(ParseError::NotThree { what }),
        None => Ok(out),
    }
}

/// Parses a vector `x,y,z`.
pub fn parse_vector<T: Real>(text: &str) -> Result<[T; 3], ParseError> {
    three(text, "vector components", ParseError::BadNumber)
}

/// Parses a per-vertex vector `V:x,y,z` (a vertex contact's displacement,
/// a vertex load).
pub fn parse_vertex_vector<T: Real>(text: &str) -> Result<(u32, [T; 3]), ParseError> {
    let (vertex, vector) = text.split_once(':').ok_or(ParseError::MissingColon)?;
    let vertex = vertex.trim().parse().map_err(|_| ParseError::BadVertex)?;
    Ok((
        vertex,
        three(vector, "displacement", ParseError::BadNumber)?,
    ))
}

/// Parses one contact: `V:dx,dy,dz` or `A,B,C@ba,bb,bc:dx,dy,dz`.
///
/// Only the syntax is checked here; whether the vertices are touchable and
/// the weights valid is the kernel's check ([`palpate_kernel::ContactError`]).
pub fn parse_contact<T: Real>(text: &str) -> Result<Constraint<T>, ParseError> {
    let (point, displacement) = text.split_once(':').ok_or(ParseError::MissingColon)?;
    match point.split_once('@') {
        None => {
            let (vertex, d) = parse_vertex_vector(text)?;
            Ok(Constraint::at_vertex(vertex, Vector3::from(d)))
        }
        Some((vertices, weights)) => Ok(Constraint::on_triangle(
            three(vertices, "vertices", ParseError::BadVertex)?,
            three(weights, "weights", ParseError::BadNumber)?,
            Vector3::from(three(displacement, "displacement", ParseError::BadNumber)?),
        )),
    }
}

/// Parses one sequence line (comment already removed): blank-separated
/// contacts, or `-` for a step without contact.
pub fn parse_step<T: Real>(line: &str) -> Result<StepContacts<T>, ParseError> {
    let mut contacts = StepContacts::new();
    if line.trim() == "-" {
        return Ok(contacts);
    }
    for word in line.split_whitespace() {
        contacts
            .push(parse_contact(word)?)
            .map_err(|_| ParseError::TooManyContacts)?;
    }
    Ok(contacts)
}

/// The steps of a sequence text: `(line number from 1, parsed step)` for
/// every line that is not blank or a comment.
pub fn steps<T: Real>(
    text: &str,
) -> impl Iterator<Item = (usize, Result<StepContacts<T>, ParseError>)> + '_ {
    text.lines().enumerate().filter_map(|(index, line)| {
        let line = line.split_once('#').map_or(line, |(code, _)| code);
        (!line.trim().is_empty()).then(|| (index + 1, parse_step(line)))
    })
}
