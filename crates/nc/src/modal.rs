//! Modal state tracked block by block.
//!
//! How a block changes the state (all dialects unless named):
//! - motion: `G0 G1 G2 G3` (also `G00`…`G03`);
//! - `G90`/`G91` absolute/incremental (incremental from an unknown position stays
//!   unknown); `G20`/`G21`, `G70`/`G71`, `G700`/`G710` inch/metric (also read from a `%NAME
//!   G71` header): in inch mode X Y Z and F are multiplied by 25.4 on read;
//! - TCPM: switched on and off by each dialect's codes and the machine's own
//!   ([`crate::tcpm`]: `M128`/`FUNCTION TCPM`, `TRAORI`, `G43.4`/`G43.5`, `G234`; ended
//!   by `M129`/`FUNCTION RESET TCPM`, `TRAFOOF`/`TRANSMIT`/`TRACYL`, `G49`/`G43`/`G44`,
//!   the program's end); a switch in a block that block delete (`/`) may skip leaves the
//!   state [`Tcpm::Uncertain`];
//! - F in mm/min under `G94`; under `G93` (inverse time) F is the reciprocal of the
//!   block's time in minutes, read per block ([`Modal::inverse_time_per_min`]); under
//!   `G95` (per revolution) the feed is `None`; after a change of feed mode the feed is
//!   `None` until the next F;
//! - axis words X Y Z A B C set positions in moves (and in a block without any motion mode
//!   yet, which is then not counted as a move);
//! - datum shifts — Heidenhain `G54`/`G53` with or without axis words, `G92` naming an
//!   axis polepatch follows (`G92 E0`, an extruder reset, is not one), `G10`, `G52`,
//!   `G68`/`G69`, `G50`/`G51`, Sinumerik `TRANS`/`ATRANS`/`ROT`/`SCALE`/`MIRROR`… — are not
//!   moves; afterwards X Y Z are unknown, and so is every rotary axis named in the block;
//! - reference and machine-coordinate moves (`G28`, `G30`, Fanuc/Sinumerik `G53`, `SUPA`)
//!   move but leave X Y Z (and named rotary axes) unknown;
//! - work-offset selection (Fanuc/Sinumerik `G54`…`G59`, `G500`, `G505`…`G599`) makes
//!   X Y Z unknown, then the block's own axis words apply in the new frame;
//! - `G4` dwell and `G65`/`G66` macro calls take axis letters as arguments (a macro call
//!   makes every position unknown);
//! - canned drilling cycles (`G73 G74 G76 G81`…`G89`) are modal until `G80` or a motion
//!   code: a block with axis words then drills a hole (a move that ends runs, Z unknown
//!   after it: the tool returns to a plane the reader does not follow); Heidenhain ISO
//!   `G79`, conversational `CYCL CALL`/`M99` call a cycle (positions unknown after).
//!
//! A block breaks runs ([`crate::Block::breaks_run`]) if it moves other than by G1, has
//! a D, H, U, V, W, P, Q, L or E word (a T word only where it calls the tool: Heidenhain
//! ISO `T5 G17`, conversational `TOOL CALL` naming a tool; elsewhere it preselects), an M code other than spindle/coolant
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

/// Tool-centre-point management (TCPM, RTCP, TRAORI): whether X Y Z are tool-tip
/// positions in the part frame (on) or machine-axis positions (off).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Tcpm {
    /// Off: X Y Z are machine coordinates.
    #[default]
    Off,
    /// On.
    On,
    /// Depends on whether block delete (`/`) skipped a block that switches it: treated
    /// as off by every caller (never patched), and reported.
    Uncertain,
    /// The file does not settle it: after a call of code outside the file, where a jump,
    /// a label or a loop joins paths with different states ([`crate::flow`]), or after a
    /// code whose effect on TCPM the reader does not know (`TRACON`, `G43.8`). Never
    /// patched, and reported.
    Unknown,
}

