//! Edit planning: the words a rewrite must add, and the numbers it must write, so that
//! nothing but the intended values change. Steps 2 and 3 of [`crate::apply_edits`], which
//! is their one caller.
//!
//! A block that relies on a modal axis value (it has no word for that letter) inherits
//! whatever the blocks before it left. When an edit changes the value of a letter in a
//! block, the next move after it that has no word for that letter would inherit the new
//! value and move differently: `restore_modal` gives that move its original value
//! explicitly, written in the file's style. A word in a Sinumerik direction form
//! (`C=DC(…)`) says which way to turn as well as where to: `write_direction_forms` gives
//! the edits of such words the numbers that make the patched moves, and names a
//! [`FormConflict`] where none does.

use crate::modal::{AXES, X, Z};
use crate::program::Program;
use crate::tolerances::DIRECTION_FORM_REACH_TOL_DEG;
use crate::word::{RotaryForm, Word};
use crate::writer::Edit;
use crate::writer::inserted_form;

/// For every edit, find the next block after it that moves or carries the edited letter;
/// when that block has no word for the letter and is not edited for it itself, add an edit
/// that writes the letter's original modal value there (so the move after the rewritten
/// stretch goes where it went before). `decimals_of(letter)` gives the decimals to write
/// the restored value with (the file's).
///
/// Only axis letters (X Y Z A B C) are restored; linear values are written back in the
/// units of the file (inch programs are read in mm). `allow(edited_block, block, letter)`
/// says whether a restoring word of `letter` may go into `block` for an edit of
/// `edited_block` (a caller may forbid words outside the stretch it rewrote). Edits are appended; the order of
/// `edits` is otherwise kept.
pub(crate) fn restore_modal(
    program: &Program,
    edits: &mut Vec<Edit>,
    decimals_of: &dyn Fn(u8) -> usize,
    allow: &dyn Fn(usize, usize, u8) -> bool,
) {
    use std::collections::HashSet;
    let edited: HashSet<(usize, u8)> = edits.iter().map(|e| (e.block, e.letter)).collect();
    // Only the last edit of each letter before a block that relies on it matters; visiting
    // every edit costs a short forward scan each (runs are consecutive blocks).
    let mut added: HashSet<(usize, u8)> = HashSet::new();
    let mut extra = Vec::new();
    for e in edits.iter() {
        let Some(idx) = AXES.iter().position(|&l| l == e.letter) else {
            continue;
        };
        let next = (e.block + 1..program.blocks.len())
            .find(|&b| program.blocks[b].is_move || program.word(b, e.letter).is_some());
        let Some(b) = next else { continue };
        if edited.contains(&(b, e.letter))
            || program.word(b, e.letter).is_some()
            || !allow(e.block, b, e.letter)
            || !added.insert((b, e.letter))
        {
            continue;
        }
        let st = program.state(b);
        if let Some(v) = st.pos[idx] {
            let v = if (X..=Z).contains(&idx) && st.inch {
                v / 25.4
            } else {
                v
            };
            extra.push(Edit {
                block: b,
                letter: e.letter,
                value: v,
                decimals: decimals_of(e.letter),
            });
        }
    }
    edits.extend(extra);
}

/// A rotary word in a direction form (Sinumerik `C=DC(…)`, `C=ACP(…)`, `C=ACN(…)`) that
/// cannot make the move a rewrite asks of it.
#[derive(Debug, Clone, PartialEq)]
pub struct FormConflict {
    /// The block whose word would make another move (or would get a word inserted).
    pub block: usize,
    /// Its letter.
    pub letter: u8,
    /// The last edited block of that letter at or before `block`: the edit that causes it.
    pub cause: usize,
    /// What is wrong, for people.
    pub message: String,
    /// The word is a macro variable or an expression (`C#105`), which is never rewritten,
    /// rather than a direction form that cannot make the move.
    pub variable: bool,
}

