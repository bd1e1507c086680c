//! Helpers shared by this crate's integration tests.
#![allow(dead_code)]

use polepatch::kinematics::Machine;

/// Every built-in machine.
pub fn machines() -> Vec<Machine> {
    Machine::builtin_names()
        .iter()
        .map(|n| Machine::builtin(n).unwrap())
        .collect()
}

/// The built-in machines a program was posted for: those whose rotary letters it uses.
/// On the others it is refused by name, with line and column (`Error::ForeignAxis`,
/// issue 29) — checked here for every machine left out. Never empty.
pub fn machines_for(name: &str, bytes: &[u8]) -> Vec<Machine> {
    let fit: Vec<Machine> = machines()
        .into_iter()
        .filter(|m| {
            let opts = polepatch::AnalyzeOptions {
                read: polepatch::ReadOptions {
                    name: name.to_string(),
                    ..polepatch::ReadOptions::default()
                },
                ..polepatch::AnalyzeOptions::default()
            };
            match polepatch::analyze_nc(bytes, m, &opts) {
                Err(polepatch::Error::ForeignAxis {
                    line,
                    column,
                    letter,
                    ..
                }) => {
                    assert!(line >= 1 && column >= 1, "{name} on {}", m.name);
                    assert_ne!(letter, m.primary_letter(), "{name} on {}", m.name);
                    false
                }
                _ => true,
            }
        })
        .collect();
    assert!(!fit.is_empty(), "{name}: no built-in machine takes it");
    fit
}
