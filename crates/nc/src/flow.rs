//! Program flow and the TCPM state: calls, labels, jumps and loops.
//!
//! With TCPM on, X Y Z are tool-tip positions in the part frame and a rotary word may change
//! alone; with it off they are machine positions and it may not. The reader follows the
//! state block by block — but a block that control reaches other than from the block before
//! it (a label, a jump's target, a subprogram's first block, the block after a call) has the
//! state of every way in. Where the ways in disagree, or one of them is code outside the
//! file, the state there is [`Tcpm::Unknown`], and such a run is never rewritten.
//!
//! # The statements ([`Stmt`], read with each block: ISO lines in `statements.rs`)
//!
//! | dialect | label | call | return | jump | structured (any keyword reaches any other of its statement) |
//! |---|---|---|---|---|---|
//! | Fanuc, Haas | `O2000` (program number), `N100` (a `GOTO`/`M97` target) | `M98 P2000 [L3]`, `M98 P32000`, `M97 P100`, `G65 P9001` (in the file or outside), `M198`: outside; `M6` (a tool-change macro: may end TCPM, never starts it) | `M99` | `GOTO 100`, `IF […] GOTO 100` | `WHILE […] DO 1` … `END 1` |
//! | LinuxCNC | `o100 sub` … `o100 endsub` (skipped in file order) | `o100 call`, `o<name> call` | `o100 return`, `endsub` | — | `o100 if/elseif/else/endif/while/endwhile/do/repeat/endrepeat/break/continue` |
//! | Sinumerik | `NAME:`, `N100` (a jump target) | `L123`, `CALL`, `PCALL`, `EXTCALL`, a subprogram's name: outside | `RET`, `M17` | `GOTOF`, `GOTOB`, `GOTO`, `GOTOC` (also after `IF`) | `IF/ELSE/ENDIF`, `WHILE/ENDWHILE`, `FOR/ENDFOR`, `LOOP/ENDLOOP`, `REPEAT/UNTIL` |
//! | Heidenhain ISO | `G98 L1` | `L1,0` (`L1,3`: repeated), `%NAME`: outside | `G98 L0` | — | — |
//! | conversational | `LBL 1`, `LBL "NAME"` | `CALL LBL 1 [REP 2]`, `CALL PGM`, `SEL PGM`: outside | `LBL 0` | `FN 9`…`FN 12: IF … GOTO LBL 1` | — |
//!
//! A jump whose target is computed (`GOTO #1`, `GOTO LBL QS1`), a modal macro (`G66`,
//! Sinumerik `MCALL` of a subprogram), a section repeat (`REPEAT A B P=3`), `M99 P…`, or a
//! jump to a label the file does not hold: control may reach any block, so TCPM is
//! unknown in the whole file.
//!
//! # How the state is settled
//!
//! The file is read once as it would be without flow; when that read meets a statement
//! above that joins paths (anything but a call of code outside the file, whose effect is
//! local: the state after it is unknown), the reader records the flow statements, the
//! TCPM switches and the program ends, and solves the state at each of them: a data-flow
//! problem on the lattice ⊥ < {off, on, uncertain} < unknown (join: equal states stay,
//! different ones are unknown), over these edges —
//! - each statement to the next in file order, except after a program end, an
//!   unconditional jump, a return (Heidenhain's `LBL 0`/`G98 L0` also fall through: the
//!   control ignores them where no call is active), and a LinuxCNC `sub` (to its `endsub`);
//! - a jump to every label of its name; a keyword of a structured statement to every other;
//! - a call to its subprogram's first block, and each return of that subprogram (the
//!   returns after its label, up to the next label that is called) back to the block after
//!   every call of it — and, for a repeated call, to the first block again;
//!   a call of a name the file does not hold gives `unknown` after it;
//! - a switch maps the state as the reader does ([`Tcpm::switched`]).
//!
//! Blocks no way reaches (code after the end that nothing calls) are `unknown`. The
//! solution is handed to the reader as a [`FlowPlan`]: the state to take before given
//! lines, where positions are also unknown at labels (any way in may come from anywhere).
//! The reader then reads the file again with it ([`crate::Settled::Again`]). Work: the
//! statements only, a few per subprogram; the file is lexed twice when it has flow (three
//! times when a jump targets block numbers, whose blocks are found in a second pass).

