//! Byte-faithful reading and rewriting of NC programs.
//!
//! [`parse`] reads a program as bytes (any encoding; only ASCII is interpreted) into
//! blocks and words, each word keeping its byte span, with the modal state after every
//! block. [`runs`] groups G1 motion into runs with the cumulative tool-tip path length s.
//! [`write()`] renders the program with chosen words changed or inserted in the file's own
//! number style; every other byte is copied unchanged, so `write(&parse(b)?, &[]) == b`.
//! [`apply_edits`] is the one application of a rewrite's edits: the words that keep what
//! the edits do not change, the direction forms, and the write in the file's style.
//!
//! Units: linear values and s in mm (inch programs, G20/G70, are converted on read),
//! feed in mm/min, rotary values in degrees as written.
//!
//! # Where things are
//!
//! Each module imports only modules listed before it:
//!
//! - the basic types: [`tolerances`] (named tolerances and tuning numbers), `dialect.rs`
//!   ([`Dialect`]), `word.rs` ([`Word`], [`RotaryForm`]), `block.rs` ([`Block`], [`Flags`]),
//!   [`modal`] (the state after a block: [`Modal`], positions, TCPM), [`lines`] (line ends),
//!   [`error`];
//! - [`lexer`] (the tokens of a line), [`flow`] (program flow and how it settles TCPM),
//!   [`tcpm`] (which codes switch TCPM; [`ReadOptions`]);
//! - reading a line: `lexed.rs` (what a line says, and what every dialect reads alike),
//!   [`millplus`], [`conversational`], `statements.rs` (the flow statements of ISO lines),
//!   `interp.rs` (ISO lines, and how a line changes the modal state);
//! - reading a file: `detect.rs` (the dialect), [`program`] ([`Program`]), `reader.rs` (the
//!   one reader, [`scan_blocks_with`], and its simpler forms), `builder.rs` ([`parse`],
//!   [`ProgramBuilder`]);
//! - using a program: [`run`] (runs of G1 motion), [`style`] (the file's number style),
//!   [`writer`] ([`write()`]), [`plan`] (the words a rewrite must add, and its direction
//!   forms), [`apply`] ([`apply_edits`]: edits in, bytes or the groups that conflict out),
//!   [`emit`] (new programs), [`tooldesc`] (what the text says of the tool: descriptions,
//!   calls, `DL`), [`stretch`] (a stretch read again from a place a first read kept).

pub mod apply;
mod block;
mod builder;
pub mod conversational;
mod detect;
mod dialect;
pub mod emit;
pub mod error;
pub mod flow;
mod interp;
mod lexed;
pub mod lexer;
pub mod lines;
pub mod millplus;
pub mod modal;
pub mod plan;
pub mod program;
mod reader;
pub mod run;
pub mod settings;
mod statements;
pub mod stretch;
pub mod style;
pub mod tcpm;
pub mod tolerances;
pub mod tooldesc;
mod word;
pub mod writer;

pub use apply::{Applied, EditGroup, EditPlan, GroupConflict, apply_edits};
pub use block::{Block, Flags};
pub use builder::{ProgramBuilder, parse, parse_with};
pub use detect::detect as detect_dialect;
pub use dialect::Dialect;
pub use error::ParseError;
pub use flow::FlowPlan;
pub use lines::LineEnds;
pub use modal::{FeedMode, Modal, Motion, RotaryLetters, Tcpm};
pub use plan::FormConflict;
pub use program::Program;
pub use reader::{
    Lookalike, Resume, Scanned, Settled, scan, scan_blocks, scan_blocks_with, scan_resumed,
    style_evidence_to,
};
pub use run::{Run, RunBreak, RunBuilder, primary_in_use, primary_of, runs};
pub use style::{FileStyle, NumberStyle, StyleEvidence};
pub use tcpm::{Code, ControllerCodes, ReadOptions};
pub use word::{RotaryForm, Word};
pub use writer::{Edit, write};
