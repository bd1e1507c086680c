//! haltcl files: `[HAL] HALFILE = NAME.tcl`, which LinuxCNC runs with `haltcl` (a Tcl
//! interpreter with the HAL commands) instead of `halcmd`.
//!
//! polepatch does not run Tcl. It reads the commands a kinematics configuration writes
//! (LinuxCNC's `docs/src/hal/haltcl.adoc`):
//!
//! - `setp PIN VALUE`, `sets SIGNAL VALUE` (also as `hal setp …`): haltcl's `setp` and
//!   `sets` take exactly a pin and a value and pass the value through Tcl's `expr`; a value
//!   that is a number is read, any other (`6.28/360*$x`) is a Tcl expression: not known.
//! - `net SIGNAL PIN…`, `linksp`, `linkps`: the nets.
//! - INI values as haltcl gives them: `$::SECTION(KEY)` (a key given once, a value
//!   without blanks or Tcl's special characters) and `[lindex $::SECTION(KEY) 0]`.
//! - Words in braces (`{1}`, no substitution) and plain words.
//! - Commands that set no value: `loadrt`, `loadusr`, `addf`, `delf`, `start`, `stop`,
//!   `waitusr`, `newsig`, `puts`, `show`, `package`, `getp`, `ptype`, `stype`, `help`,
//!   `status`, `lock`, `unlock`, `save`, `hal list`, `hal gets`, and `set NAME VALUE` of a
//!   plain Tcl variable (using it later is a variable, not read).
//! - Comments: `#` where a command begins (also after `;`); `\` at a line's end continues
//!   it.
//!
//! Anything else — a Tcl variable or command substitution in a pin's or a signal's name,
//! a loop, a condition, a procedure, `source`, `eval`, `alias`, a command polepatch does
//! not know — could set any pin: it is recorded with its file, line and column and its
//! form ([`Hal::opaque`]), and a kinematics parameter read after it says so instead of
//! taking a value. A value that is not known (a Tcl expression, a variable) makes only its
//! own pin or signal unknown.

use crate::hal::{Hal, Value};
use crate::ini::Ini;
use std::ops::Range;

/// One word of a Tcl command: its text as written (without the braces or quotes that
/// delimit it), how it is delimited, and its 1-based line and column.
#[derive(Debug, Clone, PartialEq)]
struct Word {
    text: String,
    kind: Kind,
    line: usize,
    column: usize,
}

/// How a word is delimited (Tcl's rules of substitution differ).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind {
    /// Plain: `$` and `[…]` are substituted.
    Bare,
    /// `{…}`: taken as written.
    Braced,
    /// `"…"`: `$` and `[…]` are substituted.
    Quoted,
}

/// A command: its words, or why the text could not be split into words (at a line and
/// column).
type Command = Result<Vec<Word>, (usize, usize, String)>;

/// The commands of a Tcl script, in order (module docs: comments, continuation lines,
/// braces, quotes and brackets as Tcl groups them).
fn commands(text: &str) -> Vec<Command> {
    let mut sc = Scanner {
        text,
        b: text.as_bytes(),
        i: 0,
        line: 1,
        line_start: 0,
    };
    let mut out = Vec::new();
    while sc.i < sc.b.len() {
        if sc.skip_separator() {
            continue;
        }
        if sc.b[sc.i] == b'#' {
            sc.skip_comment();
            continue;
        }
        match sc.command() {
            Err(e) => {
                out.push(Err(e));
                break;
            }
            Ok(words) if words.is_empty() => {}
            Ok(words) => out.push(Ok(words)),
        }
    }
    out
}

/// A place in a Tcl script as [`commands`] splits it: the byte `i`, its 1-based line and
/// where that line starts.
struct Scanner<'t> {
    text: &'t str,
    b: &'t [u8],
    i: usize,
    line: usize,
    line_start: usize,
}