use crate::modal::Tcpm;
use std::collections::{HashMap, HashSet};

/// What a jump, a call or a label names.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub(crate) enum Key {
    /// A named or numbered label (conversational `LBL`, Heidenhain ISO `G98 L`, Sinumerik
    /// `NAME:`, LinuxCNC `o100`/`o<name>` subroutines), upper case.
    Label(String),
    /// A Fanuc program number (`O2000`, `M98 P2000`, `G65 P9001`).
    Program(u64),
    /// A block number (`N100`, as `GOTO 100` and `M97 P100` name it).
    Block(u64),
    /// The keywords of one structured statement (LinuxCNC by its o-word; Sinumerik and
    /// Fanuc by nesting, numbered by the recorder).
    Group(String),
}

/// Role of a keyword of a structured statement whose keywords are matched by nesting.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Nest {
    /// `IF`, `WHILE`, `FOR`, `LOOP`, `REPEAT`, Fanuc `DO m`.
    Open,
    /// `ELSE`.
    Middle,
    /// `ENDIF`, `ENDWHILE`, `ENDFOR`, `ENDLOOP`, `UNTIL`, Fanuc `END m`.
    Close,
}

/// What a block says about program flow (module docs).
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Stmt {
    /// A label.
    Label(Key),
    /// LinuxCNC `oN sub`: a definition that flow in file order skips.
    SubStart(Key),
    /// LinuxCNC `oN endsub`: the end of the definition, a return.
    SubEnd(Key),
    /// A return to the caller; `falls_through`: the control goes on in file order where
    /// no call is active (Heidenhain `LBL 0`, `G98 L0`).
    Return {
        /// Falls through when not called.
        falls_through: bool,
    },
    /// A call of `key` (a subprogram in the file, or outside it if the file holds none of
    /// that name); `repeats`: more than once.
    Call {
        /// What is called.
        key: Key,
        /// Called more than once in a row.
        repeats: bool,
    },
    /// A call of code outside the file: the state after it is unknown.
    External,
    /// A tool change that may run a macro (Fanuc `M6`): it may end TCPM but does not
    /// start it, so TCPM on becomes unknown and off stays off.
    ToolChange,
    /// A jump to `key`; `cond`: it may also go on in file order.
    Jump {
        /// Where to.
        key: Key,
        /// Conditional.
        cond: bool,
    },
    /// A keyword of a structured statement named by the file (LinuxCNC o-words).
    Group(Key),
    /// A keyword of a structured statement matched by nesting; `tag` keeps Fanuc's `DO m`
    /// and `END m` numbers apart.
    Nested {
        /// Its role.
        role: Nest,
        /// Fanuc's loop number, if any.
        tag: u32,
    },
    /// Flow the reader cannot follow: TCPM is unknown in the whole file.
    Opaque,
}

impl Stmt {
    /// Whether the statement needs the whole file's flow to settle the state (anything but
    /// a call of code that is certainly outside the file).
    pub(crate) fn is_global(&self) -> bool {
        // A call of code outside the file acts on the block after it only; a label only
        // matters where something jumps or calls (which is global itself): a Fanuc
        // program's `O1000` line alone is read once.
        !matches!(self, Stmt::External | Stmt::ToolChange | Stmt::Label(_))
    }
}

/// One recorded event, in file order.
#[derive(Debug, Clone, PartialEq)]
enum Kind {
    /// The program's start (line 1).
    Start,
    Switch {
        to: Tcpm,
        skippable: bool,
    },
    End,
    Label(Key),
    /// LinuxCNC `sub`: in file order, flow goes to after the matching `endsub`.
    SubSkip(Key),
    /// The first block of a LinuxCNC subroutine (reached by calls only).
    SubBody(Key),
    SubEnd(Key),
    /// The block after a LinuxCNC `endsub`: where flow in file order goes on.
    AfterSub(Key),
    Return {
        falls_through: bool,
    },
    Call {
        key: Key,
        repeats: bool,
    },
    /// The block after a call: where its returns arrive.
    AfterCall,
    External,
    ToolChange,
    Jump {
        key: Key,
        cond: bool,
    },
    Group(Key),
}

