//! The Gmsh MSH 4.1 file format, ASCII and binary, parsed from bytes into its sections (issue 36):
//! the engine's own parser, written so that no input can make it panic, abort or allocate more
//! than a small multiple of the file's size.
//!
//! Why not a general-purpose crate: the one used before (`mshio`) dropped the node tags of a
//! `$Nodes` section whose header called them contiguous (a valid file listing its nodes out of
//! tag order was read mirrored), allocated on counts read from the file (a `$PhysicalNames`
//! count of 10⁹ aborted the process), panicked on some binary headers and reported "Unknown
//! error" with a dump of the rest of the file. Here:
//! - node tags are always read and kept; what the header says about their range is not used;
//! - every count read from the file is checked against the bytes left before anything is
//!   allocated for it: an ASCII number takes at least 2 bytes (a digit and a separator), a
//!   binary one its width, so a count that cannot fit is refused, and no allocation exceeds a
//!   few times the file's size;
//! - each error is a [`MshError`]: the section, the entity or block and the reason, one line,
//!   with any quoted file text cut to a few characters.
//!
//! What is read: `$MeshFormat` (version 4.1, ASCII or binary with 4- or 8-byte `size_t`, either
//! byte order as Gmsh reads it), `$PhysicalNames` (ASCII in both encodings), `$Entities` (the
//! physical tags of each entity), `$Nodes` (tags and coordinates, parametric coordinates
//! skipped), `$Elements` (the types the engine knows: points, 2-/3-node lines, 3-/6-node
//! triangles, 4-/9-node quadrilaterals, 4-/10-node tetrahedra, 8-/27-node hexahedra). Every other
//! section (`$Periodic`, `$NodeData`, `$Comments`, …) is skipped up to its `$End…` line, as the
//! format specifies for sections a reader does not know. A partitioned file is refused.

use std::fmt;

/// Why the bytes are not a readable MSH 4.1 file: where (section and entity) and why.
#[derive(Debug, Clone, PartialEq)]
pub struct MshError {
    /// The section, e.g. `$Nodes`.
    pub section: String,
    /// The entity, block or line the reason concerns, e.g. "block 2 (entity 1 of dimension 1)".
    pub at: String,
    pub reason: String,
}

impl fmt::Display for MshError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.at.is_empty() {
            write!(f, "{}: {}", self.section, self.reason)
        } else {
            write!(f, "{}, {}: {}", self.section, self.at, self.reason)
        }
    }
}

/// A geometric entity of `$Entities`: its tag and physical tags.
#[derive(Debug, Clone, PartialEq)]
pub struct Entity {
    pub tag: i32,
    pub physical_tags: Vec<i32>,
}

/// One block of `$Nodes`.
#[derive(Debug, Clone, PartialEq)]
pub struct NodeBlock {
    pub entity_dim: i32,
    pub entity_tag: i32,
    pub tags: Vec<u64>,
    pub coords: Vec<[f64; 3]>,
}

/// One block of `$Elements`: elements of one Gmsh type.
#[derive(Debug, Clone, PartialEq)]
pub struct ElementBlock {
    pub entity_dim: i32,
    pub entity_tag: i32,
    /// Gmsh's element type id (a supported one, [`nodes_of_type`]).
    pub element_type: i32,
    pub tags: Vec<u64>,
    /// The node tags, `nodes_of_type(element_type)` per element.
    pub nodes: Vec<u64>,
}

impl ElementBlock {
    /// Nodes per element.
    pub fn nodes_per_element(&self) -> usize {
        nodes_of_type(self.element_type).unwrap_or(1)
    }

    /// The node tags of element `i` of the block.
    pub fn element(&self, i: usize) -> &[u64] {
        let k = self.nodes_per_element();
        &self.nodes[i * k..(i + 1) * k]
    }
}

/// The sections of a file the engine uses.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct MshFile {
    pub binary: bool,
    /// (dimension, physical tag, name) per `$PhysicalNames` line.
    pub names: Vec<(usize, i32, String)>,
    /// Points, curves, surfaces, volumes; `None` without `$Entities`.
    pub entities: Option<[Vec<Entity>; 4]>,
    pub node_blocks: Vec<NodeBlock>,
    pub element_blocks: Vec<ElementBlock>,
}

