//! Parameters from the command line: `--set key=value` (repeatable) on top of a sweep file, or
//! instead of one (`run --scene bar1d --set …`).
//!
//! An override is applied to the parsed TOML tree *before* the checks, so a value given on the
//! command line is validated by exactly the code that validates the file, and gives the same
//! messages; only the place differs: issues raised by an override name the flag
//! (`--set h=-1: key `fixed.h`: …`) instead of a file line. The nodes of an override carry the
//! line [`SET_LINE`] + its index, which [`super::SweepError`] renders as the flag.
//!
//! Where a value goes:
//! - `table.key=value` (`fixed.h`, `grid.h`, `zip.dt`, `summary.errors`, `reference.h`, …): into
//!   that table, replacing the key if the file set it;
//! - `key=value` for a parameter: a list makes it an axis of `[grid]`, a single value goes to
//!   `[fixed]`; either way the file's own `[fixed]`, `[grid]` and `[zip]` entries of that key are
//!   removed first (the command line replaces the parameter, it does not add a second axis);
//! - `key=value` for anything else (`name`, `description`, `series_every`, …): the top-level key.
//!
//! Values are TOML (`0.01`, `[0.01, 0.005]`, `{ space = "nitsche", nitsche_gamma0 = 1e-6 }`,
//! `"x"`); a bare word is a string (`scheme=hybrid`), and so are the bare words of a list
//! (`scheme=[hybrid,crank-nicolson]`), so that shells need no nested quoting.
//!
//! Run ids depend only on the canonical parameters of each run, so a run given on the command
//! line has the id of the same run given by a file.

use super::tree::{self, Kind, Node};
use crate::model::{Key, ValueType};

/// Lines of override nodes start here: far beyond any sweep file, so that a line number alone
/// tells a file line from an override (override `i` has line `SET_LINE + i`).
pub const SET_LINE: usize = 1 << 40;

/// One `--set key=value`, parsed.
#[derive(Debug, Clone, PartialEq)]
pub struct Set {
    /// The flag's argument as given (`h=[0.01,0.005]`), for messages and the manifest.
    pub arg: String,
    /// `["h"]` or `["fixed", "h"]`.
    pub path: Vec<String>,
    /// The value, every node at line `SET_LINE + index`.
    pub value: Node,
}

/// Parse the arguments of the `--set` flags. Errors name the flag and the argument.
pub fn parse(args: &[String]) -> Result<Vec<Set>, String> {
    args.iter()
        .enumerate()
        .map(|(i, arg)| {
            let (key, value) = arg.split_once('=').ok_or_else(|| {
                format!("--set `{arg}`: expected key=value (e.g. h=0.01, or h=[0.01,0.005] for an axis)")
            })?;
            let key = key.trim();
            let path: Vec<String> = key.split('.').map(|s| s.trim().to_string()).collect();
            if key.is_empty() || path.iter().any(String::is_empty) {
                return Err(format!("--set `{arg}`: empty key"));
            }
            if path.len() > 2 {
                return Err(format!(
                    "--set `{arg}`: key `{key}` has more than one dot (use key or table.key, e.g. fixed.h)"
                ));
            }
            let mut value = parse_value(value.trim());
            relabel(&mut value, SET_LINE + i);
            Ok(Set {
                arg: arg.clone(),
                path,
                value,
            })
        })
        .collect()
}

/// A TOML value; a bare word (or a list of bare words) is read as string(s).
fn parse_value(text: &str) -> Node {
    if let Some(v) = toml_value(text) {
        return v;
    }
    if let Some(inner) = text.strip_prefix('[').and_then(|t| t.strip_suffix(']')) {
        let items = split_top(inner)
            .into_iter()
            .filter(|s| !s.trim().is_empty())
            .map(|s| parse_value(s.trim()))
            .collect();
        return Node {
            kind: Kind::Array(items),
            line: 1,
        };
    }
    Node {
        kind: Kind::Str(text.to_string()),
        line: 1,
    }
}

fn toml_value(text: &str) -> Option<Node> {
    let doc = tree::parse(&format!("v = {text}\n")).ok()?;
    doc.into_iter().next().map(|(_, _, n)| n)
}

