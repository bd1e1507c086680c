//! What the reader carried through without analysing it, for the report: every block that
//! could change the motion is honoured or named, never passed over in silence.
//!
//! [`Notes`] takes the blocks in file order (from any read: the stream survey, the
//! no-zone fast path, a whole parsed program) and gives the same list for each:
//! - blocks whose axis or feed words are expressions or variables (`A#<a>`, `X=R1+2`,
//!   `X+Q5`): kept byte for byte, their axes unknown after them, so no run spans them;
//! - arcs (G2/G3, conversational `C`/`CR`/`CT`/`CP`/`LP`/`APPR`/`DEP`) and blocks that
//!   block delete may skip, when they turn a rotary axis near the pole (the primary axis
//!   within the cone at their start or end, or unknown there): the rotary motion across
//!   them is not analysed, so a slowdown there would go unseen;
//! - conversational lines polepatch does not model;
//! - moves with a feed per revolution (G95), which has no time base;
//! - feed moves that turn a rotary axis by more than half a turn with a plain absolute word
//!   on an axis that turns without end, or under Heidenhain `M126`
//!   ([`polepatch_nc::Flags::ROTARY_WRAP`]): a controller that takes the shorter way turns
//!   it the other way round, and which one the machine does is not in the program;
//! - and, as warnings: letters carried through without analysis (`E`, `U`, `V`, `W`),
//!   `(` comments without `)` that hide what looks like axis words, words that look like a
//!   TCPM code without being one (`TRAOOF` for `TRAFOOF`: [`Notes::lookalike`]), and the length units
//!   assumed when the program states none (nothing in a Haas program without `G20` tells
//!   its inches from mm: the report says which was read, `--units` says which to read).
//!
//! `--strict` counts the items (not the warnings) as a failure: the file was read, but
//! not all of it was analysed.

use crate::settings::NAMED_LINES;
use polepatch_nc::modal::{A, B, C};
use polepatch_nc::{Block, FeedMode, Flags, Lookalike, Modal, Motion, RotaryLetters, Word};
use serde::Serialize;

/// Why a stretch of blocks was not analysed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SkipReason {
    /// An axis or feed word is an expression or a variable.
    Expression,
    /// An arc or polar move near the pole.
    ArcNearPole,
    /// A block that block delete (`/`) may skip, moving near the pole.
    SkippableNearPole,
    /// A conversational line polepatch does not model.
    NotModelled,
    /// A move with a feed per revolution (G95).
    FeedPerRevolution,
    /// A posted CL file's `INSERT/` text, written as it is between two moves near the pole
    /// (`post`): polepatch does not read what it does to the motion.
    Insert,
    /// A feed move that turns an endless rotary axis by more than half a turn (or any
    /// rotary axis under Heidenhain `M126`): the shorter way is the other way round.
    RotaryWrap,
}

/// Lines carried through without analysis, and why.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NotAnalysed {
    /// First and last file line.
    pub lines: [usize; 2],
    /// Why.
    pub reason: SkipReason,
    /// For people.
    pub message: String,
}

/// An item in progress: the smallest |A|, |B| and |C| at the start or end of its blocks
/// (unknown counts as 0), since the tilting letter in use and the cone are known only at
/// the end.
#[derive(Debug, Clone)]
struct Item {
    lines: [usize; 2],
    reason: SkipReason,
    min_abs_deg: [f64; 3],
    /// The message, where it says more than the reason and the lines.
    message: Option<String>,
}

/// The collector (module docs).
#[derive(Debug, Clone, Default)]
pub struct Notes {
    items: Vec<Item>,
    /// First line of each letter carried through (E U V W), in `b"EUVW"` order.
    other_letters: [Option<usize>; 4],
    /// First line of an A, a B and a C word: the rotary letter that is not analysed is
    /// named once.
    tilt_first: [Option<usize>; 3],
    /// Lines of unclosed comments that hide axis-like words (the first few).
    unclosed: Vec<usize>,
    unclosed_count: usize,
    /// Words that look like a TCPM code (the first few, with their lines), and how many.
    lookalikes: Vec<(usize, Lookalike)>,
    lookalike_count: usize,
    /// The units a program is read in until it states them (`None` before the first
    /// block): inches when true.
    default_inch: Option<bool>,
    /// The first block that states the units: its line and whether they are inches.
    stated: Option<(usize, bool)>,
}