/// Check the edits against the words they change: a word whose value is a variable or an
/// expression (`C#105`) is never rewritten ([`FormConflict::variable`]); and write the
/// edits of rotary letters that the file writes in a direction form
/// ([`crate::RotaryForm`]): an edited `C=DC(…)` gets the patched position modulo 360 in
/// [0, 360), rounded to the edit's decimals, where that number makes the controller move
/// from the (patched) position before it to the patched position — DC the shorter way,
/// ACP in the positive, ACN in the negative direction; an unedited direction word after an
/// edit is checked the same way from its new starting point. The edits' values are the
/// unwrapped positions the reader follows ([`crate::Modal::pos`]); those of direction words
/// are replaced by the numbers to write. Where the form cannot make the move, or where an
/// edit would insert a word of a letter the file writes in a direction form (a plain word
/// there is not the same kind of move), a [`FormConflict`] names it: the caller must drop
/// the edits that cause it (and call again on the original values). Letters without a
/// direction word in the file are left as they are.
pub(crate) fn write_direction_forms(program: &Program, edits: &mut [Edit]) -> Vec<FormConflict> {
    use crate::modal::A;
    let mut conflicts = variable_conflicts(program, edits);
    for (k, &letter) in AXES.iter().enumerate().skip(A) {
        if program
            .words
            .iter()
            .any(|w| w.letter == letter && w.form.is_directional())
        {
            direction_forms_of(program, edits, k, letter, &mut conflicts);
        }
    }
    conflicts
}

/// The edits of words whose value is a variable or an expression (`C#105`, read as the
/// variable's constant value): never rewritten, nor given a second word of its letter.
fn variable_conflicts(program: &Program, edits: &[Edit]) -> Vec<FormConflict> {
    let mut conflicts = Vec::new();
    for e in edits.iter() {
        let block = &program.blocks[e.block];
        let held = crate::lexer::Lexer::new(&program.bytes, block.span())
            .filter_map(Result::ok)
            .find_map(|t| match t {
                crate::lexer::Token::Assign { letter, span } if letter == e.letter => Some(span),
                _ => None,
            });
        if let Some(span) = held {
            conflicts.push(FormConflict {
                block: e.block,
                letter: e.letter,
                cause: e.block,
                message: format!(
                    "line {}: the patch would change {}, and the block writes it as `{}` (a \
                     variable or an expression, never rewritten)",
                    block.line,
                    e.letter as char,
                    String::from_utf8_lossy(&program.bytes[span])
                ),
                variable: true,
            });
        }
    }
    conflicts
}

/// [`write_direction_forms`] for the rotary `letter` (axis index `k`), which the file
/// writes in a direction form somewhere: from its first edit on, each block's word is
/// written or checked from the patched position before it.
fn direction_forms_of(
    program: &Program,
    edits: &mut [Edit],
    k: usize,
    letter: u8,
    conflicts: &mut Vec<FormConflict>,
) {
    use std::collections::HashMap;
    let by_block: HashMap<usize, usize> = edits
        .iter()
        .enumerate()
        .filter(|(_, e)| e.letter == letter)
        .map(|(i, e)| (e.block, i))
        .collect();
    let Some(&first) = by_block.keys().min() else {
        return;
    };
    let last = by_block.keys().copied().max().unwrap_or(first);
    let l = letter as char;
    // The patched position before block `b`, and the block of the last edit.
    let mut now = program.state_before(first).pos[k];
    let mut cause = first;
    for b in first..program.blocks.len() {
        let before = program.state_before(b).pos[k];
        if b > last && now == before {
            break;
        }
        let after = program.state(b).pos[k];
        let word = program.word(b, letter);
        let line = program.blocks[b].line;
        let edit = by_block.get(&b).copied();
        if edit.is_some() {
            cause = b;
        }
        let (next, conflict) = match (word, edit) {
            (Some(w), Some(i)) if w.form.is_directional() => {
                edited_direction_word(w, &mut edits[i], now, line, l)
            }
            (Some(w), None) if w.form.is_directional() => {
                unedited_direction_word(w, now, before, after, line, l)
            }
            (None, Some(i)) => {
                // Inserted in the form of the letter's word before it.
                let form = inserted_form(program, b, letter);
                inserted_word(form, &mut edits[i], now, line, l)
            }
            (Some(_), Some(i)) => (Some(edits[i].value), None),
            (Some(_), None) => (after, None),
            (None, None) => (if after.is_none() { None } else { now }, None),
        };
        now = next;
        if let Some(message) = conflict {
            conflicts.push(FormConflict {
                block: b,
                letter,
                cause,
                message,
                variable: false,
            });
        }
    }
}