#[derive(Debug, Clone)]
struct Node {
    /// The line before whose block the node's in-state holds.
    line: u32,
    kind: Kind,
}

/// Records the flow events of a read ([`crate::program`] feeds it block by block, in file
/// order) and solves them into a [`FlowPlan`].
#[derive(Debug, Default)]
pub(crate) struct Recorder {
    nodes: Vec<Node>,
    /// A statement that needs the whole file's flow was seen.
    pub(crate) global: bool,
    /// Flow that cannot be followed was seen.
    opaque: bool,
    /// Block numbers that jumps and calls name.
    pub(crate) block_targets: HashSet<u64>,
    /// Block numbers to record as labels (the second pass, once the targets are known).
    label_blocks: Option<HashSet<u64>>,
    /// Open nested statements: (group number, Fanuc tag).
    stack: Vec<(u32, u32)>,
    next_group: u32,
}

/// What one block gives the recorder.
pub(crate) struct BlockFlow<'a> {
    pub(crate) line: usize,
    pub(crate) stmt: Option<&'a Stmt>,
    pub(crate) switch: Option<Tcpm>,
    pub(crate) skippable: bool,
    pub(crate) program_end: bool,
    /// The block's number (`N…`), if it has one.
    pub(crate) number: Option<u64>,
}

impl Recorder {
    /// A recorder for a second pass that also records blocks numbered `targets` as labels.
    pub(crate) fn with_block_labels(targets: HashSet<u64>) -> Self {
        Recorder {
            label_blocks: Some(targets),
            ..Recorder::default()
        }
    }

    fn push(&mut self, line: usize, kind: Kind) {
        let line = u32::try_from(line).unwrap_or(u32::MAX);
        self.nodes.push(Node { line, kind });
    }

    /// Take one block.
    pub(crate) fn block(&mut self, b: &BlockFlow<'_>) {
        if self.nodes.is_empty() {
            self.push(1, Kind::Start);
        }
        let line = b.line;
        if let (Some(n), Some(labels)) = (b.number, &self.label_blocks)
            && labels.contains(&n)
        {
            self.push(line, Kind::Label(Key::Block(n)));
        }
        // Labels first: the block's own switch applies after the ways in meet.
        match b.stmt {
            Some(Stmt::Label(k)) => self.push(line, Kind::Label(k.clone())),
            Some(Stmt::Group(k)) => self.push(line, Kind::Group(k.clone())),
            Some(Stmt::Nested { role, tag }) => {
                let group = match role {
                    Nest::Open => {
                        self.next_group += 1;
                        self.stack.push((self.next_group, *tag));
                        Some(self.next_group)
                    }
                    Nest::Middle => self.stack.last().map(|&(g, _)| g),
                    Nest::Close => {
                        let at = self.stack.iter().rposition(|&(_, t)| t == *tag);
                        at.map(|k| self.stack.drain(k..).next().map_or(0, |(g, _)| g))
                    }
                };
                match group {
                    Some(g) => self.push(line, Kind::Group(Key::Group(format!("#{g}")))),
                    // A closing keyword without its opening: not followed.
                    None => self.opaque = true,
                }
            }
            Some(Stmt::SubStart(k)) => {
                self.push(line, Kind::SubSkip(k.clone()));
                self.push(line + 1, Kind::SubBody(k.clone()));
            }
            _ => {}
        }
        if let Some(to) = b.switch {
            self.push(
                line,
                Kind::Switch {
                    to,
                    skippable: b.skippable,
                },
            );
        }
        match b.stmt {
            Some(Stmt::SubEnd(k)) => {
                self.push(line, Kind::SubEnd(k.clone()));
                self.push(line + 1, Kind::AfterSub(k.clone()));
            }
            Some(Stmt::Return { falls_through }) => self.push(
                line,
                Kind::Return {
                    falls_through: *falls_through,
                },
            ),
            Some(Stmt::Call { key, repeats }) => {
                if let Key::Block(n) = key {
                    self.block_targets.insert(*n);
                }
                self.push(
                    line,
                    Kind::Call {
                        key: key.clone(),
                        repeats: *repeats,
                    },
                );
                self.push(line + 1, Kind::AfterCall);
            }
            Some(Stmt::External) => self.push(line, Kind::External),
            Some(Stmt::ToolChange) => self.push(line, Kind::ToolChange),
            Some(Stmt::Jump { key, cond }) => {
                if let Key::Block(n) = key {
                    self.block_targets.insert(*n);
                }
                self.push(
                    line,
                    Kind::Jump {
                        key: key.clone(),
                        cond: *cond,
                    },
                );
            }
            Some(Stmt::Opaque) => self.opaque = true,
            _ => {}
        }
        if let Some(s) = b.stmt
            && s.is_global()
        {
            self.global = true;
        }
        if b.program_end {
            self.push(line, Kind::End);
        }
    }

