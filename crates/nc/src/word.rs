//! Address words (`C+148.494`, `X=10`, `C=DC(12.5)`) with their byte spans, and the forms a
//! rotary word states its position in.

use crate::tolerances::FORM_EPS_DEG;
use std::ops::Range;

/// How a rotary word states where the axis goes: as a plain number (`C12.5`, `C=12.5`:
/// the axis moves to that value), or in a Sinumerik direction form (`C=DC(12.5)`,
/// `C=ACP(12.5)`, `C=ACN(12.5)`) whose number is a position modulo 360 reached the
/// shorter way, in the positive direction or in the negative direction (a modulo,
/// rotary-endless axis). The reader follows the unwrapped position the controller
/// reaches ([`RotaryForm::delta`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum RotaryForm {
    /// A plain number.
    #[default]
    Plain,
    /// `DC(…)`: the shorter way to the value modulo 360.
    Dc,
    /// `ACP(…)`: in the positive direction to the value modulo 360.
    Acp,
    /// `ACN(…)`: in the negative direction to the value modulo 360.
    Acn,
}

impl RotaryForm {
    /// The form's name as written (`DC`, `ACP`, `ACN`; empty for a plain number).
    pub fn name(self) -> &'static str {
        match self {
            RotaryForm::Plain => "",
            RotaryForm::Dc => "DC",
            RotaryForm::Acp => "ACP",
            RotaryForm::Acn => "ACN",
        }
    }

    /// Whether the word states a position modulo 360 with a direction.
    pub fn is_directional(self) -> bool {
        self != RotaryForm::Plain
    }

    /// The move (degrees, signed) the controller makes from the unwrapped position `from`
    /// for a word of this form with the number `target`: DC the shorter way (in
    /// (−180, 180); `None` for a half turn exactly, which DC does not name), ACP in
    /// [0, 360), ACN in (−360, 0] — the same modulo position is no move. A plain number
    /// moves to itself (`target − from`).
    pub fn delta(self, from: f64, target: f64) -> Option<f64> {
        let d = (target - from).rem_euclid(360.0);
        // `d` within the tolerance of a whole turn is no turn.
        let d = if d > 360.0 - FORM_EPS_DEG { 0.0 } else { d };
        match self {
            RotaryForm::Plain => Some(target - from),
            RotaryForm::Dc if (d - 180.0).abs() <= FORM_EPS_DEG => None,
            RotaryForm::Dc if d > 180.0 => Some(d - 360.0),
            RotaryForm::Dc | RotaryForm::Acp => Some(d),
            RotaryForm::Acn if d <= FORM_EPS_DEG => Some(0.0),
            RotaryForm::Acn => Some(d - 360.0),
        }
    }

    /// How a word of this form writes the unwrapped position `to` reached from `from`:
    /// the number to write (for a direction form, `to` modulo 360 in [0, 360), rounded to
    /// `decimals`), or why the form cannot make that move (`Err`: the move the written
    /// word would make instead, degrees). Checked on the rounded number.
    pub fn write(self, from: f64, to: f64, decimals: usize) -> Result<f64, Option<f64>> {
        if self == RotaryForm::Plain {
            return Ok(to);
        }
        let scale = 10f64.powi(decimals.min(15) as i32);
        let mut t = (to.rem_euclid(360.0) * scale).round() / scale;
        if t >= 360.0 {
            t -= 360.0;
        }
        let wanted = to - from;
        match self.delta(from, t) {
            // The rounding of the written number moves the axis by at most half a unit
            // of its last decimal: the same move.
            Some(d) if (d - wanted).abs() <= 0.5 / scale + FORM_EPS_DEG => Ok(t),
            other => Err(other),
        }
    }
}

/// One address word such as `C+148.494`, `X-.5`, `G01`, `X=10`, `C=DC(12.5)`.
///
/// Offsets are `u32` (a program is at most 4 GiB, see [`crate::parse`]) so that a word takes 24
/// bytes: a large program holds millions of them.
#[derive(Debug, Clone, PartialEq)]
pub struct Word {
    /// Upper-case letter.
    pub letter: u8,
    /// A rotary word's form (Sinumerik `DC(…)`, `ACP(…)`, `ACN(…)`); [`RotaryForm::Plain`]
    /// for every other word.
    pub form: RotaryForm,
    /// Bytes of the word after its number (the `)` of `C=DC(12.5)`, and blanks before it).
    pub tail: u8,
    /// Byte offset of the letter in the file.
    pub start: u32,
    /// Byte offset of the number (its sign, if any) in the file.
    pub value_start: u32,
    /// Byte offset just past the last digit.
    pub end: u32,
    /// Numeric value as written (no unit conversion; for a direction form, the number in
    /// its brackets: the position the axis reaches is in the modal state).
    pub value: f64,
}

impl Word {
    /// Bytes of the whole word (letter to last digit, or to the `)` of a direction form)
    /// in the file.
    pub fn span(&self) -> Range<usize> {
        self.start as usize..self.end as usize + usize::from(self.tail)
    }
    /// Bytes of the number (sign included) in the file.
    pub fn value_span(&self) -> Range<usize> {
        self.value_start as usize..self.end as usize
    }
}
