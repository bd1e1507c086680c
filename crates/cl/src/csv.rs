//! Cutter locations as text columns: `x,y,z,i,j,k[,f]` per line (mm, mm/min), straight
//! moves. The values are separated by commas, by semicolons, or — on a line without
//! either — by blanks (`113.560775   7.735266 -2.209314 -0.107258 0.624902 0.773300`, as
//! research data sets and CAM exports write them). Blank lines and lines starting with `#`
//! are skipped; the first other line is a header when none of its values is a number
//! (`x,y,z,i,j,k,f`, `X Y Z I J K`), and a point otherwise (an error then points at it);
//! a missing `f` carries the previous feed on.

use crate::records::{At, ClItem, ClPoint, ClProgram};
use crate::values::{coordinate, number};
use crate::{ClError, MAX_FEED_MM_MIN, err, unit_axis};

/// Split `s` into its values (module docs): (value, byte offset of the value in `s`).
fn fields(s: &str) -> Vec<(&str, usize)> {
    let sep = if s.contains(',') {
        Some(',')
    } else if s.contains(';') {
        Some(';')
    } else {
        None
    };
    let mut out = Vec::new();
    match sep {
        Some(sep) => {
            let mut start = 0;
            for (i, c) in s.char_indices() {
                if c == sep {
                    out.push((&s[start..i], start));
                    start = i + 1;
                }
            }
            out.push((&s[start..], start));
        }
        None => {
            let mut start = None;
            for (i, c) in s.char_indices().chain(std::iter::once((s.len(), ' '))) {
                match (c.is_whitespace(), start) {
                    (true, Some(b)) => {
                        out.push((&s[b..i], b));
                        start = None;
                    }
                    (false, None) => start = Some(i),
                    _ => {}
                }
            }
        }
    }
    out
}

/// Read cutter locations as text columns (module docs).
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
        if first_data && f.iter().all(|(v, _)| v.trim().parse::<f64>().is_err()) {
            // A header line: no value in it is a number.
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

    /// Issue 30 item 8: values separated by blanks, no header; a header is told by its
    /// content, not by being first.
    #[test]
    fn blank_separated_columns_and_headers_by_content() {
        let text = "113.560775   7.735266    -2.209314   -0.107258 0.624902  0.773300\n\
                    117.864949 -10.950074   -0.974065   -0.003002 0.653008  0.757345   \n";
        let p = parse(text.as_bytes()).unwrap();
        assert_eq!(p.point_count(), 2);
        let first = p.points().next().unwrap();
        assert_eq!(first.pos_mm, [113.560775, 7.735266, -2.209314]);
        assert!(p.notes.is_empty(), "{:?}", p.notes);
        // Semicolons, tabs, a header in words.
        let p = parse(b"X\tY\tZ\tI\tJ\tK\n1\t2\t3\t0\t0\t1\n").unwrap();
        assert_eq!((p.point_count(), p.notes.len()), (1, 1));
        let p = parse(b"1;2;3;0;0;1;1500\n").unwrap();
        assert_eq!(p.points().next().unwrap().feed_mm_min, Some(1500.0));
        // A first line with a bad value is a point with an error, not a header.
        let e = parse(b"1 2 x 0 0 1\n4 5 6 0 0 1\n").unwrap_err();
        assert_eq!((e.line, e.column), (1, 5));
        assert!(e.message.contains("'x'"), "{e}");
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