/// Nodes per element of the Gmsh element types the engine reads.
pub fn nodes_of_type(t: i32) -> Option<usize> {
    Some(match t {
        15 => 1,
        1 => 2,
        8 => 3,
        2 => 3,
        9 => 6,
        3 => 4,
        10 => 9,
        4 => 4,
        11 => 10,
        5 => 8,
        12 => 27,
        _ => return None,
    })
}

/// Dimension of a supported Gmsh element type.
pub fn dim_of_type(t: i32) -> Option<usize> {
    Some(match t {
        15 => 0,
        1 | 8 => 1,
        2 | 9 | 3 | 10 => 2,
        4 | 11 | 5 | 12 => 3,
        _ => return None,
    })
}

/// Gmsh's name of an element type (those a user may meet), for messages.
pub fn type_name(t: i32) -> String {
    let s = match t {
        1 => "2-node line",
        2 => "3-node triangle",
        3 => "4-node quadrilateral",
        4 => "4-node tetrahedron",
        5 => "8-node hexahedron",
        6 => "6-node prism",
        7 => "5-node pyramid",
        8 => "3-node line",
        9 => "6-node triangle",
        10 => "9-node quadrilateral",
        11 => "10-node tetrahedron",
        12 => "27-node hexahedron",
        13 => "18-node prism",
        14 => "14-node pyramid",
        15 => "point",
        16 => "8-node quadrilateral",
        17 => "20-node hexahedron",
        18 => "15-node prism",
        19 => "13-node pyramid",
        20 => "9-node triangle",
        21 => "10-node triangle",
        26 => "4-node line",
        27 => "5-node line",
        29 => "20-node tetrahedron",
        _ => return format!("type {t}"),
    };
    s.to_string()
}

/// A few characters of file text, printable, for a message.
fn snippet(b: &[u8]) -> String {
    let s = String::from_utf8_lossy(&b[..b.len().min(16)]);
    let mut out: String = s.chars().flat_map(char::escape_default).take(24).collect();
    if b.len() > 16 {
        out.push('…');
    }
    out
}

/// A cursor over the file's bytes in one encoding.
struct Cur<'a> {
    b: &'a [u8],
    pos: usize,
    binary: bool,
    /// Binary numbers in the other byte order (the file's `1` read as 0x01000000).
    swap: bool,
    /// Width of a binary `size_t` (4 or 8).
    size_t: usize,
    section: &'static str,
    at: String,
}

impl<'a> Cur<'a> {
    fn err(&self, reason: impl Into<String>) -> MshError {
        MshError {
            section: self.section.to_string(),
            at: self.at.clone(),
            reason: reason.into(),
        }
    }

    fn left(&self) -> usize {
        self.b.len() - self.pos
    }

    /// Refuse a count whose items cannot fit in the bytes left: `per_item` numbers of at least
    /// `min_bytes` each (ASCII: 2, a digit and a separator; binary: their width).
    fn check_count(&self, what: &str, count: u64, min_bytes: u64) -> Result<usize, MshError> {
        let need = count.saturating_mul(min_bytes.max(1));
        if need > self.left() as u64 {
            return Err(self.err(format!(
                "{count} {what} announced, but only {} bytes are left in the file",
                self.left()
            )));
        }
        Ok(count as usize)
    }

    /// Bytes an ASCII number or a binary one of `width` bytes takes at least.
    fn min_bytes(&self, width: usize) -> u64 {
        if self.binary { width as u64 } else { 2 }
    }

    fn skip_ws(&mut self) {
        while self.pos < self.b.len() && self.b[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
    }

    /// The next whitespace-separated ASCII token.
    fn token(&mut self, what: &str) -> Result<&'a [u8], MshError> {
        self.skip_ws();
        let start = self.pos;
        while self.pos < self.b.len() && !self.b[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        let t = &self.b[start..self.pos];
        if t.is_empty() {
            return Err(self.err(format!("the file ends before {what}")));
        }
        if t[0] == b'$' {
            self.pos = start;
            return Err(self.err(format!(
                "the section ends (\"{}\") before {what}",
                snippet(t)
            )));
        }
        Ok(t)
    }

    fn bytes(&mut self, n: usize, what: &str) -> Result<&'a [u8], MshError> {
        if self.left() < n {
            return Err(self.err(format!("the file ends before {what}")));
        }
        let s = &self.b[self.pos..self.pos + n];
        self.pos += n;
        Ok(s)
    }