impl Notes {
    /// An empty collector.
    pub fn new() -> Self {
        Notes::default()
    }

    fn add(&mut self, line: usize, reason: SkipReason, min_abs_deg: [f64; 3]) {
        if let Some(last) = self.items.last_mut()
            && last.reason == reason
            && line <= last.lines[1] + 1
        {
            last.lines[1] = line;
            for (l, m) in last.min_abs_deg.iter_mut().zip(min_abs_deg) {
                *l = l.min(m);
            }
            return;
        }
        self.items.push(Item {
            lines: [line, line],
            reason,
            min_abs_deg,
            message: None,
        });
    }

    /// Take the next block of the file: its words, the state before and after it.
    pub fn push(&mut self, block: &Block, words: &[Word], before: &Modal, after: &Modal) {
        let f = block.flags;
        let line = block.line;
        let min_abs = |idx: usize| {
            let abs = |v: Option<f64>| v.map_or(0.0, f64::abs);
            abs(before.pos[idx]).min(abs(after.pos[idx]))
        };
        let near = [min_abs(A), min_abs(B), min_abs(C)];
        let always = [0.0; 3];
        self.default_inch.get_or_insert(before.inch);
        if f.has(Flags::UNITS) && self.stated.is_none() {
            self.stated = Some((line, after.inch));
        }
        if f.has(Flags::NOT_ANALYSABLE) {
            self.add(line, SkipReason::Expression, always);
        }
        if f.has(Flags::NOT_MODELLED) {
            self.add(line, SkipReason::NotModelled, always);
        }
        // An arc or a skippable move that turns no rotary axis cannot swing C.
        let turns = [A, B, C].into_iter().any(|i| before.pos[i] != after.pos[i]);
        if block.is_move && turns {
            if f.has(Flags::ARC) {
                self.add(line, SkipReason::ArcNearPole, near);
            }
            if f.has(Flags::SKIPPABLE) {
                self.add(line, SkipReason::SkippableNearPole, near);
            }
        }
        if f.has(Flags::ROTARY_WRAP) {
            self.items.push(Item {
                lines: [line, line],
                reason: SkipReason::RotaryWrap,
                min_abs_deg: always,
                message: Some(wrap_message(block, words, before, after)),
            });
        }
        if block.is_move
            && after.feed_mode == FeedMode::PerRevolution
            && after.motion == Motion::Linear
        {
            self.add(line, SkipReason::FeedPerRevolution, always);
        }
        if f.has(Flags::UNCLOSED_COMMENT) {
            self.unclosed_count += 1;
            if self.unclosed.len() < NAMED_LINES {
                self.unclosed.push(line);
            }
        }
        for w in words {
            if let Some(k) = b"EUVW".iter().position(|&l| l == w.letter) {
                self.other_letters[k].get_or_insert(line);
            }
            if let Some(k) = b"ABC".iter().position(|&l| l == w.letter) {
                self.tilt_first[k].get_or_insert(line);
            }
        }
    }

    /// Take a word of the block at `line` that looks like a TCPM code without being one
    /// ([`polepatch_nc::Scanned::lookalike`]).
    pub fn lookalike(&mut self, line: usize, word: Option<&Lookalike>) {
        let Some(w) = word else { return };
        self.lookalike_count += 1;
        if self.lookalikes.len() < NAMED_LINES {
            self.lookalikes.push((line, w.clone()));
        }
    }

