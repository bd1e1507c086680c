//! Cutter locations (CL) as CAM systems hand them out: tool-tip position and tool axis
//! per point, in the part frame — G16's stage 1, before any machine's inverse kinematics.
//!
//! Two formats ([`parse`] detects which):
//!
//! - **APT CLDATA** (the text form CAM post-processors read): one record per line, a `$`
//!   at the end of a line continues the record on the next, `$$` starts a comment.
//!   Records read: `GOTO/x,y,z[,i,j,k]` (a point; without i j k the last tool axis, or +Z),
//!   `FEDRAT/f[,MMPM|IPM]` (also `FEDRAT/MMPM,f`), `RAPID` (the next GOTO is a rapid move),
//!   `MULTAX[/ON|OFF]`, `UNITS/MM|INCHES` (inch values are converted to mm), `PPRINT/…` and
//!   `PARTNO/…` (kept as notes). Every other record (`CUTTER/`, `LOADTL/`, `SPINDL/`,
//!   `COOLNT/`, `FINI`, …) is ignored and counted in a note.
//! - **CSV** `x,y,z,i,j,k[,f]` per line, mm and mm/min, with or without a header line;
//!   blank lines and lines starting with `#` are skipped.
//!
//! A tool axis is normalised when its length is within [`UNIT_TOLERANCE`] of 1 and refused
//! otherwise (a CL file with a non-unit axis is damaged, or not what it seems). Errors name
//! the line and column and the value.

use std::fmt::Write as _;

/// A tool axis may differ from unit length by this much (CAM files round to 4–7
/// decimals); it is then normalised.
pub const UNIT_TOLERANCE: f64 = 1e-3;

/// mm per inch.
const MM_PER_INCH: f64 = 25.4;

/// One cutter location.
#[derive(Debug, Clone, PartialEq)]
pub struct ClPoint {
    /// Tool tip, part frame, mm.
    pub pos_mm: [f64; 3],
    /// Tool axis, unit vector, part frame.
    pub axis: [f64; 3],
    /// Feed in force, mm/min (`None` before any feed).
    pub feed_mm_min: Option<f64>,
    /// A rapid move (APT `RAPID` before it).
    pub rapid: bool,
    /// 1-based line of the record in the file.
    pub line: usize,
}

/// A CL file read.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ClProgram {
    /// The points in order.
    pub points: Vec<ClPoint>,
    /// What was kept as text or ignored (`PARTNO`, `PPRINT`, counts of other records).
    pub notes: Vec<String>,
    /// Program name (`PARTNO`), if any.
    pub name: Option<String>,
}

/// A bad record.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{line}:{column}: {message}")]
pub struct ClError {
    /// 1-based line.
    pub line: usize,
    /// 1-based byte column.
    pub column: usize,
    /// What is wrong, naming the value.
    pub message: String,
}

fn err(line: usize, column: usize, message: impl Into<String>) -> ClError {
    ClError {
        line,
        column,
        message: message.into(),
    }
}

/// Read a CL file: APT when a line starts with an APT record word (`GOTO/`, `FEDRAT/`,
/// `MULTAX`, …), else CSV.
pub fn parse(bytes: &[u8]) -> Result<ClProgram, ClError> {
    let text = std::str::from_utf8(bytes).map_err(|e| {
        let before = &bytes[..e.valid_up_to()];
        let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
        let col = before.len()
            - before
                .iter()
                .rposition(|&b| b == b'\n')
                .map_or(0, |p| p + 1)
            + 1;
        err(line, col, "the file is not text (invalid UTF-8)")
    })?;
    let is_apt = text.lines().any(|l| {
        let u = l.trim_start().to_ascii_uppercase();
        [
            "GOTO/", "FEDRAT/", "MULTAX", "PARTNO", "RAPID", "UNITS/", "TLAXIS", "LOADTL", "CUTTER",
        ]
        .iter()
        .any(|k| u.starts_with(k))
    });
    if is_apt {
        parse_apt(text)
    } else {
        parse_csv(text)
    }
}

/// A number in a field, with its column for errors.
fn number(field: &str, line: usize, column: usize, what: &str) -> Result<f64, ClError> {
    let t = field.trim();
    let v: f64 = t
        .parse()
        .map_err(|_| err(line, column, format!("{what} '{t}' is not a number")))?;
    if !v.is_finite() {
        return Err(err(
            line,
            column,
            format!("{what} '{t}' is not a finite number"),
        ));
    }
    Ok(v)
}