/// Split at the commas not nested in brackets, braces or quotes.
fn split_top(s: &str) -> Vec<&str> {
    let (mut depth, mut quote, mut start) = (0i32, None::<char>, 0usize);
    let mut out = Vec::new();
    for (i, c) in s.char_indices() {
        match (quote, c) {
            (Some(q), c) if c == q => quote = None,
            (Some(_), _) => {}
            (None, '"' | '\'') => quote = Some(c),
            (None, '[' | '{') => depth += 1,
            (None, ']' | '}') => depth -= 1,
            (None, ',') if depth == 0 => {
                out.push(&s[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    out.push(&s[start..]);
    out
}

fn relabel(n: &mut Node, line: usize) {
    n.line = line;
    match &mut n.kind {
        Kind::Array(items) => items.iter_mut().for_each(|i| relabel(i, line)),
        Kind::Table(entries) => entries.iter_mut().for_each(|(_, l, v)| {
            *l = line;
            relabel(v, line);
        }),
        _ => {}
    }
}

type Entries = Vec<(String, usize, Node)>;

/// The entries of top-level table `name`, created (empty, at `line`) if absent; a non-table
/// value of that name is replaced (it would have been refused anyway).
fn table_mut<'a>(top: &'a mut Entries, name: &str, line: usize) -> &'a mut Entries {
    let i = match top.iter().position(|(k, _, _)| k == name) {
        Some(i) => i,
        None => {
            top.push((
                name.to_string(),
                line,
                Node {
                    kind: Kind::Table(Vec::new()),
                    line,
                },
            ));
            top.len() - 1
        }
    };
    if !matches!(top[i].2.kind, Kind::Table(_)) {
        top[i].2 = Node {
            kind: Kind::Table(Vec::new()),
            line,
        };
    }
    match &mut top[i].2.kind {
        Kind::Table(t) => t,
        _ => unreachable!("made a table above"),
    }
}

fn put(entries: &mut Entries, key: &str, line: usize, value: Node) {
    match entries.iter_mut().find(|(k, _, _)| k == key) {
        Some(e) => *e = (key.to_string(), line, value),
        None => entries.push((key.to_string(), line, value)),
    }
}

/// Apply the overrides, in order, to a parsed sweep file's top-level entries.
pub fn apply(top: &mut Entries, sets: &[Set]) {
    for s in sets {
        let line = s.value.line;
        match s.path.as_slice() {
            [table, key] => put(table_mut(top, table, line), key, line, s.value.clone()),
            [key] => match Key::from_name(key) {
                Some(k) => {
                    for section in ["fixed", "grid", "zip"] {
                        if let Some((
                            _,
                            _,
                            Node {
                                kind: Kind::Table(t),
                                ..
                            },
                        )) = top.iter_mut().find(|(n, _, _)| n == section)
                        {
                            t.retain(|(n, _, _)| n != key);
                        }
                    }
                    // A list is an axis, except the value of a list-valued key
                    // (mass_weights = [1, 2]), which is an axis only as a list of lists.
                    let axis = match &s.value.kind {
                        Kind::Array(items) => {
                            k.value_type() != ValueType::FloatList
                                || items.iter().all(|i| matches!(i.kind, Kind::Array(_)))
                        }
                        _ => false,
                    };
                    let section = if axis { "grid" } else { "fixed" };
                    put(table_mut(top, section, line), key, line, s.value.clone());
                }
                None => put(top, key, line, s.value.clone()),
            },
            _ => unreachable!("checked by parse"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn one(arg: &str) -> Set {
        parse(&[arg.to_string()]).unwrap().remove(0)
    }

    #[test]
    fn values_are_toml_or_bare_words() {
        assert_eq!(one("h=0.01").value.kind, Kind::Float(0.01));
        assert_eq!(one("scheme=hybrid").value.kind, Kind::Str("hybrid".into()));
        assert_eq!(one("fixed.T=3").path, ["fixed", "T"]);
        let Kind::Array(items) = one("scheme=[hybrid, \"crank-nicolson\"]").value.kind else {
            panic!("a list")
        };
        assert_eq!(items[0].kind, Kind::Str("hybrid".into()));
        assert_eq!(items[1].kind, Kind::Str("crank-nicolson".into()));
        let Kind::Array(items) = one("h=[0.01,0.005]").value.kind else {
            panic!("a list")
        };
        assert_eq!(items[1].kind, Kind::Float(0.005));
        // every node names its flag through the line
        assert_eq!(
            parse(&["a=1".into(), "b=2".into()]).unwrap()[1].value.line,
            SET_LINE + 1
        );
        assert!(
            parse(&["h".into()])
                .unwrap_err()
                .contains("--set `h`: expected key=value")
        );
        assert!(
            parse(&["a.b.c=1".into()])
                .unwrap_err()
                .contains("more than one dot")
        );
    }

    #[test]
    fn a_bare_parameter_replaces_the_files_axis() {
        let mut top =
            tree::parse("name = \"x\"\n[fixed]\nT = 1.0\n[grid]\nh = [0.1, 0.05]\n").unwrap();
        apply(
            &mut top,
            &parse(&["h=0.2".into(), "dt=[0.1,0.05]".into()]).unwrap(),
        );
        let table = |n: &str| match &top.iter().find(|(k, _, _)| k == n).unwrap().2.kind {
            Kind::Table(t) => t.iter().map(|(k, _, _)| k.clone()).collect::<Vec<_>>(),
            _ => panic!(),
        };
        assert_eq!(table("fixed"), ["T", "h"]);
        assert_eq!(table("grid"), ["dt"]);
    }
}
