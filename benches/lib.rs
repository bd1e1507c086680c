//! Shared helpers for the criterion benches.

/// File style of a generated program.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Style {
    /// Heidenhain ISO: `%NAME G71 *`, `N` numbers, `+` signs, `*` block ends, every
    /// word written in every block.
    Heidenhain,
    /// Fanuc: `%`, `O` number, `( )` comments, G43.4, unsigned numbers with trailing
    /// points, modal omission of unchanged words.
    Fanuc,
}

/// A 5-axis G1 finishing program of at least `bytes` bytes in `style` with no point
/// near the pole: the tilting axis (letter `primary`, `'A'` or `'B'`) stays within
/// 20°–35°, so a patcher with the default 5° cone finds no zone. C sweeps through ±180°
/// and beyond like a real spiral. The feed alternates between F2000 and F2500 every 4000
/// blocks, so the program has many runs (about one per 4000 points).
pub fn no_zone_program(bytes: usize, style: Style, primary: char) -> Vec<u8> {
    let mut text = Vec::with_capacity(bytes + 256);
    let p = primary;
    match style {
        Style::Heidenhain => text.extend_from_slice(
            format!("%BIG G71 *\nN10 G90 *\nN20 T5 *\nN30 M128 *\nN40 G01 X+0 Y+0 Z-8 {p}+25 C+0 F2000 *\n").as_bytes(),
        ),
        Style::Fanuc => text.extend_from_slice(
            format!("%\nO1000 (NO ZONE)\nG90 G21\nT5 M6\nG43.4 H5\nG1 X0. Y0. Z-8. {p}25. C0. F2000.\n").as_bytes(),
        ),
    }
    let mut k = 0u64;
    let mut n = 50u64;
    use std::fmt::Write;
    let mut line = String::with_capacity(96);
    while text.len() < bytes {
        let t = k as f64;
        let x = t * 0.01 % 500.0;
        let y = (t * 0.001).sin() * 20.0;
        let a = 27.5 + (t * 0.0003).cos() * 7.5;
        let c = (t * 0.07) % 720.0 - 360.0;
        line.clear();
        let feed_change = k > 0 && k.is_multiple_of(4000);
        let feed = if (k / 4000).is_multiple_of(2) {
            2000
        } else {
            2500
        };
        match style {
            Style::Heidenhain => {
                let _ = write!(line, "N{n} X{x:+.3} Y{y:+.3} Z-8 {p}{a:+.3} C{c:+.3}");
                if feed_change {
                    let _ = write!(line, " F{feed}");
                }
                line.push_str(" *\n");
            }
            Style::Fanuc => {
                // Z never changes: omitted, as a Fanuc post does.
                let _ = write!(line, "X{x:.3} Y{y:.3} {p}{a:.3} C{c:.3}");
                if feed_change {
                    let _ = write!(line, " F{feed}.");
                }
                if k.is_multiple_of(1000) {
                    let _ = write!(line, " (P{k})");
                }
                line.push('\n');
            }
        }
        text.extend_from_slice(line.as_bytes());
        k += 1;
        n += 10;
    }
    text.extend_from_slice(match style {
        Style::Heidenhain => b"N999999 M30 *\n".as_slice(),
        Style::Fanuc => b"M30\n%\n".as_slice(),
    });
    text
}