    /// The list for a program read with the rotary letters `letters` and the singular cone
    /// `cone_deg`, and the warnings (named `name`).
    pub fn finish(
        &self,
        letters: RotaryLetters,
        cone_deg: f64,
        name: &str,
    ) -> (Vec<NotAnalysed>, Vec<String>) {
        let l = usize::from(letters.tilt - b'A');
        let (own, other, pole) = (
            letters.tilt as char,
            letters.other() as char,
            letters.pole as char,
        );
        let other_slot = usize::from(letters.other() - b'A');
        let items = self
            .items
            .iter()
            .filter(|it| it.min_abs_deg[l] <= cone_deg)
            .map(|it| NotAnalysed {
                lines: it.lines,
                reason: it.reason,
                message: it
                    .message
                    .clone()
                    .unwrap_or_else(|| message(it.reason, it.lines)),
            })
            .collect();
        let mut warnings = Vec::new();
        let letters: Vec<String> = b"EUVW"
            .iter()
            .zip(self.other_letters)
            .filter_map(|(&l, first)| {
                first.map(|line| format!("{} (first at line {line})", l as char))
            })
            .collect();
        if !letters.is_empty() {
            warnings.push(format!(
                "{name}: words {} are carried through as written and not analysed (polepatch \
                 analyses X Y Z, the tilting axis and {pole})",
                letters.join(", ")
            ));
        }
        // The other rotary letter (B when A and C are analysed): an axis of another machine.
        if let Some(line) = self.tilt_first[other_slot] {
            warnings.push(format!(
                "{name}: words {other} (first at line {line}) are of a rotary axis the machine \
                 does not have (the program is read with {own} and {pole}); none turns it (each is 0, \
                 or an expression): they are carried through as written, and a run where \
                 {other} is not known to be 0 is not analysed"
            ));
        }
        if self.stated.is_none()
            && let Some(inch) = self.default_inch
        {
            warnings.push(if inch {
                format!(
                    "{name}: the program states no length units (G20/G21, G70/G71, BEGIN PGM … \
                     MM|INCH): read in inches, as asked (--units inch)"
                )
            } else {
                format!(
                    "{name}: the program states no length units (G20/G21, G70/G71, BEGIN PGM … \
                     MM|INCH): read in mm; if it is written in inches, give --units inch"
                )
            });
        }
        if self.unclosed_count > 0 {
            let lines: Vec<String> = self.unclosed.iter().map(|l| l.to_string()).collect();
            warnings.push(format!(
                "{name}: {} comment(s) opened with '(' and not closed hide what looks like axis \
                 words (line {}{}); polepatch reads them as comments, as most controllers do — \
                 check the program",
                self.unclosed_count,
                lines.join(", "),
                if self.unclosed_count > lines.len() {
                    ", …"
                } else {
                    ""
                }
            ));
        }
        if self.lookalike_count > 0 {
            let words: Vec<String> = self
                .lookalikes
                .iter()
                .map(|(line, w)| {
                    format!(
                        "line {line}, col {}: {} looks like the TCPM code {}",
                        w.column, w.word, w.code
                    )
                })
                .collect();
            warnings.push(format!(
                "{name}: {} word(s) that look like a TCPM code are not one ({}{}); polepatch does \
                 not read them as a TCPM switch, and a controller would reject them or run \
                 something else — check the program",
                self.lookalike_count,
                words.join("; "),
                if self.lookalike_count > words.len() {
                    "; …"
                } else {
                    ""
                }
            ));
        }
        (items, warnings)
    }
}