impl Scanner<'_> {
    /// Advance over byte `k` (a newline starts a line).
    fn step(&mut self, k: usize) {
        if self.b[k] == b'\n' {
            self.line += 1;
            self.line_start = k + 1;
        }
    }

    /// Between commands: a blank, a newline, `;` or a continued line, passed over (`false`
    /// if there is none at `i`).
    fn skip_separator(&mut self) -> bool {
        let (b, i) = (self.b, self.i);
        if matches!(b[i], b' ' | b'\t' | b'\r' | b'\n' | b';') {
            self.step(i);
            self.i += 1;
            return true;
        }
        if b[i] == b'\\' && b.get(i + 1) == Some(&b'\n') {
            self.step(i + 1);
            self.i += 2;
            return true;
        }
        false
    }

    /// A comment runs to the end of its line (a `\` before the newline continues it).
    fn skip_comment(&mut self) {
        let b = self.b;
        while self.i < b.len() && b[self.i] != b'\n' {
            if b[self.i] == b'\\' && b.get(self.i + 1) == Some(&b'\n') {
                self.step(self.i + 1);
                self.i += 1;
            }
            self.i += 1;
        }
    }

    /// A command: words up to a newline or `;` outside any grouping.
    fn command(&mut self) -> Command {
        let b = self.b;
        let mut words = Vec::new();
        loop {
            while self.i < b.len() && matches!(b[self.i], b' ' | b'\t' | b'\r') {
                self.i += 1;
            }
            if self.i + 1 < b.len() && b[self.i] == b'\\' && b[self.i + 1] == b'\n' {
                self.step(self.i + 1);
                self.i += 2;
                continue;
            }
            if self.i >= b.len() || b[self.i] == b'\n' || b[self.i] == b';' {
                break;
            }
            let (wl, wc) = (self.line, self.i - self.line_start + 1);
            let word = match b[self.i] {
                b'{' => self.braced(),
                b'"' => self.quoted(),
                _ => self.bare(),
            };
            let (kind, body) = word.map_err(|what| (wl, wc, what.to_string()))?;
            words.push(Word {
                text: self.text[body].to_string(),
                kind,
                line: wl,
                column: wc,
            });
        }
        Ok(words)
    }

    /// A word in braces from `i` (at its `{`), nested braces counted: its text inside them.
    fn braced(&mut self) -> Result<(Kind, Range<usize>), &'static str> {
        let b = self.b;
        let start = self.i;
        let mut depth = 0usize;
        while self.i < b.len() {
            self.step(self.i);
            match b[self.i] {
                b'\\' => {
                    if self.i + 1 < b.len() {
                        self.step(self.i + 1);
                    }
                    self.i += 1;
                }
                b'{' => depth += 1,
                b'}' => {
                    depth -= 1;
                    if depth == 0 {
                        let end = self.i;
                        self.i += 1;
                        return Ok((Kind::Braced, start + 1..end));
                    }
                }
                _ => {}
            }
            self.i += 1;
        }
        Err("an open brace '{' never closed")
    }

    /// A word in quotes from `i` (at its `"`), brackets inside counted: its text inside
    /// them.
    fn quoted(&mut self) -> Result<(Kind, Range<usize>), &'static str> {
        let b = self.b;
        let start = self.i;
        self.i += 1;
        let mut brackets = 0usize;
        while self.i < b.len() {
            self.step(self.i);
            match b[self.i] {
                b'\\' => {
                    if self.i + 1 < b.len() {
                        self.step(self.i + 1);
                    }
                    self.i += 1;
                }
                b'[' => brackets += 1,
                b']' => brackets = brackets.saturating_sub(1),
                b'"' if brackets == 0 => {
                    let end = self.i;
                    self.i += 1;
                    return Ok((Kind::Quoted, start + 1..end));
                }
                _ => {}
            }
            self.i += 1;
        }
        Err("an open quote '\"' never closed")
    }

    /// A plain word from `i`: up to a blank, a newline or `;` outside brackets (and braces
    /// inside them), which group across blanks.
    fn bare(&mut self) -> Result<(Kind, Range<usize>), &'static str> {
        let b = self.b;
        let start = self.i;
        let (mut brackets, mut braces) = (0usize, 0usize);
        while self.i < b.len() {
            let c = b[self.i];
            if brackets == 0 && braces == 0 && matches!(c, b' ' | b'\t' | b'\r' | b'\n' | b';') {
                break;
            }
            self.step(self.i);
            match c {
                b'\\' => {
                    if self.i + 1 < b.len() {
                        self.step(self.i + 1);
                    }
                    self.i += 1;
                }
                b'[' if braces == 0 => brackets += 1,
                b']' if braces == 0 => brackets = brackets.saturating_sub(1),
                b'{' if brackets > 0 => braces += 1,
                b'}' if brackets > 0 => braces = braces.saturating_sub(1),
                _ => {}
            }
            self.i += 1;
        }
        if brackets > 0 {
            return Err("an open bracket '[' never closed");
        }
        Ok((Kind::Bare, start..self.i))
    }
}