impl Tcpm {
    /// The state after a tool change that may run a macro (Fanuc `M6`): such a macro may
    /// end TCPM (`G49`) but never starts it.
    pub fn after_tool_change(self) -> Tcpm {
        match self {
            Tcpm::On => Tcpm::Unknown,
            other => other,
        }
    }

    /// Whether TCPM is certainly on.
    pub fn is_on(self) -> bool {
        self == Tcpm::On
    }

    /// The state after a block that switches TCPM to `to` (`On`, `Off` or `Unknown`), from
    /// `self`: a block that block delete (`/`) may skip (`skippable`) leaves it
    /// [`Tcpm::Uncertain`] where the switch would change it — or [`Tcpm::Unknown`] where it
    /// was unknown already. One rule for the reader and for [`crate::flow`]'s solver.
    pub fn switched(self, to: Tcpm, skippable: bool) -> Tcpm {
        if !skippable || self == to {
            to
        } else if self == Tcpm::Unknown || to == Tcpm::Unknown {
            Tcpm::Unknown
        } else {
            Tcpm::Uncertain
        }
    }

    /// Where two ways into a block meet: their common state, or [`Tcpm::Unknown`] where
    /// they differ.
    pub fn join(self, other: Tcpm) -> Tcpm {
        if self == other { self } else { Tcpm::Unknown }
    }
}

/// Transformations of the programmed frame that are more than a shift: while one is in
/// force the program's X Y Z (and the tool axis as the part sees it) are not the frame
/// polepatch computes in, so no run is rewritten ([`Modal::transform`]).
pub mod transform {
    /// A rotation (Fanuc `G68`, `G68.2`; Heidenhain ISO `G73`; conversational
    /// `CYCL DEF 10`, `19`, `PLANE`; Sinumerik `ROT`, `AROT`, `CYCLE800(…)`; LinuxCNC
    /// `G10 L2 … R`).
    pub const ROTATION: u8 = 1;
    /// A scaling (Fanuc `G51`; Heidenhain ISO `G72`; conversational `CYCL DEF 11`, `26`;
    /// Sinumerik `SCALE`, `ASCALE`).
    pub const SCALING: u8 = 2;
    /// A mirror image (Fanuc `G51.1`; Heidenhain ISO `G28` in its own meaning;
    /// conversational `CYCL DEF 8`; Sinumerik `MIRROR`, `AMIRROR`).
    pub const MIRROR: u8 = 4;
    /// All of them.
    pub const ALL: u8 = ROTATION | SCALING | MIRROR;

    /// Names for people, in bit order.
    pub fn names(bits: u8) -> Vec<&'static str> {
        [
            (ROTATION, "rotation"),
            (SCALING, "scaling"),
            (MIRROR, "mirror image"),
        ]
        .into_iter()
        .filter(|(b, _)| bits & b != 0)
        .map(|(_, n)| n)
        .collect()
    }
}

/// Feed interpretation (modal G group 5).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FeedMode {
    /// G94: F is a feed per minute (mm/min, or inch/min in inch mode).
    #[default]
    PerMinute,
    /// G93: F is the reciprocal of the block's time in minutes.
    InverseTime,
    /// G95: F is a feed per spindle revolution (not analysable: no time base).
    PerRevolution,
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

/// Index in [`Modal::pos`] of an axis letter (upper case), `None` for another letter.
pub fn axis_index(letter: u8) -> Option<usize> {
    AXES.iter().position(|&l| l == letter)
}

/// The two rotary letters a program is read with for a machine: its tilting axis and its
/// pole axis (the one whose turning cannot change a tool axis along it). A and C, or B and
/// C, on the usual table-table machines; A and B on an A-B trunnion whose platter is B.
/// Both are among A B C and differ; the third of those letters is one the machine lacks
/// ([`RotaryLetters::other`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct RotaryLetters {
    /// The tilting axis' letter.
    pub tilt: u8,
    /// The pole axis' letter.
    pub pole: u8,
}

