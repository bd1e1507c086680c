//! Byte-level lexing of one line into words and pass-through tokens.
