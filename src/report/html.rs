//! The report's HTML: escaping, the summary's Markdown rendered (headings, paragraphs, lists,
//! GitHub tables: all the summary's `.md` files use), plain tables, the style sheet, and the
//! [`Page`] the sections write into. The report is one self-contained file, so this is all
//! hand-written: no template engine, no Markdown crate for five constructs.

use std::fmt::Write as _;

use super::figures::FigureError;

/// The report's body as the sections write it, with the figures drawn counted and the ones
/// that could not be drawn noted (the report lists them at its end, `report` on stderr).
#[derive(Default)]
pub(super) struct Page {
    pub body: String,
    pub figures: usize,
    pub skipped: Vec<String>,
}

impl Page {
    /// A figure as drawn: its SVG appended to the body, or its error noted.
    pub fn figure(&mut self, drawn: Result<String, FigureError>) {
        match drawn {
            Ok(svg) => {
                self.body.push_str(&svg);
                self.figures += 1;
            }
            Err(x) => self.skipped.push(x.to_string()),
        }
    }

    /// [`Page::figure`] for a figure on its own line (`<div class="fig">`).
    pub fn figure_alone(&mut self, drawn: Result<String, FigureError>) {
        match drawn {
            Ok(svg) => {
                let _ = writeln!(self.body, "<div class=\"fig\">{svg}</div>");
                self.figures += 1;
            }
            Err(x) => self.skipped.push(x.to_string()),
        }
    }
}

/// HTML-escape text.
pub(super) fn esc(s: &str) -> String {
    let mut o = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => o.push_str("&amp;"),
            '<' => o.push_str("&lt;"),
            '>' => o.push_str("&gt;"),
            '"' => o.push_str("&quot;"),
            c => o.push(c),
        }
    }
    o
}

/// Inline Markdown of the summary's text: `code` spans, **bold**.
fn inline(s: &str) -> String {
    let e = esc(s);
    let mut out = String::new();
    for (i, part) in e.split('`').enumerate() {
        if i % 2 == 1 {
            let _ = write!(out, "<code>{part}</code>");
        } else {
            for (j, b) in part.split("**").enumerate() {
                if j % 2 == 1 {
                    let _ = write!(out, "<b>{b}</b>");
                } else {
                    out.push_str(b);
                }
            }
        }
    }
    out
}

/// The summary's Markdown (headings, paragraphs, lists, GitHub tables) as HTML; heading
/// levels are shifted by `shift` so that the files' `#` sit under the report's sections.
pub(super) fn markdown(md: &str, shift: usize) -> String {
    let mut out = String::new();
    let lines: Vec<&str> = md.lines().collect();
    let mut i = 0;
    let cells = |l: &str| -> Vec<String> {
        let t = l.trim().trim_start_matches('|').trim_end_matches('|');
        // split at | not preceded by a backslash
        let mut v = Vec::new();
        let mut cur = String::new();
        let mut prev = ' ';
        for c in t.chars() {
            if c == '|' && prev != '\\' {
                v.push(cur.trim().replace("\\|", "|"));
                cur.clear();
            } else {
                cur.push(c);
            }
            prev = c;
        }
        v.push(cur.trim().replace("\\|", "|"));
        v
    };
    while i < lines.len() {
        let l = lines[i];
        if l.trim().is_empty() {
            i += 1;
        } else if l.starts_with('#') {
            let level = l.chars().take_while(|&c| c == '#').count();
            let h = (level + shift).min(6);
            let _ = writeln!(out, "<h{h}>{}</h{h}>", inline(l[level..].trim()));
            i += 1;
        } else if l.starts_with('|') {
            let header = cells(l);
            let right: Vec<bool> = lines
                .get(i + 1)
                .map(|a| {
                    cells(a)
                        .iter()
                        .map(|c| c.ends_with(':') && !c.starts_with(':'))
                        .collect()
                })
                .unwrap_or_default();
            out.push_str("<table><thead><tr>");
            for h in &header {
                let _ = write!(out, "<th>{}</th>", inline(h));
            }
            out.push_str("</tr></thead><tbody>\n");
            i += 2;
            while i < lines.len() && lines[i].starts_with('|') {
                out.push_str("<tr>");
                for (k, c) in cells(lines[i]).iter().enumerate() {
                    let cls = if right.get(k).copied().unwrap_or(false) {
                        " class=\"r\""
                    } else {
                        ""
                    };
                    let _ = write!(out, "<td{cls}>{}</td>", inline(c));
                }
                out.push_str("</tr>\n");
                i += 1;
            }
            out.push_str("</tbody></table>\n");
        } else if l.starts_with("- ") {
            out.push_str("<ul>");
            while i < lines.len() && lines[i].starts_with("- ") {
                let _ = write!(out, "<li>{}</li>", inline(&lines[i][2..]));
                i += 1;
            }
            out.push_str("</ul>\n");
        } else {
            let mut p = Vec::new();
            while i < lines.len()
                && !lines[i].trim().is_empty()
                && !lines[i].starts_with('#')
                && !lines[i].starts_with('|')
                && !lines[i].starts_with("- ")
            {
                p.push(lines[i]);
                i += 1;
            }
            let _ = writeln!(out, "<p>{}</p>", inline(&p.join(" ")));
        }
    }
    out
}