    /// Whether this pass records numbered blocks as labels.
    pub(crate) fn wants_block_labels(&self) -> bool {
        self.label_blocks.is_some()
    }

    /// Whether a second pass must find the blocks that jumps name by number.
    pub(crate) fn needs_block_labels(&self) -> bool {
        self.label_blocks.is_none() && !self.block_targets.is_empty() && !self.opaque
    }

    /// Solve the recorded flow from the state `initial` (module docs).
    pub(crate) fn solve(&self, initial: Tcpm) -> FlowPlan {
        let unknown_everywhere = FlowPlan {
            entries: Vec::new(),
            all_unknown: true,
        };
        if self.opaque {
            return unknown_everywhere;
        }
        let Some(edges) = Edges::new(&self.nodes) else {
            // A jump to a label the file does not hold: control may go anywhere.
            return unknown_everywhere;
        };
        let state = self.propagate(&edges, initial);
        self.plan(&state)
    }

    /// The state before every node: the data-flow problem of the module docs solved by a
    /// worklist from `initial` at the first node (`None`: no way in).
    fn propagate(&self, edges: &Edges<'_>, initial: Tcpm) -> Vec<Option<Tcpm>> {
        let mut w = Worklist {
            state: vec![None; self.nodes.len()],
            work: Vec::new(),
        };
        w.send(0, initial);
        while let Some(i) = w.work.pop() {
            let Some(s) = w.state[i] else { continue };
            self.send_on(i, s, edges, &mut w);
        }
        w.state
    }

    /// Send the state `s` before node `i` along the node's edges (module docs).
    fn send_on(&self, i: usize, s: Tcpm, edges: &Edges<'_>, w: &mut Worklist) {
        let nodes = &self.nodes;
        let labels = &edges.labels;
        let next = i + 1;
        match &nodes[i].kind {
            Kind::Start
            | Kind::Label(_)
            | Kind::SubBody(_)
            | Kind::AfterCall
            | Kind::AfterSub(_) => w.send(next, s),
            Kind::Switch { to, skippable } => w.send(next, s.switched(*to, *skippable)),
            Kind::End => {}
            Kind::Group(k) => {
                w.send(next, s);
                for &j in &labels[k] {
                    w.send(j, s);
                }
            }
            Kind::SubSkip(k) => {
                // In file order the definition is skipped (one without its end: what
                // follows it is not reached in order).
                let after = Kind::AfterSub(k.clone());
                if let Some(p) = nodes[next..].iter().position(|nd| nd.kind == after) {
                    w.send(next + p, s);
                }
            }
            Kind::SubEnd(_) | Kind::Return { .. } => self.send_return(i, s, edges, w),
            Kind::Call { key, .. } => match labels.get(key) {
                Some(entries) => {
                    for &j in entries {
                        w.send(j, s);
                    }
                }
                // Nothing of that name in the file: code outside it.
                None => w.send(next, Tcpm::Unknown),
            },
            Kind::External => w.send(next, Tcpm::Unknown),
            Kind::ToolChange => w.send(next, s.after_tool_change()),
            Kind::Jump { key, cond } => {
                for &j in &labels[key] {
                    w.send(j, s);
                }
                if *cond {
                    w.send(next, s);
                }
            }
        }
    }