/// Split `s` at commas: (field, byte offset of the field in `s`).
fn fields(s: &str) -> Vec<(&str, usize)> {
    let mut out = Vec::new();
    let mut start = 0;
    for (i, c) in s.char_indices() {
        if c == ',' {
            out.push((&s[start..i], start));
            start = i + 1;
        }
    }
    out.push((&s[start..], start));
    out
}

fn unit_axis(v: [f64; 3], line: usize, column: usize) -> Result<[f64; 3], ClError> {
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if (n - 1.0).abs() > UNIT_TOLERANCE {
        return Err(err(
            line,
            column,
            format!(
                "tool axis ({}, {}, {}) has length {n:.6}, not 1",
                v[0], v[1], v[2]
            ),
        ));
    }
    Ok([v[0] / n, v[1] / n, v[2] / n])
}

/// Read APT CLDATA (module docs).
pub fn parse_apt(text: &str) -> Result<ClProgram, ClError> {
    let mut prog = ClProgram::default();
    let mut feed: Option<f64> = None;
    let mut rapid_next = false;
    let mut inch = false;
    let mut axis = [0.0, 0.0, 1.0];
    let mut ignored: std::collections::BTreeMap<String, usize> = Default::default();
    // (record text, line of its start, byte column offset of each piece) — continuation
    // lines are joined; columns refer to the first line for simplicity of messages.
    let mut record = String::new();
    let mut record_line = 0;
    let lines: Vec<&str> = text.lines().collect();
    let mut k = 0;
    while k < lines.len() {
        let raw = lines[k];
        let line_no = k + 1;
        k += 1;
        let code = match raw.find("$$") {
            Some(p) => &raw[..p],
            None => raw,
        };
        let trimmed = code.trim_end();
        if record.is_empty() {
            record_line = line_no;
        }
        if let Some(stripped) = trimmed.strip_suffix('$') {
            record.push_str(stripped);
            continue;
        }
        record.push_str(trimmed);
        let rec = std::mem::take(&mut record);
        let rec = rec.trim();
        if rec.is_empty() {
            continue;
        }
        let line = record_line;
        let (word, args, args_col) = match rec.find('/') {
            Some(p) => (rec[..p].trim().to_ascii_uppercase(), &rec[p + 1..], p + 2),
            None => (rec.to_ascii_uppercase(), "", rec.len() + 1),
        };
        let col0 = raw.len() - raw.trim_start().len();
        match word.as_str() {
            "GOTO" => {
                let f = fields(args);
                if f.len() != 3 && f.len() != 6 {
                    return Err(err(
                        line,
                        col0 + args_col,
                        format!("GOTO needs x,y,z or x,y,z,i,j,k; got {} values", f.len()),
                    ));
                }
                let mut v = [0.0; 6];
                for (i, (t, off)) in f.iter().enumerate() {
                    let what = ["x", "y", "z", "i", "j", "k"][i];
                    v[i] = number(t, line, col0 + args_col + off, what)?;
                }
                let scale = if inch { MM_PER_INCH } else { 1.0 };
                if f.len() == 6 {
                    axis = unit_axis([v[3], v[4], v[5]], line, col0 + args_col + f[3].1)?;
                }
                prog.points.push(ClPoint {
                    pos_mm: [v[0] * scale, v[1] * scale, v[2] * scale],
                    axis,
                    feed_mm_min: feed,
                    rapid: rapid_next,
                    line,
                });
                rapid_next = false;
            }
            "FEDRAT" => {
                let f = fields(args);
                let mut value = None;
                let mut per_inch = inch;
                for (t, off) in &f {
                    let u = t.trim().to_ascii_uppercase();
                    match u.as_str() {
                        "MMPM" => per_inch = false,
                        "IPM" => per_inch = true,
                        "" => {}
                        _ => value = Some(number(t, line, col0 + args_col + off, "feed")?),
                    }
                }
                let v =
                    value.ok_or_else(|| err(line, col0 + args_col, "FEDRAT without a value"))?;
                if v <= 0.0 {
                    return Err(err(
                        line,
                        col0 + args_col,
                        format!("feed {v} must be positive"),
                    ));
                }
                feed = Some(if per_inch { v * MM_PER_INCH } else { v });
            }
            "RAPID" => rapid_next = true,
            "MULTAX" => {}
            "UNITS" => match args.trim().to_ascii_uppercase().as_str() {
                "MM" => inch = false,
                "INCHES" | "INCH" => inch = true,
                other => {
                    return Err(err(
                        line,
                        col0 + args_col,
                        format!("UNITS '{other}' is not MM or INCHES"),
                    ));
                }
            },
            "PARTNO" => {
                let name = args.trim().to_string();
                let name = if name.is_empty() {
                    rec[6..].trim().to_string()
                } else {
                    name
                };
                prog.notes.push(format!("line {line}: PARTNO {name}"));
                prog.name = Some(name);
            }
            "PPRINT" => prog
                .notes
                .push(format!("line {line}: PPRINT {}", args.trim())),
            other => *ignored.entry(other.to_string()).or_default() += 1,
        }
    }
    if !record.trim().is_empty() {
        return Err(err(
            record_line,
            1,
            "the file ends inside a continued record ('$' at the end of the last line)",
        ));
    }
    for (w, n) in ignored {
        let mut s = String::new();
        let _ = write!(s, "{w} records ignored: {n}");
        prog.notes.push(s);
    }
    if prog.points.is_empty() {
        return Err(err(1, 1, "no GOTO record: no cutter location in the file"));
    }
    Ok(prog)
}

