//! The file's number style, so that rewritten words look like their neighbours.

use crate::program::Program;

/// How numbers of one address letter are written in a file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NumberStyle {
    /// Positive values carry an explicit `+` (Heidenhain style `C+12.5`).
    pub plus_sign: bool,
    /// Decimal places written (the maximum seen for this letter).
    pub decimals: usize,
    /// Trailing zeros are dropped (`C+126.28` beside `C+148.494`), and a whole number is
    /// written without a point unless `trailing_point`.
    pub strip_trailing_zeros: bool,
    /// Whole numbers keep a trailing point (`C180.`, Fanuc style).
    pub trailing_point: bool,
    /// A value below 1 in magnitude is written with its leading zero (`0.5`, not `.5`).
    pub leading_zero: bool,
    /// `=` between letter and number (`C=12.5`, Sinumerik).
    pub equals: bool,
}

impl NumberStyle {
    /// The style of `letter` words in `program`, falling back to the style of the other
    /// axis words when the letter never occurs.
    pub fn of(program: &Program, letter: u8) -> NumberStyle {
        let _ = (program, letter);
        todo!()
    }
    /// The number as this style writes it with `decimals` places (not the letter).
    pub fn render(&self, value: f64, decimals: usize) -> String {
        let _ = (value, decimals);
        todo!()
    }
    /// The value the controller receives: `render` parsed back.
    pub fn rounded(&self, value: f64, decimals: usize) -> f64 {
        let _ = (value, decimals);
        todo!()
    }
}