    /// Send the state `s` before the return (or `endsub`) node `i` back to the block after
    /// every call of its subprogram (and to its start again for a repeated call).
    fn send_return(&self, i: usize, s: Tcpm, edges: &Edges<'_>, w: &mut Worklist) {
        let nodes = &self.nodes;
        let next = i + 1;
        let falls = matches!(
            nodes[i].kind,
            Kind::Return {
                falls_through: true
            }
        );
        match edges.owner[i] {
            Some(k) => {
                for &c in edges.calls.get(k).map_or(&[][..], Vec::as_slice) {
                    w.send(c + 1, s);
                    if matches!(nodes[c].kind, Kind::Call { repeats: true, .. }) {
                        for &j in &edges.labels[k] {
                            w.send(j, s);
                        }
                    }
                }
                if falls {
                    w.send(next, s);
                }
            }
            // A return where no call is active: Heidenhain's label 0 goes on;
            // Fanuc's M99 in the main program starts it again.
            None if falls => w.send(next, s),
            None => w.send(0, s),
        }
    }

    /// The plan: every node's state before its line (⊥, no way in: unknown), and after a
    /// node that does not fall through, the state of the lines up to the next node.
    fn plan(&self, state: &[Option<Tcpm>]) -> FlowPlan {
        let nodes = &self.nodes;
        let mut entries = Vec::with_capacity(2 * nodes.len());
        for (i, node) in nodes.iter().enumerate() {
            let join = matches!(
                node.kind,
                Kind::Label(_) | Kind::SubBody(_) | Kind::Group(_)
            );
            entries.push(Entry {
                line: node.line,
                tcpm: state[i].unwrap_or(Tcpm::Unknown),
                join,
            });
            let stops = match &node.kind {
                Kind::End | Kind::SubSkip(_) => true,
                Kind::Jump { cond, .. } => !cond,
                Kind::Return { falls_through } => !falls_through,
                Kind::SubEnd(_) => true,
                _ => false,
            };
            if stops {
                // Reached by no way until the next node (whose own entry, at the same
                // line or later, comes after this one).
                entries.push(Entry {
                    line: node.line.saturating_add(1),
                    tcpm: Tcpm::Unknown,
                    join: false,
                });
            }
        }
        // In line order; at one line, in node order (the last one read wins).
        entries.sort_by_key(|e| e.line);
        FlowPlan {
            entries,
            all_unknown: false,
        }
    }
}

/// Where the recorded nodes lead besides the next one (module docs): the nodes of each
/// label, the calls of each called label, and the called label each return belongs to.
struct Edges<'a> {
    /// The label, subroutine-body and group nodes of each key.
    labels: HashMap<&'a Key, Vec<usize>>,
    /// The call nodes of each key the file holds.
    calls: HashMap<&'a Key, Vec<usize>>,
    /// The owner (called label) of every return and `endsub` node.
    owner: Vec<Option<&'a Key>>,
}

impl<'a> Edges<'a> {
    /// The edges of `nodes`; `None` when a jump names a label the file does not hold.
    fn new(nodes: &'a [Node]) -> Option<Self> {
        let mut labels: HashMap<&Key, Vec<usize>> = HashMap::new();
        for (i, node) in nodes.iter().enumerate() {
            match &node.kind {
                Kind::Label(k) | Kind::SubBody(k) | Kind::Group(k) => {
                    labels.entry(k).or_default().push(i)
                }
                _ => {}
            }
        }
        let unresolved = nodes.iter().any(|node| match &node.kind {
            Kind::Jump { key, .. } => !labels.contains_key(key),
            _ => false,
        });
        if unresolved {
            return None;
        }
        // Calls per called key, and the owner (called label) of every return.
        let mut calls: HashMap<&Key, Vec<usize>> = HashMap::new();
        for (i, node) in nodes.iter().enumerate() {
            if let Kind::Call { key, .. } = &node.kind
                && labels.contains_key(key)
            {
                calls.entry(key).or_default().push(i);
            }
        }
        let mut owner: Vec<Option<&Key>> = vec![None; nodes.len()];
        let mut current: Option<&Key> = None;
        for (i, node) in nodes.iter().enumerate() {
            match &node.kind {
                Kind::Label(k) | Kind::SubBody(k) if calls.contains_key(k) => current = Some(k),
                Kind::Return { .. } => owner[i] = current,
                Kind::SubEnd(k) => owner[i] = Some(k),
                _ => {}
            }
        }
        Some(Edges {
            labels,
            calls,
            owner,
        })
    }
}

/// The states of the nodes as the solution grows, and the nodes whose state changed.
struct Worklist {
    state: Vec<Option<Tcpm>>,
    work: Vec<usize>,
}