fn message(reason: SkipReason, lines: [usize; 2]) -> String {
    let at = if lines[0] == lines[1] {
        format!("line {}", lines[0])
    } else {
        format!("lines {}–{}", lines[0], lines[1])
    };
    match reason {
        SkipReason::Expression => format!(
            "{at}: an axis or feed word is an expression or a variable (or an indexed address \
             such as Sinumerik's A3= orientation vector); the blocks are kept as written and no \
             run is analysed across them"
        ),
        SkipReason::ArcNearPole => format!(
            "{at}: an arc or polar move near the pole; polepatch does not analyse the rotary \
             motion along it, so a slowdown there is not measured"
        ),
        SkipReason::SkippableNearPole => format!(
            "{at}: a block that block delete (/) may skip, moving near the pole; the motion \
             across it depends on the switch and is not analysed"
        ),
        SkipReason::NotModelled => format!(
            "{at}: a line polepatch does not model (carried through as written); positions \
             after it are unknown until the program states them again"
        ),
        SkipReason::FeedPerRevolution => {
            format!("{at}: feed per revolution (G95) has no time base for Equation 6; not analysed")
        }
        SkipReason::Insert => insert_message(lines[0], 0),
        SkipReason::RotaryWrap => format!(
            "{at}: a feed move turns a rotary axis by more than half a turn; a controller that \
             takes the shorter way turns it the other way round: not analysed"
        ),
    }
}

/// What a block flagged [`Flags::ROTARY_WRAP`] does, both ways: its line and the column of
/// the word, the axis, the move as written and the shorter one.
fn wrap_message(block: &Block, words: &[Word], before: &Modal, after: &Modal) -> String {
    let turn = [A, B, C].into_iter().find_map(|k| {
        let (p, q) = (before.pos[k]?, after.pos[k]?);
        let letter = b'A' + (k - A) as u8;
        let w = words.iter().find(|w| w.letter == letter)?;
        ((q - p).abs() > 180.0).then_some((letter as char, w, p, q))
    });
    let Some((letter, w, p, q)) = turn else {
        return message(SkipReason::RotaryWrap, [block.line, block.line]);
    };
    let col = (w.start as usize).saturating_sub(block.span().start) + 1;
    let d = q - p;
    let shorter = d - 360.0 * (d / 360.0).round();
    let why = if after.shortest_path {
        "under M126 the controller turns it the shorter way"
    } else {
        "a controller that takes the shorter way on an axis that turns without end (Haas or \
         Fanuc rollover, a Sinumerik modulo axis, Heidenhain M126) turns it"
    };
    format!(
        "line {}, col {col}: a feed move turns {letter} from {} to {} — {:+} as written; {why} \
         {:+} instead. Which one the machine does is not in the program: the move is kept as \
         written and no run is analysed across it (a machine whose {letter} never takes the \
         shorter way can say so with a range_deg for {letter} in its machine file)",
        block.line,
        fmt_deg(p),
        fmt_deg(q),
        Deg(d),
        Deg(shorter),
    )
}

/// Degrees with up to 3 decimals, no trailing zeros (`7.501°`, `-352.356°`, `180°`).
fn fmt_deg(v: f64) -> String {
    format!("{}°", Deg(v))
}

struct Deg(f64);

impl std::fmt::Display for Deg {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let r = (self.0 * 1000.0).round() / 1000.0;
        let r = if r == 0.0 { 0.0 } else { r };
        let text = format!("{r:.3}");
        let text = text.trim_end_matches('0').trim_end_matches('.');
        if f.sign_plus() && r >= 0.0 {
            write!(f, "+{text}°")
        } else if f.sign_plus() {
            write!(f, "{text}°")
        } else {
            f.write_str(text)
        }
    }
}

