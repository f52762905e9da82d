//! A Gmsh MSH 4.1 writer for the tests (ASCII or binary), from the library's parsed sections: the
//! valid rewrites of issue 36's fuzz test (another encoding, other node order, tag gaps, CRLF,
//! comment sections) and files with counts that lie, written without Gmsh.
#![allow(dead_code)]

use std::fmt::Write as _;

use contact_sweep::space::fe::msh::{MshFile, nodes_of_type};

/// How to write a file.
#[derive(Debug, Clone, Default)]
pub struct Style {
    pub binary: bool,
    /// A `$Comments` section after every section.
    pub comments: bool,
    /// Counts replaced by these values (each `None` keeps the true one).
    pub lie: Lie,
}

/// Counts to write instead of the true ones.
#[derive(Debug, Clone, Default)]
pub struct Lie {
    pub names: Option<u64>,
    pub node_blocks: Option<u64>,
    pub nodes: Option<u64>,
    pub first_node_block: Option<u64>,
    pub element_blocks: Option<u64>,
    pub elements: Option<u64>,
    pub first_element_block: Option<u64>,
}

struct W {
    out: Vec<u8>,
    binary: bool,
}

impl W {
    fn text(&mut self, s: &str) {
        self.out.extend_from_slice(s.as_bytes());
    }
    /// Numbers of one record: binary as they are, ASCII space-separated on one line.
    fn size(&mut self, v: u64) {
        if self.binary {
            self.out.extend_from_slice(&v.to_le_bytes());
        } else {
            let _ = write!(self, "{v} ");
        }
    }
    fn int(&mut self, v: i32) {
        if self.binary {
            self.out.extend_from_slice(&v.to_le_bytes());
        } else {
            let _ = write!(self, "{v} ");
        }
    }
    fn double(&mut self, v: f64) {
        if self.binary {
            self.out.extend_from_slice(&v.to_le_bytes());
        } else {
            // Debug prints the shortest decimal that reads back to the same double.
            let _ = write!(self, "{v:?} ");
        }
    }
    fn eol(&mut self) {
        if !self.binary {
            if self.out.last() == Some(&b' ') {
                self.out.pop();
            }
            self.out.push(b'\n');
        }
    }
    fn end(&mut self, name: &str, comments: bool) {
        if self.binary {
            self.out.push(b'\n');
        }
        let _ = writeln!(self, "$End{name}");
        if comments {
            self.text("$Comments\nwritten by the tests' MSH writer; $Nodes here is no section\n$EndComments\n");
        }
    }
}

impl std::fmt::Write for W {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        self.out.extend_from_slice(s.as_bytes());
        Ok(())
    }
}

/// Write `m` in `style`.
pub fn write(m: &MshFile, style: &Style) -> Vec<u8> {
    let mut w = W {
        out: Vec::new(),
        binary: false,
    };
    let lie = &style.lie;
    w.text(&format!(
        "$MeshFormat\n4.1 {} 8\n",
        if style.binary { 1 } else { 0 }
    ));
    if style.binary {
        w.out.extend_from_slice(&1i32.to_le_bytes());
        w.out.push(b'\n');
    }
    w.text("$EndMeshFormat\n");
    if style.comments {
        w.text("$Comments\nthe body\n$EndComments\n");
    }
    if !m.names.is_empty() {
        w.text("$PhysicalNames\n");
        let _ = writeln!(w, "{}", lie.names.unwrap_or(m.names.len() as u64));
        for (d, t, n) in &m.names {
            let _ = writeln!(w, "{d} {t} \"{n}\"");
        }
        w.end("PhysicalNames", style.comments);
    }
    w.binary = style.binary;
    if let Some(en) = &m.entities {
        w.text("$Entities\n");
        for e in en {
            w.size(e.len() as u64);
        }
        w.eol();
        for (d, list) in en.iter().enumerate() {
            for e in list {
                w.int(e.tag);
                for _ in 0..if d == 0 { 3 } else { 6 } {
                    w.double(0.0);
                }
                w.size(e.physical_tags.len() as u64);
                for &p in &e.physical_tags {
                    w.int(p);
                }
                if d > 0 {
                    w.size(0);
                }
                w.eol();
            }
        }
        w.end("Entities", style.comments);
    }
    w.text("$Nodes\n");
    let all = m.node_blocks.iter().flat_map(|b| b.tags.iter().copied());
    let (lo, hi) = all.fold((u64::MAX, 0), |(l, h), t| (l.min(t), h.max(t)));
    let total: usize = m.node_blocks.iter().map(|b| b.tags.len()).sum();
    w.size(lie.node_blocks.unwrap_or(m.node_blocks.len() as u64));
    w.size(lie.nodes.unwrap_or(total as u64));
    w.size(lo.min(hi));
    w.size(hi);
    w.eol();
    for (i, b) in m.node_blocks.iter().enumerate() {
        w.int(b.entity_dim);
        w.int(b.entity_tag);
        w.int(0);
        let n = match (i, lie.first_node_block) {
            (0, Some(v)) => v,
            _ => b.tags.len() as u64,
        };
        w.size(n);
        w.eol();
        for &t in &b.tags {
            w.size(t);
            w.eol();
        }
        for c in &b.coords {
            for &x in c {
                w.double(x);
            }
            w.eol();
        }
    }
    w.end("Nodes", style.comments);
    w.text("$Elements\n");
    let all = m.element_blocks.iter().flat_map(|b| b.tags.iter().copied());
    let (lo, hi) = all.fold((u64::MAX, 0), |(l, h), t| (l.min(t), h.max(t)));
    let total: usize = m.element_blocks.iter().map(|b| b.tags.len()).sum();
    w.size(lie.element_blocks.unwrap_or(m.element_blocks.len() as u64));
    w.size(lie.elements.unwrap_or(total as u64));
    w.size(lo.min(hi));
    w.size(hi);
    w.eol();
    for (i, b) in m.element_blocks.iter().enumerate() {
        w.int(b.entity_dim);
        w.int(b.entity_tag);
        w.int(b.element_type);
        let n = match (i, lie.first_element_block) {
            (0, Some(v)) => v,
            _ => b.tags.len() as u64,
        };
        w.size(n);
        w.eol();
        let k = nodes_of_type(b.element_type).unwrap_or(1);
        for (e, &t) in b.tags.iter().enumerate() {
            w.size(t);
            for &n in &b.nodes[e * k..(e + 1) * k] {
                w.size(n);
            }
            w.eol();
        }
    }
    w.end("Elements", style.comments);
    w.out
}
