//! Bad input at the program level (an error), kept apart from numerical outcomes (a zone
//! that stays below feed is a status in the report, not an error).

use polepatch_nc::ParseError;

/// Why a program cannot be analysed or patched at all.
///
/// Messages name the file when the caller gave one (`PatchOptions::name`), and the line
/// and column where the input is at fault.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// Syntax error with line and column. Transparent: its message is the parse error's,
    /// and it is not also given as a `source()` (an error chain would print it twice).
    #[error(transparent)]
    Parse(#[from] ParseError),
    /// Nothing but whitespace.
    #[error("{path}: empty program")]
    Empty {
        /// File (or the name given for in-memory input).
        path: String,
    },
    /// No G1 motion at all.
    #[error("{path}: no G1 motion to analyse")]
    NoRuns {
        /// File.
        path: String,
    },
    /// Every G1 move's axis or feed words are expressions or variables (the first at
    /// `line`): nothing can be analysed.
    #[error(
        "{path}:{line}: no G1 run can be analysed: the G1 moves' axis or feed words are \
         expressions or variables (as here), which polepatch carries through but cannot evaluate"
    )]
    NothingAnalysable {
        /// File.
        path: String,
        /// 1-based line of the first such G1 move.
        line: usize,
    },
    /// No rotary axis words in any G1 run.
    #[error(
        "{path}: no rotary axis words ({primary} or C) in any G1 run; is this a 5-axis program?{vectors}"
    )]
    NoRotary {
        /// File.
        path: String,
        /// The machine's primary letter.
        primary: char,
        /// Empty, or what the G1 moves' I J K words are: tool-direction vectors, which
        /// polepatch does not read (with the line of the first).
        vectors: String,
    },
    /// The program turns a rotary axis the machine does not have (a B-C program given an
    /// A-C machine): its kinematics are not the machine's, so nothing computed for it
    /// would be true of the machine it was posted for.
    #[error(
        "{path}:{line}:{column}: {letter} is not an axis of machine {machine}, whose rotary \
         axes are {axes}: the program was posted for another machine; give that machine \
         (--machine NAME, or a machine file whose rotary axes include {letter}){fits}"
    )]
    ForeignAxis {
        /// File.
        path: String,
        /// 1-based line of the first word of that letter.
        line: usize,
        /// 1-based column of that word.
        column: usize,
        /// The letter.
        letter: char,
        /// The machine's name.
        machine: String,
        /// The machine's rotary letters (`A and C`).
        axes: String,
        /// Empty, or the built-in machines whose letters the program uses (`; the built-in
        /// mikron-ucp710 has A and C`).
        fits: String,
    },
    /// A move takes a rotary axis beyond the machine's range: the program cannot run on
    /// that machine as written (its controller refuses it at that block), and a patch
    /// would pull the values into the range by turning the tool (issue 39: 6.25° on SING
    /// with C ending at 200°).
    #[error(
        "{path}:{line}:{column}: {letter}{value_deg} is beyond machine {machine}'s {letter} range \
         {range} (degrees): the program was posted for another machine or range; give the \
         machine it runs on (--machine NAME or a machine file)"
    )]
    BeyondRange {
        /// File.
        path: String,
        /// 1-based line of the move.
        line: usize,
        /// 1-based column of the word.
        column: usize,
        /// The rotary letter.
        letter: char,
        /// The value the axis would reach, degrees.
        value_deg: f64,
        /// The machine's name.
        machine: String,
        /// Its range, `[lo, hi]`.
        range: String,
    },
    /// The program uses something polepatch does not support, at a line.
    #[error("{path}:{line}: {what}")]
    Unsupported {
        /// File.
        path: String,
        /// 1-based line.
        line: usize,
        /// What is not supported and why.
        what: String,
    },
    /// A bad record in a CL file, with line and column.
    #[error("{path}:{record}")]
    Cl {
        /// File.
        path: String,
        /// The record's error (line, column, message).
        record: polepatch_cl::ClError,
    },
    /// The output could not be written (to the writer given to
    /// [`crate::patch_nc_to`]).
    #[error("cannot write the output: {0}")]
    Output(std::io::Error),
    /// Bad options (a value out of range, or values that mean nothing together), with the
    /// field named.
    #[error("{0}")]
    Options(OptionError),
    /// A machine polepatch cannot work with as described (a layout not supported yet, a
    /// controller code or an auxiliary axis that cannot be read).
    #[error("machine {machine}: {message}")]
    Machine {
        /// The machine's name.
        machine: String,
        /// What is wrong with it.
        message: String,
    },
    /// Memory for `what` could not be allocated.
    #[error("not enough memory for {what} of a program of {bytes} bytes")]
    OutOfMemory {
        /// What was being allocated.
        what: &'static str,
        /// Size of the input, bytes.
        bytes: usize,
    },
    /// A bad point in joint or CL arrays held in memory ([`crate::joints`]), by its
    /// 0-based index.
    #[error("point {index}: {message}")]
    Point {
        /// 0-based point index.
        index: usize,
        /// What is wrong, naming the value.
        message: String,
    },
    /// A path the patcher refuses ([`crate::joints::patch_joints`]: too few points, a feed
    /// that is not positive, …).
    #[error("{0}")]
    Path(#[from] polepatch_patcher::PathError),
    /// A joint value the machine cannot reach ([`crate::joints::cl_to_joints`]), by the
    /// point's 0-based index.
    #[error("point {index}: {message}")]
    OutOfRange {
        /// 0-based point index.
        index: usize,
        /// Which axis, its value and the range.
        message: String,
    },
    /// The written program failed the check against its input ([`crate::verify`]) even with
    /// every zone that failed put back: nothing is written.
    #[error(
        "{path}: the patched program fails its verification against the input, so it is not \
         written: {}",
        .violations.iter().take(5).map(|v| format!("line {}: {}: {}", v.line, v.check.name(), v.message)).collect::<Vec<_>>().join("; ")
    )]
    Unverified {
        /// File.
        path: String,
        /// What does not hold.
        violations: Vec<crate::violation::Violation>,
    },
    /// The caller's [`crate::Hooks::cancelled`] asked the patch to stop.
    #[error("cancelled")]
    Cancelled,
}