/// The message of an `INSERT` text written at program line `line` from CL line `cl_line`
/// (0: not known) near the pole.
pub(crate) fn insert_message(line: usize, cl_line: usize) -> String {
    let from = if cl_line > 0 {
        format!(" (CL line {cl_line})")
    } else {
        String::new()
    };
    format!(
        "line {line}: INSERT text{from} written as it is between moves near the pole; polepatch \
         does not read what it does to the motion, so no run is analysed across it"
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use polepatch_nc::{Dialect, parse};

    fn notes(text: &str, tilt: usize) -> (Vec<NotAnalysed>, Vec<String>) {
        let letters = if tilt == A {
            RotaryLetters::AC
        } else {
            RotaryLetters::BC
        };
        let p = parse(text.as_bytes().to_vec(), Dialect::Auto).unwrap();
        let mut n = Notes::new();
        for b in 0..p.blocks.len() {
            n.push(
                &p.blocks[b],
                p.block_words(b),
                &p.state_before(b),
                &p.state(b),
            );
        }
        n.finish(letters, 5.0, "t")
    }

    #[test]
    fn arcs_near_the_pole_only() {
        let text = "G1 X0 Y0 Z0 A2 C0 F100\nG2 X10 Y0 I5 J0 A1\nG1 X11 A20\nG2 X20 Y0 I5 J0 A30\n";
        let (items, _) = notes(text, A);
        assert_eq!(items.len(), 1);
        assert_eq!(items[0].reason, SkipReason::ArcNearPole);
        assert_eq!(items[0].lines, [2, 2]);
        // With B as the tilting letter (never programmed: read as unknown), both are near.
        assert_eq!(notes(text, B).0.len(), 2);
        // A 3-axis arc at the pole turns no rotary axis: nothing to swing.
        let flat = "G1 X0 Y0 Z0 A0 C0 F100\nG2 X10 Y0 I5 J0\n";
        assert!(notes(flat, A).0.is_empty());
    }

    #[test]
    fn expressions_merge_into_one_item_and_letters_are_warned_once() {
        let text = "G1 X0 Y0 Z0 A2 C0 F100\nX#1\nX#2 E0.5\nX3 E0.6 U1 A20\n/X4 A30\n";
        let (items, warnings) = notes(text, A);
        assert_eq!(items.len(), 1, "{items:?}");
        assert_eq!(items[0].lines, [2, 3]);
        assert_eq!(items[0].reason, SkipReason::Expression);
        assert_eq!(warnings.len(), 2, "{warnings:?}");
        assert!(
            warnings[0].contains("E (first at line 3), U (first at line 4)"),
            "{warnings:?}"
        );
        assert!(
            warnings[1].contains("states no length units"),
            "{warnings:?}"
        );
    }

    /// Issue 30 item 2: the units read are said when the program does not state them; a
    /// program that states them (anywhere) gets no such warning.
    #[test]
    fn units_assumed_are_said() {
        let (_, w) = notes("G1 X0 Y0 Z0 A2 C0 F100\nX1 C5\n", A);
        assert!(
            w.iter()
                .any(|w| w.contains("read in mm; if it is written in inches, give --units inch")),
            "{w:?}"
        );
        for stated in [
            "G20\nG1 X0 Y0 Z0 A2 C0 F100\n",
            "G1 X0 Y0 Z0 A2 C0 F100\nG21\n",
            "%P G71 *\nN1 G1 X0 A2 C0 F100 *\n",
        ] {
            let (_, w) = notes(stated, A);
            assert!(
                !w.iter().any(|w| w.contains("length units")),
                "{stated}: {w:?}"
            );
        }
        let conv = "0 BEGIN PGM PROGRAM IN\n1 L X+.6 Y+4.6 Z+11.9 B+0 C+0 FMAX\n";
        let (_, w) = notes(conv, B);
        assert!(!w.iter().any(|w| w.contains("length units")), "{w:?}");
    }

    /// Issue 30 item 5: the tilting letter that is not analysed is named once, with why.
    #[test]
    fn the_other_tilting_letter_is_named() {
        let text = "G1 X0 Y0 Z0 A0 B225. F10\nX1 A-.274 B279.167\n";
        let (_, w) = notes(text, A);
        let other: Vec<_> = w
            .iter()
            .filter(|w| w.contains("rotary axis the machine does not have"))
            .collect();
        assert_eq!(other.len(), 1, "{w:?}");
        assert!(
            other[0].contains("words B (first at line 1)")
                && other[0].contains("read with A and C"),
            "{w:?}"
        );
        let (_, w) = notes(text, B);
        assert!(
            w.iter().any(|w| w.contains("words A (first at line 1)")),
            "{w:?}"
        );
        let (_, w) = notes("G1 X0 Y0 Z0 A2 C0 F100\n", A);
        assert!(!w.iter().any(|w| w.contains("does not have")), "{w:?}");
    }
}
