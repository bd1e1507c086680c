//! The HAL values a LinuxCNC machine's kinematics parameters come from: `setp` on a pin,
//! `sets` on a signal a pin is netted to, in the order LinuxCNC runs the HAL files
//! (`[HAL] HALFILE`, `HALCMD`, `POSTGUI_HALFILE`). halcmd lines are read here; haltcl files
//! (`.tcl`) by `haltcl.rs`, into the same state.
//!
//! A value is known, or it is not and the reason says where and why (a Tcl expression, a
//! variable): a pin whose value is asked for then says that reason, never a default. A
//! command the reader cannot follow at all (a Tcl loop, a procedure, a variable in a pin's
//! name) may set any pin: after it every pin says so ([`Hal::opaque`]).

use crate::ini::Ini;
use std::collections::HashMap;

/// A value as read: its text, or why it is not known (with its file, line and column).
pub(crate) type Value = Result<String, String>;

/// HAL values set by `setp` and `sets`, and the nets, in the order LinuxCNC runs them.
#[derive(Debug, Default)]
pub(crate) struct Hal {
    /// pin → value from `setp`.
    pins: HashMap<String, Value>,
    /// signal → value from `sets`.
    signals: HashMap<String, Value>,
    /// pin → signal it is netted to.
    pin_signal: HashMap<String, String>,
    /// signal → every pin on it.
    signal_pins: HashMap<String, Vec<String>>,
    /// The first command that could not be followed (where, and what it is): it may have
    /// set or netted any pin.
    opaque: Option<String>,
}

impl Hal {
    /// `setp PIN VALUE`.
    pub(crate) fn setp(&mut self, pin: &str, value: Value) {
        self.pins.insert(pin.to_string(), value);
    }

    /// `sets SIGNAL VALUE`.
    pub(crate) fn sets(&mut self, signal: &str, value: Value) {
        self.signals.insert(signal.to_string(), value);
    }

    /// A pin joined to a signal (`net`, `linksp`, `linkps`).
    pub(crate) fn link(&mut self, signal: &str, pin: &str) {
        self.pin_signal.insert(pin.to_string(), signal.to_string());
        self.signal_pins
            .entry(signal.to_string())
            .or_default()
            .push(pin.to_string());
    }

    /// A command that could not be followed, `why` naming where and what: only the first
    /// is kept (after it nothing is known anyway).
    pub(crate) fn opaque(&mut self, why: String) {
        self.opaque.get_or_insert(why);
    }

    /// One halcmd command line (comments after `#` removed, `[SECTION]KEY` substituted).
    pub(crate) fn halcmd_line(&mut self, line: &str, ini: &Ini) {
        let line = line.split('#').next().unwrap_or("");
        let words: Vec<String> = line
            .split_whitespace()
            .map(|w| substitute(w, ini))
            .collect();
        let Some(cmd) = words.first() else {
            return;
        };
        self.command(cmd, &words[1..], |v| Ok(v.to_string()));
    }

    /// A HAL command whose words are known; `value` reads the value of `setp`/`sets` (halcmd
    /// takes it as written, haltcl through Tcl's `expr`). Commands that set nothing polepatch
    /// reads (`loadrt`, `addf`, …) are passed over.
    pub(crate) fn command(&mut self, cmd: &str, args: &[String], value: impl Fn(&str) -> Value) {
        match (cmd, args) {
            ("setp", [pin, v, ..]) => self.setp(pin, value(v)),
            ("sets", [sig, v, ..]) => self.sets(sig, value(v)),
            ("net", [sig, rest @ ..]) => {
                for pin in rest
                    .iter()
                    .filter(|w| !matches!(w.as_str(), "=>" | "<=" | "<=>"))
                {
                    self.link(sig, pin);
                }
            }
            ("linksp", [sig, pin, ..]) => self.link(sig, pin),
            ("linkps", [pin, sig, ..]) => self.link(sig, pin),
            _ => {}
        }
    }

    /// The value of an input pin: `Ok(Some)` when set (a pin on a signal that nothing sets
    /// or drives holds the signal's 0), `Ok(None)` when never set nor netted (the module's
    /// default), `Err(why)` when it cannot be known: another component drives it at run
    /// time, its value is a form polepatch does not evaluate, or a command before could
    /// have set it.
    pub(crate) fn value(&self, pin: &str) -> Result<Option<f64>, String> {
        if let Some(why) = &self.opaque {
            return Err(format!("{pin} may be set by {why}"));
        }
        let value = if let Some(v) = self.pins.get(pin) {
            v
        } else if let Some(sig) = self.pin_signal.get(pin) {
            match self.signals.get(sig) {
                Some(v) => v,
                None => {
                    let others: Vec<&str> = self.signal_pins[sig]
                        .iter()
                        .map(String::as_str)
                        .filter(|p| *p != pin)
                        .collect();
                    if others.is_empty() {
                        return Ok(Some(0.0));
                    }
                    return Err(format!(
                        "{pin} is netted to {sig} with {} and no value set: it is set at run time",
                        others.join(", ")
                    ));
                }
            }
        } else {
            return Ok(None);
        };
        let text = value.as_ref().map_err(|why| format!("{pin}: {why}"))?;
        text.parse::<f64>()
            .map(Some)
            .map_err(|_| format!("{pin} = '{text}' is not a number"))
    }
}

/// `[SECTION]KEY` in a HAL word replaced by the INI value (as LinuxCNC's halcmd does).
pub(crate) fn substitute(word: &str, ini: &Ini) -> String {
    if let Some(rest) = word.strip_prefix('[')
        && let Some((section, key)) = rest.split_once(']')
        && let Some(v) = ini.get(section, key)
    {
        return v.to_string();
    }
    word.to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ini() -> Ini {
        Ini::parse("[KINS]\nPIVOT = 120\n", "t.ini").unwrap()
    }

    #[test]
    fn pins_signals_and_nets_as_halcmd_sets_them() {
        let ini = ini();
        let mut hal = Hal::default();
        for line in [
            "setp m.a 5   # a comment",
            "setp m.b [KINS]PIVOT",
            "net :c m.c",
            "sets :c -2.5",
            "net :d m.d",
            "net :e other.out => m.e",
            "loadrt m coordinates=xyz",
            "setp m.f x1",
        ] {
            hal.halcmd_line(line, &ini);
        }
        assert_eq!(hal.value("m.a"), Ok(Some(5.0)));
        assert_eq!(hal.value("m.b"), Ok(Some(120.0)));
        assert_eq!(hal.value("m.c"), Ok(Some(-2.5)));
        // On a signal nothing sets or drives: the signal's 0, not the pin's default.
        assert_eq!(hal.value("m.d"), Ok(Some(0.0)));
        assert_eq!(hal.value("m.never"), Ok(None));
        assert!(hal.value("m.e").unwrap_err().contains("set at run time"));
        assert!(
            hal.value("m.f")
                .unwrap_err()
                .contains("'x1' is not a number")
        );
        // A value not known says why; a command not followed makes every pin unknown.
        hal.setp("m.g", Err("k.tcl:3:8: a Tcl expression".into()));
        assert_eq!(
            hal.value("m.g"),
            Err("m.g: k.tcl:3:8: a Tcl expression".into())
        );
        hal.opaque("k.tcl:9:1: a Tcl loop (for)".into());
        hal.opaque("k.tcl:20:1: later".into());
        assert_eq!(
            hal.value("m.a"),
            Err("m.a may be set by k.tcl:9:1: a Tcl loop (for)".into())
        );
    }
}