/// Tcl's special characters: a word holding one is not plain text.
fn special(text: &str) -> bool {
    text.contains(['$', '[', ']', '\\', '{', '}', '"'])
}

/// A word's value, or the form it is (for a message).
fn resolve(w: &Word, ini: &Ini) -> Result<String, String> {
    let t = w.text.as_str();
    match w.kind {
        Kind::Braced => return Ok(t.to_string()),
        Kind::Quoted if !special(t) => return Ok(t.to_string()),
        Kind::Bare if !special(t) => return Ok(t.to_string()),
        _ => {}
    }
    let inner = |s: &str| -> Option<(String, String)> {
        let s = s.strip_prefix("::")?;
        let (section, rest) = s.split_once('(')?;
        let key = rest.strip_suffix(')')?;
        (!special(section) && !special(key)).then(|| (section.to_string(), key.to_string()))
    };
    let var = t
        .strip_prefix("${")
        .and_then(|s| s.strip_suffix('}'))
        .or_else(|| t.strip_prefix('$'))
        .and_then(inner);
    let lindex = t
        .strip_prefix('[')
        .and_then(|s| s.strip_suffix(']'))
        .and_then(|s| {
            let words: Vec<&str> = s.split_whitespace().collect();
            match words.as_slice() {
                ["lindex", v, "0"] => v.strip_prefix('$').and_then(inner),
                _ => None,
            }
        });
    if w.kind == Kind::Bare
        && let Some((section, key)) = var.clone().or(lindex.clone())
    {
        let values: Vec<&str> = ini.all(&section, &key).collect();
        let name = format!("$::{section}({key})");
        return match values.as_slice() {
            [] => Err(format!(
                "{name}, which the INI does not have (haltcl stops there)"
            )),
            [first, ..] if lindex.is_some() => Ok(first.to_string()),
            [one] if !special(one) && !one.contains(char::is_whitespace) => Ok(one.to_string()),
            [_] => Err(format!(
                "{name}, whose value Tcl reads as a list (write [lindex {name} 0])"
            )),
            many => Err(format!("{name}, a list of {} values", many.len())),
        };
    }
    Err(if t.starts_with('[') || t.contains('[') {
        format!("'{t}', a Tcl command substitution")
    } else if t.contains('$') {
        format!("'{t}', a Tcl variable")
    } else {
        format!("'{t}', a Tcl form polepatch does not read")
    })
}

/// Commands that set no HAL value (module docs).
const PASSIVE: &[&str] = &[
    "loadrt", "loadusr", "addf", "delf", "start", "stop", "waitusr", "newsig", "puts", "show",
    "package", "getp", "ptype", "stype", "help", "status", "lock", "unlock", "save", "list",
    "gets",
];

/// What a command polepatch does not follow is, for a message.
fn form_of(cmd: &str) -> String {
    match cmd {
        "for" | "foreach" | "while" => format!("a Tcl loop ({cmd})"),
        "if" | "switch" => format!("a Tcl condition ({cmd})"),
        "proc" => "a Tcl procedure (proc)".into(),
        "source" | "eval" | "uplevel" | "catch" => format!("'{cmd}', which runs other Tcl code"),
        "set" => "set of a global or array variable (an INI value changed)".into(),
        "alias" | "unalias" | "unlinkp" | "delsig" => {
            format!("'{cmd}', which renames or unlinks pins and signals")
        }
        _ => format!("the command '{cmd}', which polepatch does not follow"),
    }
}