    fn bin_u64(&mut self, width: usize, what: &str) -> Result<u64, MshError> {
        let s = self.bytes(width, what)?;
        let mut v = 0u64;
        // Little-endian unless swapped: the file's own order, found from its `1`.
        if self.swap {
            for &x in s {
                v = (v << 8) | x as u64;
            }
        } else {
            for &x in s.iter().rev() {
                v = (v << 8) | x as u64;
            }
        }
        Ok(v)
    }

    /// A `size_t`.
    fn size(&mut self, what: &str) -> Result<u64, MshError> {
        if self.binary {
            let w = self.size_t;
            return self.bin_u64(w, what);
        }
        let t = self.token(what)?;
        parse_u64(t).ok_or_else(|| {
            self.err(format!(
                "{what} is \"{}\", not a non-negative integer",
                snippet(t)
            ))
        })
    }

    /// An `int`.
    fn int(&mut self, what: &str) -> Result<i32, MshError> {
        if self.binary {
            return Ok(self.bin_u64(4, what)? as u32 as i32);
        }
        let t = self.token(what)?;
        std::str::from_utf8(t)
            .ok()
            .and_then(|s| s.parse::<i32>().ok())
            .ok_or_else(|| self.err(format!("{what} is \"{}\", not an integer", snippet(t))))
    }

    /// A `double`.
    fn double(&mut self, what: &str) -> Result<f64, MshError> {
        if self.binary {
            return Ok(f64::from_bits(self.bin_u64(8, what)?));
        }
        let t = self.token(what)?;
        std::str::from_utf8(t)
            .ok()
            .and_then(|s| s.parse::<f64>().ok())
            .ok_or_else(|| self.err(format!("{what} is \"{}\", not a number", snippet(t))))
    }

    /// The rest of the current line (ASCII), without its end.
    fn line(&mut self) -> &'a [u8] {
        let start = self.pos;
        while self.pos < self.b.len() && self.b[self.pos] != b'\n' {
            self.pos += 1;
        }
        let l = &self.b[start..self.pos];
        if self.pos < self.b.len() {
            self.pos += 1;
        }
        l.strip_suffix(b"\r").unwrap_or(l)
    }

    /// Expect the `$End…` line of the current section after its data.
    fn end(&mut self, name: &str) -> Result<(), MshError> {
        self.skip_ws();
        let want = format!("$End{name}");
        let rest = &self.b[self.pos..];
        if rest.starts_with(want.as_bytes())
            && rest.get(want.len()).is_none_or(|c| c.is_ascii_whitespace())
        {
            self.pos += want.len();
            Ok(())
        } else {
            self.at.clear();
            Err(self.err(format!(
                "expected {want} after the section's data, found \"{}\" (a count that does not match the data?)",
                snippet(rest)
            )))
        }
    }
}

fn parse_u64(t: &[u8]) -> Option<u64> {
    if t.is_empty() || t.len() > 20 {
        return None;
    }
    let mut v: u64 = 0;
    for &c in t {
        if !c.is_ascii_digit() {
            return None;
        }
        v = v.checked_mul(10)?.checked_add((c - b'0') as u64)?;
    }
    Some(v)
}

