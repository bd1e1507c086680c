//! One application of edits: the edits in, the bytes out, with the groups whose edits could
//! not be written.
//!
//! A rewrite (polepatch's patch of a stretch) hands [`apply_edits`] an [`EditPlan`]: its
//! edits in groups (a group is a run: the blocks it owns and the words it changes), and the
//! decimals a restored word of each axis letter is written with. Nothing calls back into
//! the caller; what it decided is data in the plan. [`apply_edits`] takes these steps:
//!
//! 1. **The edits in group order**: every group's edits, group after group, each edit
//!    belonging to its group.
//! 2. **Modal words** ([`crate::plan`]'s `restore_modal`): the next move after an edited
//!    block that relies on the edited letter's modal value gets it written out. A restoring
//!    word may go into a block of the group of the edited block, or — for X Y Z, where the
//!    group says so ([`EditGroup::restore_xyz_after`]) — into the first move after the
//!    group's last block outside every group. The restoring edits are appended in the
//!    order of the edits that call for them; each belongs to the group that owns its
//!    block (none outside every group).
//! 3. **Direction forms** ([`crate::plan`]'s `write_direction_forms`, on the edits of
//!    step 2, restored ones included): words in a Sinumerik direction form (`C=DC(…)`,
//!    `ACP`, `ACN`) are given the numbers that make the patched moves, and a word that is
//!    a variable is never rewritten. Where that cannot be done, the first conflict names
//!    the edit that causes it; the group of that edit is dropped (all its edits, restored
//!    ones included) and the check is made again on the original values of the edits
//!    kept, until nothing conflicts. A conflict whose cause belongs to no group kept
//!    drops every edit ([`Applied::unattributed`]).
//! 4. **The styled write** ([`crate::writer`]): the edits kept, written in the file's
//!    style ([`FileStyle`]); with none, the program's bytes as they are.
//!
//! The retry of step 3 is here, not with the caller: step 2 runs once on every edit, and a
//! dropped group takes its own restoring words with it while the restoring words outside
//! every group stay — the same edits a caller's loop would only get by knowing how step 2
//! assigns them. What a dropped group means (a run that keeps its values, and why) is the
//! caller's: [`Applied::dropped`] gives each dropped group with the conflict that dropped it.

use crate::modal::AXES;
use crate::plan::{FormConflict, restore_modal, write_direction_forms};
use crate::program::Program;
use crate::style::FileStyle;
use crate::writer::{Edit, write_styled};
use std::borrow::Cow;
use std::collections::HashMap;

/// The edits of one group (a run of a patch) and what it allows restoring words to do.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct EditGroup {
    /// The blocks the group owns (a run's blocks after its start point), in file order: a
    /// word restored into one of them belongs to the group, and an edit of one of them may
    /// get restoring words in the others.
    pub blocks: Vec<usize>,
    /// The words the group changes, in the order they are applied (they may edit blocks
    /// outside [`EditGroup::blocks`], such as blocks after a run that restate its end;
    /// those get no restoring words).
    pub edits: Vec<Edit>,
    /// Whether the first move after the group's last block, when it is outside every
    /// group, may get its X Y Z restored after an edit of X Y Z in that last block (the
    /// positioning move after a run keeps its target).
    pub restore_xyz_after: bool,
}

/// What [`apply_edits`] applies: the groups in order and how restored words are written.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct EditPlan {
    /// The groups, in order (a group's number is its index here).
    pub groups: Vec<EditGroup>,
    /// Decimal places of a restored word of each axis letter, in [`crate::modal::AXES`]
    /// order (X Y Z A B C): the file's.
    pub restore_decimals: [usize; 6],
}

/// A group dropped in step 3 of [`apply_edits`]: its number in [`EditPlan::groups`] and the
/// conflict its edits caused.
#[derive(Debug, Clone, PartialEq)]
pub struct GroupConflict {
    /// The group's index in [`EditPlan::groups`].
    pub group: usize,
    /// The conflict one of its edits caused (its [`FormConflict::cause`] is that edit's
    /// block).
    pub conflict: FormConflict,
}

