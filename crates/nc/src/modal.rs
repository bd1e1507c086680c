//! Modal state tracked block by block.

/// Motion mode (modal G group 1).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Motion {
    /// No motion mode programmed yet.
    None,
    /// G0 rapid.
    Rapid,
    /// G1 linear feed.
    Linear,
    /// G2 clockwise arc.
    ArcCw,
    /// G3 counter-clockwise arc.
    ArcCcw,
}

/// Index of each axis in [`Modal::pos`].
pub const X: usize = 0;
/// Y index.
pub const Y: usize = 1;
/// Z index.
pub const Z: usize = 2;
/// A index.
pub const A: usize = 3;
/// B index.
pub const B: usize = 4;
/// C index.
pub const C: usize = 5;

/// The axis letters in [`Modal::pos`] order.
pub const AXES: &[u8; 6] = b"XYZABC";

/// Modal state after a block.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Modal {
    /// Motion mode.
    pub motion: Motion,
    /// Positions X Y Z (mm) A B C (degrees), `None` until known (never programmed, or
    /// unknown after a datum shift / reference move).
    pub pos: [Option<f64>; 6],
    /// Programmed feed, mm/min (`None` until an F word; also `None` under G93 inverse time).
    pub feed_mm_min: Option<f64>,
    /// Tool-centre-point management on (M128, TRAORI, G43.4/G43.5).
    pub tcpm: bool,
    /// Incremental mode (G91).
    pub incremental: bool,
    /// Inch units (G20 / G70): values are converted to mm on read.
    pub inch: bool,
}

impl Default for Modal {
    fn default() -> Self {
        Modal {
            motion: Motion::None,
            pos: [None; 6],
            feed_mm_min: None,
            tcpm: false,
            incremental: false,
            inch: false,
        }
    }
}