/// Parse a whole MSH 4.1 file.
pub fn parse(bytes: &[u8]) -> Result<MshFile, MshError> {
    let mut c = Cur {
        b: bytes,
        pos: 0,
        binary: false,
        swap: false,
        size_t: 8,
        section: "$MeshFormat",
        at: String::new(),
    };
    let mut out = MshFile::default();
    let mut seen: Vec<String> = Vec::new();
    loop {
        c.binary = false;
        c.section = "file";
        c.at.clear();
        c.skip_ws();
        if c.pos >= bytes.len() {
            break;
        }
        let header = c.line();
        let name = std::str::from_utf8(header).unwrap_or("").trim();
        let Some(name) = name
            .strip_prefix('$')
            .filter(|n| !n.is_empty() && n.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_'))
        else {
            return Err(c.err(format!(
                "expected a section header ($Name), found \"{}\"",
                snippet(header)
            )));
        };
        let name = name.to_string();
        if seen.is_empty() && name != "MeshFormat" {
            c.section = "$MeshFormat";
            return Err(c.err("the file does not start with $MeshFormat"));
        }
        let known = [
            "MeshFormat",
            "PhysicalNames",
            "Entities",
            "Nodes",
            "Elements",
            "PartitionedEntities",
        ];
        if let Some(&k) = known.iter().find(|&&k| k == name) {
            if seen.contains(&name) {
                c.section = "file";
                return Err(c.err(format!("section ${name} appears twice")));
            }
            seen.push(name.clone());
            match k {
                "MeshFormat" => {
                    c.section = "$MeshFormat";
                    mesh_format(&mut c)?;
                    out.binary = c.binary;
                }
                "PhysicalNames" => {
                    c.section = "$PhysicalNames";
                    // ASCII in binary files too.
                    c.binary = false;
                    out.names = physical_names(&mut c)?;
                }
                "Entities" => {
                    c.section = "$Entities";
                    c.binary = out.binary;
                    out.entities = Some(entities(&mut c)?);
                }
                "Nodes" => {
                    c.section = "$Nodes";
                    c.binary = out.binary;
                    out.node_blocks = blocks(&mut c, "node", node_block)?;
                }
                "Elements" => {
                    c.section = "$Elements";
                    c.binary = out.binary;
                    out.element_blocks = blocks(&mut c, "element", element_block)?;
                }
                _ => {
                    c.section = "$PartitionedEntities";
                    return Err(
                        c.err("partitioned meshes are not supported; save the mesh unpartitioned")
                    );
                }
            }
            c.binary = false;
            c.end(&name)?;
        } else {
            // A section the engine does not use: skipped to its end line (the format's rule
            // for unknown sections, e.g. `$Comments`).
            let want = format!("$End{name}");
            let rest = &bytes[c.pos..];
            match find_line(rest, want.as_bytes()) {
                Some(p) => c.pos += p + want.len(),
                None => {
                    c.section = "file";
                    return Err(c.err(format!("section ${name} has no {want} line")));
                }
            }
            seen.push(name);
        }
    }
    if seen.is_empty() {
        c.section = "$MeshFormat";
        return Err(c.err("the file is empty"));
    }
    Ok(out)
}

/// Position of `needle` at the start of a line in `hay`.
fn find_line(hay: &[u8], needle: &[u8]) -> Option<usize> {
    let mut from = 0;
    while from + needle.len() <= hay.len() {
        let p = hay[from..]
            .windows(needle.len())
            .position(|w| w == needle)?
            + from;
        if p == 0 || hay[p - 1] == b'\n' {
            return Some(p);
        }
        from = p + 1;
    }
    None
}

fn mesh_format(c: &mut Cur) -> Result<(), MshError> {
    let v = c.token("the version")?;
    if v != b"4.1" {
        return Err(c.err(format!(
            "version \"{}\"; save the mesh with Gmsh's -format msh41",
            snippet(v)
        )));
    }
    let t = c.token("the file type")?;
    let binary = match t {
        b"0" => false,
        b"1" => true,
        _ => {
            return Err(c.err(format!(
                "file type \"{}\", expected 0 (ASCII) or 1 (binary)",
                snippet(t)
            )));
        }
    };
    let d = c.token("the data size")?;
    c.size_t = match d {
        b"8" => 8,
        b"4" => 4,
        _ => {
            return Err(c.err(format!(
                "data size \"{}\", expected 8 (or 4), the bytes of a size_t",
                snippet(d)
            )));
        }
    };
    if binary {
        // One newline, then the integer 1 in the writer's byte order.
        if c.b.get(c.pos) == Some(&b'\r') {
            c.pos += 1;
        }
        if c.b.get(c.pos) != Some(&b'\n') {
            return Err(c.err("no line end after the header line of a binary file"));
        }
        c.pos += 1;
        let one = c.bytes(4, "the binary file's integer 1")?;
        c.swap = match one {
            [1, 0, 0, 0] => false,
            [0, 0, 0, 1] => true,
            _ => {
                return Err(c.err(format!(
                    "the binary file's integer 1 reads {one:02x?}: neither byte order"
                )));
            }
        };
    }
    c.binary = binary;
    Ok(())
}

fn physical_names(c: &mut Cur) -> Result<Vec<(usize, i32, String)>, MshError> {
    let n = c.size("the number of names")?;
    // A line is at least `d t ""` plus its end: 7 bytes.
    let n = c.check_count("physical names", n, 7)?;
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        c.at = format!("name {}", i + 1);
        let d = c.int("the dimension")?;
        if !(0..=3).contains(&d) {
            return Err(c.err(format!("dimension {d}, expected 0 to 3")));
        }
        let t = c.int("the physical tag")?;
        c.skip_ws();
        if c.b.get(c.pos) != Some(&b'"') {
            let rest = &c.b[c.pos..];
            return Err(c.err(format!(
                "expected a quoted name, found \"{}\"",
                snippet(rest)
            )));
        }
        c.pos += 1;
        let rest = &c.b[c.pos..];
        let close = rest
            .iter()
            .take(1024)
            .position(|&b| b == b'"' || b == b'\n')
            .filter(|&p| rest[p] == b'"')
            .ok_or_else(|| c.err("the name has no closing quote on its line"))?;
        let name = std::str::from_utf8(&rest[..close])
            .map_err(|_| c.err("the name is not UTF-8"))?
            .to_string();
        c.pos += close + 1;
        out.push((d as usize, t, name));
    }
    c.at.clear();
    Ok(out)
}

