//! A stretch of a file read again from a place a first read kept: its blocks as a program
//! of their own and its runs, without lexing the rest of the file.
//!
//! A reader that needs only some parts of a large file in full (`polepatch`'s patch: the
//! runs near the pole) reads the file once as a stream, keeps a [`Resume`] before each
//! part it may need ([`crate::Scanned::resume_after`]), and then reads each part again
//! with [`read_stretch`]: the blocks from the place to the stretch's last block, into a
//! [`ProgramBuilder`], and the runs among them as the first read's run walk found them
//! ([`RunBuilder::resumed_at`] where the place is a run's first block).

use crate::builder::ProgramBuilder;
use crate::error::ParseError;
use crate::modal::Modal;
use crate::reader::{Resume, Scanned, scan_resumed};
use crate::run::{Run, RunBuilder};
use crate::tcpm::ReadOptions;
use std::ops::ControlFlow;

/// Which stretch to read ([`read_stretch`]).
#[derive(Debug, Clone)]
pub struct StretchSpec {
    /// Where to read from, and how the run walk starts there: [`ReadFrom::RunStart`] before the
    /// block that is the first of a run (the walk is taken up there), [`ReadFrom::FileStart`]
    /// from the start of the file (the walk from the start; the blocks before
    /// `first_block` are read, not kept).
    pub from: ReadFrom,
    /// The file's block index of the stretch's first block.
    pub first_block: usize,
    /// The file's block index of its last block.
    pub last_block: usize,
    /// The whole file: the program holds the bytes before the first block and after the
    /// last too.
    pub whole: bool,
    /// The run walk's kind ([`RunBuilder::passes`] or the default).
    pub passes: bool,
}

/// Where a stretch is read from ([`StretchSpec::from`]).
#[derive(Debug, Clone)]
pub enum ReadFrom {
    /// The place before the first block of a run, which is the stretch's first block.
    RunStart(Box<Resume>),
    /// The start of the file.
    FileStart,
}

/// A stretch as read ([`read_stretch`]).
#[derive(Debug)]
pub struct Stretch {
    /// Its blocks (finish with the file's bytes from [`ProgramBuilder::base`] to
    /// `end_byte`).
    pub program: ProgramBuilder,
    /// The runs the walk found whose first block the caller wanted, in file order. A run
    /// still open at the stretch's last block is given as [`RunBuilder::finish`] gives it
    /// (ended by [`crate::RunBreak::End`]: the caller knows what ended it in the file).
    pub runs: Vec<Run>,
    /// The byte just past the stretch's last line (its line ending included; the end of
    /// the file for the whole file).
    pub end_byte: usize,
}

/// Read the stretch `spec` of `bytes` again, as `opts` (the options the first read
/// settled on) read it; `wanted` picks the runs to keep by their first block.
pub fn read_stretch(
    bytes: &[u8],
    opts: &ReadOptions,
    spec: &StretchSpec,
    wanted: impl Fn(usize) -> bool,
) -> Result<Stretch, ParseError> {
    let mut program: Option<ProgramBuilder> = None;
    let walked = walk(bytes, opts, spec, wanted, |s, prev| {
        let base = if spec.whole { 0 } else { s.block.span().start };
        program
            .get_or_insert_with(|| ProgramBuilder::new(base, prev))
            .push(s);
    })?;
    Ok(Stretch {
        program: program.unwrap_or_else(|| ProgramBuilder::new(0, &walked.after)),
        runs: walked.runs,
        end_byte: walked.end_byte,
    })
}

/// A stretch's runs as read ([`read_stretch_runs`]): without its program.
#[derive(Debug)]
pub struct StretchRuns {
    /// The file line (1-based) of each block of the stretch, from its first block.
    pub lines: Vec<usize>,
    /// The runs, as [`Stretch::runs`].
    pub runs: Vec<Run>,
    /// The byte just past the stretch's last line, as [`Stretch::end_byte`].
    pub end_byte: usize,
}

/// [`read_stretch`] for a reader that needs the runs and where their blocks are, not the
/// blocks: the runs and the line of each block, no words, blocks or modal states kept
/// (`polepatch simulate`: a run of n points costs its run, not its program).
pub fn read_stretch_runs(
    bytes: &[u8],
    opts: &ReadOptions,
    spec: &StretchSpec,
    wanted: impl Fn(usize) -> bool,
) -> Result<StretchRuns, ParseError> {
    let mut lines = Vec::new();
    let walked = walk(bytes, opts, spec, wanted, |s, _| lines.push(s.block.line))?;
    Ok(StretchRuns {
        lines,
        runs: walked.runs,
        end_byte: walked.end_byte,
    })
}

/// What [`walk`] found besides the blocks it handed out.
struct Walked {
    runs: Vec<Run>,
    end_byte: usize,
    /// The modal state after the last block read.
    after: Modal,
}