/// Read CSV `x,y,z,i,j,k[,f]` (module docs).
pub fn parse_csv(text: &str) -> Result<ClProgram, ClError> {
    let mut prog = ClProgram::default();
    let mut first_data = true;
    for (k, raw) in text.lines().enumerate() {
        let line = k + 1;
        let t = raw.trim();
        if t.is_empty() || t.starts_with('#') {
            continue;
        }
        let f = fields(t);
        let col0 = raw.len() - raw.trim_start().len() + 1;
        if first_data && f[0].0.trim().parse::<f64>().is_err() {
            // A header line.
            first_data = false;
            prog.notes.push(format!("line {line}: header '{t}'"));
            continue;
        }
        first_data = false;
        if f.len() != 6 && f.len() != 7 {
            return Err(err(
                line,
                col0,
                format!("expected x,y,z,i,j,k[,f]; got {} values", f.len()),
            ));
        }
        let mut v = [0.0; 7];
        for (i, (s, off)) in f.iter().enumerate() {
            let what = ["x", "y", "z", "i", "j", "k", "feed"][i];
            v[i] = number(s, line, col0 + off, what)?;
        }
        let axis = unit_axis([v[3], v[4], v[5]], line, col0 + f[3].1)?;
        let feed = if f.len() == 7 {
            if v[6] <= 0.0 {
                return Err(err(
                    line,
                    col0 + f[6].1,
                    format!("feed {} must be positive", v[6]),
                ));
            }
            Some(v[6])
        } else {
            prog.points.last().and_then(|p| p.feed_mm_min)
        };
        prog.points.push(ClPoint {
            pos_mm: [v[0], v[1], v[2]],
            axis,
            feed_mm_min: feed,
            rapid: false,
            line,
        });
    }
    if prog.points.is_empty() {
        return Err(err(1, 1, "no cutter location in the file"));
    }
    Ok(prog)
}

/// Write points as APT CLDATA (`MULTAX`, `FEDRAT/f,MMPM` where the feed changes, `RAPID`,
/// `GOTO/x,y,z,i,j,k` with `decimals` places).
pub fn to_apt(points: &[ClPoint], name: &str, decimals: usize) -> String {
    let mut s = format!("PARTNO/{name}\nUNITS/MM\nMULTAX/ON\n");
    let mut feed = None;
    for p in points {
        if p.feed_mm_min != feed && !p.rapid {
            if let Some(f) = p.feed_mm_min {
                let _ = writeln!(s, "FEDRAT/{f},MMPM");
            }
            feed = p.feed_mm_min;
        }
        if p.rapid {
            s.push_str("RAPID\n");
        }
        let d = decimals;
        let _ = writeln!(
            s,
            "GOTO/{:.d$},{:.d$},{:.d$},{:.d$},{:.d$},{:.d$}",
            p.pos_mm[0], p.pos_mm[1], p.pos_mm[2], p.axis[0], p.axis[1], p.axis[2]
        );
    }
    s.push_str("FINI\n");
    s
}