fn entities(c: &mut Cur) -> Result<[Vec<Entity>; 4], MshError> {
    let mut counts = [0u64; 4];
    let kinds = ["points", "curves", "surfaces", "volumes"];
    for (k, what) in counts.iter_mut().zip(kinds) {
        *k = c.size(&format!("the number of {what}"))?;
    }
    let mut out: [Vec<Entity>; 4] = Default::default();
    for d in 0..4 {
        // A point: a tag, 3 coordinates and a count; a curve and up: a tag, 6 bounds, 2 counts.
        let (ints, doubles, sizes) = if d == 0 { (1, 3, 1) } else { (1, 6, 2) };
        let min = ints * c.min_bytes(4) + doubles * c.min_bytes(8) + sizes * c.min_bytes(c.size_t);
        let n = c.check_count(kinds[d], counts[d], min)?;
        let mut v = Vec::with_capacity(n);
        for i in 0..n {
            c.at = format!("{} {} of {}", &kinds[d][..kinds[d].len() - 1], i + 1, n);
            let tag = c.int("the entity tag")?;
            c.at = format!("entity {tag} of dimension {d}");
            for _ in 0..doubles {
                c.double("a coordinate")?;
            }
            let np = c.size("the number of physical tags")?;
            let np = c.check_count("physical tags", np, c.min_bytes(4))?;
            let mut phys = Vec::with_capacity(np);
            for _ in 0..np {
                phys.push(c.int("a physical tag")?);
            }
            if d > 0 {
                let nb = c.size("the number of bounding entities")?;
                let nb = c.check_count("bounding entities", nb, c.min_bytes(4))?;
                for _ in 0..nb {
                    c.int("a bounding entity")?;
                }
            }
            v.push(Entity {
                tag,
                physical_tags: phys,
            });
        }
        out[d] = v;
    }
    c.at.clear();
    Ok(out)
}

/// The blocks of `$Nodes` or `$Elements` (`item`: "node" or "element"), each read by `body`
/// after its entity: the section's header (the number of blocks, checked against the bytes
/// left, and of items), the blocks, and the header's count against the items the blocks hold.
/// `body` reads the rest of a block of the entity (dimension, tag) and returns it with its
/// number of items.
fn blocks<'a, T>(
    c: &mut Cur<'a>,
    item: &str,
    mut body: impl FnMut(&mut Cur<'a>, i32, i32) -> Result<(T, usize), MshError>,
) -> Result<Vec<T>, MshError> {
    let nb = c.size("the number of blocks")?;
    let total = c.size(&format!("the number of {item}s"))?;
    // The header's tag range is not used: tags are read and kept whatever it says.
    c.size(&format!("the smallest {item} tag"))?;
    c.size(&format!("the largest {item} tag"))?;
    let block_min = 3 * c.min_bytes(4) + c.min_bytes(c.size_t);
    let nb = c.check_count(&format!("{item} blocks"), nb, block_min)?;
    let mut out = Vec::with_capacity(nb);
    let mut read: u64 = 0;
    for b in 0..nb {
        c.at = format!("block {} of {nb}", b + 1);
        let entity_dim = c.int("the entity dimension")?;
        let entity_tag = c.int("the entity tag")?;
        c.at = format!(
            "block {} of {nb} (entity {entity_tag} of dimension {entity_dim})",
            b + 1
        );
        if !(0..=3).contains(&entity_dim) {
            return Err(c.err(format!("entity dimension {entity_dim}, expected 0 to 3")));
        }
        let (block, n) = body(c, entity_dim, entity_tag)?;
        read += n as u64;
        out.push(block);
    }
    c.at.clear();
    if read != total {
        return Err(c.err(format!(
            "the header announces {total} {item}s, the blocks hold {read}"
        )));
    }
    Ok(out)
}

