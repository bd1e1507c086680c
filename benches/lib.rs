//! Shared helpers for the criterion benches (nothing yet).