impl Worklist {
    /// Join `t` into the state of node `to` (past the last node: nothing); a change puts
    /// `to` on the list.
    fn send(&mut self, to: usize, t: Tcpm) {
        if to >= self.state.len() {
            return;
        }
        let joined = self.state[to].map_or(t, |s| s.join(t));
        if self.state[to] != Some(joined) {
            self.state[to] = Some(joined);
            self.work.push(to);
        }
    }
}

/// One entry of a [`FlowPlan`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Entry {
    line: u32,
    tcpm: Tcpm,
    /// Ways in meet here: positions are unknown.
    join: bool,
}

/// How program flow settles the TCPM state of a file (module docs): the state to take
/// before given lines. Made by the reader ([`crate::Settled::Again`]) and handed back to it
/// in [`crate::ReadOptions::flow`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FlowPlan {
    entries: Vec<Entry>,
    /// Flow the reader cannot follow: TCPM is unknown everywhere.
    all_unknown: bool,
}

impl FlowPlan {
    /// The plan of a file without flow that joins paths: nothing to change.
    pub fn none() -> Self {
        FlowPlan {
            entries: Vec::new(),
            all_unknown: false,
        }
    }

    /// Whether TCPM is unknown in the whole file (flow the reader cannot follow).
    pub fn all_unknown(&self) -> bool {
        self.all_unknown
    }
}

/// The reader's place in a [`FlowPlan`] (lines come in increasing order).
#[derive(Debug, Clone, Default)]
pub(crate) struct Cursor {
    next: usize,
}