impl RotaryLetters {
    /// A and C: the tilting axis A (about X), the pole axis C.
    pub const AC: RotaryLetters = RotaryLetters {
        tilt: b'A',
        pole: b'C',
    };
    /// B and C.
    pub const BC: RotaryLetters = RotaryLetters {
        tilt: b'B',
        pole: b'C',
    };

    /// The pair, when both letters are among A B C (either case) and differ.
    pub fn new(tilt: u8, pole: u8) -> Option<RotaryLetters> {
        let (tilt, pole) = (tilt.to_ascii_uppercase(), pole.to_ascii_uppercase());
        let rotary = |l: u8| matches!(l, b'A' | b'B' | b'C');
        (rotary(tilt) && rotary(pole) && tilt != pole).then_some(RotaryLetters { tilt, pole })
    }
    /// Index of the tilting letter in [`Modal::pos`].
    pub fn tilt_index(self) -> usize {
        axis_index(self.tilt).unwrap_or(A)
    }
    /// Index of the pole letter in [`Modal::pos`].
    pub fn pole_index(self) -> usize {
        axis_index(self.pole).unwrap_or(C)
    }
    /// The letter of A B C that is neither (one the machine does not have).
    pub fn other(self) -> u8 {
        [b'A', b'B', b'C']
            .into_iter()
            .find(|&l| l != self.tilt && l != self.pole)
            .unwrap_or(b'B')
    }
    /// The same pair with `tilt` as the tilting letter (the pole unchanged): how a program
    /// that tilts with another letter reads.
    pub fn with_tilt(self, tilt: u8) -> RotaryLetters {
        RotaryLetters { tilt, ..self }
    }
}

/// Modal state after a block.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Modal {
    /// Motion mode.
    pub motion: Motion,
    /// Positions X Y Z (mm) A B C (degrees), `None` until known (never programmed, or
    /// unknown after a datum shift / reference move).
    pub pos: [Option<f64>; 6],
    /// Programmed feed, mm/min (`None` until an F word; also `None` under G93 and G95).
    pub feed_mm_min: Option<f64>,
    /// Under G93: this block's F, the reciprocal of its time in minutes (1/min); `None` in
    /// a block without F and under G94/G95. Not modal: each G93 move states its own.
    pub inverse_time_per_min: Option<f64>,
    /// Feed mode (G94, G93, G95).
    pub feed_mode: FeedMode,
    /// Tool-centre-point management.
    pub tcpm: Tcpm,
    /// A canned drilling cycle is active (Fanuc/LinuxCNC `G73 G74 G76 G81`…`G89`, until
    /// `G80` or a `G0`…`G3`): a block with axis words drills a hole there.
    pub canned_cycle: bool,
    /// Incremental mode (G91).
    pub incremental: bool,
    /// Inch units (G20 / G70): values are converted to mm on read.
    pub inch: bool,
    /// Frame transformations in force beyond a shift ([`transform`] bits: rotation,
    /// scaling, mirror image), 0 where none.
    pub transform: u8,
    /// The code that switched TCPM on last refers X Y Z to the centre of a ball
    /// (Heidenhain `M128`, `FUNCTION TCPM … REFPNT CENTER-CENTER`); false: to the tool tip
    /// (`FUNCTION TCPM` by default, `TRAORI`, `G43.4`, `G234`, a machine's own codes).
    pub tcpm_centre: bool,
    /// Heidenhain `M126` is in force (until `M127` or the program's end): the controller
    /// turns a rotary axis the shorter way to a plain absolute value, so a feed move written
    /// as more than half a turn is not the move it reads as ([`crate::Flags::ROTARY_WRAP`]).
    pub shortest_path: bool,
}

impl Default for Modal {
    fn default() -> Self {
        Modal {
            motion: Motion::None,
            pos: [None; 6],
            feed_mm_min: None,
            inverse_time_per_min: None,
            feed_mode: FeedMode::PerMinute,
            tcpm: Tcpm::Off,
            canned_cycle: false,
            incremental: false,
            inch: false,
            transform: 0,
            tcpm_centre: false,
            shortest_path: false,
        }
    }
}