/// An edited direction word `w` (edit `e`, the patched position before it `now`; `line`,
/// `l`: its line and letter): the number to write, the patched position after it, and a
/// conflict if the form cannot make the move.
fn edited_direction_word(
    w: &Word,
    e: &mut Edit,
    now: Option<f64>,
    line: usize,
    l: char,
) -> (Option<f64>, Option<String>) {
    let to = e.value;
    let form = w.form.name();
    let from = now.unwrap_or(to);
    match w.form.write(from, to, e.decimals) {
        Ok(t) => {
            e.value = t;
            (
                Some(from + w.form.delta(from, t).unwrap_or(to - from)),
                None,
            )
        }
        Err(d) => (
            Some(to),
            Some(format!(
                "line {line}: the patched {l} moves {:+.3}° (from {from:.3} to \
                 {to:.3}); {l}={form}(…) {}",
                to - from,
                match d {
                    Some(d) => format!("would move {d:+.3}° instead"),
                    None => "names no direction for a half turn".into(),
                }
            )),
        ),
    }
}

/// An unedited direction word `w` after an edit: from where the patch left the axis
/// (`now`), the word moves as it did only if it reaches the same unwrapped position as
/// before (`after`; `before`: the position before it in the original). The patched
/// position after it, and a conflict if it does not.
fn unedited_direction_word(
    w: &Word,
    now: Option<f64>,
    before: Option<f64>,
    after: Option<f64>,
    line: usize,
    l: char,
) -> (Option<f64>, Option<String>) {
    let form = w.form.name();
    match (now, after) {
        (Some(p), Some(a)) => {
            let reached = w.form.delta(p, w.value).map(|d| p + d);
            let conflict = reached
                .is_none_or(|r| (r - a).abs() > DIRECTION_FORM_REACH_TOL_DEG)
                .then(|| {
                    format!(
                        "line {line}: {l}={form}({}) after the patched moves starts from \
                         {p:.3}, not {}, and reaches {} instead of {a:.3}",
                        w.value,
                        before.map_or("an unknown position".into(), |v| format!("{v:.3}")),
                        reached.map_or("no settled position".into(), |r| format!("{r:.3}")),
                    )
                });
            (Some(a), conflict)
        }
        _ => (after, None),
    }
}

/// A word to be inserted for edit `e` in `form` (the form of the letter's word before it),
/// the patched position before it `now`: the number to write in a direction form, the
/// patched position after it, and a conflict if the word cannot make the move.
fn inserted_word(
    form: RotaryForm,
    e: &mut Edit,
    now: Option<f64>,
    line: usize,
    l: char,
) -> (Option<f64>, Option<String>) {
    let to = e.value;
    let from = now.unwrap_or(to);
    let conflict = if form.is_directional() {
        match form.write(from, to, e.decimals) {
            Ok(t) => {
                e.value = t;
                None
            }
            Err(d) => Some(format!(
                "line {line}: the patched {l} moves {:+.3}° (from {from:.3} to \
                 {to:.3}); an inserted {l}={}(…) {}",
                to - from,
                form.name(),
                match d {
                    Some(d) => format!("would move {d:+.3}° instead"),
                    None => "names no direction for a half turn".into(),
                }
            )),
        }
    } else if !(0.0..360.0).contains(&to) {
        // A plain word after direction words, outside [0, 360): how the
        // controller reads it on a modulo axis is not settled here.
        Some(format!(
            "line {line}: the patch would insert a plain {l} word ({to:.3}, \
             outside [0, 360)) into a file that writes {l} in a direction form \
             (DC/ACP/ACN)"
        ))
    } else {
        None
    };
    (Some(to), conflict)
}