/// One block of `$Nodes` after its entity: the parametric flag, the node tags, then their
/// coordinates (parametric ones skipped).
fn node_block(c: &mut Cur, entity_dim: i32, tag: i32) -> Result<(NodeBlock, usize), MshError> {
    let parametric = c.int("the parametric flag")?;
    if !(0..=1).contains(&parametric) {
        return Err(c.err(format!("parametric flag {parametric}, expected 0 or 1")));
    }
    let extra = if parametric == 1 {
        entity_dim as u64
    } else {
        0
    };
    let n = c.size("the number of nodes in the block")?;
    let per = c.min_bytes(c.size_t) + (3 + extra) * c.min_bytes(8);
    let n = c.check_count("nodes", n, per)?;
    let mut tags = Vec::with_capacity(n);
    for _ in 0..n {
        tags.push(c.size("a node tag")?);
    }
    let mut coords = Vec::with_capacity(n);
    for (i, _) in tags.iter().enumerate() {
        let mut x = [0.0; 3];
        for v in &mut x {
            *v = c.double("a coordinate").map_err(|mut e| {
                e.at = format!("{}, node {}", e.at, tags[i]);
                e
            })?;
        }
        for _ in 0..extra {
            c.double("a parametric coordinate")?;
        }
        coords.push(x);
    }
    let block = NodeBlock {
        entity_dim,
        entity_tag: tag,
        tags,
        coords,
    };
    Ok((block, n))
}

/// One block of `$Elements` after its entity: the element type (supported, of the entity's
/// dimension), then each element's tag and node tags.
fn element_block(
    c: &mut Cur,
    entity_dim: i32,
    entity_tag: i32,
) -> Result<(ElementBlock, usize), MshError> {
    let element_type = c.int("the element type")?;
    let n = c.size("the number of elements in the block")?;
    let Some(k) = nodes_of_type(element_type) else {
        // The first element's tag names it (its node count is unknown, so the block
        // cannot be read past it).
        let first = if n > 0 {
            c.size("an element tag")
                .map(|t| format!("element {t}"))
                .unwrap_or_default()
        } else {
            String::new()
        };
        return Err(c.err(format!(
            "{first} has Gmsh type {element_type} ({}), not supported (P1/P2 triangles and tetrahedra, Q1/Q2 quadrilaterals and hexahedra, their faces, points)",
            type_name(element_type)
        )
        .trim_start()
        .to_string()));
    };
    let td = dim_of_type(element_type).unwrap_or(0);
    if td as i32 != entity_dim {
        return Err(c.err(format!(
            "{}s (dimension {td}) in a block of an entity of dimension {entity_dim}",
            type_name(element_type)
        )));
    }
    let n = c.check_count("elements", n, (1 + k as u64) * c.min_bytes(c.size_t))?;
    let mut tags = Vec::with_capacity(n);
    let mut nodes = Vec::with_capacity(n * k);
    for _ in 0..n {
        let t = c.size("an element tag")?;
        tags.push(t);
        for _ in 0..k {
            nodes.push(c.size("a node tag").map_err(|mut e| {
                e.at = format!("{}, element {t}", e.at);
                e
            })?);
        }
    }
    let block = ElementBlock {
        entity_dim,
        entity_tag,
        element_type,
        tags,
        nodes,
    };
    Ok((block, n))
}