/// An HTML table from rows of text; `right[k]`: column k right-aligned.
pub(super) fn html_table(header: &[String], right: &[bool], rows: &[Vec<String>]) -> String {
    let mut out = String::from("<table><thead><tr>");
    for h in header {
        let _ = write!(out, "<th>{}</th>", esc(h));
    }
    out.push_str("</tr></thead><tbody>\n");
    for r in rows {
        out.push_str("<tr>");
        for (k, c) in r.iter().enumerate() {
            let cls = if right.get(k).copied().unwrap_or(false) {
                " class=\"r\""
            } else {
                ""
            };
            let _ = write!(out, "<td{cls}>{}</td>", esc(c));
        }
        out.push_str("</tr>\n");
    }
    out.push_str("</tbody></table>\n");
    out
}

pub(super) const CSS: &str = "body{font-family:system-ui,-apple-system,'Segoe UI',sans-serif;margin:0 auto;max-width:1560px;padding:16px 24px;color:#222;line-height:1.4}
h1{font-size:1.6em;margin:.2em 0}h2{border-bottom:1px solid #ccc;margin-top:1.6em}
table{border-collapse:collapse;margin:.6em 0;font-size:.86em}th,td{border:1px solid #ddd;padding:2px 6px;text-align:left}
th{background:#f3f3f3}td.r{text-align:right;font-variant-numeric:tabular-nums}
.figs{display:grid;grid-template-columns:repeat(auto-fill,minmax(600px,1fr));gap:12px}
.figs svg,.fig svg{max-width:100%;height:auto;border:1px solid #eee}
pre{background:#f7f7f7;padding:8px;overflow-x:auto;font-size:.85em}
.hints{background:#fff8e1;border-left:4px solid #e6a700;padding:6px 12px}
.note{color:#666;font-size:.9em}details{margin:.6em 0}summary{cursor:pointer;font-weight:600}
nav a{margin-right:1em}
.legend{display:flex;flex-wrap:wrap;gap:4px 18px;font-size:.85em;margin:.4em 0}.legend i{display:inline-block;width:22px;height:4px;margin:0 6px 3px 0;vertical-align:middle;font-style:normal;font-size:12px;line-height:4px;text-align:center}";
#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn markdown_tables_headings_and_code_become_html() {
        let md = "# Title\n\nSome `code` and **bold** < text.\n\n| a | b \\| c |\n|:---|---:|\n| 1 | 2 |\n\n- item\n";
        let h = markdown(md, 1);
        assert!(h.contains("<h2>Title</h2>"), "{h}");
        assert!(
            h.contains("<code>code</code>") && h.contains("<b>bold</b>") && h.contains("&lt; text")
        );
        assert!(
            h.contains("<th>b | c</th>") && h.contains("<td class=\"r\">2</td>"),
            "{h}"
        );
        assert!(h.contains("<li>item</li>"));
    }
}