/// What [`apply_edits`] wrote.
#[derive(Debug, Clone, PartialEq)]
pub struct Applied<'p> {
    /// The program's bytes with the edits kept written (borrowed when none is).
    pub bytes: Cow<'p, [u8]>,
    /// The number of edits written (restoring ones included).
    pub edits_written: usize,
    /// The groups dropped because their edits conflict with a direction form or a
    /// variable, in the order found; none of their edits is written.
    pub dropped: Vec<GroupConflict>,
    /// A conflict whose cause belongs to no group kept (not expected): nothing is written.
    pub unattributed: Option<FormConflict>,
}

/// Apply `plan` to `program` in `file`'s style: the steps of the module docs (restoring
/// words, direction forms with the groups that conflict dropped, the styled write).
///
/// `program` may be a stretch of a larger file ([`crate::ProgramBuilder`]) whose own words
/// are too few to show the file's style; `file` is the whole file's.
///
/// # Panics
/// If an edit names a block that does not exist.
pub fn apply_edits<'p>(program: &'p Program, plan: &EditPlan, file: &FileStyle) -> Applied<'p> {
    let mut edits: Vec<Edit> = Vec::new();
    let mut owner: Vec<Option<usize>> = Vec::new();
    for (g, group) in plan.groups.iter().enumerate() {
        edits.extend_from_slice(&group.edits);
        owner.resize(edits.len(), Some(g));
    }
    let group_of: HashMap<usize, usize> = plan
        .groups
        .iter()
        .enumerate()
        .flat_map(|(g, group)| group.blocks.iter().map(move |&b| (b, g)))
        .collect();
    let decimals_of = |letter: u8| {
        AXES.iter()
            .position(|&l| l == letter)
            .map_or(0, |i| plan.restore_decimals[i])
    };
    let allow =
        |edited: usize, b: usize, letter: u8| allows(program, plan, &group_of, edited, b, letter);
    restore_modal(program, &mut edits, &decimals_of, &allow);
    owner.extend(
        edits[owner.len()..]
            .iter()
            .map(|e| group_of.get(&e.block).copied()),
    );
    let forms = direction_forms(program, &edits, &owner);
    let bytes = if forms.edits.is_empty() {
        Cow::Borrowed(program.bytes.as_slice())
    } else {
        Cow::Owned(write_styled(program, &forms.edits, file))
    };
    Applied {
        bytes,
        edits_written: forms.edits.len(),
        dropped: forms.dropped,
        unattributed: forms.unattributed,
    }
}

/// Whether a restoring word of `letter` may go into block `b` for an edit of block
/// `edited` (step 2): the edited block is a group's, and `b` is of the same group, or `b`
/// is the first move after the group's last block (which was edited), outside every group,
/// the letter is X, Y or Z, and the group allows it.
fn allows(
    program: &Program,
    plan: &EditPlan,
    group_of: &HashMap<usize, usize>,
    edited: usize,
    b: usize,
    letter: u8,
) -> bool {
    let Some(&g) = group_of.get(&edited) else {
        return false;
    };
    if group_of.get(&b) == Some(&g) {
        return true;
    }
    let group = &plan.groups[g];
    let last = *group.blocks.last().unwrap_or(&edited);
    group.restore_xyz_after
        && matches!(letter, b'X' | b'Y' | b'Z')
        && edited == last
        && !group_of.contains_key(&b)
        && (last + 1..b).all(|k| !program.blocks[k].is_move)
}

/// What step 3 leaves: the edits to write, the groups dropped, and a conflict no group
/// kept caused.
struct Forms {
    edits: Vec<Edit>,
    dropped: Vec<GroupConflict>,
    unattributed: Option<FormConflict>,
}