/// Write points as CSV `x,y,z,i,j,k,f` with a header.
pub fn to_csv(points: &[ClPoint], decimals: usize) -> String {
    let mut s = String::from("x,y,z,i,j,k,f\n");
    let d = decimals;
    for p in points {
        let _ = write!(
            s,
            "{:.d$},{:.d$},{:.d$},{:.d$},{:.d$},{:.d$}",
            p.pos_mm[0], p.pos_mm[1], p.pos_mm[2], p.axis[0], p.axis[1], p.axis[2]
        );
        match p.feed_mm_min {
            Some(f) => {
                let _ = writeln!(s, ",{f}");
            }
            None => s.push('\n'),
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    const APT: &str = "PARTNO/BLADE 7\n$$ a comment\nUNITS/MM\nMULTAX/ON\nCUTTER/6.0\nLOADTL/5\nFEDRAT/2000.0,MMPM\nGOTO/1.0,2.0,3.0,0.0,0.0,1.0\nGOTO/1.5,2.0,$\n3.0,0.6,0.0,0.8\nRAPID\nGOTO/0,0,50\nPPRINT/END OF PASS\nFINI\n";

    #[test]
    fn apt_records() {
        let p = parse(APT.as_bytes()).unwrap();
        assert_eq!(p.points.len(), 3);
        assert_eq!(p.name.as_deref(), Some("BLADE 7"));
        assert_eq!(p.points[1].pos_mm, [1.5, 2.0, 3.0]);
        assert_eq!(p.points[1].axis, [0.6, 0.0, 0.8]);
        assert_eq!(p.points[1].line, 9, "a continued record has its first line");
        assert!(p.points[2].rapid && !p.points[1].rapid);
        assert_eq!(
            p.points[2].axis,
            [0.6, 0.0, 0.8],
            "GOTO/x,y,z keeps the last axis"
        );
        assert_eq!(p.points[0].feed_mm_min, Some(2000.0));
        assert!(
            p.notes
                .iter()
                .any(|n| n.contains("CUTTER records ignored: 1"))
        );
        assert!(p.notes.iter().any(|n| n.contains("PPRINT END OF PASS")));
    }

    #[test]
    fn inch_units_and_ipm() {
        let p = parse(b"UNITS/INCHES\nFEDRAT/IPM,10\nGOTO/1,0,0,0,0,1\n").unwrap();
        assert_eq!(p.points[0].pos_mm, [25.4, 0.0, 0.0]);
        assert_eq!(p.points[0].feed_mm_min, Some(254.0));
    }

    #[test]
    fn csv_with_and_without_header() {
        let a = parse(b"x,y,z,i,j,k,f\n1,2,3,0,0,1,1500\n2,2,3,0,0.6,0.8\n").unwrap();
        assert_eq!(a.points.len(), 2);
        assert_eq!(a.points[1].feed_mm_min, Some(1500.0), "the feed carries on");
        let b = parse(b"# from CAM\n1,2,3,0,0,1\n").unwrap();
        assert_eq!(b.points[0].feed_mm_min, None);
    }

    #[test]
    fn bad_records_name_line_and_column() {
        let e = parse(b"MULTAX\nGOTO/1,2,x3,0,0,1\n").unwrap_err();
        assert_eq!((e.line, e.column), (2, 10));
        assert!(e.message.contains("z 'x3' is not a number"), "{e}");
        let e = parse(b"MULTAX\nGOTO/1,2,3,0,0,0\n").unwrap_err();
        assert!(e.message.contains("length 0"), "{e}");
        let e = parse(b"MULTAX\nGOTO/1,2,3,0,0.5,0.5\n").unwrap_err();
        assert!(e.message.contains("not 1"), "{e}");
        let e = parse(b"MULTAX\nGOTO/1,2\n").unwrap_err();
        assert!(e.message.contains("got 2 values"), "{e}");
        let e = parse(b"MULTAX\nGOTO/1,2,$\n").unwrap_err();
        assert!(e.message.contains("ends inside a continued record"), "{e}");
        let e = parse(b"1,2,3,0,0,1\n1,2,3,0,0\n").unwrap_err();
        assert_eq!(e.line, 2);
        let e = parse(b"1,2,3,0,0,1,inf\n").unwrap_err();
        assert!(e.message.contains("not a finite number"), "{e}");
        let e = parse(b"\xff\xfe").unwrap_err();
        assert!(e.message.contains("not text"), "{e}");
        assert!(parse(b"").is_err());
        assert!(parse(b"FEDRAT/-5\nGOTO/0,0,0\n").is_err());
    }

    #[test]
    fn writers_read_back() {
        let p = parse(APT.as_bytes()).unwrap();
        for text in [to_apt(&p.points, "X", 7), to_csv(&p.points, 7)] {
            let q = parse(text.as_bytes()).unwrap();
            assert_eq!(q.points.len(), p.points.len());
            for (a, b) in p.points.iter().zip(&q.points) {
                assert_eq!(a.pos_mm, b.pos_mm);
                assert_eq!(a.axis, b.axis);
            }
        }
    }
}
