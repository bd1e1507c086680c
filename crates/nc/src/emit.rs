//! Writing a new 5-axis TCPM program from joint values (`polepatch post`): Heidenhain ISO
//! with M128, Sinumerik with TRAORI, Fanuc with G43.4. Numbers go through
//! [`NumberStyle`], in each dialect's usual style; every block writes every axis word (the
//! simplest program every controller reads the same way).

use crate::program::Dialect;
use crate::style::NumberStyle;

/// One block to write: tool tip (part frame, mm), primary and C (degrees), feed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EmitPoint {
    /// X Y Z, mm.
    pub xyz_mm: [f64; 3],
    /// Primary axis (A or B), degrees.
    pub p_deg: f64,
    /// C, degrees.
    pub c_deg: f64,
    /// Feed, mm/min (written where it changes; `None` for a rapid).
    pub feed_mm_min: Option<f64>,
    /// A rapid move (G0).
    pub rapid: bool,
}

/// How to write the program.
#[derive(Debug, Clone, PartialEq)]
pub struct EmitOptions {
    /// Dialect (`Auto` is taken as Heidenhain).
    pub dialect: Dialect,
    /// Program name (Heidenhain `%NAME`, Fanuc comment, Sinumerik comment).
    pub name: String,
    /// Letter of the primary axis (`b'A'` or `b'B'`).
    pub primary_letter: u8,
    /// Decimals of rotary words.
    pub rotary_decimals: usize,
    /// Decimals of linear words.
    pub linear_decimals: usize,
    /// Comment lines to put at the top (source notes).
    pub comments: Vec<String>,
}

fn style(dialect: Dialect) -> NumberStyle {
    match dialect {
        Dialect::Fanuc => NumberStyle {
            plus_sign: false,
            decimals: 3,
            strip_trailing_zeros: true,
            trailing_point: true,
            leading_zero: true,
            equals: false,
        },
        Dialect::Sinumerik => NumberStyle {
            plus_sign: false,
            decimals: 3,
            strip_trailing_zeros: true,
            trailing_point: false,
            leading_zero: true,
            equals: false,
        },
        // The post writes Heidenhain ISO for either Heidenhain dialect.
        Dialect::Heidenhain | Dialect::Conversational | Dialect::Auto => NumberStyle {
            plus_sign: true,
            decimals: 3,
            strip_trailing_zeros: true,
            trailing_point: false,
            leading_zero: true,
            equals: false,
        },
    }
}

/// Only characters every dialect accepts in a comment or a program name.
fn clean(s: &str) -> String {
    s.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || " _-.,:/".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// The program's bytes.
pub fn emit(points: &[EmitPoint], o: &EmitOptions) -> Vec<u8> {
    let st = style(o.dialect);
    let (rd, ld) = (o.rotary_decimals, o.linear_decimals);
    let p = o.primary_letter as char;
    let name = clean(&o.name);
    let mut body: Vec<String> = Vec::with_capacity(points.len() + 8);
    let mut feed: Option<f64> = None;
    let mut motion: Option<bool> = None;
    for q in points {
        let mut words = Vec::with_capacity(8);
        if motion != Some(q.rapid) {
            words.push(if q.rapid { "G00" } else { "G01" }.to_string());
            motion = Some(q.rapid);
        }
        words.push(format!("X{}", st.render(q.xyz_mm[0], ld)));
        words.push(format!("Y{}", st.render(q.xyz_mm[1], ld)));
        words.push(format!("Z{}", st.render(q.xyz_mm[2], ld)));
        words.push(format!("{p}{}", st.render(q.p_deg, rd)));
        words.push(format!("C{}", st.render(q.c_deg, rd)));
        if !q.rapid && q.feed_mm_min != feed {
            if let Some(f) = q.feed_mm_min {
                let plain = NumberStyle {
                    plus_sign: false,
                    ..st
                };
                words.push(format!("F{}", plain.render(f, 0)));
            }
            feed = q.feed_mm_min;
        }
        body.push(words.join(" "));
    }
    let mut out = String::new();
    let mut n = 0u64;
    match o.dialect {
        Dialect::Heidenhain | Dialect::Conversational | Dialect::Auto => {
            let mut block = |s: &str, out: &mut String| {
                n += 10;
                out.push_str(&format!("N{n} {s} *\n"));
            };
            out.push_str(&format!("%{name} G71 *\n"));
            for c in &o.comments {
                block(&format!("; {}", clean(c)), &mut out);
            }
            block("G90", &mut out);
            block("M128", &mut out);
            for b in &body {
                block(b, &mut out);
            }
            block("M129", &mut out);
            block("M30", &mut out);
            out.push_str(&format!("N999999 %{name} G71 *\n"));
        }
        Dialect::Sinumerik => {
            out.push_str(&format!("; {name}\n"));
            for c in &o.comments {
                out.push_str(&format!("; {}\n", clean(c)));
            }
            out.push_str("G90 G71\nTRAORI\n");
            for b in &body {
                out.push_str(b);
                out.push('\n');
            }
            out.push_str("TRAFOOF\nM30\n");
        }
        Dialect::Fanuc => {
            out.push_str(&format!("%\nO1000 ({name})\n"));
            for c in &o.comments {
                out.push_str(&format!("({})\n", clean(c)));
            }
            out.push_str("G90 G21\nG43.4 H1\n");
            for b in &body {
                out.push_str(b);
                out.push('\n');
            }
            out.push_str("G49\nM30\n%\n");
        }
    }
    out.into_bytes()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{modal, parse, runs};

    fn pts() -> Vec<EmitPoint> {
        vec![
            EmitPoint {
                xyz_mm: [0.0, 0.0, 50.0],
                p_deg: 10.0,
                c_deg: -5.0,
                feed_mm_min: None,
                rapid: true,
            },
            EmitPoint {
                xyz_mm: [1.25, 0.5, -8.0],
                p_deg: 14.825,
                c_deg: 137.259,
                feed_mm_min: Some(2000.0),
                rapid: false,
            },
            EmitPoint {
                xyz_mm: [2.0, 0.5, -8.0],
                p_deg: -0.5,
                c_deg: 400.0,
                feed_mm_min: Some(2000.0),
                rapid: false,
            },
        ]
    }

    /// Every dialect reads back (with the nc reader) to the same values, TCPM on, one run.
    #[test]
    fn every_dialect_reads_back() {
        for dialect in [Dialect::Heidenhain, Dialect::Sinumerik, Dialect::Fanuc] {
            let bytes = emit(
                &pts(),
                &EmitOptions {
                    dialect,
                    name: "T (1)".into(),
                    primary_letter: b'A',
                    rotary_decimals: 3,
                    linear_decimals: 3,
                    comments: vec!["from t.apt".into()],
                },
            );
            let prog = parse(bytes.clone(), Dialect::Auto).unwrap();
            assert_eq!(prog.dialect, dialect, "{}", String::from_utf8_lossy(&bytes));
            let r = runs(&prog);
            assert_eq!(r.len(), 1, "{}", String::from_utf8_lossy(&bytes));
            assert!(r[0].tcpm.is_on());
            assert_eq!(r[0].feed_mm_min, Some(2000.0));
            let last = r[0].pos.last().unwrap();
            assert_eq!(last[modal::A], Some(-0.5));
            assert_eq!(last[modal::C], Some(400.0));
            assert_eq!(last[modal::X], Some(2.0));
        }
    }
}
