//! The choices both two-body scenes share (contract §2.6): which bodies a mass variant modifies
//! (`mass_side`) and how the unbiased Nitsche method weights its two sides (`nitsche_sides`).
//! One definition, so `bars1d` and `blocks2d`/`blocks3d` read the keys the same way.

/// Which bodies a mass variant modifies (contract §2.6 `mass_side`): layer 0 of body i is its
/// elements touching its own contact face.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MassSide {
    Both,
    A,
    B,
}

impl MassSide {
    /// From the `mass_side` key's index into its choices (both, a, b).
    pub fn from_index(x: f64) -> MassSide {
        match x as usize {
            1 => MassSide::A,
            2 => MassSide::B,
            _ => MassSide::Both,
        }
    }

    /// Whether the mass variant acts on body `body` (0 = A, 1 = B).
    pub fn includes(self, body: usize) -> bool {
        match self {
            MassSide::Both => true,
            MassSide::A => body == 0,
            MassSide::B => body == 1,
        }
    }
}

/// The weights of the two sides' Nitsche terms (contract §2.6 `nitsche_sides`): unbiased
/// (w_a = w_b = ½) or A the slave (w_a = 1, w_b = 0).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NitscheSides {
    Unbiased,
    A,
}

impl NitscheSides {
    /// From the `nitsche_sides` key's index into its choices (unbiased, a).
    pub fn from_index(x: f64) -> NitscheSides {
        if x == 1.0 {
            NitscheSides::A
        } else {
            NitscheSides::Unbiased
        }
    }

    /// The sides' weights (w_a, w_b).
    pub fn weights(self) -> [f64; 2] {
        match self {
            NitscheSides::Unbiased => [0.5, 0.5],
            NitscheSides::A => [1.0, 0.0],
        }
    }
}