/// Step 3: the direction forms written on the edits of the groups kept (`owner`: each
/// edit's group), dropping the group of the edit that causes the first conflict and
/// checking again, until none is left.
fn direction_forms(program: &Program, edits: &[Edit], owner: &[Option<usize>]) -> Forms {
    let mut dropped: Vec<GroupConflict> = Vec::new();
    let is_dropped = |dropped: &[GroupConflict], g: usize| dropped.iter().any(|d| d.group == g);
    loop {
        let mut kept: Vec<Edit> = edits
            .iter()
            .zip(owner)
            .filter(|(_, o)| o.is_none_or(|g| !is_dropped(&dropped, g)))
            .map(|(e, _)| *e)
            .collect();
        let mut conflicts = write_direction_forms(program, &mut kept);
        if conflicts.is_empty() {
            return Forms {
                edits: kept,
                dropped,
                unattributed: None,
            };
        }
        let k = conflicts.swap_remove(0);
        // The group of the edit that causes it.
        let group = edits
            .iter()
            .zip(owner)
            .filter(|(e, o)| e.block == k.cause && o.is_some_and(|g| !is_dropped(&dropped, g)))
            .find_map(|(_, o)| *o);
        let Some(group) = group else {
            return Forms {
                edits: Vec::new(),
                dropped,
                unattributed: Some(k),
            };
        };
        dropped.push(GroupConflict { group, conflict: k });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Dialect, parse};

    fn c(block: usize, value: f64) -> Edit {
        Edit {
            block,
            letter: b'C',
            value,
            decimals: 3,
        }
    }

    /// One group owning `blocks`, with `edits`, that lets the move after it keep its X Y Z.
    fn group(blocks: std::ops::Range<usize>, edits: Vec<Edit>) -> EditGroup {
        EditGroup {
            blocks: blocks.collect(),
            edits,
            restore_xyz_after: true,
        }
    }

    fn plan(groups: Vec<EditGroup>, decimals: usize) -> EditPlan {
        EditPlan {
            groups,
            restore_decimals: [decimals; 6],
        }
    }

    /// What [`apply_edits`] made of `src`, owned.
    #[derive(Debug)]
    struct Out {
        text: String,
        /// The program's bytes were handed back as they are.
        borrowed: bool,
        written: usize,
        dropped: Vec<GroupConflict>,
        unattributed: Option<FormConflict>,
    }

    fn applied(src: &str, dialect: Dialect, plan: &EditPlan) -> Out {
        let p = parse(src.as_bytes().to_vec(), dialect).unwrap();
        let a = apply_edits(&p, plan, &FileStyle::of(&p));
        Out {
            text: String::from_utf8(a.bytes.to_vec()).unwrap(),
            borrowed: matches!(a.bytes, Cow::Borrowed(_)),
            written: a.edits_written,
            dropped: a.dropped,
            unattributed: a.unattributed,
        }
    }

    /// The move after an edited block relied on modal C: it gets its old C written out,
    /// and a block that carries its own C is left alone.
    #[test]
    fn next_move_keeps_its_position() {
        let src = "G1 X0 Y0 Z0 A1 C10.5 F100\nX1 C20.25\nX2\nX3 C40.125\n";
        let o = applied(
            src,
            Dialect::Auto,
            &plan(vec![group(1..4, vec![c(1, 25.0)])], 3),
        );
        assert_eq!(o.written, 2);
        assert_eq!(
            o.text,
            "G1 X0 Y0 Z0 A1 C10.5 F100\nX1 C25\nX2 C20.25\nX3 C40.125\n"
        );
        // Consecutive edits: only the block after the last one is restored.
        let two = plan(vec![group(1..4, vec![c(1, 25.0), c(2, 30.0)])], 3);
        assert_eq!(
            applied(src, Dialect::Auto, &two).written,
            2,
            "block 3 has its own C"
        );
        // A group that does not own the next move gets no word there.
        let o = applied(
            src,
            Dialect::Auto,
            &plan(vec![group(1..2, vec![c(1, 25.0)])], 3),
        );
        assert_eq!(o.written, 1);
        assert_eq!(
            o.text,
            "G1 X0 Y0 Z0 A1 C10.5 F100\nX1 C25\nX2\nX3 C40.125\n"
        );
        // An edit outside every group (a block after a run that restates its end) gets none.
        let o = applied(
            src,
            Dialect::Auto,
            &plan(vec![group(2..4, vec![c(1, 25.0)])], 3),
        );
        assert_eq!(o.written, 1);
    }

    /// Comments and non-moves between the edit and the next move are skipped; the primary
    /// letter is restored like C; an inch program gets its linear value back in inches; the
    /// restored words are written with the plan's decimals.
    #[test]
    fn skips_non_moves_and_handles_every_axis_letter() {
        let src = "G20 G1 X0 Y0 Z0 A1 C10 F10\n(NOTE)\nX1 A2 C20\nM8\nY2\n";
        let at2 = |letter, value| Edit {
            block: 2,
            letter,
            value,
            decimals: 3,
        };
        let edits = vec![at2(b'A', -2.0), at2(b'X', 1.5)];
        let o = applied(src, Dialect::Auto, &plan(vec![group(1..5, edits)], 1));
        assert_eq!(
            o.text,
            "G20 G1 X0 Y0 Z0 A1 C10 F10\n(NOTE)\nX1.500 A-2.000 C20\nM8\nX1.0 Y2 A2.0\n"
        );
    }

    /// The first move after a group, outside every group, keeps its X Y Z target when the
    /// group's last block got new X Y Z, and only where the group allows it; its rotary
    /// words are never restored.
    #[test]
    fn the_move_after_a_group_keeps_its_xyz_where_the_group_allows_it() {
        let src = "G1 X0 Y0 Z0 A1 C10 F100\nX1 C20\nM8\nG0 Z50\n";
        let edits = vec![
            Edit {
                block: 1,
                letter: b'X',
                value: 1.25,
                decimals: 2,
            },
            c(1, 21.0),
        ];
        let mut p = plan(vec![group(1..2, edits)], 3);
        let o = applied(src, Dialect::Auto, &p);
        assert_eq!(o.written, 3);
        assert_eq!(
            o.text,
            "G1 X0 Y0 Z0 A1 C10 F100\nX1.25 C21.000\nM8\nG0 X1.000 Z50\n"
        );
        p.groups[0].restore_xyz_after = false;
        let o = applied(src, Dialect::Auto, &p);
        assert_eq!(o.written, 2);
        assert_eq!(
            o.text,
            "G1 X0 Y0 Z0 A1 C10 F100\nX1.25 C21.000\nM8\nG0 Z50\n"
        );
    }

    const DC: &str = "N10 TRAORI\nN20 G1 X0 Y0 Z0 A1 C=DC(350.) F1000\nN30 X1 A0.5 C=DC(10.)\n\
                      N40 X2 A0.5 C=DC(30.)\nN50 X3 A1 C=DC(40.)\n";

    /// Issue 30 item 10: an edited `C=DC(…)` is written modulo 360 in the same form where
    /// the shorter way is the patched move; an unedited one after it is checked from its
    /// new starting point.
    #[test]
    fn direction_forms_are_written_modulo_360_where_they_make_the_move() {
        let p = parse(DC.as_bytes().to_vec(), Dialect::Sinumerik).unwrap();
        assert_eq!(p.state(2).pos[crate::modal::C], Some(370.0));
        let edits = vec![c(2, 375.5), c(3, 385.25)];
        let o = applied(DC, Dialect::Sinumerik, &plan(vec![group(2..5, edits)], 3));
        assert_eq!((o.written, o.dropped.len()), (2, 0));
        assert!(
            o.text
                .contains("N30 X1 A0.5 C=DC(15.5)\nN40 X2 A0.5 C=DC(25.25)\n"),
            "{}",
            o.text
        );
        // A patched move the shorter way cannot make (a turn of +190°): the group is
        // dropped and the program's bytes are handed back.
        let o = applied(
            DC,
            Dialect::Sinumerik,
            &plan(vec![group(2..5, vec![c(2, 540.0)])], 3),
        );
        assert!(o.borrowed && o.text == DC && o.written == 0, "{o:?}");
        assert_eq!(o.dropped.len(), 1, "{o:?}");
        let k = &o.dropped[0].conflict;
        assert_eq!((o.dropped[0].group, k.block, k.cause), (0, 2, 2));
        assert!(k.message.contains("would move -170.000° instead"), "{k:?}");
        // A word inserted after direction words takes their form.
        let src = "G1 X0 A1 C=DC(350.) F1000\nX1\nX2 C=DC(10.)\n";
        let o = applied(
            src,
            Dialect::Sinumerik,
            &plan(vec![group(1..3, vec![c(1, 365.0)])], 3),
        );
        assert_eq!(
            o.text,
            "G1 X0 A1 C=DC(350.) F1000\nX1 C=DC(5.000)\nX2 C=DC(10.)\n"
        );
    }

    /// ACP turns only forward, ACN only back: an edit is written in its form where the
    /// patched move goes that way, and its group is dropped where it does not.
    #[test]
    fn acp_and_acn_keep_their_direction() {
        let src = "G1 X0 A1 C=ACP(350.) F1000\nX1 C=ACP(10.)\nX2 C=ACN(0.)\nX3 C=ACN(355.)\n";
        let p = parse(src.as_bytes().to_vec(), Dialect::Sinumerik).unwrap();
        let cs: Vec<_> = (0..4).map(|b| p.state(b).pos[crate::modal::C]).collect();
        assert_eq!(cs, [Some(350.0), Some(370.0), Some(360.0), Some(355.0)]);
        let one = |edit: Edit| plan(vec![group(1..4, vec![edit])], 3);
        // ACP to 362 is +12 from 350: written 2.
        let o = applied(src, Dialect::Sinumerik, &one(c(1, 362.0)));
        assert!(
            o.dropped.is_empty() && o.text.contains("X1 C=ACP(2.000)"),
            "{o:?}"
        );
        // ACP cannot move back.
        let o = applied(src, Dialect::Sinumerik, &one(c(1, 345.0)));
        assert!(o.dropped[0].conflict.message.contains("ACP"), "{o:?}");
        // ACN to 357 from 360 is −3: written 357; the ACN(355.) after it still goes −2.
        let o = applied(src, Dialect::Sinumerik, &one(c(2, 357.0)));
        assert!(
            o.dropped.is_empty() && o.text.contains("X2 C=ACN(357.000)"),
            "{o:?}"
        );
        // ACN cannot move forward.
        let o = applied(src, Dialect::Sinumerik, &one(c(3, 362.0)));
        assert!(o.text == src && o.dropped.len() == 1, "{o:?}");
    }

    /// Issue 30 item 11: `C#105` is read as the constant but never rewritten; the conflict
    /// says it is a variable.
    #[test]
    fn a_variable_word_is_never_rewritten() {
        let src = "#105=10.\nG1 X0 A1 C#105 F1000\nX1 C20.\n";
        let p = parse(src.as_bytes().to_vec(), Dialect::Fanuc).unwrap();
        assert_eq!(p.state(1).pos[crate::modal::C], Some(10.0));
        let o = applied(
            src,
            Dialect::Fanuc,
            &plan(vec![group(1..3, vec![c(1, 12.0)])], 3),
        );
        assert!(o.text == src && o.dropped.len() == 1, "{o:?}");
        let k = &o.dropped[0].conflict;
        assert!(k.variable && k.message.contains("`C#105`"), "{k:?}");
        let o = applied(
            src,
            Dialect::Fanuc,
            &plan(vec![group(1..3, vec![c(2, 22.0)])], 3),
        );
        assert!(
            o.dropped.is_empty() && o.text.ends_with("X1 C22.000\n"),
            "{o:?}"
        );
    }

    /// A conflict names the group whose edit causes it: that group is dropped with its
    /// restoring words, and the others are written, checked again without it.
    #[test]
    fn a_conflict_names_its_group_and_only_that_group_is_dropped() {
        let src = "N10 TRAORI\nN20 G1 X0 A1 C=DC(350.) F1000\nN30 X1 C=DC(10.)\nN40 X2\n\
                   N50 G0 Z50\nN60 G1 X3 A1 C=DC(20.)\nN70 X4 C=DC(30.)\nN80 X5\n";
        // Group 0 owns N30 N40 and turns N30 from 350 to 375 (DC(15.)), N40 getting its
        // C back; group 2 owns N70 N80 and asks N70 for a turn of +190° from 380, which
        // DC makes the shorter way (−170°).
        let groups = vec![
            group(2..4, vec![c(2, 375.0)]),
            EditGroup::default(),
            group(6..8, vec![c(6, 570.0)]),
        ];
        let o = applied(src, Dialect::Sinumerik, &plan(groups, 3));
        assert_eq!(o.dropped.len(), 1, "{o:?}");
        assert_eq!((o.dropped[0].group, o.dropped[0].conflict.cause), (2, 6));
        assert!(o.unattributed.is_none());
        assert_eq!(o.written, 2, "group 0's edit and the word it restores");
        assert!(
            o.text.contains("N30 X1 C=DC(15.000)\nN40 X2 C=DC(")
                && o.text.ends_with("N70 X4 C=DC(30.)\nN80 X5\n"),
            "{}",
            o.text
        );
    }
}