/// The walk of [`read_stretch`]: each block of the stretch to `keep` with the modal state
/// before it, the wanted runs collected.
fn walk(
    bytes: &[u8],
    opts: &ReadOptions,
    spec: &StretchSpec,
    wanted: impl Fn(usize) -> bool,
    mut keep: impl FnMut(&Scanned<'_>, &Modal),
) -> Result<Walked, ParseError> {
    let (from, mut i) = match &spec.from {
        ReadFrom::RunStart(at) => (Resume::clone(at), spec.first_block),
        ReadFrom::FileStart => (Resume::file_start(opts), 0),
    };
    // The walk: taken up at the run's first block when read from there, else from the start.
    let mut builder = match spec.from {
        ReadFrom::RunStart(_) => None,
        ReadFrom::FileStart => Some(RunBuilder::of_kind(spec.passes)),
    };
    let mut runs = Vec::new();
    let mut end_byte = bytes.len();
    let mut prev = *from.state();
    scan_resumed(bytes, opts, &from, |s: Scanned<'_>| {
        if i >= spec.first_block {
            keep(&s, &prev);
        }
        match &mut builder {
            Some(b) => b.push(i, s.block, s.state, &mut |run| {
                if wanted(run.blocks[0]) {
                    runs.push(run);
                }
            }),
            None => builder = Some(RunBuilder::resumed_at(spec.passes, i, s.state)),
        }
        if i == spec.last_block {
            if !spec.whole {
                end_byte = line_end_after(bytes, s.block.span().end);
            }
            return ControlFlow::Break(());
        }
        prev = *s.state;
        i += 1;
        ControlFlow::Continue(())
    })?;
    if let Some(b) = &mut builder {
        b.finish(&mut |run| {
            if wanted(run.blocks[0]) {
                runs.push(run);
            }
        });
    }
    Ok(Walked {
        runs,
        end_byte,
        after: prev,
    })
}

/// The byte just past the line ending after `at` (the end of `bytes` if none).
fn line_end_after(bytes: &[u8], at: usize) -> usize {
    bytes[at..]
        .iter()
        .position(|&b| b == b'\n')
        .map_or(bytes.len(), |k| at + k + 1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Dialect;
    use crate::reader::scan_blocks_with;

    /// Every run of `text` as the walk of the whole file finds it, and the place after
    /// every block.
    fn walked(text: &str, passes: bool) -> (Vec<Run>, Vec<Resume>) {
        let opts = ReadOptions::dialect(Dialect::Fanuc);
        let (mut runs, mut places) = (Vec::new(), Vec::new());
        let mut b = RunBuilder::of_kind(passes);
        let mut i = 0usize;
        let _ = scan_blocks_with(text.as_bytes(), &opts, |s| {
            b.push(i, s.block, s.state, &mut |r| runs.push(r));
            places.push(s.resume_after());
            i += 1;
            ControlFlow::Continue(())
        })
        .unwrap();
        b.finish(&mut |r| runs.push(r));
        (runs, places)
    }

    #[test]
    fn a_run_read_again_from_its_place_is_the_run_the_whole_walk_found_with_or_without_its_program()
    {
        // Runs that share a block (a change of F ends a run of the default walk), a run
        // that starts at a rapid, one after a zero-length move, one whose first rotary word
        // comes with its first move, and the file's last run.
        let text = "G90 G94\nG0 X0 Y0 Z5 A0 C0\nG1 Z0 F500\nX1 A1 C2\nX2 A2 C4 F800\nX3 A3 C6\n\
                    G0 Z20\nX10 Y10\nG1 Z0 F300\nZ0\nX11 B5\nX12 B6\nM5\nG1 X13 F400\nX14 A4\n";
        let whole = crate::parse(text.as_bytes().to_vec(), Dialect::Fanuc).unwrap();
        for passes in [false, true] {
            let (runs, places) = walked(text, passes);
            assert!(runs.len() >= 3, "{runs:?}");
            let opts = ReadOptions::dialect(Dialect::Fanuc);
            for run in &runs {
                let first = run.blocks[0];
                let last = *run.blocks.last().unwrap();
                let from = if first == 0 {
                    ReadFrom::FileStart
                } else {
                    ReadFrom::RunStart(Box::new(places[first - 1].clone()))
                };
                let spec = StretchSpec {
                    from,
                    first_block: first,
                    last_block: last,
                    whole: false,
                    passes,
                };
                let got = read_stretch(text.as_bytes(), &opts, &spec, |f| f == first).unwrap();
                assert_eq!(got.runs.len(), 1, "passes {passes}, run at block {first}");
                let mut again = got.runs[0].clone();
                again.ended_by = run.ended_by;
                assert_eq!(&again, run, "passes {passes}, run at block {first}");
                assert_eq!(got.program.len(), last - first + 1);
                let light =
                    read_stretch_runs(text.as_bytes(), &opts, &spec, |f| f == first).unwrap();
                assert_eq!(
                    light.runs, got.runs,
                    "passes {passes}, run at block {first}"
                );
                assert_eq!(light.end_byte, got.end_byte);
                let lines: Vec<usize> = whole.blocks[first..=last].iter().map(|b| b.line).collect();
                assert_eq!(light.lines, lines);
            }
        }
    }
}
