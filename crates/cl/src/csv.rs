//! CSV cutter locations: `x,y,z,i,j,k[,f]` per line (mm, mm/min), straight moves, with or
//! without a header line; blank lines and lines starting with `#` are skipped; a missing
//! `f` carries the previous feed on.

use crate::apt::{coordinate, number};
use crate::records::{At, ClItem, ClPoint, ClProgram};
use crate::{ClError, MAX_FEED_MM_MIN, err, unit_axis};

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

/// Read CSV `x,y,z,i,j,k[,f]` (module docs).
pub fn parse_csv(text: &str) -> Result<ClProgram, ClError> {
    let mut prog = ClProgram::default();
    let mut first_data = true;
    let mut feed: Option<f64> = None;
    for (k, raw) in crate::lines(text).enumerate() {
        let line = k + 1;
        let t = raw.trim();
        if t.is_empty() || t.starts_with('#') {
            continue;
        }
        let f = fields(t);
        let col0 = raw.len() - raw.trim_start().len() + 1;
        let at = |off: usize| At {
            line,
            column: col0 + off,
        };
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
            v[i] = number(s, at(*off), what)?;
            if i < 3 {
                coordinate(v[i], at(*off), what, s.trim())?;
            }
        }
        let axis = unit_axis([v[3], v[4], v[5]], line, col0 + f[3].1)?;
        if f.len() == 7 {
            if !(v[6] > 0.0 && v[6] <= MAX_FEED_MM_MIN) {
                return Err(err(
                    line,
                    col0 + f[6].1,
                    format!(
                        "feed {} must be within 0…{MAX_FEED_MM_MIN} mm/min (and not 0)",
                        v[6]
                    ),
                ));
            }
            feed = Some(v[6]);
        }
        prog.items.push(ClItem::Move(ClPoint {
            column: col0,
            ..ClPoint::straight([v[0], v[1], v[2]], axis, feed, false, line)
        }));
    }
    if prog.items.is_empty() {
        return Err(err(1, 1, "no cutter location in the file"));
    }
    Ok(prog)
}

#[cfg(test)]
mod tests {
    use crate::parse;

    #[test]
    fn with_and_without_header() {
        let a = parse(b"x,y,z,i,j,k,f\n1,2,3,0,0,1,1500\n2,2,3,0,0.6,0.8\n").unwrap();
        assert_eq!(a.point_count(), 2);
        let p: Vec<_> = a.points().collect();
        assert_eq!(p[1].feed_mm_min, Some(1500.0), "the feed carries on");
        let b = parse(b"# from CAM\n1,2,3,0,0,1\n").unwrap();
        assert_eq!(b.points().next().unwrap().feed_mm_min, None);
    }

    /// Issue 19 §5: a UTF-8 byte-order mark made the first point a "header".
    #[test]
    fn a_byte_order_mark_is_not_a_header() {
        let plain = parse(b"1,2,3,0,0,1,1000\n4,5,6,0,0,1\n").unwrap();
        let bom = parse(b"\xEF\xBB\xBF1,2,3,0,0,1,1000\n4,5,6,0,0,1\n").unwrap();
        assert_eq!(bom.point_count(), 2);
        assert_eq!(bom.items, plain.items);
        assert!(bom.notes.is_empty(), "{:?}", bom.notes);
        // With a header after the mark, the header is still one.
        let h = parse(b"\xEF\xBB\xBFx,y,z,i,j,k\n1,2,3,0,0,1\n").unwrap();
        assert_eq!(h.point_count(), 1);
        // And an APT file with a mark is still APT.
        let a = parse(b"\xEF\xBB\xBFGOTO/1,2,3\n").unwrap();
        assert_eq!(a.points().next().unwrap().pos_mm, [1.0, 2.0, 3.0]);
    }

    #[test]
    fn bad_lines_name_line_and_column() {
        let e = parse(b"1,2,3,0,0,1\n1,2,3,0,0\n").unwrap_err();
        assert_eq!(e.line, 2);
        let e = parse(b"1,2,3,0,0,1,inf\n").unwrap_err();
        assert!(e.message.contains("not a finite number"), "{e}");
        let e = parse(b"1,2,1e308,0,0,1,100\n").unwrap_err();
        assert_eq!((e.line, e.column), (1, 5));
        assert!(e.message.contains("beyond"), "{e}");
        let e = parse(b"1,2,3,0,0,1,1e300\n").unwrap_err();
        assert!(e.message.contains("feed"), "{e}");
        // CR-only line ends are line ends.
        let e = parse(b"1,2,3,0,0,1\r1,2,x,0,0,1\r").unwrap_err();
        assert_eq!((e.line, e.column), (2, 5));
    }
}