impl Cursor {
    /// What the plan says before the block on `line`: the TCPM state to take (if any) and
    /// whether ways in meet there.
    pub(crate) fn at(&mut self, plan: &FlowPlan, line: usize) -> (Option<Tcpm>, bool) {
        if plan.all_unknown {
            return (Some(Tcpm::Unknown), false);
        }
        let line = u32::try_from(line).unwrap_or(u32::MAX);
        let e = &plan.entries;
        while self.next < e.len() && e[self.next].line < line {
            self.next += 1;
        }
        let mut out = (None, false);
        while self.next < e.len() && e[self.next].line == line {
            out.0 = Some(e[self.next].tcpm);
            out.1 |= e[self.next].join;
            self.next += 1;
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rec(blocks: &[(usize, Option<Stmt>, Option<Tcpm>, bool)]) -> Recorder {
        let mut r = Recorder::default();
        for (line, stmt, switch, end) in blocks {
            r.block(&BlockFlow {
                line: *line,
                stmt: stmt.as_ref(),
                switch: *switch,
                skippable: false,
                program_end: *end,
                number: None,
            });
        }
        r
    }

    fn at(plan: &FlowPlan, line: usize) -> Option<Tcpm> {
        Cursor::default().at(plan, line).0
    }

    #[test]
    fn a_call_is_settled_by_its_subprogram() {
        // 2 TCPM on, 3 call 2000, 4 the zone, 5 M30; 6 O2000, 7 off, 8 M99.
        let call = Stmt::Call {
            key: Key::Program(2000),
            repeats: false,
        };
        let r = rec(&[
            (2, None, Some(Tcpm::On), false),
            (3, Some(call.clone()), None, false),
            (5, None, Some(Tcpm::Off), true),
            (6, Some(Stmt::Label(Key::Program(2000))), None, false),
            (7, None, Some(Tcpm::Off), false),
            (
                8,
                Some(Stmt::Return {
                    falls_through: false,
                }),
                None,
                false,
            ),
        ]);
        assert!(r.global);
        let plan = r.solve(Tcpm::Off);
        assert_eq!(at(&plan, 4), Some(Tcpm::Off), "the subprogram ends TCPM");
        assert_eq!(at(&plan, 6), Some(Tcpm::On), "called with it on");
        // Without the G49 in the subprogram: on after the call.
        let r = rec(&[
            (2, None, Some(Tcpm::On), false),
            (3, Some(call), None, false),
            (5, None, Some(Tcpm::Off), true),
            (6, Some(Stmt::Label(Key::Program(2000))), None, false),
            (
                8,
                Some(Stmt::Return {
                    falls_through: false,
                }),
                None,
                false,
            ),
        ]);
        assert_eq!(at(&r.solve(Tcpm::Off), 4), Some(Tcpm::On));
    }

    #[test]
    fn a_call_of_code_outside_the_file_is_unknown() {
        let r = rec(&[
            (2, None, Some(Tcpm::On), false),
            (
                3,
                Some(Stmt::Call {
                    key: Key::Program(9001),
                    repeats: false,
                }),
                None,
                false,
            ),
        ]);
        assert_eq!(at(&r.solve(Tcpm::Off), 4), Some(Tcpm::Unknown));
    }

    #[test]
    fn a_jump_over_a_switch_joins_two_states() {
        let r = rec(&[
            (
                2,
                Some(Stmt::Jump {
                    key: Key::Block(100),
                    cond: true,
                }),
                None,
                false,
            ),
            (3, None, Some(Tcpm::On), false),
        ]);
        assert!(r.needs_block_labels());
        let mut r2 = Recorder::with_block_labels(r.block_targets.clone());
        for (line, stmt, switch, number) in [
            (
                2,
                Some(Stmt::Jump {
                    key: Key::Block(100),
                    cond: true,
                }),
                None,
                None,
            ),
            (3, None, Some(Tcpm::On), None),
            (4, None, None, Some(100)),
        ] {
            r2.block(&BlockFlow {
                line,
                stmt: stmt.as_ref(),
                switch,
                skippable: false,
                program_end: false,
                number,
            });
        }
        let plan = r2.solve(Tcpm::Off);
        assert_eq!(Cursor::default().at(&plan, 4), (Some(Tcpm::Unknown), true));
        // Unconditional: the switch is never reached; the target has the jump's state.
        let r = rec(&[
            (
                2,
                Some(Stmt::Jump {
                    key: Key::Label("SKIP".into()),
                    cond: false,
                }),
                None,
                false,
            ),
            (3, None, Some(Tcpm::On), false),
            (4, Some(Stmt::Label(Key::Label("SKIP".into()))), None, false),
        ]);
        let plan = r.solve(Tcpm::Off);
        assert_eq!(at(&plan, 4), Some(Tcpm::Off));
        assert_eq!(at(&plan, 3), Some(Tcpm::Unknown), "not reached");
    }

    #[test]
    fn loops_and_unfollowable_flow() {
        // A switch inside a loop body: the loop's keywords join before and after.
        let open = Stmt::Nested {
            role: Nest::Open,
            tag: 0,
        };
        let close = Stmt::Nested {
            role: Nest::Close,
            tag: 0,
        };
        let r = rec(&[
            (2, None, Some(Tcpm::On), false),
            (3, Some(open), None, false),
            (4, None, Some(Tcpm::Off), false),
            (5, Some(close), None, false),
        ]);
        let plan = r.solve(Tcpm::Off);
        assert_eq!(at(&plan, 3), Some(Tcpm::Unknown));
        assert_eq!(at(&plan, 5), Some(Tcpm::Unknown));
        // A jump to a label that is not in the file, or a computed one: unknown everywhere.
        let r = rec(&[(
            2,
            Some(Stmt::Jump {
                key: Key::Label("NOWHERE".into()),
                cond: true,
            }),
            None,
            false,
        )]);
        assert!(r.solve(Tcpm::Off).all_unknown());
        assert!(
            rec(&[(2, Some(Stmt::Opaque), None, false)])
                .solve(Tcpm::On)
                .all_unknown()
        );
    }

    #[test]
    fn linuxcnc_subroutines_are_skipped_in_file_order() {
        let k = Key::Label("O200".into());
        let r = rec(&[
            (1, Some(Stmt::SubStart(k.clone())), None, false),
            (2, None, Some(Tcpm::Off), false),
            (3, Some(Stmt::SubEnd(k.clone())), None, false),
            (4, None, Some(Tcpm::On), false),
            (
                5,
                Some(Stmt::Call {
                    key: k,
                    repeats: false,
                }),
                None,
                false,
            ),
        ]);
        let plan = r.solve(Tcpm::Off);
        assert_eq!(at(&plan, 2), Some(Tcpm::On), "the body runs when called");
        assert_eq!(at(&plan, 6), Some(Tcpm::Off), "after the call");
        assert_eq!(at(&plan, 4), Some(Tcpm::Off), "the definition is skipped");
    }
}