/// [`Modal`] as the program stores it: 64 bytes instead of 136 (one bit per known value
/// instead of an `Option` tag on each), converted losslessly both ways.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct PackedModal {
    /// Positions; meaningful where bit `i` of `known` is set.
    pos: [f64; 6],
    /// Feed, mm/min (bit 6 of `known`), or the block's inverse-time F (bit 7): at most
    /// one of them is known (G93 leaves the feed per minute unknown).
    feed: f64,
    /// Bits 0–5: `pos[i]` is known; bit 6: the feed is known; bit 7: the inverse-time F.
    known: u8,
    /// Bits 0–2: motion (0 none … 4 G3); bit 3 TCPM on; bit 4 incremental; bit 5 inch;
    /// bit 6 TCPM uncertain; bit 7 canned cycle.
    flags: u8,
    /// Bits 0–1: feed mode (0 G94, 1 G93, 2 G95); bits 2–4: [`transform`] bits; bit 5:
    /// TCPM unknown; bit 6: TCPM refers to the ball's centre; bit 7: shortest path (M126).
    feed_mode: u8,
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
        debug_assert!(
            m.feed_mm_min.is_none() || m.inverse_time_per_min.is_none(),
            "a feed per minute and an inverse-time F at once"
        );
        let mut feed = 0.0;
        if let Some(f) = m.feed_mm_min {
            known |= 1 << 6;
            feed = f;
        }
        if let Some(f) = m.inverse_time_per_min {
            known |= 1 << 7;
            feed = f;
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
            feed,
            known,
            flags: motion
                | u8::from(m.tcpm == Tcpm::On) << 3
                | u8::from(m.incremental) << 4
                | u8::from(m.inch) << 5
                | u8::from(m.tcpm == Tcpm::Uncertain) << 6
                | u8::from(m.canned_cycle) << 7,
            feed_mode: match m.feed_mode {
                FeedMode::PerMinute => 0,
                FeedMode::InverseTime => 1,
                FeedMode::PerRevolution => 2,
            } | (m.transform & transform::ALL) << 2
                | u8::from(m.tcpm == Tcpm::Unknown) << 5
                | u8::from(m.tcpm_centre) << 6
                | u8::from(m.shortest_path) << 7,
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
            feed_mm_min: bit(6).then_some(self.feed),
            inverse_time_per_min: bit(7).then_some(self.feed),
            feed_mode: match self.feed_mode & 3 {
                0 => FeedMode::PerMinute,
                1 => FeedMode::InverseTime,
                _ => FeedMode::PerRevolution,
            },
            tcpm: if self.flags & 8 != 0 {
                Tcpm::On
            } else if self.flags & 64 != 0 {
                Tcpm::Uncertain
            } else if self.feed_mode & 32 != 0 {
                Tcpm::Unknown
            } else {
                Tcpm::Off
            },
            transform: (self.feed_mode >> 2) & transform::ALL,
            tcpm_centre: self.feed_mode & 64 != 0,
            shortest_path: self.feed_mode & 128 != 0,
            incremental: self.flags & 16 != 0,
            inch: self.flags & 32 != 0,
            canned_cycle: self.flags & 128 != 0,
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
            m.inverse_time_per_min = (k == 3).then_some(12.5);
            m.feed_mode = [
                FeedMode::PerMinute,
                FeedMode::InverseTime,
                FeedMode::PerRevolution,
            ][k % 3];
            m.tcpm = [Tcpm::Off, Tcpm::On, Tcpm::Uncertain, Tcpm::Unknown][k % 4];
            m.transform = (k as u8 * 3) & transform::ALL;
            m.tcpm_centre = k % 2 == 1;
            m.shortest_path = k % 3 != 1;
            m.canned_cycle = k % 2 == 0;
            m.incremental = k % 3 == 1;
            m.inch = k >= 3;
            let back = PackedModal::pack(&m).unpack();
            assert_eq!(back, m);
            assert_eq!(back.pos[k].map(f64::to_bits), Some((-0.0f64).to_bits()));
        }
    }
}
