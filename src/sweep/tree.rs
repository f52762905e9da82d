//! The sweep file as a tree of values that remember their line, so that every error can name
//! the file, the key and the line (TOML parsing by the `toml` crate's spanned document API).

use toml::de::{DeTable, DeValue};

/// A TOML value with the line it starts on (1-based).
#[derive(Debug, Clone, PartialEq)]
pub struct Node {
    pub kind: Kind,
    pub line: usize,
}

#[derive(Debug, Clone, PartialEq)]
pub enum Kind {
    Str(String),
    Int(i64),
    Float(f64),
    Bool(bool),
    Array(Vec<Node>),
    /// Entries in file order: (key, line of the key, value).
    Table(Vec<(String, usize, Node)>),
    Other(&'static str),
}

impl Kind {
    pub fn type_name(&self) -> &'static str {
        match self {
            Kind::Str(_) => "string",
            Kind::Int(_) => "integer",
            Kind::Float(_) => "float",
            Kind::Bool(_) => "boolean",
            Kind::Array(_) => "array",
            Kind::Table(_) => "table",
            Kind::Other(t) => t,
        }
    }
}

/// A TOML syntax error with its line.
#[derive(Debug, Clone, PartialEq)]
pub struct SyntaxError {
    pub line: Option<usize>,
    pub message: String,
}

/// The offsets of the newlines of a text: the line of an offset by binary search. (Counting
/// the newlines before each value made parsing quadratic: a list of 20 000 numbers took a
/// second — found by the fuzz test.)
struct Lines(Vec<usize>);

impl Lines {
    fn new(text: &str) -> Lines {
        Lines(
            text.bytes()
                .enumerate()
                .filter(|(_, b)| *b == b'\n')
                .map(|(i, _)| i)
                .collect(),
        )
    }
}

fn line_of(lines: &Lines, offset: usize) -> usize {
    lines.0.partition_point(|&nl| nl < offset) + 1
}

fn convert(text: &Lines, v: &DeValue<'_>, line: usize) -> Node {
    let kind = match v {
        DeValue::String(s) => Kind::Str(s.to_string()),
        DeValue::Integer(i) => match i64::from_str_radix(i.as_str(), i.radix()) {
            Ok(x) => Kind::Int(x),
            Err(_) => Kind::Other("integer out of range"),
        },
        DeValue::Float(f) => match f.as_str().replace('_', "").parse::<f64>() {
            Ok(x) => Kind::Float(x),
            Err(_) => Kind::Other("unparsable float"),
        },
        DeValue::Boolean(b) => Kind::Bool(*b),
        DeValue::Datetime(_) => Kind::Other("datetime"),
        DeValue::Array(a) => Kind::Array(
            a.iter()
                .map(|item| convert(text, item.get_ref(), line_of(text, item.span().start)))
                .collect(),
        ),
        DeValue::Table(t) => Kind::Table(table(text, t)),
    };
    Node { kind, line }
}

fn table(text: &Lines, t: &DeTable<'_>) -> Vec<(String, usize, Node)> {
    t.iter()
        .map(|(k, v)| {
            let kl = line_of(text, k.span().start);
            let vl = line_of(text, v.span().start);
            (k.get_ref().to_string(), kl, convert(text, v.get_ref(), vl))
        })
        .collect()
}

/// Parse a whole document into its top-level entries.
pub fn parse(text: &str) -> Result<Vec<(String, usize, Node)>, SyntaxError> {
    let lines = Lines::new(text);
    match DeTable::parse(text) {
        Ok(doc) => Ok(table(&lines, doc.get_ref())),
        Err(e) => Err(SyntaxError {
            line: e.span().map(|s| line_of(&lines, s.start)),
            message: e.message().trim().to_string(),
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_are_counted_from_one_at_newlines() {
        let l = Lines::new("a\nbc\n\nd");
        assert_eq!(
            [0, 1, 2, 3, 4, 5, 6].map(|o| line_of(&l, o)),
            [1, 1, 2, 2, 2, 3, 4]
        );
    }
}
