//! A record's numbers: a field read as a finite number, a coordinate checked against the
//! range polepatch accepts. Used by every record reader (`apt`, `frames`).

use crate::records::At;
use crate::{ClError, MAX_COORDINATE_MM, err};

/// A finite number in a field (mm or whatever `what` is), with its column for errors.
pub(crate) fn number(field: &str, at: At, what: &str) -> Result<f64, ClError> {
    let t = field.trim();
    let v: f64 = t
        .parse()
        .map_err(|_| err(at.line, at.column, format!("{what} '{t}' is not a number")))?;
    if !v.is_finite() {
        return Err(err(
            at.line,
            at.column,
            format!("{what} '{t}' is not a finite number"),
        ));
    }
    Ok(v)
}

/// A coordinate in range (after conversion to mm).
pub(crate) fn coordinate(v_mm: f64, at: At, what: &str, text: &str) -> Result<f64, ClError> {
    if v_mm.abs() > MAX_COORDINATE_MM {
        return Err(err(
            at.line,
            at.column,
            format!(
                "{what} '{text}' is {v_mm:.6e} mm, beyond the ±{MAX_COORDINATE_MM} mm polepatch accepts for a coordinate"
            ),
        ));
    }
    Ok(v_mm)
}
