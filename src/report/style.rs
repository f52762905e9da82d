//! How the report tells method groups apart: group g has colour g mod 12 and marker g mod 5,
//! the same in every figure and in the HTML legend, so one legend serves every figure.
//!
//! Twelve colours and five markers: 12 and 5 are coprime, so by the Chinese remainder theorem
//! the pair (g mod 12, g mod 5) is different for each of the first lcm(12, 5) = 60 groups —
//! no two groups of a sweep with up to 60 method groups look the same, and groups 12 apart
//! (the first repeat of a colour) differ in marker. Past 60 the pairs cycle. The first eight
//! colours are the report's earlier palette (Okabe–Ito's, readable by colour-blind readers),
//! the four added ones are Paul Tol's dark green, wine, olive and indigo, dark enough on white
//! and away from the first eight in hue or lightness. Black stays reserved for the exact
//! solution and the Pareto front.

use plotters::style::RGBColor;

/// The qualitative palette as 0xRRGGBB (as the SVG writes them), in the order groups take it.
const PALETTE: [u32; 12] = [
    0x0072b2, 0xd55e00, 0x009e73, 0xcc79a7, 0xe69f00, 0x56b4e9, 0x785ef0, 0xa02020, 0x117733,
    0x882255, 0x999933, 0x332288,
];

/// A marker shape, drawn at a curve's points (convergence, work-precision) or at a dozen
/// points along it (time series).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Marker {
    Circle,
    Square,
    TriangleUp,
    Diamond,
    TriangleDown,
}

/// The markers, in the order groups take them.
const MARKERS: [Marker; 5] = [
    Marker::Circle,
    Marker::Square,
    Marker::TriangleUp,
    Marker::Diamond,
    Marker::TriangleDown,
];

impl Marker {
    /// The radius of the circle marker, in pixels.
    pub const RADIUS: i32 = 3;

    /// The outline of a polygonal marker in pixels around its point (y downwards), None for
    /// the circle. Sizes chosen so that the shapes cover about the circle's area.
    pub fn outline(self) -> Option<&'static [(i32, i32)]> {
        match self {
            Marker::Circle => None,
            Marker::Square => Some(&[(-3, -3), (3, -3), (3, 3), (-3, 3)]),
            Marker::TriangleUp => Some(&[(0, -4), (4, 3), (-4, 3)]),
            Marker::Diamond => Some(&[(0, -4), (4, 0), (0, 4), (-4, 0)]),
            Marker::TriangleDown => Some(&[(0, 4), (4, -3), (-4, -3)]),
        }
    }

    /// The marker as a text glyph, for the HTML legend.
    pub fn glyph(self) -> char {
        match self {
            Marker::Circle => '●',
            Marker::Square => '■',
            Marker::TriangleUp => '▲',
            Marker::Diamond => '◆',
            Marker::TriangleDown => '▼',
        }
    }
}

/// The colour of group `i`.
pub fn color(i: usize) -> RGBColor {
    let c = PALETTE[i % PALETTE.len()];
    RGBColor((c >> 16) as u8, (c >> 8) as u8, c as u8)
}

/// The marker of group `i`.
pub fn marker(i: usize) -> Marker {
    MARKERS[i % MARKERS.len()]
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashSet;

    #[test]
    fn sixty_groups_have_sixty_different_looks() {
        let looks: HashSet<((u8, u8, u8), Marker)> = (0..60)
            .map(|g| {
                let c = color(g);
                ((c.0, c.1, c.2), marker(g))
            })
            .collect();
        assert_eq!(looks.len(), 60);
        let colours: HashSet<u32> = PALETTE.iter().copied().collect();
        assert_eq!(colours.len(), 12, "twelve different colours");
        assert!(!colours.contains(&0), "black is the exact solution's");
        // The first eight are the earlier palette's (reports of ≤ 8 groups keep their colours).
        assert_eq!(color(0), RGBColor(0, 114, 178));
        assert_eq!(color(7), RGBColor(160, 32, 32));
    }
}
