//! The declared column types of the summary tables, and the `columns!` macro that lists a
//! table's columns with their types.
//!
//! Below both the loader ([`super::runs`], which reads the runs table by these declarations)
//! and the table builder ([`super::table`], which writes the summaries with them): the
//! builder names runs in its rows, the loader declares what it reads, and neither needs the
//! other for the declarations.

/// The type of a declared column.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Kind {
    F64,
    I64,
    Str,
    Bool,
}

/// A table's declared columns, several to a line: `columns![run_id: Str, h: F64, …]` — each
/// column's name with its [`Kind`] — as the `&[(&str, Kind)]` that
/// [`Table::new`](super::table::Table::new) and [`owned`](super::table::owned) take.
macro_rules! columns {
    ($($name:ident : $kind:ident),* $(,)?) => {
        [$((stringify!($name), $crate::summary::columns::Kind::$kind)),*]
    };
}
pub(crate) use columns;
