//! The crate's error type.

use std::fmt;

/// Bad input: where (1-based line and column, byte columns) and what was expected.
#[derive(Debug, Clone, PartialEq)]
pub struct ParseError {
    /// File name, when the caller knows it (see [`ParseError::with_path`]).
    pub path: Option<String>,
    /// 1-based line.
    pub line: usize,
    /// 1-based byte column.
    pub column: usize,
    /// What is wrong, naming the value, e.g. `C value '12..5' is not a number`.
    pub message: String,
}

impl ParseError {
    /// An error at 1-based `line` and byte `column`, without a file name.
    pub fn at(line: usize, column: usize, message: impl Into<String>) -> Self {
        ParseError {
            path: None,
            line,
            column,
            message: message.into(),
        }
    }
    /// Attach a file name for display.
    pub fn with_path(mut self, path: impl Into<String>) -> Self {
        self.path = Some(path.into());
        self
    }
}

impl fmt::Display for ParseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.path {
            Some(p) => write!(f, "{p}:{}:{}: {}", self.line, self.column, self.message),
            None => write!(
                f,
                "line {}, col {}: {}",
                self.line, self.column, self.message
            ),
        }
    }
}

impl std::error::Error for ParseError {}