/// An option refused: which field (as the caller spells it: a struct member such as
/// `cone_deg`, or a flag such as `--ignore`) and the whole message, which names it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct OptionError {
    /// The field refused.
    pub field: String,
    /// The message, naming the field, the rule and the value.
    pub message: String,
}

impl OptionError {
    /// `field` refused; `rest` follows its name in the message (`{field} {rest}`).
    pub fn new(field: &str, rest: impl std::fmt::Display) -> Self {
        OptionError {
            field: field.to_string(),
            message: format!("{field} {rest}"),
        }
    }

    /// `field` refused with a message of its own (which should name it).
    pub fn with_message(field: &str, message: impl Into<String>) -> Self {
        OptionError {
            field: field.to_string(),
            message: message.into(),
        }
    }

    /// The patcher's refusal, its field by its Rust name.
    pub fn of_patcher(e: &polepatch_patcher::OptionsError) -> Self {
        OptionError {
            field: e.field.name().to_string(),
            message: e.to_string(),
        }
    }
}

impl std::fmt::Display for OptionError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

impl From<OptionError> for Error {
    fn from(e: OptionError) -> Self {
        Error::Options(e)
    }
}

impl Error {
    /// A machine refused: `machine` named, `message` what is wrong.
    pub(crate) fn machine(machine: &str, message: impl Into<String>) -> Self {
        Error::Machine {
            machine: machine.to_string(),
            message: message.into(),
        }
    }

    /// The program was read but holds nothing to analyse: no G1 motion, no rotary word in
    /// any G1 run, or every G1 move written with expressions. `patch` writes such a program
    /// unchanged and `analyze` reports no run, each with this error as a warning (a folder
    /// of a shop's programs holds 3-axis and drilling programs too); `simulate` and
    /// `reorient`, which need motion, refuse it.
    pub fn is_nothing_to_analyse(&self) -> bool {
        matches!(
            self,
            Error::NoRuns { .. } | Error::NoRotary { .. } | Error::NothingAnalysable { .. }
        )
    }
}
