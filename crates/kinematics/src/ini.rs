//! LinuxCNC's INI files: `[SECTION]` headers and `KEY = VALUE` lines, as its `IniFile`
//! reads them (the machine itself is read in [`crate::linuxcnc`]; its HAL files in
//! `hal.rs` and `haltcl.rs`, which look values up here).

use crate::machine::MachineError;

/// One `KEY = VALUE` of an INI file, with its 1-based line.
#[derive(Debug, Clone)]
pub(crate) struct Entry {
    pub(crate) section: String,
    pub(crate) key: String,
    pub(crate) value: String,
    pub(crate) line: usize,
}

/// An INI file as LinuxCNC reads it: `[SECTION]` headers, `KEY = VALUE` lines, `#` and `;`
/// comment lines; a key may repeat (`REMAP`, `HALCMD`, `HALFILE`), and a look-up takes the
/// first, as LinuxCNC's `IniFile::Find` does.
#[derive(Debug, Default)]
pub struct Ini {
    entries: Vec<Entry>,
    /// `#INCLUDE` lines (expanded by LinuxCNC's start script, not here): 1-based lines.
    pub(crate) includes: Vec<usize>,
}

impl Ini {
    /// Parse INI text; `origin` names it in errors.
    pub fn parse(text: &str, origin: &str) -> Result<Ini, MachineError> {
        let mut section = String::new();
        let mut entries = Vec::new();
        let mut includes = Vec::new();
        for (n, raw) in text.lines().enumerate() {
            let line = raw.trim();
            if line.starts_with("#INCLUDE") {
                includes.push(n + 1);
            }
            if line.is_empty() || line.starts_with('#') || line.starts_with(';') {
                continue;
            }
            if let Some(rest) = line.strip_prefix('[') {
                let Some(name) = rest.strip_suffix(']') else {
                    return Err(invalid(
                        origin,
                        format!("line {}: a section header must end with ']': {line}", n + 1),
                    ));
                };
                section = name.trim().to_string();
                continue;
            }
            let Some((key, value)) = line.split_once('=') else {
                return Err(invalid(
                    origin,
                    format!("line {}: expected KEY = VALUE, got '{line}'", n + 1),
                ));
            };
            entries.push(Entry {
                section: section.clone(),
                key: key.trim().to_string(),
                value: value.trim().to_string(),
                line: n + 1,
            });
        }
        Ok(Ini { entries, includes })
    }

    /// The first value of `key` in `[section]`.
    pub fn get(&self, section: &str, key: &str) -> Option<&str> {
        self.entry(section, key).map(|e| e.value.as_str())
    }

    pub(crate) fn entry(&self, section: &str, key: &str) -> Option<&Entry> {
        self.entries
            .iter()
            .find(|e| e.section == section && e.key == key)
    }

    /// Every entry of `key` in `[section]`, in file order.
    pub(crate) fn entries_of<'a>(
        &'a self,
        section: &'a str,
        key: &'a str,
    ) -> impl Iterator<Item = &'a Entry> {
        self.entries
            .iter()
            .filter(move |e| e.section == section && e.key == key)
    }

    /// Every value of `key` in `[section]`, in file order.
    pub fn all<'a>(&'a self, section: &'a str, key: &'a str) -> impl Iterator<Item = &'a str> {
        self.entries
            .iter()
            .filter(move |e| e.section == section && e.key == key)
            .map(|e| e.value.as_str())
    }
}

fn invalid(origin: &str, message: String) -> MachineError {
    MachineError::Invalid {
        path: origin.to_string(),
        message,
    }
}
