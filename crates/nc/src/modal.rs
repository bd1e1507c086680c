//! Modal state tracked block by block.
//!
//! How a block changes the state (all dialects unless named):
//! - motion: `G0 G1 G2 G3` (also `G00`…`G03`);
//! - `G90`/`G91` absolute/incremental (incremental from an unknown position stays
//!   unknown); `G20`/`G21`, `G70`/`G71`, `G700`/`G710` inch/metric (also read from a `%NAME
//!   G71` header): in inch mode X Y Z and F are multiplied by 25.4 on read;
//! - TCPM: `M128`/`M129`, `TRAORI`/`TRAFOOF`, `G43.4`/`G43.5`/`G49`;
//! - F in mm/min under `G94`; under `G93` (inverse time) or `G95` (per revolution) the
//!   feed is `None`, and after returning to `G94` it is `None` until the next F;
//! - axis words X Y Z A B C set positions in moves (and in a block without any motion mode
//!   yet, which is then not counted as a move);
//! - datum shifts — Heidenhain `G54`/`G53` with or without axis words, `G92`, `G10`, `G52`,
//!   `G68`/`G69`, `G50`/`G51`, Sinumerik `TRANS`/`ATRANS`/`ROT`/`SCALE`/`MIRROR`… — are not
//!   moves; afterwards X Y Z are unknown, and so is every rotary axis named in the block;
//! - reference and machine-coordinate moves (`G28`, `G30`, Fanuc/Sinumerik `G53`, `SUPA`)
//!   move but leave X Y Z (and named rotary axes) unknown;
//! - work-offset selection (Fanuc/Sinumerik `G54`…`G59`, `G500`, `G505`…`G599`) makes
//!   X Y Z unknown, then the block's own axis words apply in the new frame;
//! - `G4` dwell and `G65`/`G66` macro calls take axis letters as arguments (a macro call
//!   makes every position unknown).
//!
//! A block breaks runs ([`crate::Block::breaks_run`]) if it moves other than by G1, has
//! a T, D, H, U, V, W, P, Q, L or E word, an M code other than spindle/coolant
//! (`M3 M4 M5 M7 M8 M9 M13 M14`) and TCPM, a G code outside motion, plane, units,
//! absolute/incremental, `G40 G60 G61 G64 G641`…`G645 G80 G94`, an identifier other than
//! `MSG` (e.g. `CYCLE800`), a non-numeric `T=`/`D=`… assignment, a `/` block-delete
//! marker, or changes the TCPM state, feed mode or datum. Comments, empty lines, `%`
//! lines, S words and spindle/coolant M codes never do.

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

/// [`Modal`] as the program stores it: 64 bytes instead of 120 (one bit per known value
/// instead of an `Option` tag on each), converted losslessly both ways.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct PackedModal {
    /// Positions; meaningful where bit `i` of `known` is set.
    pos: [f64; 6],
    /// Feed, mm/min; meaningful where bit 6 of `known` is set.
    feed_mm_min: f64,
    /// Bits 0–5: `pos[i]` is known; bit 6: the feed is known.
    known: u8,
    /// Bits 0–2: motion (0 none … 4 G3); bit 3 TCPM; bit 4 incremental; bit 5 inch.
    flags: u8,
}

impl PackedModal {
    pub(crate) fn pack(m: &Modal) -> Self {
        let mut pos = [0.0; 6];
        let mut known = 0u8;
        for (i, p) in m.pos.iter().enumerate() {
            if let Some(v) = *p {
                pos[i] = v;
                known |= 1 << i;
            }
        }
        if m.feed_mm_min.is_some() {
            known |= 1 << 6;
        }
        let motion = match m.motion {
            Motion::None => 0,
            Motion::Rapid => 1,
            Motion::Linear => 2,
            Motion::ArcCw => 3,
            Motion::ArcCcw => 4,
        };
        PackedModal {
            pos,
            feed_mm_min: m.feed_mm_min.unwrap_or(0.0),
            known,
            flags: motion
                | u8::from(m.tcpm) << 3
                | u8::from(m.incremental) << 4
                | u8::from(m.inch) << 5,
        }
    }

    pub(crate) fn unpack(&self) -> Modal {
        let bit = |i: u32| self.known & (1 << i) != 0;
        Modal {
            motion: match self.flags & 7 {
                0 => Motion::None,
                1 => Motion::Rapid,
                2 => Motion::Linear,
                3 => Motion::ArcCw,
                _ => Motion::ArcCcw,
            },
            pos: std::array::from_fn(|i| bit(i as u32).then_some(self.pos[i])),
            feed_mm_min: bit(6).then_some(self.feed_mm_min),
            tcpm: self.flags & 8 != 0,
            incremental: self.flags & 16 != 0,
            inch: self.flags & 32 != 0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn packing_is_lossless() {
        assert_eq!(std::mem::size_of::<PackedModal>(), 64);
        let mut m = Modal::default();
        assert_eq!(PackedModal::pack(&m).unpack(), m);
        for (k, motion) in [
            Motion::None,
            Motion::Rapid,
            Motion::Linear,
            Motion::ArcCw,
            Motion::ArcCcw,
        ]
        .into_iter()
        .enumerate()
        {
            m.motion = motion;
            m.pos[k] = Some(-0.0);
            m.pos[5 - k] = Some(f64::MAX);
            m.feed_mm_min = (k % 2 == 0).then_some(1e-300 * k as f64);
            m.tcpm = k % 2 == 1;
            m.incremental = k % 3 == 1;
            m.inch = k >= 3;
            let back = PackedModal::pack(&m).unpack();
            assert_eq!(back, m);
            assert_eq!(back.pos[k].map(f64::to_bits), Some((-0.0f64).to_bits()));
        }
    }
}