/// Reads a haltcl file's text into `hal`; `name` names the file in messages
/// (`NAME:LINE:COLUMN: …`).
pub(crate) fn read(text: &str, name: &str, ini: &Ini, hal: &mut Hal) {
    let at = |w: &Word| format!("{name}:{}:{}", w.line, w.column);
    for cmd in commands(text) {
        let words = match cmd {
            Ok(words) => words,
            Err((line, column, what)) => {
                hal.opaque(format!("{name}:{line}:{column}: {what}"));
                return;
            }
        };
        let mut words = words.as_slice();
        if words.len() > 1 && words[0].kind == Kind::Bare && words[0].text == "hal" {
            words = &words[1..];
        }
        let head = &words[0];
        let cmd = match resolve(head, ini) {
            Ok(c) if head.kind == Kind::Bare => c,
            Ok(_) | Err(_) => {
                hal.opaque(format!(
                    "{}: a command named by '{}', which polepatch does not follow",
                    at(head),
                    head.text
                ));
                continue;
            }
        };
        let args = &words[1..];
        match cmd.as_str() {
            "setp" | "sets" => {
                let [target, value] = args else {
                    hal.opaque(format!(
                        "{}: {cmd} with {} arguments (haltcl's {cmd} takes a name and a value)",
                        at(head),
                        args.len()
                    ));
                    continue;
                };
                let target_name = match resolve(target, ini) {
                    Ok(t) => t,
                    Err(form) => {
                        hal.opaque(format!("{}: {cmd} of {form}", at(target)));
                        continue;
                    }
                };
                // haltcl's setp and sets take the value through `expr`.
                let v: Value = match resolve(value, ini) {
                    Ok(v) if v.trim().parse::<f64>().is_ok() => Ok(v.trim().to_string()),
                    Ok(v) => Err(format!(
                        "{}: '{v}' is a Tcl expression (haltcl's {cmd} evaluates it with expr), \
                         which polepatch does not evaluate",
                        at(value)
                    )),
                    Err(form) => Err(format!(
                        "{}: {form}, which polepatch does not evaluate",
                        at(value)
                    )),
                };
                if cmd == "setp" {
                    hal.setp(&target_name, v);
                } else {
                    hal.sets(&target_name, v);
                }
            }
            "net" | "linksp" | "linkps" => {
                let mut resolved = Vec::with_capacity(args.len());
                for w in args {
                    match resolve(w, ini) {
                        Ok(t) => resolved.push(t),
                        Err(form) => {
                            hal.opaque(format!("{}: {cmd} with {form}", at(w)));
                            break;
                        }
                    }
                }
                if resolved.len() == args.len() {
                    hal.command(&cmd, &resolved, |v| Ok(v.to_string()));
                }
            }
            c if PASSIVE.contains(&c) => {}
            "set"
                if args.first().is_some_and(|v| {
                    v.kind == Kind::Bare
                        && !special(&v.text)
                        && !v.text.contains("::")
                        && !v.text.contains('(')
                }) => {}
            other => hal.opaque(format!("{}: {}", at(head), form_of(other))),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ini() -> Ini {
        Ini::parse(
            "[KINS]\nKINEMATICS = xyzac-trt-kins\nPIVOT = 150\nTWICE = 1\nTWICE = 2\n\
             SPACED = a b\n",
            "t.ini",
        )
        .unwrap()
    }

    fn words(text: &str) -> Vec<Vec<(String, Kind, usize, usize)>> {
        commands(text)
            .into_iter()
            .map(|c| {
                c.unwrap()
                    .into_iter()
                    .map(|w| (w.text, w.kind, w.line, w.column))
                    .collect()
            })
            .collect()
    }

    #[test]
    fn commands_split_as_tcl_splits_them() {
        let text = "# a comment \\\n still the comment\nsetp a.b 1 ;# trailing\n\
                    setp a.c {2} ; sets :s \"3\"\n\
                    loadrt m base=[expr {500000000 / 2}] \\\n   x=1\n";
        let w = words(text);
        let b = Kind::Bare;
        assert_eq!(
            w,
            vec![
                vec![
                    ("setp".into(), b, 3, 1),
                    ("a.b".into(), b, 3, 6),
                    ("1".into(), b, 3, 10)
                ],
                vec![
                    ("setp".into(), b, 4, 1),
                    ("a.c".into(), b, 4, 6),
                    ("2".into(), Kind::Braced, 4, 10)
                ],
                vec![
                    ("sets".into(), b, 4, 16),
                    (":s".into(), b, 4, 21),
                    ("3".into(), Kind::Quoted, 4, 24)
                ],
                vec![
                    ("loadrt".into(), b, 5, 1),
                    ("m".into(), b, 5, 8),
                    ("base=[expr {500000000 / 2}]".into(), b, 5, 10),
                    ("x=1".into(), b, 6, 4)
                ],
            ]
        );
        let broken = commands("setp a {1\n");
        assert_eq!(
            broken.last().unwrap().clone().unwrap_err(),
            (1, 8, "an open brace '{' never closed".to_string())
        );
    }

    fn read_str(text: &str) -> Hal {
        let mut hal = Hal::default();
        read(text, "k.tcl", &ini(), &mut hal);
        hal
    }

    #[test]
    fn the_forms_kinematics_configs_write_are_read() {
        let hal = read_str(
            "# kinematics parameters\n\
             loadrt $::KINS(KINEMATICS)\n\
             setp xyzac-trt-kins.conventional-directions 1\n\
             hal setp xyzac-trt-kins.x-rot-point -12.5\n\
             setp xyzac-trt-kins.y-rot-point $::KINS(PIVOT)\n\
             setp xyzac-trt-kins.z-rot-point [lindex $::KINS(TWICE) 0]\n\
             setp xyzac-trt-kins.y-offset {7}\n\
             set gain 3\n\
             net :z-off xyzac-trt-kins.z-offset\n\
             sets :z-off ${::KINS(PIVOT)}\n\
             puts \"kinematics set\"\n\
             hal list pin xyzac-trt-kins\n",
        );
        let v = |p: &str| hal.value(&format!("xyzac-trt-kins.{p}"));
        assert_eq!(v("conventional-directions"), Ok(Some(1.0)));
        assert_eq!(v("x-rot-point"), Ok(Some(-12.5)));
        assert_eq!(v("y-rot-point"), Ok(Some(150.0)));
        assert_eq!(v("z-rot-point"), Ok(Some(1.0)));
        assert_eq!(v("y-offset"), Ok(Some(7.0)));
        assert_eq!(v("z-offset"), Ok(Some(150.0)));
        assert_eq!(v("x-offset"), Ok(None));
    }

    #[test]
    fn values_that_are_not_read_say_where_and_why() {
        let hal = read_str(
            "setp m.a 6.28/360\n\
             setp m.b $gain\n\
             setp m.c $::KINS(TWICE)\n\
             setp m.d $::KINS(SPACED)\n\
             setp m.e $::KINS(NOPE)\n\
             setp m.f [expr {2*3}]\n\
             setp m.ok 4\n",
        );
        let e = |p: &str| hal.value(p).unwrap_err();
        assert_eq!(
            e("m.a"),
            "m.a: k.tcl:1:10: '6.28/360' is a Tcl expression (haltcl's setp evaluates it with \
             expr), which polepatch does not evaluate"
        );
        assert!(
            e("m.b").contains("k.tcl:2:10: '$gain', a Tcl variable"),
            "{}",
            e("m.b")
        );
        assert!(e("m.c").contains("a list of 2 values"), "{}", e("m.c"));
        assert!(
            e("m.d").contains("write [lindex $::KINS(SPACED) 0]"),
            "{}",
            e("m.d")
        );
        assert!(
            e("m.e").contains("which the INI does not have"),
            "{}",
            e("m.e")
        );
        assert!(
            e("m.f").contains("a Tcl command substitution"),
            "{}",
            e("m.f")
        );
        // Only those pins: the others are known.
        assert_eq!(hal.value("m.ok"), Ok(Some(4.0)));
    }

    #[test]
    fn forms_that_could_set_any_pin_make_every_pin_unknown() {
        let cases = [
            (
                "setp m.a 1\nfor {set j 0} {$j < 3} {incr j} {\n  setp m.$j 0\n}\n",
                "k.tcl:2:1: a Tcl loop (for)",
            ),
            ("if {1} {setp m.a 2}\n", "k.tcl:1:1: a Tcl condition (if)"),
            ("proc p {} {}\n", "k.tcl:1:1: a Tcl procedure (proc)"),
            ("setp $::KINS(KINEMATICS).a 1\n", "k.tcl:1:6: setp of"),
            ("setp m.$j 1\n", "k.tcl:1:6: setp of 'm.$j', a Tcl variable"),
            ("net :s m.a [other]\n", "k.tcl:1:12: net with"),
            ("setp m.a 1 2\n", "k.tcl:1:1: setp with 3 arguments"),
            ("source more.tcl\n", "k.tcl:1:1: 'source'"),
            ("set ::KINS(PIVOT) 3\n", "k.tcl:1:1: set of a global"),
            ("alias pin m.a short\n", "k.tcl:1:1: 'alias'"),
            ("frobnicate m.a\n", "k.tcl:1:1: the command 'frobnicate'"),
            ("$cmd m.a 1\n", "k.tcl:1:1: a command named by '$cmd'"),
            ("setp m.a {1\n", "k.tcl:1:10: an open brace"),
        ];
        for (text, want) in cases {
            let hal = read_str(text);
            let err = hal.value("m.a").unwrap_err();
            assert!(err.contains(want), "{text:?}: {err}");
        }
    }
}
